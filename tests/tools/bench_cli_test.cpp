// `octray bench` end to end: the table, the JSON report and its required keys, Embree
// side by side when it was built in (and the one-line notice when it was not), and the
// exit codes of bad input. Tiny frames and one repetition: this checks behaviour, not
// speed (speed lives in bench/).

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "bench/embree_baseline.h"
#include "run_octray.h"

namespace octray {
namespace {

namespace fs = std::filesystem;
using testing::run_octray;

class BenchCliTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = fs::path(OCTRAY_TEST_TMPDIR) / "bench_cli" /
               ::testing::UnitTest::GetInstance()->current_test_info()->name();
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    fs::path dir_;
};

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

nlohmann::json read_json(const fs::path& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
}

TEST_F(BenchCliTest, JsonReportHasContextAndValidatedRowsForEveryRayKind) {
    const auto r = run_octray(
        {"bench", "random:16", "--width", "48", "--height", "32", "--reps", "2", "--warmup",
         "1", "--threads", "2", "--rays", "primary,shadow,secondary,whitted", "--min-time",
         "0.002", "--json", "report.json"},
        dir_);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "Mrays/s") || contains(r.output, "mrays")) << r.output;
    const nlohmann::json report = read_json(dir_ / "report.json");
    ASSERT_TRUE(report.contains("context")) << report.dump(2);
    for (const char* key : {"cpu", "threads", "isa", "compiler", "date"})
        EXPECT_TRUE(report["context"].contains(key)) << key << "\n"
                                                     << report["context"].dump(2);
    ASSERT_TRUE(report["rows"].is_array());
    std::set<std::string> kinds, systems;
    for (const auto& row : report["rows"]) {
        for (const char* key : {"scene", "ray_kind", "system", "mode", "threads",
                                "mrays_median", "mrays_min", "mrays_max", "valid"})
            ASSERT_TRUE(row.contains(key)) << key << "\n" << row.dump(2);
        kinds.insert(row["ray_kind"].get<std::string>());
        systems.insert(row["system"].get<std::string>());
        EXPECT_EQ(row["scene"], "random:16");
        EXPECT_EQ(row["threads"], 2);
        EXPECT_TRUE(row["valid"].get<bool>()) << row.dump(2);
        const double lo = row["mrays_min"], mid = row["mrays_median"], hi = row["mrays_max"];
        EXPECT_GT(lo, 0.0) << row.dump(2);
        EXPECT_LE(lo, mid);
        EXPECT_LE(mid, hi);
    }
    // --rays whitted: whole frames both ways, a still and a frame of a prepared scene.
    EXPECT_EQ(kinds,
              (std::set<std::string>{"primary", "shadow", "secondary", "still", "frame"}));
    EXPECT_TRUE(systems.count("octray"));
    EXPECT_EQ(report["context"]["min_time"], 0.002);
    if (bench::embree_compiled()) {
        EXPECT_TRUE(systems.count("embree")) << "Embree was built in but has no rows";
    } else {
        EXPECT_FALSE(systems.count("embree"));
        EXPECT_TRUE(contains(r.output, "Embree 3 was not found")) << r.output;
    }
}

TEST_F(BenchCliTest, NoEmbreeMeasuresOctrayAlone) {
    const auto r = run_octray({"bench", "whitted", "--width", "32", "--height", "24", "--reps",
                               "1", "--rays", "primary", "--no-embree", "--json", "r.json"},
                              dir_);
    ASSERT_EQ(r.status, 0) << r.output;
    const nlohmann::json report = read_json(dir_ / "r.json");
    ASSERT_FALSE(report["rows"].empty());
    for (const auto& row : report["rows"]) EXPECT_EQ(row["system"], "octray") << row.dump(2);
}

