// bench/bench_runner.h: statistics, ratios, the JSON report's schema, and the frames' storage
// (timings are never asserted, only their shape).

#include "bench/bench_runner.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "bench/bench_detail.h"
#include "bench/embree_baseline.h"
#include "render/packet_renderer.h"
#include "scene/load.h"

namespace octray::bench {
namespace {

TEST(Summarize, MedianMinMaxOverRepetitions) {
    // 1e6 rays in 1, 2 and 4 seconds: 1, 0.5 and 0.25 Mrays/s.
    const Timing t = summarize({2.0, 4.0, 1.0}, 1000000);
    EXPECT_DOUBLE_EQ(t.seconds_median, 2.0);
    EXPECT_DOUBLE_EQ(t.mrays_median, 0.5);
    EXPECT_DOUBLE_EQ(t.mrays_min, 0.25);
    EXPECT_DOUBLE_EQ(t.mrays_max, 1.0);
    EXPECT_DOUBLE_EQ(summarize({1.0, 3.0}, 1000000).seconds_median, 2.0);
    EXPECT_DOUBLE_EQ(summarize({}, 10).mrays_median, 0.0);
    // The spread: the slowest repetition over the fastest.
    EXPECT_DOUBLE_EQ(t.spread, 4.0);
    EXPECT_DOUBLE_EQ(summarize({2.0}, 10).spread, 1.0);
}

// Issue 42: each timed repetition repeats its run until the seconds its runs count reach
// the minimum time, and counts their mean (a run here "takes" 3 ms: it only says so, so
// nothing depends on this machine's speed).
TEST(RepeatTimed, EachRepetitionRunsUntilTheMinimumTime) {
    BenchOptions o;
    o.warmup = 2;
    o.reps = 3;
    o.min_time = 0.010;
    int calls = 0;
    const auto run = [&calls] {
        ++calls;
        return 0.003;
    };
    const Repetitions reps = repeat_timed_in_rounds({run}, o).front();
    EXPECT_EQ(reps.runs, (std::vector<std::uint32_t>{4, 4, 4}));  // 4 x 3 ms >= 10 ms
    ASSERT_EQ(reps.seconds.size(), 3u);
    for (double s : reps.seconds) EXPECT_DOUBLE_EQ(s, 0.003);
    EXPECT_EQ(calls, 2 + 3 * 4);  // the warm-up runs are single runs

    o.min_time = 0.0;  // one run per repetition
    calls = 0;
    EXPECT_EQ(repeat_timed_in_rounds({run}, o).front().runs,
              (std::vector<std::uint32_t>{1, 1, 1}));
    EXPECT_EQ(calls, 2 + 3);
}

// Issue 42: the rows of one ray set are timed in rounds, one repetition of every row per
// round, the round's first row moving on by one each round; each repetition still runs
// until the minimum time, and the warm-up runs come first.
TEST(RepeatTimed, RowsAreTimedInRoundsOneRepetitionOfEachPerRound) {
    BenchOptions o;
    o.warmup = 1;
    o.reps = 3;
    o.min_time = 0.005;
    std::string order;
    std::vector<std::function<double()>> runs;
    for (const char name : {'a', 'b', 'c'})
        runs.push_back([&order, name] {
            order += name;
            return name == 'b' ? 0.003 : 0.005;  // b needs two runs a repetition
        });
    const std::vector<Repetitions> reps = repeat_timed_in_rounds(runs, o);
    EXPECT_EQ(order,
              "abc"
              "abbc"
              "bbca"
              "cabb");
    ASSERT_EQ(reps.size(), 3u);
    EXPECT_EQ(reps[0].runs, (std::vector<std::uint32_t>{1, 1, 1}));
    EXPECT_EQ(reps[1].runs, (std::vector<std::uint32_t>{2, 2, 2}));
    EXPECT_EQ(reps[2].seconds, (std::vector<double>{0.005, 0.005, 0.005}));
    // One row alone: its repetitions back to back.
    order.clear();
    EXPECT_EQ(repeat_timed_in_rounds({runs[1]}, o).front().runs,
              (std::vector<std::uint32_t>{2, 2, 2}));
    EXPECT_EQ(order,
              "b"
              "bbbbbb");
}

// The frames the TimeFrames tests time: a 16x8 whitted prepared once, one warm-up frame and
// two timed repetitions of one frame each.
struct TinyFrames {
    PreparedScene prepared{load_scene("whitted,width=16,height=8"), Accel::automatic, 1};
    BenchOptions o = [] {
        BenchOptions options;
        options.warmup = 1;
        options.reps = 2;
        options.min_time = 0.0;
        return options;
    }();
    // A frame into `spare` (nullptr: fresh storage); its first plane's storage goes to
    // `planes`.
    RenderResult render(Image* spare, std::vector<const float*>& planes) const {
        RenderOptions ro;
        ro.threads = 1;
        ro.spare_image = spare;
        RenderResult r = render_packet(prepared, ro);
        planes.push_back(r.image.plane(0));
        return r;
    }
};

// Issue 42: a `frame` row renders each frame into the storage of the frame before (as
// octray render's frame loop does with RenderOptions::spare_image); a `still` row maps
// fresh storage for every frame, as a one-picture render does.
TEST(TimeFrames, FramesRenderIntoTheLastFramesStorageStillsIntoFreshStorage) {
    const TinyFrames tiny;
    for (const bool reuse : {true, false}) {
        SCOPED_TRACE(reuse ? "frame" : "still");
        std::vector<const float*> planes;
        std::vector<bool> given_spare;
        std::vector<detail::FrameRow> rows{{BenchRow{},
                                            [&](Image* spare) {
                                                given_spare.push_back(spare != nullptr);
                                                return tiny.render(spare, planes);
                                            },
                                            reuse}};
        detail::time_frames_in_rounds(rows, tiny.o);
        const BenchRow& row = rows.front().row;
        ASSERT_EQ(planes.size(), 3u);   // one warm-up frame, two timed
        EXPECT_GE(row.rays, 16u * 8u);  // the last frame's rays, its primary rays at least
        for (std::size_t i = 0; i < planes.size(); ++i) {
            EXPECT_EQ(given_spare[i], reuse) << "frame " << i;
            if (reuse && i > 0) {
                EXPECT_EQ(planes[i], planes[0]) << "frame " << i;
            }
        }
    }
}

// Issue 42: whole-frame rows timed together go in rounds, and each row keeps its own
// storage: a frame row is handed the storage of its own frame before, never another row's.
TEST(TimeFrames, RowsInRoundsEachRenderIntoTheirOwnLastFrame) {
    const TinyFrames tiny;
    std::string order;
    std::vector<std::vector<const float*>> planes(2);
    std::vector<detail::FrameRow> rows;
    for (const int k : {0, 1})
        rows.push_back({BenchRow{},
                        [&, k](Image* spare) {
                            order += static_cast<char>('a' + k);
                            return tiny.render(spare, planes[k]);
                        },
                        true});
    detail::time_frames_in_rounds(rows, tiny.o);
    EXPECT_EQ(order,
              "ab"
              "ab"
              "ba");  // warm-up, then two rounds, the second from b
    for (const int k : {0, 1}) {
        ASSERT_EQ(planes[k].size(), 3u);
        EXPECT_EQ(planes[k][1], planes[k][0]);
        EXPECT_EQ(planes[k][2], planes[k][0]);
        EXPECT_EQ(rows[k].row.seconds.size(), 2u);
        EXPECT_GE(rows[k].row.rays, 16u * 8u);
    }
    EXPECT_NE(planes[0][0], planes[1][0]);
}

BenchRow row(std::string system, Workload w, double mrays, bool valid = true) {
    // Scene, order and tile stay empty: equal on every row, so one comparison group per
    // workload.
    BenchRow r;
    r.workload = w;
    r.system = std::move(system);
    r.timing.mrays_median = mrays;
    r.valid = valid;
    return r;
}

TEST(Ratios, OctrayRowsAreMeasuredAgainstTheBestValidEmbreeMode) {
    std::vector<BenchRow> rows{
        row("embree", Workload::primary, 10.0), row("embree", Workload::primary, 40.0),
        row("embree", Workload::primary, 400.0, false),  // invalid
        row("octray", Workload::primary, 20.0), row("octray", Workload::shadow, 5.0)};
    compute_ratios(rows);
    ASSERT_TRUE(rows[3].ratio);
    EXPECT_DOUBLE_EQ(*rows[3].ratio, 0.5);  // 20 / best valid Embree (40)
    EXPECT_DOUBLE_EQ(*rows[0].ratio, 2.0);  // best octray (20) / 10
    EXPECT_DOUBLE_EQ(*rows[1].ratio, 0.5);
    EXPECT_FALSE(rows[4].ratio);  // no Embree shadow row to compare with
}

// A small but complete run: every workload, both paths.
BenchReport small_run() {
    BenchOptions o;
    o.scenes = {"random:16"};
    o.width = 48;
    o.height = 24;
    o.reps = 2;
    o.warmup = 1;
    o.threads = 1;
    o.validate_rays = 0;
    o.validate_width = 48;
    o.validate_height = 24;
    o.paths = {RenderPath::simd, RenderPath::scalar};
    o.min_time = 0.002;
    o.command_line = "test";
    return run_bench(o);
}

TEST(Report, JsonHasTheContextAndRowsSchema) {
    const BenchReport report = small_run();
    const nlohmann::json j = nlohmann::json::parse(report_json(report));

    const nlohmann::json& c = j.at("context");
    for (const char* key :
         {"cpu", "isa", "compiler", "date", "embree", "octray_version", "command"})
        EXPECT_TRUE(c.at(key).is_string()) << key;
    EXPECT_EQ(c.at("threads").get<int>(), 1);
    EXPECT_EQ(c.at("embree_available").get<bool>(), embree_compiled());

    ASSERT_TRUE(j.at("scenes").is_array());
    ASSERT_EQ(j.at("scenes").size(), 1u);
    EXPECT_EQ(j["scenes"][0].at("spheres").get<int>(), 16);
    EXPECT_GT(j["scenes"][0].at("primary_rays").get<int>(), 0);
    // Time to first pixel: load, compile, BVH and one tile, so more than the compile alone.
    EXPECT_GT(j["scenes"][0].at("first_pixel_ms").get<double>(), 0.0);
    EXPECT_EQ(j["scenes"][0]["first_pixel_ms"].get<double>(), report.scenes[0].first_pixel_ms);

    const nlohmann::json& rows = j.at("rows");
    ASSERT_TRUE(rows.is_array());
    std::set<std::string> kinds, systems, modes;
    for (const nlohmann::json& r : rows) {
        for (const char* key : {"scene", "ray_kind", "system", "mode", "isa", "order", "tile"})
            ASSERT_TRUE(r.at(key).is_string()) << key;
        EXPECT_EQ(r.at("threads").get<int>(), 1);
        for (const char* key : {"mrays_median", "mrays_min", "mrays_max"})
            ASSERT_TRUE(r.at(key).is_number()) << key;
        EXPECT_LE(r["mrays_min"].get<double>(), r["mrays_median"].get<double>());
        EXPECT_LE(r["mrays_median"].get<double>(), r["mrays_max"].get<double>());
        EXPECT_TRUE(r.at("valid").get<bool>()) << r.at("validation");
        EXPECT_EQ(r.at("seconds").size(), 2u);
        // Each repetition's runs, and the spread of the repetitions against the bound.
        ASSERT_EQ(r.at("runs").size(), 2u);
        for (const auto& n : r["runs"]) EXPECT_GE(n.get<int>(), 1);
        EXPECT_GE(r.at("spread").get<double>(), 1.0);
        EXPECT_EQ(r.at("steady").get<bool>(),
                  r["spread"].get<double>() <= c.at("max_spread").get<double>());
        EXPECT_TRUE(r.at("counts").is_object());
        kinds.insert(r["ray_kind"].get<std::string>());
        systems.insert(r["system"].get<std::string>());
        modes.insert(r["mode"].get<std::string>());
        EXPECT_EQ(r.at("whole_frame").get<bool>(),
                  r["ray_kind"] == "still" || r["ray_kind"] == "frame");
        if (r["whole_frame"].get<bool>()) {
            EXPECT_GT(r.at("frames_per_second").get<double>(), 0.0);
            EXPECT_EQ(r["counts"]["primary"].get<int>(), 48 * 24);
        }
    }
    EXPECT_EQ(kinds,
              (std::set<std::string>{"primary", "shadow", "secondary", "still", "frame"}));
    // octray's packets are 8 rays, or 16 where it runs AVX-512 (brute force and BVH).
    EXPECT_TRUE((modes.count("packet8") || modes.count("packet16")) && modes.count("single"));
    EXPECT_EQ(systems.count("embree") == 1, embree_compiled());
    if (embree_compiled()) {
        // Every octray ray-set row has its ratio against Embree.
        for (const nlohmann::json& r : rows) {
            if (r["system"] == "octray" && !r["whole_frame"].get<bool>()) {
                EXPECT_TRUE(r.at("ratio_octray_over_embree").is_number());
            }
        }
    }

    // The file says the same, and the table names every scene and system.
    const std::filesystem::path dir = OCTRAY_TEST_TMPDIR;
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "bench_report.json").string();
    write_json_file(report, path);
    std::ifstream in(path);
    EXPECT_EQ(nlohmann::json::parse(in), j);
    std::ostringstream table;
    print_table(report, table);
    EXPECT_NE(table.str().find("random:16"), std::string::npos);
    EXPECT_NE(table.str().find("octray"), std::string::npos);
}

// Issue 42: a row whose repetitions spread past the bound is marked unsteady in the table
// (its spread with "~", "yes, unsteady", "~" after a headline figure it holds), and a
// headline ratio below 1 is marked LOSS.
TEST(Report, UnsteadyRowsAndLossesAreMarkedInTheTable) {
    BenchReport report;
    BenchOptions o;
    const auto add = [&](const char* system, std::vector<double> seconds) {
        BenchRow r;
        r.scene = "s";
        r.system = system;
        r.mode = "packet16";
        r.isa = "x";
        r.order = "tiled";
        r.tile = "16x16";
        r.threads = 2;
        r.rays = 1000000;
        r.seconds = std::move(seconds);
        r.runs.assign(r.seconds.size(), 3);
        r.timing = summarize(r.seconds, r.rays);
        r.steady = r.timing.spread <= o.max_spread;
        r.valid = true;
        report.rows.push_back(r);
    };
    add("octray", {1.0, 1.5, 1.1});    // spread 1.5: unsteady; 0.91 Mrays/s
    add("embree", {0.5, 0.51, 0.52});  // steady; 1.96 Mrays/s: octray loses
    EXPECT_FALSE(report.rows[0].steady);
    EXPECT_TRUE(report.rows[1].steady);
    compute_ratios(report.rows);
    std::ostringstream out;
    print_table(report, out);
    const std::string table = out.str();
    EXPECT_NE(table.find("1.50~"), std::string::npos) << table;
    EXPECT_NE(table.find("yes, unsteady"), std::string::npos) << table;
    EXPECT_NE(table.find("0.91~"), std::string::npos) << table;       // the headline's octray
    EXPECT_NE(table.find("0.464 LOSS"), std::string::npos) << table;  // 0.91 / 1.96
    const nlohmann::json j = nlohmann::json::parse(report_json(report));
    EXPECT_FALSE(j["rows"][0]["steady"].get<bool>());
    EXPECT_DOUBLE_EQ(j["rows"][0]["spread"].get<double>(), 1.5);
    EXPECT_EQ(j["rows"][0]["runs"], nlohmann::json::array({3, 3, 3}));
}

// Issue 42: the run says where its time went: the timed repetitions and the validation
// apart, both within the wall clock.
TEST(Report, TimedAndValidationSecondsAreAccountedApart) {
    const BenchReport report = small_run();
    const BenchContext& c = report.context;
    EXPECT_GT(c.timed_seconds, 0.0);
    EXPECT_GT(c.validation_seconds, 0.0);
    EXPECT_LE(c.timed_seconds + c.validation_seconds, c.wall_seconds);
    std::ostringstream table;
    print_table(report, table);
    EXPECT_NE(table.str().find("time: "), std::string::npos) << table.str();
    EXPECT_NE(table.str().find(", validation "), std::string::npos) << table.str();
}

// Issue 42: whole frames both ways for both systems. A still (octray: compile, BVH and
// first frame; Embree: the same compile, its build at its faster quality, LOW or MEDIUM,
// and the frame) and a frame of a prepared scene (octray: a PreparedScene; Embree: its
// HIGH build made before), every row validated against the reference render.
TEST(Report, WholeFramesAreMeasuredAsStillsAndAsPreparedFramesForBothSystems) {
    const BenchReport report = small_run();
    std::set<std::pair<std::string, std::string>> seen;  // (system, kind)
    for (const BenchRow& r : report.rows) {
        if (!whole_frame(r.workload)) continue;
        seen.insert({r.system, workload_name(r.workload)});
        EXPECT_TRUE(r.valid) << r.validation;
        if (r.system == "embree" && r.workload == Workload::still) {
            EXPECT_EQ(r.build_quality, report.scenes[0].embree_still_quality);
        } else {
            EXPECT_EQ(r.build_quality, "-");
        }
        if (r.system == "octray" && r.isa != "scalar") {
            EXPECT_NE(r.validation.find(r.workload == Workload::frame ? "prepared-scene"
                                                                      : "packet image"),
                      std::string::npos)
                << r.validation;
        }
    }
    EXPECT_TRUE(seen.count({"octray", "still"}));
    EXPECT_TRUE(seen.count({"octray", "frame"}));
    EXPECT_EQ(seen.count({"embree", "still"}) == 1, embree_compiled());
    EXPECT_EQ(seen.count({"embree", "frame"}) == 1, embree_compiled());
    const SceneInfo& scene = report.scenes[0];
    if (embree_compiled()) {
        ASSERT_TRUE(scene.embree_build_low_ms && scene.embree_build_medium_ms);
        // The faster of the two, as measured.
        EXPECT_EQ(
            scene.embree_still_quality,
            *scene.embree_build_low_ms <= *scene.embree_build_medium_ms ? "low" : "medium");
    }
    // --rays whitted asks for both kinds.
    EXPECT_EQ(parse_workloads("whitted"),
              (std::vector<Workload>{Workload::still, Workload::frame}));
    EXPECT_EQ(parse_workloads("frame"), (std::vector<Workload>{Workload::frame}));
    EXPECT_TRUE(parse_workloads("sideways").empty());
}

}  // namespace
}  // namespace octray::bench
