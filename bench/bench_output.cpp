// The output of `octray bench`: the table (a headline per scene and ray kind, then every
// row) and the JSON report (bench/README.md describes both; tests/bench and bench/plot.py
// read them).

#include <algorithm>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <tuple>
#include <vector>

#include "bench/bench_detail.h"
#include "bench/bench_runner.h"
#include "render/image/image_io.h"

namespace octray::bench {

using detail::format;

namespace {

// The thread counts of the rows, in the order measured (one for a run, more for a sweep).
std::vector<int> thread_counts(const BenchReport& report) {
    std::vector<int> counts;
    for (const BenchRow& r : report.rows)
        if (std::find(counts.begin(), counts.end(), r.threads) == counts.end())
            counts.push_back(r.threads);
    if (counts.empty()) counts.push_back(report.context.threads);
    return counts;
}

// The threads column of a sweep, in front of the others.
std::string format_threads(const std::string& text) {
    char cell[32];
    std::snprintf(cell, sizeof cell, "%7s ", text.c_str());
    return cell;
}

// The headline: one line per scene and ray kind (and thread count in a sweep) with the
// best valid octray row, the best valid Embree row and octray / Embree, before the detail.
void print_headline(const BenchReport& report, bool sweep, std::ostream& out) {
    struct Best {
        std::optional<double> octray, embree;
        bool octray_steady = true, embree_steady = true;  // the best rows'
    };
    std::vector<std::string> order;  // keys as first measured
    std::map<std::string, Best> best;
    std::map<std::string, std::tuple<std::string, std::string, int>> label;
    for (const BenchRow& r : report.rows) {
        const std::string key = r.scene + '\n' + workload_name(r.workload) + '\n' +
                                std::to_string(sweep ? r.threads : 0);
        if (!best.count(key)) {
            order.push_back(key);
            best[key] = {};
            label[key] = {r.scene, workload_name(r.workload), r.threads};
        }
        if (!r.valid) continue;
        const bool embree = r.system == "embree";
        std::optional<double>& b = embree ? best[key].embree : best[key].octray;
        if (b && *b >= r.timing.mrays_median) continue;
        b = r.timing.mrays_median;
        (embree ? best[key].embree_steady : best[key].octray_steady) = r.steady;
    }
    out << "Mrays/s, median of the repetitions; the best valid row of each system (the detail\n"
           "below has every configuration). octray/Embree > 1: octray is faster; below 1 it "
           "is\n"
           "marked LOSS. ~: that row is unsteady (its repetitions spread past the bound).\n"
           "still: scene made ready (compile + BVH build; Embree at its faster build quality)\n"
           "+ first frame; frame: a frame of a scene made ready before.\n";
    char line[256];
    std::snprintf(line, sizeof line, "%-14s %-9s %s%12s %12s %14s\n", "scene", "rays",
                  sweep ? "threads " : "", "octray", "Embree", "octray/Embree");
    // (a LOSS ratio is wider than its column; it is the last one)
    out << line;
    for (const std::string& key : order) {
        const Best& b = best[key];
        const auto& [scene, rays, threads] = label[key];
        const auto cell = [](const std::optional<double>& v, bool steady) {
            return v ? format("%.2f", *v) + (steady ? "" : "~") : std::string("-");
        };
        const bool compared = b.octray && b.embree && *b.embree > 0.0;
        const std::string ratio =
            compared ? format("%.3f", *b.octray / *b.embree) +
                           (*b.octray < *b.embree ? std::string(" LOSS") : std::string())
                     : std::string("-");
        const std::string thread_cell = sweep ? format_threads(std::to_string(threads)) : "";
        std::snprintf(line, sizeof line, "%-14s %-9s %s%12s %12s %14s\n", scene.c_str(),
                      rays.c_str(), thread_cell.c_str(),
                      cell(b.octray, b.octray_steady).c_str(),
                      cell(b.embree, b.embree_steady).c_str(), ratio.c_str());
        out << line;
    }
    out << "\n";
}

std::string join_counts(const std::vector<int>& counts) {
    std::string out;
    for (int n : counts) out += (out.empty() ? "" : ",") + std::to_string(n);
    return out;
}

}  // namespace

void print_table(const BenchReport& report, std::ostream& out) {
    const BenchContext& c = report.context;
    const std::vector<int> counts = thread_counts(report);
    const bool sweep = counts.size() > 1;  // then a threads column
    out << "octray bench " << c.octray_version << "  " << c.date << "\n"
        << "CPU: " << c.cpu << " (" << c.logical_cpus << " logical), threads "
        << join_counts(counts) << ", octray ISA " << c.isa << ", " << c.compiler << "\n"
        << "Embree: " << c.embree << "\n"
        << "frame " << c.width << "x" << c.height << ", " << c.reps << " timed reps after "
        << c.warmup << " warm-up, each rep at least " << format("%.3g s", c.min_time)
        << " (runs repeated), unsteady past max/min " << format("%.3g", c.max_spread)
        << ", load average at start " << format("%.2f", c.load_average) << "\n";
    if (c.wall_seconds > 0.0)
        out << "time: " << format_duration(c.wall_seconds) << " in all: timed "
            << format_duration(c.timed_seconds) << ", validation "
            << format_duration(c.validation_seconds) << ", setup and the rest "
            << format_duration(
                   std::max(0.0, c.wall_seconds - c.timed_seconds - c.validation_seconds))
            << "\n";
    if (!c.command_line.empty()) out << "command: " << c.command_line << "\n";
    for (const SceneInfo& s : report.scenes) {
        out << "scene " << s.spec << ": " << s.objects << " objects (" << s.spheres
            << " spheres, " << s.planes << " planes), " << s.lights << " lights; compile "
            << format("%.3f ms", s.compile_ms) << ", first pixel "
            << format("%.1f ms", s.first_pixel_ms);
        if (s.embree_build_ms)
            out << ", Embree BVH " << format("%.3f ms", *s.embree_build_ms) << " (HIGH)";
        if (s.embree_build_low_ms && s.embree_build_medium_ms)
            out << ", LOW " << format("%.3f ms", *s.embree_build_low_ms) << ", MEDIUM "
                << format("%.3f ms", *s.embree_build_medium_ms) << " (stills use "
                << s.embree_still_quality << ")";
        if (s.embree_bytes_per_sphere)
            out << " (" << format("%.1f", *s.embree_bytes_per_sphere) << " bytes/sphere)";
        if (s.bvh_build_ms)
            out << ", octray BVH " << format("%.3f ms", *s.bvh_build_ms) << " ("
                << format("%.1f", *s.bvh_bytes_per_sphere) << " bytes/sphere, " << s.bvh_nodes
                << " nodes, " << s.bvh_leaves << " leaves, depth " << s.bvh_depth << ")";
        if (s.primary_rays || s.shadow_rays || s.secondary_rays)
            out << "; ray sets: " << s.primary_rays << " primary, " << s.shadow_rays
                << " shadow, " << s.secondary_rays << " secondary";
        out << "\n";
    }
    out << "\n";
    print_headline(report, sweep, out);
    out << "Detail:\n";
    char line[512];
    std::snprintf(
        line, sizeof line,
        "%-14s %-9s %-6s %-7s %-6s %-6s %-8s %-5s %9s %6s %9s %9s %9s %7s %6s %8s %s\n",
        "scene", "rays", "system", "mode", "isa", "accel", "order", "tile", "count", "hit%",
        "Mrays/s", "min", "max", "spread", "runs", "oct/emb", "valid");
    if (sweep) out << format_threads("threads");
    out << line;
    for (const BenchRow& r : report.rows) {
        const std::string ratio = r.ratio ? format("%.3f", *r.ratio) : "-";
        const std::string hit =
            std::isnan(r.hit_fraction) ? "-" : format("%.1f", 100.0 * r.hit_fraction);
        const std::string spread = format("%.2f", r.timing.spread) + (r.steady ? " " : "~");
        const std::uint32_t runs =
            r.runs.empty() ? 0u : *std::min_element(r.runs.begin(), r.runs.end());
        std::snprintf(line, sizeof line,
                      "%-14s %-9s %-6s %-7s %-6s %-6s %-8s %-5s %9llu %6s %9.2f %9.2f %9.2f "
                      "%7s %6u %8s %s\n",
                      r.scene.c_str(), workload_name(r.workload), r.system.c_str(),
                      r.mode.c_str(), r.isa.c_str(), r.accel_label().c_str(), r.order.c_str(),
                      r.tile.c_str(), static_cast<unsigned long long>(r.rays), hit.c_str(),
                      r.timing.mrays_median, r.timing.mrays_min, r.timing.mrays_max,
                      spread.c_str(), runs, ratio.c_str(),
                      !r.valid   ? "NO"
                      : r.steady ? "yes"
                                 : "yes, unsteady");
        if (sweep) out << format_threads(std::to_string(r.threads));
        out << line;
        if (whole_frame(r.workload))
            out << "               frames/s " << format("%.3f", r.frames_per_second)
                << (r.build_quality != "-" ? "; Embree build " + r.build_quality : "")
                << "; rays: " << r.counts.primary << " primary, " << r.counts.shadow
                << " shadow, " << r.counts.reflected << " reflected, " << r.counts.refracted
                << " refracted\n";
    }
    bool any_invalid = false;
    for (const BenchRow& r : report.rows)
        if (!r.valid) {
            if (!any_invalid) out << "\nInvalid rows (their speed means nothing):\n";
            any_invalid = true;
            out << "  " << r.scene << " " << workload_name(r.workload) << " " << r.system << " "
                << r.mode << " " << r.isa << ": " << r.validation << "\n";
        }
}

std::string report_json(const BenchReport& report) {
    using nlohmann::json;
    const BenchContext& c = report.context;
    json j;
    j["context"] = {
        {"date", c.date},
        {"cpu", c.cpu},
        {"logical_cpus", c.logical_cpus},
        {"threads", c.threads},
        {"thread_counts", thread_counts(report)},
        {"isa", c.isa},
        {"compiler", c.compiler},
        {"octray_version", c.octray_version},
        {"embree", c.embree},
        {"embree_available", c.embree_available},
        {"load_average", c.load_average},
        {"width", c.width},
        {"height", c.height},
        {"reps", c.reps},
        {"warmup", c.warmup},
        {"min_time", c.min_time},
        {"max_spread", c.max_spread},
        {"wall_seconds", c.wall_seconds},
        {"timed_seconds", c.timed_seconds},
        {"validation_seconds", c.validation_seconds},
        {"validate_rays", c.validate_rays},
        {"command", c.command_line},
    };
    j["scenes"] = json::array();
    for (const SceneInfo& s : report.scenes) {
        json js = {{"scene", s.spec},
                   {"objects", s.objects},
                   {"spheres", s.spheres},
                   {"planes", s.planes},
                   {"lights", s.lights},
                   {"epsilon", s.epsilon},
                   {"compile_ms", s.compile_ms},
                   {"first_pixel_ms", s.first_pixel_ms},
                   {"primary_rays", s.primary_rays},
                   {"shadow_rays", s.shadow_rays},
                   {"secondary_rays", s.secondary_rays}};
        js["embree_build_ms"] = s.embree_build_ms ? json(*s.embree_build_ms) : json(nullptr);
        js["embree_build_low_ms"] =
            s.embree_build_low_ms ? json(*s.embree_build_low_ms) : json(nullptr);
        js["embree_build_medium_ms"] =
            s.embree_build_medium_ms ? json(*s.embree_build_medium_ms) : json(nullptr);
        js["embree_still_quality"] =
            s.embree_still_quality.empty() ? json(nullptr) : json(s.embree_still_quality);
        js["embree_bytes_per_sphere"] =
            s.embree_bytes_per_sphere ? json(*s.embree_bytes_per_sphere) : json(nullptr);
        js["bvh_build_ms"] = s.bvh_build_ms ? json(*s.bvh_build_ms) : json(nullptr);
        js["bvh_bytes_per_sphere"] =
            s.bvh_bytes_per_sphere ? json(*s.bvh_bytes_per_sphere) : json(nullptr);
        js["bvh_nodes"] = s.bvh_nodes;
        js["bvh_leaves"] = s.bvh_leaves;
        js["bvh_depth"] = s.bvh_depth;
        j["scenes"].push_back(std::move(js));
    }
    j["rows"] = json::array();
    for (const BenchRow& r : report.rows) {
        json jr = {
            {"scene", r.scene},
            {"ray_kind", workload_name(r.workload)},
            {"system", r.system},
            {"mode", r.mode},
            {"isa", r.isa},
            {"accel", r.accel},
            {"packet_min_lanes", r.packet_min_lanes},
            {"order", r.order},
            {"tile", r.tile},
            {"threads", r.threads},
            {"rays", r.rays},
            {"mrays_median", r.timing.mrays_median},
            {"mrays_min", r.timing.mrays_min},
            {"mrays_max", r.timing.mrays_max},
            {"seconds", r.seconds},
            {"runs", r.runs},
            {"spread", r.timing.spread},
            {"steady", r.steady},
            {"whole_frame", whole_frame(r.workload)},
            {"valid", r.valid},
            {"validation", r.validation},
            {"counts",
             {{"primary", r.counts.primary},
              {"shadow", r.counts.shadow},
              {"reflected", r.counts.reflected},
              {"refracted", r.counts.refracted}}},
        };
        jr["hit_fraction"] = std::isnan(r.hit_fraction) ? json(nullptr) : json(r.hit_fraction);
        jr["frames_per_second"] =
            whole_frame(r.workload) ? json(r.frames_per_second) : json(nullptr);
        jr["build_quality"] = r.build_quality == "-" ? json(nullptr) : json(r.build_quality);
        jr["ratio_octray_over_embree"] = r.ratio ? json(*r.ratio) : json(nullptr);
        j["rows"].push_back(std::move(jr));
    }
    return j.dump(2) + "\n";
}

void write_json_file(const BenchReport& report, const std::string& path) {
    const std::string text = report_json(report);
    write_file_atomically(path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        out << text;
        out.close();
        if (!out) throw IoError("cannot write " + tmp);
    });
}

}  // namespace octray::bench
