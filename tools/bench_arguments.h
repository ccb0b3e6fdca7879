#pragma once
// `octray bench`'s options (tools/cmd_bench.cpp) and its body, which runs in octray-bench
// (tools/own_executable.h, tools/bench_run.cpp): Embree is linked there only.

#include <cstdint>
#include <string>
#include <vector>

#include "bench/bench_runner.h"

namespace octray::tools {

struct BenchArguments {
    std::vector<std::string> scenes;
    std::vector<std::string> rays;
    std::vector<std::string> tiles;
    std::vector<std::string> orders;
    std::vector<std::string> isas;
    std::vector<std::string> paths;
    std::vector<std::string> accels;
    std::vector<std::uint32_t> packet_lanes;
    std::vector<int> threads;  // a scaling sweep; empty: every core
    int reps = 5, warmup = 1, width = 1920, height = 1080;
    double min_time = bench::BenchOptions::kDefaultMinTime;
    double max_spread = bench::BenchOptions::kDefaultMaxSpread;
    std::uint32_t validate_rays = 1u << 16;
    bool no_embree = false;
    std::string json;
    std::string csv;
};

// Measures and reports (bench/bench_runner.h), writes --json and --csv.
void run_bench_command(const BenchArguments& a);

}  // namespace octray::tools
