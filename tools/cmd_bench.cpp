// `octray bench`: rays per second of octray and Embree, side by side (bench/README.md).
// Thin: parse, call bench/bench_runner.h, report.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "bench/bench_runner.h"
#include "bench/embree_baseline.h"
#include "core/thread_check.h"
#include "kernels/dispatch.h"
#include "render/image/image_io.h"
#include "render/prepare/scene_view.h"
#include "tools/cli_checks.h"
#include "tools/commands.h"

namespace octray::tools {
namespace {

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

std::string join(const std::vector<std::string>& items) {
    std::string out;
    for (const std::string& s : items) out += (out.empty() ? "" : ",") + s;
    return out;
}

// The options as a command line that reproduces the run (recorded in the report).
std::string command_line(const BenchArguments& a) {
    std::string c = "octray bench";
    for (const std::string& s : a.scenes) c += " " + s;
    if (!a.rays.empty()) c += " --rays " + join(a.rays);
    if (!a.threads.empty()) {
        std::vector<std::string> counts;
        for (int n : a.threads) counts.push_back(std::to_string(n));
        c += " --threads " + join(counts);
    }
    c += " --reps " + std::to_string(a.reps);
    if (a.warmup != 1) c += " --warmup " + std::to_string(a.warmup);
    char number[64];
    std::snprintf(number, sizeof number, "%g", a.min_time);
    c += std::string(" --min-time ") + number;
    if (a.max_spread != bench::BenchOptions::kDefaultMaxSpread) {
        std::snprintf(number, sizeof number, "%g", a.max_spread);
        c += std::string(" --max-spread ") + number;
    }
    c += " --width " + std::to_string(a.width) + " --height " + std::to_string(a.height);
    if (!a.tiles.empty()) c += " --tile " + join(a.tiles);
    if (!a.orders.empty()) c += " --order " + join(a.orders);
    if (!a.isas.empty()) c += " --isa " + join(a.isas);
    if (!a.paths.empty()) c += " --path " + join(a.paths);
    if (!a.accels.empty()) c += " --accel " + join(a.accels);
    if (!a.packet_lanes.empty()) {
        std::vector<std::string> lanes;
        for (std::uint32_t l : a.packet_lanes) lanes.push_back(std::to_string(l));
        c += " --packet-lanes " + join(lanes);
    }
    if (a.validate_rays != (1u << 16))
        c += " --validate-rays " + std::to_string(a.validate_rays);
    if (a.no_embree) c += " --no-embree";
    if (!a.json.empty()) c += " --json " + a.json;
    if (!a.csv.empty()) c += " --csv " + a.csv;
    return c;
}

// A CSV field: quoted when it holds a comma, a quote or a line break.
std::string csv_field(const std::string& text) {
    if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
    std::string out = "\"";
    for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

std::string csv_number(double value) {
    char text[64];
    std::snprintf(text, sizeof text, "%.17g", value);
    return text;
}

// The rows as CSV (RFC 4180), one line per row, for spreadsheets and plotting: the JSON
// rows' keys that are single values, ratio empty where there is none.
void write_csv_file(const bench::BenchReport& report, const std::string& path) {
    std::string text =
        "scene,ray_kind,system,mode,isa,accel,packet_min_lanes,order,tile,threads,rays,"
        "mrays_median,mrays_min,mrays_max,seconds_median,frames_per_second,hit_fraction,"
        "ratio_octray_over_embree,valid,spread,steady,build_quality\n";
    for (const bench::BenchRow& r : report.rows) {
        const std::vector<std::string> fields = {
            r.scene,
            bench::workload_name(r.workload),
            r.system,
            r.mode,
            r.isa,
            r.accel,
            std::to_string(r.packet_min_lanes),
            r.order,
            r.tile,
            std::to_string(r.threads),
            std::to_string(r.rays),
            csv_number(r.timing.mrays_median),
            csv_number(r.timing.mrays_min),
            csv_number(r.timing.mrays_max),
            csv_number(r.timing.seconds_median),
            bench::whole_frame(r.workload) ? csv_number(r.frames_per_second) : "",
            std::isnan(r.hit_fraction) ? "" : csv_number(r.hit_fraction),
            r.ratio ? csv_number(*r.ratio) : "",
            r.valid ? "true" : "false",
            csv_number(r.timing.spread),
            r.steady ? "true" : "false",
            r.build_quality == "-" ? "" : r.build_quality};
        std::string line;
        for (const std::string& f : fields) line += (line.empty() ? "" : ",") + csv_field(f);
        text += line + "\n";
    }
    write_file_atomically(path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        out << text;
        out.close();
        if (!out) throw IoError("cannot write " + tmp);
    });
}

// Each list option into its values; an unknown value is a usage error naming it.
template <class T, class Parse>
std::vector<T> parse_list(const std::vector<std::string>& items, const char* option,
                          Parse parse, std::vector<T> fallback) {
    if (items.empty()) return fallback;
    std::vector<T> out;
    for (const std::string& s : items) {
        const auto v = parse(s);
        if (!v) throw UsageError(std::string(option) + ": unknown value '" + s + "'");
        out.push_back(*v);
    }
    return out;
}

void run_bench_command(const BenchArguments& a) {
    // Before oneTBB starts a worker: it would abort where they cannot start (ulimit -v).
    for (const int n : a.threads) check_threads_can_start(n);
    if (a.threads.empty()) check_threads_can_start(0);
    bench::BenchOptions o;
    if (!a.scenes.empty()) o.scenes = a.scenes;
    if (!a.rays.empty()) {
        o.workloads.clear();
        for (const std::string& word : a.rays) {
            const std::vector<bench::Workload> ws = bench::parse_workloads(word);
            if (ws.empty()) throw UsageError("--rays: unknown value '" + word + "'");
            for (bench::Workload w : ws)
                if (std::find(o.workloads.begin(), o.workloads.end(), w) == o.workloads.end())
                    o.workloads.push_back(w);
        }
    }
    o.tiles = parse_list<TileSize>(
        a.tiles, "--tile", [](std::string_view s) { return parse_tile_size(s); }, o.tiles);
    o.orders =
        parse_list<bench::PixelOrder>(a.orders, "--order", bench::parse_pixel_order, o.orders);
    o.isas = parse_list<Isa>(a.isas, "--isa", parse_isa, o.isas);
    o.paths = parse_list<RenderPath>(a.paths, "--path", parse_render_path, o.paths);
    o.accels = parse_list<Accel>(a.accels, "--accel", parse_accel, o.accels);
    if (!a.packet_lanes.empty()) {
        o.packet_lanes = a.packet_lanes;
        o.packet_lanes_for_secondary = true;
    }
    for (Isa isa : o.isas)
        if (!isa_supported(isa))
            throw UsageError(std::string("--isa ") + isa_name(isa) +
                             ": this CPU does not support it");
    o.reps = a.reps;
    o.warmup = a.warmup;
    o.min_time = a.min_time;
    o.max_spread = a.max_spread;
    o.width = a.width;
    o.height = a.height;
    o.validate_rays = a.validate_rays;
    o.embree = !a.no_embree;
    o.command_line = command_line(a);

    if (!bench::embree_compiled())
        std::cerr
            << "octray bench: Embree 3 was not found when octray was built; measuring octray "
               "alone\n";
    // A --threads list is a scaling sweep: the whole run once per count, one row per
    // configuration and count, octray against Embree at the same count.
    bench::BenchReport report;
    const std::vector<int> counts = a.threads.empty() ? std::vector<int>{0} : a.threads;
    for (std::size_t k = 0; k < counts.size(); ++k) {
        o.threads = counts[k];
        bench::BenchReport part = bench::run_bench(o, &std::cerr);
        if (k == 0) {
            report = std::move(part);
        } else {
            report.rows.insert(report.rows.end(), part.rows.begin(), part.rows.end());
            report.context.wall_seconds += part.context.wall_seconds;
            report.context.timed_seconds += part.context.timed_seconds;
            report.context.validation_seconds += part.context.validation_seconds;
        }
    }
    bench::compute_ratios(report.rows);
    const bench::BenchContext& c = report.context;
    std::size_t unsteady = 0;
    for (const bench::BenchRow& r : report.rows) unsteady += r.steady ? 0 : 1;
    std::cerr << "octray bench: " << report.rows.size() << " rows in "
              << bench::format_duration(c.wall_seconds) << ": timed "
              << bench::format_duration(c.timed_seconds) << ", validation "
              << bench::format_duration(c.validation_seconds) << ", setup and the rest "
              << bench::format_duration(
                     std::max(0.0, c.wall_seconds - c.timed_seconds - c.validation_seconds))
              << "; " << unsteady << " unsteady (max/min of the repetitions past "
              << a.max_spread << ")\n";
    std::cout << '\n';
    bench::print_table(report, std::cout);
    if (!a.json.empty()) {
        bench::write_json_file(report, a.json);
        std::cerr << "wrote " << a.json << '\n';
    }
    if (!a.csv.empty()) {
        write_csv_file(report, a.csv);
        std::cerr << "wrote " << a.csv << '\n';
    }
}

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
                        " [default: 5]")
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
    cmd->callback([a, &run] { run.action = [a] { run_bench_command(*a); }; });
}

}  // namespace octray::tools
