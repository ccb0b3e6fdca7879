// `octray render` as a batch renderer, end to end: animations and frame lists, a frame
// rendered alone equal to the same frame of a sequence, progress formats, shards run
// concurrently as array tasks would, crop + assemble, progressive passes, per-frame
// attributes and several scenes. Resume, claims, interrupts and failures:
// batch_resume_cli_test.cpp. Every image comparison is bit for bit.

#include <gtest/gtest.h>

#include "batch_cli_fixture.h"

namespace octray::testing {
namespace {

TEST_F(BatchCliTest, FrameRenderedAloneEqualsTheSameFrameOfTheSequence) {
    const auto all = run_octray(
        {"render", "shot.json", "-o", "out/shot.####.exr", "--progress", "lines"}, dir_);
    ASSERT_EQ(all.status, 0) << all.output;
    EXPECT_EQ(files_in("out"),
              (std::set<std::string>{"shot.0000.exr", "shot.0001.exr", "shot.0002.exr",
                                     "shot.0003.exr", "shot.0004.exr", "shot.0005.exr"}));
    const auto alone = run_octray({"render", "shot.json", "--frames", "3", "-o",
                                   "alone.{frame:04d}.exr", "--path", "scalar"},
                                  dir_);
    ASSERT_EQ(alone.status, 0) << alone.output;
    expect_same_pixels(read("out/shot.0003.exr"), read("alone.0003.exr"), "frame 3");
    // The animation moves things: frames differ.
    EXPECT_FALSE(read("out/shot.0000.exr").channels == read("out/shot.0005.exr").channels);
}

TEST_F(BatchCliTest, FrameSpecsPickTheFramesInOrder) {
    const auto r = run_octray({"render", "shot.json", "--frames", "0-4:2,5", "-o", "out/f#.exr",
                               "--progress", "json"},
                              dir_);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(files_in("out"), (std::set<std::string>{"f0.exr", "f2.exr", "f4.exr", "f5.exr"}));
    std::vector<int> order;
    std::istringstream lines(r.output);
    int summaries = 0;
    for (std::string line; std::getline(lines, line);) {
        const auto event = nlohmann::json::parse(line);  // every line is JSON
        if (event["event"] == "frame") order.push_back(event["frame"].get<int>());
        if (event["event"] == "summary") {
            ++summaries;
            EXPECT_EQ(event["rendered"], 4);
            EXPECT_EQ(event["failed"], 0);
        }
    }
    EXPECT_EQ(order, (std::vector<int>{0, 2, 4, 5}));
    EXPECT_EQ(summaries, 1);
}

// Issue 26: the frame line and the summary report trace time and rate apart from write time
// (EXR/PNG encoding), and `Progress: 100%` always follows the last frame's line.
TEST_F(BatchCliTest, FrameLinesReportTraceAndWriteTimesInAFixedOrder) {
    const std::regex frame_line(
        R"(frame [1-3]/3  shot frame [0-2]  -> out/t\.[0-2]\.exr \+ out/t\.[0-2]\.png  )"
        R"(prepare [0-9]+\.[0-9]{3} s  trace [0-9]+\.[0-9]{3} s  [0-9]+\.[0-9]{2} Mrays/s  )"
        R"(write [0-9]+\.[0-9]{3} s)");
    const std::regex summary(
        R"(done: 3 frames: 3 rendered, 0 skipped, 0 failed in \S+: )"
        R"(prepare \S+, trace \S+ \([0-9]+\.[0-9]{2} Mrays/s\), write \S+)");
    for (int run = 0; run < 4; ++run) {
        const auto r = run_octray(
            {"render", "shot.json", "--frames", "0-2", "--width", "64", "--height", "48", "-o",
             "out/t.#.exr", "--png", "out/t.#.png", "--progress", "lines"},
            dir_, /*capture_stderr=*/false);
        ASSERT_EQ(r.status, 0) << r.output;
        std::vector<std::string> lines;
        std::istringstream in(r.output);
        for (std::string line; std::getline(in, line);) lines.push_back(line);
        ASSERT_GE(lines.size(), 3u) << r.output;
        int frames = 0, hundreds = 0;
        for (const std::string& line : lines) {
            if (line.rfind("frame ", 0) == 0) {
                ++frames;
                EXPECT_TRUE(std::regex_match(line, frame_line)) << line;
            }
            hundreds += line == "Progress: 100%" ? 1 : 0;
        }
        EXPECT_EQ(frames, 3) << r.output;
        EXPECT_EQ(hundreds, 1) << r.output;
        const std::size_t n = lines.size();
        EXPECT_EQ(lines[n - 3].rfind("frame 3/3 ", 0), 0u) << r.output;
        EXPECT_EQ(lines[n - 2], "Progress: 100%") << r.output;
        EXPECT_TRUE(std::regex_match(lines[n - 1], summary)) << lines[n - 1];
    }

    // --progress json: the same figures as numbers; trace and write fit in the frame's time.
    const auto r = run_octray({"render", "shot.json", "--frames", "0", "--width", "64",
                               "--height", "48", "-o", "out/j.#.exr", "--progress", "json"},
                              dir_, false);
    ASSERT_EQ(r.status, 0) << r.output;
    std::istringstream in(r.output);
    int checked = 0;
    for (std::string line; std::getline(in, line);) {
        const auto event = nlohmann::json::parse(line);
        if (event["event"] == "progress") continue;
        for (const char* key :
             {"trace_seconds", "write_seconds", "seconds", "mrays_per_second"})
            ASSERT_TRUE(event.contains(key)) << key << "\n" << line;
        EXPECT_GT(event["trace_seconds"].get<double>(), 0.0) << line;
        EXPECT_GT(event["write_seconds"].get<double>(), 0.0) << line;
        EXPECT_LE(event["trace_seconds"].get<double>() + event["write_seconds"].get<double>(),
                  event["seconds"].get<double>() + 1e-3)
            << line;
        if (event["event"] == "frame") {
            // The phases of --stats: compile, BVH and render within the trace time; the
            // write time the frame's own.
            const nlohmann::json& phases = event.at("phases");
            double traced = 0.0;
            for (const char* key : {"compile_seconds", "bvh_seconds", "render_seconds"}) {
                ASSERT_TRUE(phases.at(key).is_number()) << key << "\n" << line;
                EXPECT_GE(phases[key].get<double>(), 0.0) << key;
                traced += phases[key].get<double>();
            }
            EXPECT_GT(phases["render_seconds"].get<double>(), 0.0) << line;
            EXPECT_LE(traced, event["trace_seconds"].get<double>() + 1e-3) << line;
            EXPECT_GT(phases.at("load_seconds").get<double>(), 0.0) << line;
            EXPECT_EQ(phases.at("write_seconds"), event["write_seconds"]) << line;
        }
        ++checked;
    }
    EXPECT_EQ(checked, 2) << r.output;  // the frame and the summary
}

TEST_F(BatchCliTest, OnATerminalAutoProgressIsALiveBar) {
    // `script` gives octray a pseudo-terminal, as a user's shell would.
    if (shell("command -v script >/dev/null") != 0) GTEST_SKIP() << "no script(1) here";
    const int status = shell("script -qec " +
                             shell_quote(shell_quote(OCTRAY_EXE) +
                                         " render shot.json --frames 0-2 -o 'out/b.#.exr'") +
                             " /dev/null > tty.txt 2>&1 </dev/null");
    ASSERT_EQ(status, 0);
    std::ifstream tty_file(dir_ / "tty.txt", std::ios::binary);
    const std::string tty((std::istreambuf_iterator<char>(tty_file)), {});
    EXPECT_TRUE(contains(tty, "\r\033[K[")) << tty;  // redrawn in place
    EXPECT_TRUE(contains(tty, "] 100%  frame 3/3")) << tty;
    EXPECT_TRUE(contains(tty, "ETA")) << tty;
    EXPECT_TRUE(contains(tty, "Mrays/s")) << tty;
    EXPECT_TRUE(contains(tty, "done: 3 frames: 3 rendered")) << tty;
    EXPECT_FALSE(contains(tty, "Progress: ")) << "lines mode on a terminal\n" << tty;
}

TEST_F(BatchCliTest, ConcurrentSlurmShardsRenderEachFrameOnceAndMatchOneProcess) {
    // The directory does not exist yet: render creates it (issue 26; it used to refuse).
    ASSERT_EQ(run_octray({"render", "shot.json", "-o", "single/s.####.exr"}, dir_).status, 0);

    // Three array tasks (ids 1..3, as `sbatch --array=1-3` numbers them) at once, sharing
    // one output directory, each claiming frames with placeholders.
    std::string command;
    for (int task = 1; task <= 3; ++task) {
        command += "SLURM_ARRAY_TASK_ID=" + std::to_string(task) +
                   " SLURM_ARRAY_TASK_MIN=1 SLURM_ARRAY_TASK_COUNT=3 " +
                   shell_quote(OCTRAY_EXE) +
                   " render shot.json --shard auto --placeholders --progress lines -o "
                   "out/s.####.exr > log" +
                   std::to_string(task) + ".txt 2>&1 </dev/null & ";
    }
    command += "wait";
    ASSERT_EQ(shell(command), 0);

    std::map<std::string, int> renders;  // frame file -> how many runs rendered it
    for (int task = 1; task <= 3; ++task) {
        std::ifstream log(dir_ / ("log" + std::to_string(task) + ".txt"));
        for (std::string line; std::getline(log, line);) {
            const auto arrow = line.find("-> out/");
            if (arrow != std::string::npos && contains(line, "Mrays/s"))
                ++renders[line.substr(arrow + 3, line.find(' ', arrow + 3) - (arrow + 3))];
        }
    }
    ASSERT_EQ(renders.size(), 6u);
    for (const auto& [file, count] : renders) EXPECT_EQ(count, 1) << file;
    for (int f = 0; f < 6; ++f) {
        const std::string name = "s.000" + std::to_string(f) + ".exr";
        expect_same_pixels(read("out/" + name), read("single/" + name), name);
    }
    EXPECT_TRUE(temporaries("out").empty());
}

TEST_F(BatchCliTest, KubernetesIndexNeedsAShardCount) {
    const auto r =
        run_octray({"render", "shot.json", "--shard", "auto", "-o", "out/k.#.exr"}, dir_);
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "SLURM_ARRAY_TASK_ID")) << r.output;
    const int status = shell("JOB_COMPLETION_INDEX=1 " + shell_quote(OCTRAY_EXE) +
                             " render shot.json --shard auto --shard-count 2 -o out/k.#.exr "
                             ">log.txt 2>&1 </dev/null");
    EXPECT_EQ(status, 0);
    EXPECT_EQ(files_in("out"), (std::set<std::string>{"k.1.exr", "k.3.exr", "k.5.exr"}));
}