TEST_F(BenchCliTest, ScalarAndSimdPathsAreBothRowsOfOneRun) {
    const auto r = run_octray(
        {"bench", "random:16", "--width", "32", "--height", "24", "--reps", "1", "--rays",
         "primary", "--path", "scalar,simd", "--no-embree", "--json", "r.json"},
        dir_);
    ASSERT_EQ(r.status, 0) << r.output;
    std::set<std::string> modes;
    const nlohmann::json report = read_json(dir_ / "r.json");
    for (const auto& row : report["rows"]) modes.insert(row["mode"].get<std::string>());
    EXPECT_GE(modes.size(), 2u) << "one mode per path expected";
}

// Issue 26: --threads takes a list, a scaling sweep with rows for each count (octray against
// Embree at the same count), and --warmup 0 is allowed.
TEST_F(BenchCliTest, ThreadListIsAScalingSweepAndWarmupZeroIsAllowed) {
    const auto r = run_octray(
        {"bench", "random:16", "--width", "32", "--height", "24", "--reps", "1", "--warmup",
         "0", "--rays", "primary", "--threads", "1,2", "--json", "r.json"},
        dir_);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "threads 1,2,")) << r.output;
    EXPECT_TRUE(contains(r.output, "--threads 1,2 ")) << r.output;  // the command line
    const nlohmann::json report = read_json(dir_ / "r.json");
    EXPECT_EQ(report["context"]["warmup"], 0);
    EXPECT_EQ(report["context"]["thread_counts"], nlohmann::json::array({1, 2}));
    std::set<int> threads;
    for (const auto& row : report["rows"]) {
        threads.insert(row["threads"].get<int>());
        EXPECT_TRUE(row["valid"].get<bool>()) << row.dump(2);
        // A ratio compares the two systems at one thread count.
        if (!row["ratio_octray_over_embree"].is_null()) {
            bool partner = false;
            for (const auto& other : report["rows"])
                partner |=
                    other["system"] != row["system"] && other["threads"] == row["threads"];
            EXPECT_TRUE(partner) << row.dump(2);
        }
    }
    EXPECT_EQ(threads, (std::set<int>{1, 2}));
}

// Issue 42: progress with an estimate of the time left while it runs, the total and where
// it went at the end (stderr), the minimum time per repetition in the report and the
// command, and bad values refused.
TEST_F(BenchCliTest, ProgressTotalAndMinimumTime) {
    const auto r = run_octray(
        {"bench", "random:16", "--width", "32", "--height", "24", "--reps", "2", "--rays",
         "primary,shadow", "--min-time", "0.001", "--max-spread", "1.5", "--json", "r.json"},
        dir_);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(contains(r.output, " left]")) << r.output;  // "[1/12 rows, 0.1 s, about..."
    EXPECT_TRUE(contains(r.output, " rows, ")) << r.output;
    EXPECT_TRUE(contains(r.output, "rows in ")) << r.output;  // the total at the end
    EXPECT_TRUE(contains(r.output, ", validation ")) << r.output;
    EXPECT_TRUE(contains(r.output, "--min-time 0.001 --max-spread 1.5")) << r.output;
    const nlohmann::json report = read_json(dir_ / "r.json");
    EXPECT_EQ(report["context"]["max_spread"], 1.5);
    for (const char* key : {"wall_seconds", "timed_seconds", "validation_seconds"})
        EXPECT_TRUE(report["context"].at(key).is_number()) << key;
    for (const auto& row : report["rows"]) {
        EXPECT_EQ(row.at("runs").size(), 2u) << row.dump(2);
        EXPECT_EQ(row.at("steady").get<bool>(), row.at("spread").get<double>() <= 1.5);
    }
    for (const std::vector<std::string>& bad : {std::vector<std::string>{"--min-time", "-1"},
                                                {"--min-time", "x"},
                                                {"--max-spread", "0.5"}}) {
        std::vector<std::string> command = {"bench", "--no-embree"};
        command.insert(command.end(), bad.begin(), bad.end());
        EXPECT_EQ(run_octray(command, dir_).status, 2) << bad[0] << " " << bad[1];
    }
}

