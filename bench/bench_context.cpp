// The context of an `octray bench` report (the machine, the build, the run) and the
// engine's log lines.

#include <oneapi/tbb/info.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <ostream>
#include <string>
#include <thread>

#include "bench/bench_detail.h"
#include "core/version.h"
#include "kernels/dispatch.h"

namespace octray::bench::detail {

namespace {

std::string cpu_model() {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("model name", 0) == 0) {
            const std::size_t colon = line.find(':');
            if (colon != std::string::npos)
                return line.substr(line.find_first_not_of(' ', colon + 1));
        }
    }
    return "unknown";
}

double load_average() {
    std::ifstream in("/proc/loadavg");
    double load = 0.0;
    in >> load;
    return load;
}

std::string utc_date() {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char buffer[32];
    std::strftime(buffer, sizeof buffer, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buffer;
}

std::string compiler_name() {
#if defined(__clang__)
    return std::string("clang ") + __clang_version__;
#elif defined(__GNUC__)
    return std::string("g++ ") + __VERSION__;
#else
    return "unknown";
#endif
}

}  // namespace

BenchContext make_context(const BenchOptions& o) {
    BenchContext ctx;
    ctx.date = utc_date();
    ctx.cpu = cpu_model();
    ctx.logical_cpus = static_cast<int>(std::thread::hardware_concurrency());
    ctx.threads = o.threads > 0 ? o.threads : tbb::info::default_concurrency();
    ctx.isa = isa_name(resolve_isa(Isa::automatic));
    ctx.compiler = compiler_name();
    ctx.octray_version = kVersion;
    ctx.embree_available = embree_compiled() && o.embree;
#if OCTRAY_HAVE_EMBREE
    ctx.embree = o.embree ? "embree " + EmbreeScene::version() : "disabled (--no-embree)";
#else
    ctx.embree = "not built (Embree 3 was not found by CMake)";
#endif
    ctx.load_average = load_average();
    ctx.width = o.width, ctx.height = o.height, ctx.reps = o.reps, ctx.warmup = o.warmup;
    ctx.min_time = o.min_time, ctx.max_spread = o.max_spread;
    ctx.validate_rays = o.validate_rays;
    ctx.command_line = o.command_line;
    return ctx;
}

void log_line(std::ostream* log, const std::string& line) {
    if (log) *log << line << std::endl;
}

std::string format(const char* fmt, double a) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, fmt, a);
    return buffer;
}

namespace {
std::int64_t now_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
}
}  // namespace

Stopwatch::Stopwatch(double& total) : total_(total), start_ns_(now_ns()) {}
Stopwatch::~Stopwatch() { total_ += 1e-9 * static_cast<double>(now_ns() - start_ns_); }

}  // namespace octray::bench::detail

namespace octray::bench {

std::string format_duration(double seconds) {
    if (seconds < 10.0) return detail::format("%.1f s", seconds);
    const long s = std::lround(seconds);
    if (s < 60) return std::to_string(s) + " s";
    if (s < 3600) return std::to_string(s / 60) + " min " + std::to_string(s % 60) + " s";
    return std::to_string(s / 3600) + " h " + std::to_string(s % 3600 / 60) + " min";
}

}  // namespace octray::bench