TEST_F(BatchCliTest, CropsAssembleIntoTheFullFrameBitForBit) {
    ASSERT_EQ(run_octray({"render", "shot.json", "--frames", "2", "-o", "full.exr", "--aov",
                          "depth,id"},
                         dir_)
                  .status,
              0);
    const char* crops[] = {"0,0,17,11", "17,0,40,11", "0,11,40,30"};
    std::vector<std::string> args = {"assemble"};
    for (int i = 0; i < 3; ++i) {
        const std::string part = "part" + std::to_string(i) + ".exr";
        const auto r = run_octray({"render", "shot.json", "--frames", "2", "--crop", crops[i],
                                   "-o", part, "--aov", "depth,id"},
                                  dir_);
        ASSERT_EQ(r.status, 0) << r.output;
        args.push_back(part);
    }
    args.insert(args.end(), {"-o", "assembled.exr"});
    const auto assembled = run_octray(args, dir_);
    ASSERT_EQ(assembled.status, 0) << assembled.output;
    expect_same_pixels(read("assembled.exr"), read("full.exr"), "assembled");

    const auto outside = run_octray({"render", "shot.json", "--crop", "0,0,41,30"}, dir_);
    EXPECT_EQ(outside.status, 2) << outside.output;
}

TEST_F(BatchCliTest, ProgressiveFinalImageEqualsThePlainRender) {
    ASSERT_EQ(
        run_octray({"render", "shot.json", "--frames", "1", "--spp", "5", "-o", "plain.exr"},
                   dir_)
            .status,
        0);
    const auto r = run_octray({"render", "shot.json", "--frames", "1", "--spp", "5",
                               "--progressive", "-o", "passes.exr"},
                              dir_);
    ASSERT_EQ(r.status, 0) << r.output;
    expect_same_pixels(read("passes.exr"), read("plain.exr"), "progressive");
    Imf::InputFile file((dir_ / "passes.exr").c_str());
    EXPECT_EQ(file.header().findTypedAttribute<Imf::IntAttribute>("octray.samplesSoFar"),
              nullptr)
        << "the final image is marked unfinished";
}

