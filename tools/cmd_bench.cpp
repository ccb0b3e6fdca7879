// `octray bench`: its options (rays per second of octray and Embree, side by side,
// bench/README.md). The bench itself runs in octray-bench (tools/own_executable.h,
// tools/bench_run.cpp), the one executable that links Embree.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>

#include "bench/bench_runner.h"
#include "tools/bench_arguments.h"
#include "tools/cli_checks.h"
#include "tools/commands.h"
#include "tools/own_executable.h"

namespace octray::tools {
namespace {

// Limits of bench's own integer options (the shared ones are in cli_checks.h).
constexpr std::uint64_t kMaxPacketLanes = 9;  // 8 lanes: 9 means no packet is traced
constexpr std::uint64_t kMaxValidateRays = std::numeric_limits<std::uint32_t>::max();
constexpr double kMaxMinTime = 3600.0;  // an hour per repetition
constexpr double kMaxSpreadLimit = 1000.0;

std::string detail_number(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", value);
    return text;
}

}  // namespace

void add_bench_command(CLI::App& app, CommandRunner& run) {
    auto a = std::make_shared<BenchArguments>();
    CLI::App* cmd =
        app.add_subcommand("bench",
                           "Rays per second of octray and Embree 3 on the same scenes and rays "
                           "(bench/README.md)");
    cmd->add_option("scenes", a->scenes,
                    "Scenes [default: whitted random:16 random:1024 sphereflake:4]")
        ->type_name("SCENE...")
        ->check(completes(builtin_scene_words()));
    cmd->add_option("--rays", a->rays,
                    "Workloads: primary,shadow,secondary (ray sets); still (scene made ready + "
                    "first frame), frame (a frame of a scene made ready before), whitted (both "
                    "whole-frame kinds) [default: all]")
        ->delimiter(',')
        ->type_name("LIST");
    cmd->add_option("--threads", a->threads,
                    "Threads for both systems, each " + integer_range_text(0, kMaxThreadCount) +
                        "; a list (1,2,4) is a scaling sweep, rows for each count; 0 = all "
                        "cores [default: all cores]")
        ->delimiter(',')
        ->type_name("LIST")
        ->transform(decimal_integer(0, kMaxThreadCount));
    cmd->add_option("--reps", a->reps,
                    "Timed repetitions per row, " + integer_range_text(1, kNoIntegerLimit) +
                        "; the rows of a ray set (or of a tile size's stills or frames) take "
                        "theirs in rounds, one of each row per round, so that octray and "
                        "Embree are timed side by side [default: 5]")
        ->transform(decimal_integer(1, kNoIntegerLimit));
    cmd->add_option("--warmup", a->warmup,
                    "Untimed runs before them, " + integer_range_text(0, kNoIntegerLimit) +
                        "; 0 for none (the hits of the last timed run are validated) "
                        "[default: 1]")
        ->transform(decimal_integer(0, kNoIntegerLimit));
    cmd->add_option("--min-time", a->min_time,
                    "Seconds each timed repetition lasts at least: its ray set or frame is run "
                    "again until then, and the repetition counts their mean, " +
                        real_range_text(0.0, kMaxMinTime, false) +
                        "; 0 for one run [default: " +
                        detail_number(bench::BenchOptions::kDefaultMinTime) + "]")
        ->type_name("SECONDS")
        ->transform(real_number(0.0, kMaxMinTime, false));
    cmd->add_option("--max-spread", a->max_spread,
                    "A row whose slowest repetition took more than this many times its "
                    "fastest is marked unsteady, " +
                        real_range_text(1.0, kMaxSpreadLimit, false) + " [default: " +
                        detail_number(bench::BenchOptions::kDefaultMaxSpread) + "]")
        ->type_name("X")
        ->transform(real_number(1.0, kMaxSpreadLimit, false));
    cmd->add_option("--width", a->width,
                    "Frame width, " + integer_range_text(1, kMaxImageSide) + " [default: 1920]")
        ->transform(decimal_integer(1, kMaxImageSide));
    cmd->add_option(
           "--height", a->height,
           "Frame height, " + integer_range_text(1, kMaxImageSide) + " [default: 1080]")
        ->transform(decimal_integer(1, kMaxImageSide));
    cmd->add_option("--json", a->json, "Also write the report as JSON")->type_name("FILE");
    cmd->add_option("--csv", a->csv,
                    "Also write the rows as CSV (one line per row, the JSON rows' keys)")
        ->type_name("FILE");
    cmd->add_option("--tile", a->tiles,
                    "Tile sizes WxH (or N for NxN), sides " +
                        integer_range_text(1, kMaxTileSide) +
                        " (tiled order, whole renders); a list is measured in one run "
                        "[default: " +
                        tile_size_name(TileSize{}) + "]")
        ->delimiter(',')
        ->type_name("LIST")
        ->transform(tile_size(kMaxTileSide));
    cmd->add_option("--order", a->orders,
                    "Pixel orders of the rays: rowmajor, tiled, morton [default: tiled]")
        ->delimiter(',')
        ->type_name("LIST")
        ->check(completes({"rowmajor", "tiled", "morton"}));
    cmd->add_option("--isa", a->isas,
                    "octray kernel ISAs: auto, sse2, sse4.1, avx2, avx512 [default: auto]")
        ->delimiter(',')
        ->type_name("LIST")
        ->check(completes({"auto", "sse2", "sse4.1", "avx2", "avx512"}));
    cmd->add_option(
           "--path", a->paths,
           "octray paths: simd (packet kernels), scalar (the reference) [default: simd]")
        ->delimiter(',')
        ->type_name("LIST")
        ->check(completes({"simd", "scalar"}));
    cmd->add_option("--accel", a->accels,
                    "octray's sphere acceleration: auto (a BVH from " +
                        std::to_string(kBvhAutoMinSpheres) +
                        " spheres on), bvh, none (brute force; skipped above " +
                        std::to_string(bench::BenchOptions{}.brute_force_max_spheres) +
                        " spheres) [default: auto]")
        ->delimiter(',')
        ->type_name("LIST")
        ->check(completes({"auto", "bvh", "none"}));
    cmd->add_option("--packet-lanes", a->packet_lanes,
                    "With the BVH: packets with fewer live lanes go on ray by ray, each " +
                        integer_range_text(0, kMaxPacketLanes) + "; 0 packets only, " +
                        std::to_string(kMaxPacketLanes) +
                        " single rays only [default: " + std::to_string(kBvhPacketMinLanes) +
                        "; secondary rays " + std::to_string(kMaxPacketLanes) + " from " +
                        std::to_string(kBvhSecondaryRayByRayMinSpheres) + " spheres on, or " +
                        std::to_string(kBvhSecondaryRayByRayDenseMinSpheres) +
                        " where a line crosses " +
                        std::to_string(static_cast<int>(kBvhSecondaryRayByRayMinCrossings)) +
                        " or more]")
        ->delimiter(',')
        ->type_name("LIST")
        ->transform(decimal_integer(0, kMaxPacketLanes));
    cmd->add_option(
           "--validate-rays", a->validate_rays,
           "Rays per set checked against the oracles (octray rows: the scalar reference, bit "
           "for bit; Embree rows: double precision, within 1e-4, brute force, so at most "
           "2^30 / objects of them), " +
               integer_range_text(0, kMaxValidateRays) + "; 0 for all [default: 65536]")
        ->transform(decimal_integer(0, kMaxValidateRays));
    cmd->add_flag("--no-embree", a->no_embree, "Measure octray alone");
    cmd->footer(
        "Examples:\n"
        "  octray bench                                   # the default table\n"
        "  octray bench random:1024 --rays primary,shadow --threads 2 --json out.json\n"
        "  octray bench whitted --rays primary --csv rows.csv     # for a spreadsheet\n"
        "  octray bench random:1024 --rays primary --threads 1,2,4,8 # a scaling sweep\n"
        "  octray bench whitted --order rowmajor,tiled,morton --rays primary\n"
        "  octray bench random:65536 random:1048576 sphereflake:5 --rays primary,shadow "
        "--threads 2\n"
        "  octray bench random:256 --accel bvh,none --packet-lanes 0,3,5,9 --rays primary\n\n" +
        exit_code_help());
    cmd->callback(
        [a, &run] { run.action = [a] { OwnExecutable<BenchArguments>::run("bench", *a); }; });
}

}  // namespace octray::tools
