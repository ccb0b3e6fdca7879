// Batch specifications (render/batch/spec.h): frame specs, output patterns, shards, crops and
// scene names, with the message of every refusal.

#include "render/batch/spec.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "batch_checks.h"

namespace octray::batch {
namespace {

// Runs `f`, which must throw a SpecError whose message holds every needle.
void expect_spec_error(const std::function<void()>& f,
                       std::initializer_list<std::string> needles) {
    try {
        f();
        ADD_FAILURE() << "expected a SpecError";
    } catch (const SpecError& e) {
        const std::string what = e.what();
        for (const std::string& n : needles) {
            EXPECT_NE(what.find(n), std::string::npos)
                << "missing \"" << n << "\" in: " << what;
        }
    }
}

void expect_frame_error(const std::string& spec, std::initializer_list<std::string> needles) {
    SCOPED_TRACE(spec);
    expect_spec_error([&] { (void)parse_frame_spec(spec); }, needles);
}

std::vector<int> range(int first, int last, int step = 1) {
    std::vector<int> out;
    for (int f = first; f <= last; f += step) out.push_back(f);
    return out;
}

// ---------------------------------------------------------------------------------------
// Frame specs

TEST(FrameSpec, EveryForm) {
    EXPECT_EQ(parse_frame_spec("5"), std::vector<int>{5});
    EXPECT_EQ(parse_frame_spec("0"), std::vector<int>{0});
    EXPECT_EQ(parse_frame_spec("0-47"), range(0, 47));
    EXPECT_EQ(parse_frame_spec("3-3"), std::vector<int>{3});
    EXPECT_EQ(parse_frame_spec("1-100:2"), range(1, 99, 2));
    EXPECT_EQ(parse_frame_spec("0-10:5"), (std::vector<int>{0, 5, 10}));
    EXPECT_EQ(parse_frame_spec("0-10:20"), std::vector<int>{0});
    std::vector<int> expected = range(1, 99, 2);
    expected.push_back(150);
    EXPECT_EQ(parse_frame_spec("1-100:2,150"), expected);
    EXPECT_EQ(parse_frame_spec("007"), std::vector<int>{7});
    EXPECT_EQ(parse_frame_spec("2147483647"), std::vector<int>{2147483647});
    EXPECT_EQ(parse_frame_spec("2147483640-2147483647:4"),
              (std::vector<int>{2147483640, 2147483644}));
}

TEST(FrameSpec, OrderKeptAndRepeatsDropped) {
    EXPECT_EQ(parse_frame_spec("10,2,7"), (std::vector<int>{10, 2, 7}));
    EXPECT_EQ(parse_frame_spec("5,1-6,5,0"), (std::vector<int>{5, 1, 2, 3, 4, 6, 0}));
    EXPECT_EQ(parse_frame_spec("0-4,0-4"), range(0, 4));
}

TEST(FrameSpec, BlanksAroundNumbersAreIgnored) {
    EXPECT_EQ(parse_frame_spec(" 1 - 3 , 7 "), (std::vector<int>{1, 2, 3, 7}));
    EXPECT_EQ(parse_frame_spec("0-8 : 4"), (std::vector<int>{0, 4, 8}));
}

TEST(FrameSpec, Errors) {
    expect_frame_error("", {"frame spec \"\"", "the frame list is empty", "\"1-100:2\""});
    expect_frame_error("  ", {"empty"});
    expect_frame_error("a-b", {"in item \"a-b\"", "expected a first frame", "found \"a\""});
    expect_frame_error("1-b", {"expected a last frame after '-'", "found \"b\""});
    expect_frame_error("5-", {"in item \"5-\"", "expected a last frame", "found nothing"});
    expect_frame_error("-3", {"numbers start at 0", "found \"-3\""});
    expect_frame_error("2--3", {"numbers start at 0"});
    expect_frame_error("10-1", {"range runs backwards", "write \"1-10\""});
    expect_frame_error("1-10:0", {"expected a step >= 1, found 0"});
    expect_frame_error("1-10:", {"expected a step after ':'", "found nothing"});
    expect_frame_error("1-10:-2", {"numbers start at 0"});
    expect_frame_error("5:2", {"a step needs a range"});
    expect_frame_error("1:2-5", {"the step after the range"});
    expect_frame_error("1,,2", {"empty item"});
    expect_frame_error("1,", {"empty item"});
    expect_frame_error(",1", {"empty item"});
    expect_frame_error("1.5", {"decimal digits only", "found \"1.5\""});
    expect_frame_error("+4", {"decimal digits only"});
    expect_frame_error("1 0", {"decimal digits only"});
    expect_frame_error("1-2-3", {"found \"2-3\""});
    expect_frame_error("0x10", {"decimal digits only"});
    // Overflow: beyond int, beyond int64, absurdly long.
    expect_frame_error("2147483648", {"at most 2147483647", "found \"2147483648\""});
    expect_frame_error("0-99999999999999999999", {"at most 2147483647"});
    expect_frame_error(std::string(500, '9'), {"at most 2147483647", "..."});
    // Too many frames, also when the items overlap.
    expect_frame_error("0-1000000", {"more than 1000000 frames"});
    expect_frame_error("0-2147483647", {"more than 1000000 frames"});
    expect_frame_error("0-999999,0", {"more than 1000000 frames"});
    EXPECT_EQ(parse_frame_spec("0-999999").size(), 1000000u);
    // Control bytes are shown escaped.
    expect_frame_error(std::string("1\n"), {"\\x0a"});
}

// ---------------------------------------------------------------------------------------
// Output patterns

TEST(OutputPattern, HashRuns) {
    EXPECT_EQ(expand_output_pattern("out_####.exr", 7, "s"), "out_0007.exr");
    EXPECT_EQ(expand_output_pattern("out_#.exr", 7, "s"), "out_7.exr");
    EXPECT_EQ(expand_output_pattern("out_#.exr", 123, "s"), "out_123.exr");  // more digits
    EXPECT_EQ(expand_output_pattern("out_##.exr", 12345, "s"), "out_12345.exr");
    EXPECT_EQ(expand_output_pattern("a##b###", 5, "s"), "a05b005");
    EXPECT_EQ(expand_output_pattern("f####", 0, "s"), "f0000");
}

TEST(OutputPattern, BraceFields) {
    EXPECT_EQ(expand_output_pattern("{scene}_{frame}.exr", 42, "bounce"), "bounce_42.exr");
    EXPECT_EQ(expand_output_pattern("{scene}_{frame:04d}.exr", 42, "bounce"),
              "bounce_0042.exr");
    EXPECT_EQ(expand_output_pattern("{frame:01d}", 42, "b"), "42");
    EXPECT_EQ(expand_output_pattern("{frame:09d}", 42, "b"), "000000042");
    EXPECT_EQ(expand_output_pattern("{frame:02d}", 12345, "b"), "12345");
    EXPECT_EQ(expand_output_pattern("renders/{scene}/{scene}.png", 1, "random-8"),
              "renders/random-8/random-8.png");
}

TEST(OutputPattern, Escapes) {
    EXPECT_EQ(expand_output_pattern("{{frame}}_{frame}", 3, "s"), "{frame}_3");
    EXPECT_EQ(expand_output_pattern("a}}b{{c", 3, "s"), "a}b{c");
    EXPECT_EQ(expand_output_pattern("{{{frame}}}", 3, "s"), "{3}");
    EXPECT_FALSE(pattern_has_frame_field("{{frame}}.exr"));
}

TEST(OutputPattern, HasFrameField) {
    EXPECT_TRUE(pattern_has_frame_field("out_####.exr"));
    EXPECT_TRUE(pattern_has_frame_field("out_#.exr"));
    EXPECT_TRUE(pattern_has_frame_field("{frame}.exr"));
    EXPECT_TRUE(pattern_has_frame_field("x/{frame:04d}.exr"));
    EXPECT_FALSE(pattern_has_frame_field("{scene}.exr"));
    EXPECT_FALSE(pattern_has_frame_field("out.exr"));
    EXPECT_FALSE(pattern_has_frame_field(""));
}

TEST(OutputPattern, BadFields) {
    const auto bad = [](const std::string& pattern,
                        std::initializer_list<std::string> needles) {
        SCOPED_TRACE(pattern);
        expect_spec_error([&] { (void)expand_output_pattern(pattern, 1, "s"); }, needles);
        expect_spec_error([&] { (void)pattern_has_frame_field(pattern); }, needles);
    };
    bad("{fram}.exr",
        {"output pattern \"{fram}.exr\"", "unknown field \"{fram}\"", "{frame:04d}"});
    bad("{}.exr", {"unknown field \"{}\""});
    bad("{Frame}", {"unknown field"});
    bad("{frame:4d}", {"unsupported frame format \"{frame:4d}\""});
    bad("{frame:00d}", {"unsupported frame format"});
    bad("{frame:010d}", {"unsupported frame format"});
    bad("{frame:04}", {"unsupported frame format"});
    bad("{frame", {"never closed"});
    bad("out}.exr", {"a lone '}' at position 3"});
    bad("{scene", {"never closed"});
    expect_spec_error([] { (void)expand_output_pattern("#", -1, "s"); },
                      {"expected a frame number >= 0"});
}

// ---------------------------------------------------------------------------------------
// Shards

TEST(Shard, Parse) {
    const Shard s = parse_shard("2/5");
    EXPECT_EQ(s.index, 2);
    EXPECT_EQ(s.count, 5);
    EXPECT_EQ(parse_shard("0/1").count, 1);
    const auto bad = [](const std::string& text, std::initializer_list<std::string> needles) {
        SCOPED_TRACE(text);
        expect_spec_error([&] { (void)parse_shard(text); }, needles);
    };
    bad("4/4", {"shard \"4/4\"", "below the count", "numbered 0 to 3"});
    bad("1/0", {"expected a shard count >= 1"});
    bad("3", {"expected i/n"});
    bad("", {"expected i/n"});
    bad("/4", {"a shard index", "found nothing"});
    bad("1/", {"a shard count", "found nothing"});
    bad("-1/4", {"numbers start at 0"});
    bad("a/4", {"decimal digits only"});
    bad("1/99999999999", {"at most 2147483647"});
    bad("1/2/3", {"decimal digits only"});
}

// The environment as a map, as shard_from_environment sees it.
std::function<const char*(const char*)> env(std::map<std::string, std::string> vars) {
    return [vars = std::move(vars)](const char* name) -> const char* {
        const auto it = vars.find(name);
        return it == vars.end() ? nullptr : it->second.c_str();
    };
}

TEST(Shard, Slurm) {
    Shard s = shard_from_environment(
        env({{"SLURM_ARRAY_TASK_ID", "3"}, {"SLURM_ARRAY_TASK_COUNT", "8"}}), std::nullopt);
    EXPECT_EQ(s.index, 3);
    EXPECT_EQ(s.count, 8);
    // --array=1-8: ids start at 1.
    s = shard_from_environment(env({{"SLURM_ARRAY_TASK_ID", "1"},
                                    {"SLURM_ARRAY_TASK_MIN", "1"},
                                    {"SLURM_ARRAY_TASK_COUNT", "8"}}),
                               std::nullopt);
    EXPECT_EQ(s.index, 0);
    EXPECT_EQ(s.count, 8);
    // --array=10-40:10: ids 10, 20, 30, 40.
    s = shard_from_environment(env({{"SLURM_ARRAY_TASK_ID", "40"},
                                    {"SLURM_ARRAY_TASK_MIN", "10"},
                                    {"SLURM_ARRAY_TASK_STEP", "10"},
                                    {"SLURM_ARRAY_TASK_COUNT", "4"}}),
                               std::nullopt);
    EXPECT_EQ(s.index, 3);
    EXPECT_EQ(s.count, 4);
    // The count may come from the caller instead; both must agree.
    s = shard_from_environment(env({{"SLURM_ARRAY_TASK_ID", "2"}}), 4);
    EXPECT_EQ(s.index, 2);
    EXPECT_EQ(s.count, 4);
    s = shard_from_environment(
        env({{"SLURM_ARRAY_TASK_ID", "2"}, {"SLURM_ARRAY_TASK_COUNT", "4"}}), 4);
    EXPECT_EQ(s.count, 4);
    // Slurm wins over a Kubernetes index.
    s = shard_from_environment(env({{"SLURM_ARRAY_TASK_ID", "1"},
                                    {"SLURM_ARRAY_TASK_COUNT", "2"},
                                    {"JOB_COMPLETION_INDEX", "0"}}),
                               std::nullopt);
    EXPECT_EQ(s.index, 1);
}

TEST(Shard, Kubernetes) {
    const Shard s = shard_from_environment(env({{"JOB_COMPLETION_INDEX", "5"}}), 6);
    EXPECT_EQ(s.index, 5);
    EXPECT_EQ(s.count, 6);
    // Empty variables count as unset.
    EXPECT_EQ(shard_from_environment(
                  env({{"SLURM_ARRAY_TASK_ID", ""}, {"JOB_COMPLETION_INDEX", "1"}}), 2)
                  .index,
              1);
}

TEST(Shard, EnvironmentErrors) {
    const auto bad = [](std::map<std::string, std::string> vars, std::optional<int> count,
                        std::initializer_list<std::string> needles) {
        expect_spec_error([&] { (void)shard_from_environment(env(vars), count); }, needles);
    };
    bad({}, std::nullopt,
        {"no array job found", "SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"});
    bad({}, 4, {"no array job found"});
    bad({{"JOB_COMPLETION_INDEX", "2"}}, std::nullopt,
        {"JOB_COMPLETION_INDEX=2", "Kubernetes", "expected a shard count"});
    bad({{"JOB_COMPLETION_INDEX", "6"}}, 6, {"gives shard 6 of 6", "below the count"});
    bad({{"JOB_COMPLETION_INDEX", "x"}}, 6, {"JOB_COMPLETION_INDEX=\"x\"", "decimal digits"});
    bad({{"JOB_COMPLETION_INDEX", "-1"}}, 6, {"numbers start at 0"});
    bad({{"JOB_COMPLETION_INDEX", "1"}}, 0, {"expected a shard count >= 1, found 0"});
    bad({{"SLURM_ARRAY_TASK_ID", "3"}}, std::nullopt,
        {"SLURM_ARRAY_TASK_COUNT is not", "expected both"});
    bad({{"SLURM_ARRAY_TASK_ID", "3"}, {"SLURM_ARRAY_TASK_COUNT", "3"}}, std::nullopt,
        {"gives shard 3 of 3"});
    bad({{"SLURM_ARRAY_TASK_ID", "2"}, {"SLURM_ARRAY_TASK_COUNT", "4"}}, 5,
        {"disagrees with SLURM_ARRAY_TASK_COUNT=4"});
    bad({{"SLURM_ARRAY_TASK_ID", "0"},
         {"SLURM_ARRAY_TASK_MIN", "1"},
         {"SLURM_ARRAY_TASK_COUNT", "4"}},
        std::nullopt, {"MIN + k * STEP"});
    bad({{"SLURM_ARRAY_TASK_ID", "15"},
         {"SLURM_ARRAY_TASK_MIN", "10"},
         {"SLURM_ARRAY_TASK_STEP", "10"},
         {"SLURM_ARRAY_TASK_COUNT", "4"}},
        std::nullopt, {"MIN + k * STEP"});
    bad({{"SLURM_ARRAY_TASK_ID", "1"},
         {"SLURM_ARRAY_TASK_STEP", "0"},
         {"SLURM_ARRAY_TASK_COUNT", "4"}},
        std::nullopt, {"expected a step >= 1"});
    bad({{"SLURM_ARRAY_TASK_ID", "1"}, {"SLURM_ARRAY_TASK_COUNT", "0"}}, std::nullopt,
        {"expected a count >= 1"});
    bad({{"SLURM_ARRAY_TASK_ID", "4294967296"}, {"SLURM_ARRAY_TASK_COUNT", "4"}}, std::nullopt,
        {"at most 2147483647"});
}

TEST(Shard, SelectIsInterleaved) {
    const std::vector<int> frames = {10, 11, 12, 13, 14, 15, 16};
    EXPECT_EQ(select_shard(frames, {0, 3}), (std::vector<int>{10, 13, 16}));
    EXPECT_EQ(select_shard(frames, {1, 3}), (std::vector<int>{11, 14}));
    EXPECT_EQ(select_shard(frames, {2, 3}), (std::vector<int>{12, 15}));
    EXPECT_EQ(select_shard(frames, {0, 1}), frames);
    EXPECT_TRUE(select_shard(frames, {7, 9}).empty());  // more shards than frames
    expect_spec_error([&] { (void)select_shard(frames, {3, 3}); }, {"0 <= index < count"});
}

TEST(Shard, ShardsAreDisjointAndCoverEveryFrame) {
    const std::vector<int> frames = parse_frame_spec("0-99:3,200,7,150-160");
    for (int count : {1, 2, 3, 7, 40, 100}) {
        std::multiset<int> all;
        std::size_t largest = 0, smallest = frames.size();
        for (int i = 0; i < count; ++i) {
            const std::vector<int> part = select_shard(frames, {i, count});
            all.insert(part.begin(), part.end());
            largest = std::max(largest, part.size());
            smallest = std::min(smallest, part.size());
        }
        EXPECT_EQ(all, std::multiset<int>(frames.begin(), frames.end())) << count;
        EXPECT_LE(largest - smallest, 1u) << count;  // balanced
    }
}

// ---------------------------------------------------------------------------------------
// Crops

TEST(Crop, Parse) {
    PixelRect c = parse_crop("0,0,64,48", 64, 48);
    EXPECT_EQ(c.x0, 0);
    EXPECT_EQ(c.y0, 0);
    EXPECT_EQ(c.x1, 64);
    EXPECT_EQ(c.y1, 48);
    c = parse_crop(" 10, 20 ,11,21", 64, 48);
    EXPECT_EQ(c.x0, 10);
    EXPECT_EQ(c.y0, 20);
    EXPECT_EQ(c.x1, 11);
    EXPECT_EQ(c.y1, 21);
}

TEST(Crop, Errors) {
    const auto bad = [](const std::string& text, std::initializer_list<std::string> needles) {
        SCOPED_TRACE(text);
        expect_spec_error([&] { (void)parse_crop(text, 64, 48); }, needles);
    };
    bad("", {"expected four pixel coordinates x0,y0,x1,y1"});
    bad("0,0,64", {"expected four"});
    bad("0,0,64,48,1", {"expected four"});
    bad("0,0,65,48", {"expected x1", "at most 64", "found \"65\"", "64 x 48 image"});
    bad("0,0,64,49", {"expected y1", "at most 48"});
    bad("10,0,10,48", {"expected x0 < x1", "x0 = 10, x1 = 10"});
    bad("0,30,64,20", {"expected y0 < y1"});
    bad("-1,0,64,48", {"numbers start at 0"});
    bad("0,0,,48", {"expected x1", "found nothing"});
    bad("a,0,64,48", {"decimal digits only"});
    bad("0,0,64.0,48", {"decimal digits only"});
    bad("64,0,64,48", {"expected x0 < x1"});
}

// ---------------------------------------------------------------------------------------
// Scene names

TEST(SceneDisplayName, BuiltinsAndFiles) {
    EXPECT_EQ(scene_display_name("whitted"), "whitted");
    EXPECT_EQ(scene_display_name("random:8,width=32"), "random-8");
    EXPECT_EQ(scene_display_name("sphereflake:3"), "sphereflake-3");
    EXPECT_EQ(scene_display_name("scenes/room.json"), "room");
    EXPECT_EQ(scene_display_name("/abs/path/my scene.v2.json"), "my_scene.v2");
    EXPECT_EQ(scene_display_name(""), "render");
    EXPECT_EQ(scene_display_name("dir/"), "render");
}

// ---------------------------------------------------------------------------------------
// The fuzzers' corpus (tests/fuzz/corpus/fuzz_{frame,crop}_spec) through their invariants

std::vector<std::string> corpus(const std::string& target) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::path(OCTRAY_SOURCE_DIR) / "tests" / "fuzz" / "corpus" / target;
    std::vector<fs::path> files;
    for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
        if (e.is_regular_file()) files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    std::vector<std::string> inputs;
    for (const fs::path& f : files) {
        std::ifstream in(f, std::ios::binary);
        inputs.emplace_back(std::istreambuf_iterator<char>(in),
                            std::istreambuf_iterator<char>());
    }
    return inputs;
}

TEST(BatchFuzzCorpus, FrameSpecInputsKeepTheInvariants) {
    const std::vector<std::string> inputs = corpus("fuzz_frame_spec");
    ASSERT_GE(inputs.size(), 10u);
    for (const std::string& input : inputs) {
        SCOPED_TRACE(input.substr(0, 80));
        EXPECT_NO_THROW(fuzz::check_frame_spec(input));
    }
}

TEST(BatchFuzzCorpus, CropSpecInputsKeepTheInvariants) {
    const std::vector<std::string> inputs = corpus("fuzz_crop_spec");
    ASSERT_GE(inputs.size(), 10u);
    for (const std::string& input : inputs) {
        SCOPED_TRACE(input.substr(0, 80));
        EXPECT_NO_THROW(fuzz::check_crop_spec(input));
    }
}

}  // namespace
}  // namespace octray::batch