TEST_F(BatchCliTest, EveryFrameCarriesItsAttributes) {
    ASSERT_EQ(run_octray({"render", "shot.json", "--frames", "4", "-o", "a.exr"}, dir_).status,
              0);
    Imf::InputFile file((dir_ / "a.exr").c_str());
    const Imf::Header& h = file.header();
    ASSERT_NE(h.findTypedAttribute<Imf::IntAttribute>("octray.frame"), nullptr);
    EXPECT_EQ(h.typedAttribute<Imf::IntAttribute>("octray.frame").value(), 4);
    ASSERT_TRUE(Imf::hasFramesPerSecond(h));
    EXPECT_EQ(Imf::framesPerSecond(h), Imf::Rational(24, 1));
    EXPECT_TRUE(Imf::hasWorldToCamera(h));
    EXPECT_TRUE(Imf::hasWorldToNDC(h));
    std::ifstream scene_file(dir_ / "shot.json", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(scene_file)), {});
    ASSERT_NE(h.findTypedAttribute<Imf::StringAttribute>("octray.sceneSha256"), nullptr);
    EXPECT_EQ(h.typedAttribute<Imf::StringAttribute>("octray.sceneSha256").value(),
              batch::sha256_hex(bytes));
}

// A built-in is identified by its spec string as given: hashing it is free, where the JSON
// of random:1048576 took seconds to write and hash.
TEST_F(BatchCliTest, ABuiltInsDigestIsItsSpecString) {
    const std::string spec = "random:4,width=16,height=12,seed=3";
    ASSERT_EQ(run_octray({"render", spec, "-o", "b.exr"}, dir_).status, 0);
    Imf::InputFile file((dir_ / "b.exr").c_str());
    const auto* digest =
        file.header().findTypedAttribute<Imf::StringAttribute>("octray.sceneSha256");
    ASSERT_NE(digest, nullptr);
    EXPECT_EQ(digest->value(), batch::sha256_hex(spec));
}