// Issue 26: range errors say what the option takes, not a 300-digit number or 2^31 - 1.
TEST_F(BenchCliTest, RangeErrorsReadAsTheOptionsLimits) {
    const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
        {{"--warmup", "-1"}, "--warmup must be an integer >= 0"},
        {{"--reps", "0"}, "--reps must be an integer >= 1"},
        {{"--threads", "1,x"}, "--threads must be an integer from 0 to 4096 (got \"x\")"},
        {{"--packet-lanes", "10"}, "--packet-lanes must be an integer from 0 to 9"},
    };
    for (const auto& [args, message] : cases) {
        std::vector<std::string> command = {"bench", "--no-embree"};
        command.insert(command.end(), args.begin(), args.end());
        const auto r = run_octray(command, dir_);
        EXPECT_EQ(r.status, 2) << args[0] << "\n" << r.output;
        EXPECT_TRUE(contains(r.output, message)) << args[0] << "\n" << r.output;
        EXPECT_FALSE(contains(r.output, "2147483647")) << r.output;
    }
}

// Issue 26: one headline table (scene x ray kind: octray, Embree, ratio) before the
// detail, and --csv with one line per row besides --json.
TEST_F(BenchCliTest, HeadlineTableLeadsAndCsvHasOneLinePerRow) {
    const auto r = run_octray(
        {"bench", "random:16", "--width", "32", "--height", "24", "--reps", "1", "--rays",
         "primary,shadow", "--order", "rowmajor,tiled", "--json", "r.json", "--csv", "r.csv"},
        dir_, /*capture_stderr=*/false);
    ASSERT_EQ(r.status, 0) << r.output;
    const std::size_t headline = r.output.find("octray/Embree\n");
    const std::size_t detail = r.output.find("Detail:\n");
    ASSERT_NE(headline, std::string::npos) << r.output;
    ASSERT_NE(detail, std::string::npos) << r.output;
    EXPECT_LT(headline, detail) << r.output;
    // One headline line per scene and ray kind, however many orders were measured.
    const std::string head = r.output.substr(headline, detail - headline);
    std::size_t lines = 0;
    for (std::size_t at = head.find("\nrandom:16"); at != std::string::npos;
         at = head.find("\nrandom:16", at + 1))
        ++lines;
    EXPECT_EQ(lines, 2u) << head;
    EXPECT_TRUE(contains(head, "primary")) << head;
    EXPECT_TRUE(contains(head, "shadow")) << head;

    const nlohmann::json report = read_json(dir_ / "r.json");
    std::ifstream csv(dir_ / "r.csv");
    std::vector<std::string> rows;
    for (std::string line; std::getline(csv, line);) rows.push_back(line);
    ASSERT_EQ(rows.size(), report["rows"].size() + 1) << "a header and one line per row";
    EXPECT_EQ(rows[0].rfind("scene,ray_kind,system,mode,", 0), 0u) << rows[0];
    EXPECT_EQ(rows[1].rfind("random:16,primary,", 0), 0u) << rows[1];
    const auto fields = [](const std::string& line) {
        return std::count(line.begin(), line.end(), ',') + 1;
    };
    for (const std::string& row : rows) EXPECT_EQ(fields(row), fields(rows[0])) << row;
}

TEST_F(BenchCliTest, BadInputExitsWithItsCode) {
    EXPECT_EQ(run_octray({"bench", "--rays", "sideways"}, dir_).status, 2);
    EXPECT_EQ(run_octray({"bench", "--reps", "0"}, dir_).status, 2);
    EXPECT_EQ(run_octray({"bench", "--order", "spiral"}, dir_).status, 2);
    const auto scene = run_octray({"bench", "no-such-scene.json", "--reps", "1"}, dir_);
    EXPECT_EQ(scene.status, 3) << scene.output;
    EXPECT_TRUE(contains(scene.output, "no-such-scene.json")) << scene.output;
    const auto io =
        run_octray({"bench", "random:4", "--width", "16", "--height", "16", "--reps", "1",
                    "--rays", "primary", "--no-embree", "--json", "missing/dir/r.json"},
                   dir_);
    EXPECT_EQ(io.status, 4) << io.output;
    EXPECT_TRUE(contains(io.output, "missing/dir/r.json")) << io.output;
}

}  // namespace
}  // namespace octray
