// `octray bench`'s body, linked into octray-bench (tools/own_executable.h): rays per second
// of octray and Embree, side by side (bench/README.md). Thin: call bench/bench_runner.h,
// report.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <string_view>
#include <vector>

#include "bench/bench_runner.h"
#include "bench/embree_baseline.h"
#include "core/thread_check.h"
#include "kernels/dispatch.h"
#include "render/image/image_io.h"
#include "render/prepare/scene_view.h"
#include "tools/bench_arguments.h"
#include "tools/cli_checks.h"
#include "tools/commands.h"

namespace octray::tools {
namespace {

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

}  // namespace

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

}  // namespace octray::tools