// --stats: one line per frame with the seconds of each phase (issue 19).
TEST_F(BatchCliTest, StatsPrintEachPhaseOfEachFrame) {
    const auto r =
        run_octray({"render", "shot.json", "--frames", "0,1", "--stats", "-o", "s#.exr"}, dir_,
                   /*with_stderr=*/true);
    ASSERT_EQ(r.status, 0) << r.output;
    for (const char* frame : {"stats: shot frame 0: load ", "stats: shot frame 1: load "})
        EXPECT_TRUE(contains(r.output, frame)) << r.output;
    for (const char* phase : {" s, compile ", " s, BVH ", " s, render ", " s, write "})
        EXPECT_TRUE(contains(r.output, phase)) << r.output;
}

TEST_F(BatchCliTest, SeveralScenesNeedSceneInThePattern) {
    const auto clash = run_octray(
        {"render", "shot.json", "random:4,width=16,height=12", "-o", "out/x.exr"}, dir_);
    EXPECT_EQ(clash.status, 2) << clash.output;
    const auto r = run_octray({"render", "shot.json", "random:4,width=16,height=12", "--frames",
                               "0-1", "-o", "out/{scene}.#.exr"},
                              dir_);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(files_in("out"), (std::set<std::string>{"shot.0.exr", "shot.1.exr",
                                                      "random-4.0.exr", "random-4.1.exr"}));
}

}  // namespace
}  // namespace octray::testing
