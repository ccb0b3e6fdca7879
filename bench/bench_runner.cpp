// `octray bench`: scenes -> ray sets -> (validate, warm up, time) per system and mode ->
// rows -> table / JSON. Every system reads the same ray arrays and is scheduled the same
// way: chunks of kChunkRays rays spread over one TBB arena of `threads` threads.

#include "bench/bench_runner.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <sstream>
#include <thread>
#include <tuple>

#include "bench/embree_baseline.h"
#include "bench/embree_frames.h"
#include "core/version.h"
#include "kernels/bvh_build.h"
#include "kernels/dispatch.h"
#include "render/image_io.h"
#include "render/packet_renderer.h"
#include "render/reference.h"
#include "scene/compile.h"
#include "scene/load.h"

namespace octray::bench {

const char* workload_name(Workload workload) {
    switch (workload) {
        case Workload::primary:
            return "primary";
        case Workload::shadow:
            return "shadow";
        case Workload::secondary:
            return "secondary";
        case Workload::whitted:
            return "whitted";
    }
    return "?";
}

std::optional<Workload> parse_workload(std::string_view name) {
    for (Workload w :
         {Workload::primary, Workload::shadow, Workload::secondary, Workload::whitted})
        if (name == workload_name(w)) return w;
    return std::nullopt;
}

Timing summarize(std::vector<double> seconds, std::uint64_t rays) {
    Timing t;
    if (seconds.empty()) return t;
    std::sort(seconds.begin(), seconds.end());
    const std::size_t n = seconds.size();
    t.seconds_min = seconds.front();
    t.seconds_max = seconds.back();
    t.seconds_median =
        n % 2 == 1 ? seconds[n / 2] : 0.5 * (seconds[n / 2 - 1] + seconds[n / 2]);
    const auto rate = [rays](double s) {
        return s > 0.0 ? static_cast<double>(rays) / s / 1e6 : 0.0;
    };
    t.mrays_median = rate(t.seconds_median);
    t.mrays_min = rate(t.seconds_max);
    t.mrays_max = rate(t.seconds_min);
    return t;
}

namespace {

// Rays per task: large enough to amortise scheduling, small enough to balance two cores.
constexpr std::uint32_t kChunkRays = 4096;
// Builds of each BVH per scene. One build's time moves by a third from run to run on a VM
// (the first touch of fresh memory costs the most there, and the first build of a run
// pays for it more than the others); the median of five is steadier than of three.
constexpr int kBuildReps = 5;
static_assert(kChunkRays % kernels::kPacketWidth == 0);

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// f(first, n) over [0, count) in chunks, on the arena's threads.
void for_chunks(tbb::task_arena& arena, std::uint32_t count,
                const std::function<void(std::uint32_t, std::uint32_t)>& f) {
    const std::uint32_t chunks = (count + kChunkRays - 1) / kChunkRays;
    arena.execute([&] {
        tbb::parallel_for(
            tbb::blocked_range<std::uint32_t>(0, chunks, 1),
            [&](const tbb::blocked_range<std::uint32_t>& r) {
                for (std::uint32_t c = r.begin(); c < r.end(); ++c) {
                    const std::uint32_t first = c * kChunkRays;
                    f(first, std::min(kChunkRays, count - first));
                }
            },
            tbb::simple_partitioner());
    });
}

// One way of tracing a ray set into a hit set.
using Tracer = std::function<void(const RaySet&, HitSet&)>;

// Warm-up runs, then `reps` timed runs; the hits of the last run stay in `hits`.
std::vector<double> time_runs(const Tracer& trace, const RaySet& rays, HitSet& hits, int warmup,
                              int reps) {
    for (int i = 0; i < warmup; ++i) trace(rays, hits);
    std::vector<double> seconds;
    for (int i = 0; i < reps; ++i) {
        const auto start = Clock::now();
        trace(rays, hits);
        seconds.push_back(seconds_since(start));
    }
    return seconds;
}

// octray's packet kernels over the set: closest_hit, or any_hit into the occluded flags.
Tracer octray_simd_tracer(tbb::task_arena& arena, const kernels::KernelTable& table,
                          const kernels::SceneView& view) {
    return [&arena, &table, view](const RaySet& rays, HitSet& hits) {
        if (rays.kind == RayKind::shadow) {
            // any_hit writes 0 / 1 per ray (whole packets); mapped to kNoHit / kOccluded
            // after timing by occluded_to_hits().
            auto* flags = reinterpret_cast<std::uint32_t*>(hits.object.data());
            for_chunks(arena, rays.count, [&](std::uint32_t first, std::uint32_t n) {
                table.any_hit(view, rays.shadow_stream(first), n, flags + first);
            });
            return;
        }
        for_chunks(arena, rays.count, [&](std::uint32_t first, std::uint32_t n) {
            table.closest_hit(view, rays.ray_stream(first), n, rays.t_min, hits.stream(first));
        });
    };
}

void occluded_to_hits(HitSet& hits, std::uint32_t count) {
    for (std::uint32_t i = 0; i < count; ++i)
        hits.object[i] = hits.object[i] != 0 ? kOccluded : kernels::kNoHit;
}

// The scalar reference, one ray at a time.
Tracer octray_scalar_tracer(tbb::task_arena& arena, const ReferenceTracer& tracer) {
    return [&arena, &tracer](const RaySet& rays, HitSet& hits) {
        const bool any = rays.kind == RayKind::shadow;
        for_chunks(arena, rays.count, [&](std::uint32_t first, std::uint32_t n) {
            for (std::uint32_t i = first; i < first + n; ++i) {
                const Ray ray = rays.ray(i);
                if (any) {
                    hits.object[i] = tracer.occluded(ray) ? kOccluded : kernels::kNoHit;
                    continue;
                }
                const std::optional<SurfaceHit> hit = tracer.intersect(ray);
                hits.t[i] = hit ? hit->t : kInfinity;
                hits.object[i] = hit ? static_cast<std::int32_t>(hit->object) : kernels::kNoHit;
            }
        });
    };
}

#if OCTRAY_HAVE_EMBREE
Tracer embree_tracer(tbb::task_arena& arena, const EmbreeScene& scene, EmbreeMode mode) {
    return [&arena, &scene, mode](const RaySet& rays, HitSet& hits) {
        // Camera rays are coherent; shadow and mirror rays are traced as incoherent.
        const bool coherent = rays.kind == RayKind::primary;
        const bool any = rays.kind == RayKind::shadow;
        for_chunks(arena, rays.count, [&](std::uint32_t first, std::uint32_t n) {
            if (any)
                scene.occluded(mode, rays, first, n, hits, coherent);
            else
                scene.intersect(mode, rays, first, n, hits, coherent);
        });
    };
}
#endif

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

void log_line(std::ostream* log, const std::string& line) {
    if (log) *log << line << std::endl;
}

std::string format(const char* fmt, double a) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, fmt, a);
    return buffer;
}

// The scalar oracle is brute force: checking 65 536 rays against 10^6 spheres would take
// minutes per ray set. The rays checked per set are capped at kOracleBudget / objects (at
// least kOracleMinRays); 0 (every ray) is taken as asked.
constexpr std::uint64_t kOracleBudget = 1ull << 30;  // ray-object tests per ray set
constexpr std::uint32_t kOracleMinRays = 1024;
std::uint32_t capped_validation(std::uint32_t asked, std::uint32_t objects) {
    if (asked == 0 || objects == 0) return asked;
    const std::uint64_t cap = std::max<std::uint64_t>(kOracleMinRays, kOracleBudget / objects);
    return static_cast<std::uint32_t>(std::min<std::uint64_t>(asked, cap));
}

// Loads the spec at the bench's resolution.
Scene load_bench_scene(const std::string& spec, int width, int height) {
    Scene scene = load_scene(spec);
    scene.image.width = width;
    scene.image.height = height;
    validate_scene(scene);
    return scene;
}

// Time to first pixel (SceneInfo::first_pixel_ms): what a user waits, from naming the scene
// to seeing its first tile, in the bench's arena. The median of three runs.
double time_to_first_pixel_ms(const std::string& spec, const BenchOptions& o,
                              tbb::task_arena& arena, int threads) {
    std::vector<double> ms;
    for (int run = 0; run < 3; ++run) {
        const auto start = std::chrono::steady_clock::now();
        arena.execute([&] {
            const Scene scene = load_bench_scene(spec, o.width, o.height);
            const CompiledScene compiled = compile_scene(scene);
            RenderOptions ro;
            ro.threads = threads;
            const TileSize tile = o.tiles.front();
            ro.tile_width = tile.width;
            ro.tile_height = tile.height;
            ro.crop = PixelRect{0, 0, std::min(tile.width, scene.image.width),
                                std::min(tile.height, scene.image.height)};
            (void)render_packet(compiled, ro);
        });
        ms.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count());
    }
    std::sort(ms.begin(), ms.end());
    return ms[1];
}

// The scene at the validation size of whole renders.
Scene validation_scene(const std::string& spec, const BenchOptions& o) {
    int width = std::min(o.width, o.validate_width),
        height = std::min(o.height, o.validate_height);
    // The reference render is brute force: shrink the image on large scenes (same budget
    // as the ray sets' oracle, counting pixels).
    const Scene probe = load_scene(spec);
    const auto objects =
        static_cast<std::uint64_t>(std::max<std::size_t>(1, probe.objects.size()));
    while (static_cast<std::uint64_t>(width) * height * objects > kOracleBudget &&
           width * height > 256)
        width = std::max(1, width / 2), height = std::max(1, height / 2);
    return load_bench_scene(spec, width, height);
}

// The packet render of the scene at the validation size equals the reference render,
// image and ray counts.
std::string validate_render(const std::string& spec, const BenchOptions& o, Isa isa,
                            Accel accel, bool& valid) {
    const Scene small = validation_scene(spec, o);
    RenderOptions ro;
    ro.threads = o.threads;
    ro.accel = accel;
    const RenderResult ref = render_reference(small, ro);
    const RenderResult simd = render_packet(small, ro, isa);
    valid = ref.image == simd.image && ref.rays.total() == simd.rays.total();
    return std::string(valid ? "valid" : "INVALID") + ": packet image " +
           (ref.image == simd.image ? "equals" : "differs from") + " the reference image at " +
           std::to_string(small.image.width) + "x" + std::to_string(small.image.height) +
           ", ray counts " + (ref.rays.total() == simd.rays.total() ? "equal" : "differ");
}

#if OCTRAY_HAVE_EMBREE
// An Embree frame (bench/embree_frames.h) at the validation size against the reference
// render: the same model on the same rays, so only Embree's roots, which round
// differently, may move a pixel (a shadow ray that grazes a sphere can flip a whole light
// term: sphereflake:4 at 320x180 has 0.56 % of its pixels off by more than 0.01, at
// 54.7 dB). Valid at PSNR >= kEmbreeFrameMinPsnr with at most kEmbreeFrameMaxOff of the
// pixels off by more than 0.01 in some channel, and the same number of primary rays.
constexpr double kEmbreeFrameMinPsnr = 45.0;
constexpr double kEmbreeFrameMaxOff = 0.01;
std::string validate_embree_render(const Scene& small, const EmbreeFrames& frames,
                                   const BenchOptions& o, bool& valid) {
    RenderOptions ro;
    ro.threads = o.threads;
    const RenderResult ref = render_reference(small, ro);
    const RenderResult e = frames.render(compile_scene(small), ro);
    double squared = 0.0, peak = 0.0;
    std::size_t off = 0;
    const std::size_t n = ref.image.pixel_count();
    for (std::size_t k = 0; k < n; ++k) {
        const Rgb a = ref.image.data()[k], b = e.image.data()[k];
        const double d[3] = {double(a.r) - b.r, double(a.g) - b.g, double(a.b) - b.b};
        squared += d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        peak = std::max({peak, double(a.r), double(a.g), double(a.b)});
        off += std::max({std::fabs(d[0]), std::fabs(d[1]), std::fabs(d[2])}) > 0.01 ? 1 : 0;
    }
    const double mse = squared / (3.0 * static_cast<double>(std::max<std::size_t>(n, 1)));
    const double psnr = mse > 0.0
                            ? 10.0 * std::log10(std::max(peak, 1.0) * std::max(peak, 1.0) / mse)
                            : std::numeric_limits<double>::infinity();
    const double off_fraction =
        static_cast<double>(off) / static_cast<double>(std::max<std::size_t>(n, 1));
    valid = psnr >= kEmbreeFrameMinPsnr && off_fraction <= kEmbreeFrameMaxOff &&
            ref.rays.primary == e.rays.primary;
    return std::string(valid ? "valid" : "INVALID") + ": Embree frame vs the reference at " +
           std::to_string(small.image.width) + "x" + std::to_string(small.image.height) +
           format(": PSNR %.1f dB", psnr) +
           format(", %.4f%% of pixels off by > 0.01", 100.0 * off_fraction) + ", rays " +
           std::to_string(e.rays.total()) + " vs " + std::to_string(ref.rays.total());
}
#endif

struct Variant {
    PixelOrder order;
    TileSize tile;
};

// A whole-frame row: warm-up frames, then o.reps timed ones (each frame's own seconds),
// the last frame's ray counts, the rates and frames per second.
void time_frames(BenchRow& row, const std::function<RenderResult()>& render,
                 const BenchOptions& o) {
    RenderResult last;
    for (int i = 0; i < o.warmup; ++i) last = render();
    for (int i = 0; i < o.reps; ++i) {
        last = render();
        row.seconds.push_back(last.seconds);
    }
    row.counts = last.rays;
    row.rays = last.rays.total();
    row.hit_fraction = std::nan("");
    row.timing = summarize(row.seconds, row.rays);
    row.frames_per_second =
        row.timing.seconds_median > 0.0 ? 1.0 / row.timing.seconds_median : 0.0;
}

// One configuration of the SIMD rows: brute force or the BVH with a packet/single switch.
struct SimdConfig {
    bool bvh;
    std::uint32_t lanes;
    kernels::SceneView view;
    Accel accel;  // as asked (a whole render resolves it itself)
};

}  // namespace

void compute_ratios(std::vector<BenchRow>& rows) {
    const auto key = [](const BenchRow& r) {
        // A --threads sweep compares the two systems at each thread count.
        return r.scene + '\n' + workload_name(r.workload) + '\n' + r.order + '\n' + r.tile +
               '\n' + std::to_string(r.threads);
    };
    std::map<std::string, double> best_embree, best_octray;
    for (const BenchRow& r : rows) {
        if (!r.valid) continue;
        auto& best = r.system == "embree" ? best_embree : best_octray;
        double& b = best[key(r)];
        b = std::max(b, r.timing.mrays_median);
    }
    for (BenchRow& r : rows) {
        r.ratio.reset();
        const auto& other = r.system == "embree" ? best_octray : best_embree;
        const auto it = other.find(key(r));
        if (it == other.end() || it->second <= 0.0 || r.timing.mrays_median <= 0.0) continue;
        r.ratio = r.system == "embree" ? it->second / r.timing.mrays_median
                                       : r.timing.mrays_median / it->second;
    }
}

BenchReport run_bench(const BenchOptions& o, std::ostream* log) {
    BenchReport report;
    BenchContext& ctx = report.context;
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
    ctx.validate_rays = o.validate_rays;
    ctx.command_line = o.command_line;

    // Forced ISAs are checked before any work.
    std::vector<Isa> isas;
    for (Isa isa : o.isas) {
        const Isa resolved = resolve_isa(isa);
        if (std::find(isas.begin(), isas.end(), resolved) == isas.end())
            isas.push_back(resolved);
    }

    tbb::task_arena arena(ctx.threads);
    const auto wants = [&](Workload w) {
        return std::find(o.workloads.begin(), o.workloads.end(), w) != o.workloads.end();
    };
    const bool ray_sets =
        wants(Workload::primary) || wants(Workload::shadow) || wants(Workload::secondary);

    // Pixel orders; a tile size matters to the tiled order only.
    std::vector<Variant> variants;
    for (PixelOrder order : o.orders) {
        if (order == PixelOrder::tiled)
            for (TileSize tile : o.tiles) variants.push_back({order, tile});
        else
            variants.push_back({order, o.tiles.front()});
    }

    for (const std::string& spec : o.scenes) {
        const Scene scene = load_bench_scene(spec, o.width, o.height);
        const CompiledScene compiled = compile_scene(scene);
        const kernels::SceneView view = make_scene_view(compiled);
        const ReferenceTracer reference(scene);

        SceneInfo info;
        info.spec = spec;
        info.first_pixel_ms = time_to_first_pixel_ms(spec, o, arena, ctx.threads);
        info.objects = static_cast<std::uint32_t>(scene.objects.size());
        info.spheres = compiled.spheres.count;
        info.planes = compiled.planes.count;
        info.lights = compiled.lights.count;
        info.epsilon = compiled.epsilon;
        info.compile_ms = compiled.compile_seconds * 1e3;

        // Both BVHs, on the bench's threads, kBuildReps times each (Embree's, then
        // octray's): the median build time is reported, the last builds are kept.
        std::vector<double> embree_builds, octray_builds;
#if OCTRAY_HAVE_EMBREE
        // Embree's best configuration (user geometry: its build is the one timed), and its
        // built-in sphere primitive, built once.
        std::unique_ptr<EmbreeScene> embree, embree_point;
        if (ctx.embree_available && (ray_sets || wants(Workload::whitted)))
            arena.execute([&] {
                embree_point = std::make_unique<EmbreeScene>(scene, compiled, o.threads,
                                                             EmbreeGeometry::sphere_point);
            });
#endif
        SphereBvh bvh;
        for (int build = 0; build < kBuildReps; ++build) {
#if OCTRAY_HAVE_EMBREE
            if (ctx.embree_available && (ray_sets || wants(Workload::whitted))) {
                embree.reset();
                arena.execute([&] {
                    embree = std::make_unique<EmbreeScene>(scene, compiled, o.threads,
                                                           EmbreeGeometry::user);
                });
                embree_builds.push_back(embree->build_seconds());
            }
#endif
            if (compiled.spheres.count > 0) {
                bvh = SphereBvh{};
                arena.execute([&] { bvh = build_sphere_bvh(compiled.spheres); });
                octray_builds.push_back(bvh.build_seconds);
            }
        }
#if OCTRAY_HAVE_EMBREE
        if (embree) {
            info.embree_build_ms = summarize(embree_builds, 0).seconds_median * 1e3;
            if (report.scenes.empty()) ctx.embree = embree->device_info();
        }
#endif
        if (compiled.spheres.count > 0) {
            info.bvh_build_ms = summarize(octray_builds, 0).seconds_median * 1e3;
            info.bvh_bytes_per_sphere = bvh.bytes_per_sphere();
            info.bvh_nodes = static_cast<std::uint32_t>(bvh.nodes.size());
            info.bvh_leaves = bvh.leaf_count;
            info.bvh_depth = bvh.depth;
        }
#if OCTRAY_HAVE_EMBREE
        if (embree && compiled.spheres.count > 0)
            info.embree_bytes_per_sphere =
                static_cast<double>(embree->memory_bytes()) / compiled.spheres.count;
#endif
        // Primary hits (the origins of shadow and mirror rays) come from the fastest view.
        const kernels::SceneView fast_view =
            bvh.nodes.empty() ? view : make_scene_view(compiled, bvh);
        const std::uint32_t validate_rays = capped_validation(o.validate_rays, info.objects);
        // The SIMD rows: each --accel value resolved for this scene (and each
        // --packet-lanes value with the BVH), without duplicates.
        std::vector<SimdConfig> simd_configs;
        for (Accel accel : o.accels) {
            const bool use_bvh = accel_uses_bvh(accel, compiled.spheres.count);
            if (!use_bvh && compiled.spheres.count > o.brute_force_max_spheres) {
                log_line(log, spec + ": skipping brute force (--accel " +
                                  std::string(accel_name(accel)) + ") on " +
                                  std::to_string(compiled.spheres.count) + " spheres");
                continue;
            }
            const std::vector<std::uint32_t> lanes =
                use_bvh ? o.packet_lanes : std::vector<std::uint32_t>{0};
            for (std::uint32_t l : lanes) {
                const bool seen = std::any_of(
                    simd_configs.begin(), simd_configs.end(),
                    [&](const SimdConfig& c) { return c.bvh == use_bvh && c.lanes == l; });
                if (seen) continue;
                simd_configs.push_back(
                    {use_bvh, l, use_bvh ? make_scene_view(compiled, bvh, l) : view, accel});
            }
        }
        if (bvh.sphere_count > 0)
            log_line(log,
                     spec + ": octray BVH built in " + format("%.3f ms", *info.bvh_build_ms) +
                         ", " + format("%.1f bytes/sphere", *info.bvh_bytes_per_sphere) +
                         (info.embree_bytes_per_sphere
                              ? ", Embree " +
                                    format("%.1f bytes/sphere", *info.embree_bytes_per_sphere)
                              : std::string()));
        log_line(log, spec + ": " + std::to_string(info.objects) + " objects, compiled in " +
                          format("%.3f ms", info.compile_ms) + ", first pixel after " +
                          format("%.1f ms", info.first_pixel_ms) +
                          (info.embree_build_ms ? ", Embree BVH built in " +
                                                      format("%.3f ms", *info.embree_build_ms)
                                                : std::string()));

        const auto base_row = [&](Workload w, const Variant& v) {
            BenchRow row;
            row.scene = spec;
            row.workload = w;
            row.order = w == Workload::whitted ? "tiled" : pixel_order_name(v.order);
            row.tile = w == Workload::whitted || v.order == PixelOrder::tiled
                           ? tile_size_name(v.tile)
                           : "-";
            row.threads = ctx.threads;
            return row;
        };

        for (const Variant& v : ray_sets ? variants : std::vector<Variant>{}) {
            const RaySet primary = make_primary_rays(
                reference, o.width, o.height, pixel_order(o.width, o.height, v.order, v.tile));
            // Shadow and mirror rays start at the primary hits (octray's packet hits, which
            // the primary rows validate against the oracle).
            HitSet primary_hits;
            primary_hits.resize(static_cast<std::uint32_t>(primary.ox.size()));
            octray_simd_tracer(arena, kernel_table(isas.back()), fast_view)(primary,
                                                                            primary_hits);

            for (Workload w : {Workload::primary, Workload::shadow, Workload::secondary}) {
                if (!wants(w)) continue;
                const RaySet rays = w == Workload::primary ? RaySet{}
                                    : w == Workload::shadow
                                        ? make_shadow_rays(scene, primary, primary_hits)
                                        : make_secondary_rays(scene, primary, primary_hits);
                const RaySet& set = w == Workload::primary ? primary : rays;
                (w == Workload::primary  ? info.primary_rays
                 : w == Workload::shadow ? info.shadow_rays
                                         : info.secondary_rays) = set.count;
                OracleHits oracle;
                arena.execute([&] { oracle = oracle_hits(reference, set, validate_rays); });

                const auto measure = [&](BenchRow row, const Tracer& trace,
                                         const OracleHits& truth, const ValidationRule& rule,
                                         bool octray_any_hit) {
                    HitSet hits;
                    hits.resize(static_cast<std::uint32_t>(set.ox.size()));
                    row.rays = set.count;
                    (w == Workload::primary  ? row.counts.primary
                     : w == Workload::shadow ? row.counts.shadow
                                             : row.counts.reflected) = set.count;
                    row.seconds = time_runs(trace, set, hits, o.warmup, o.reps);
                    if (octray_any_hit) occluded_to_hits(hits, set.count);
                    row.timing = summarize(row.seconds, row.rays);
                    row.hit_fraction = hit_fraction(hits, set.count);
                    const Validation val = validate_hits(hits, truth, rule);
                    row.valid = val.valid;
                    row.validation =
                        std::string(rule.exact ? "exact vs scalar oracle, "
                                               : "tolerance vs double-precision oracle, ") +
                        val.summary();
                    log_line(log, "  " + std::string(workload_name(w)) + " " + row.system +
                                      " " + row.mode + " " + row.isa + " " + row.accel_label() +
                                      " " + row.order + " " + row.tile + ": " +
                                      format("%.2f Mrays/s", row.timing.mrays_median) +
                                      (row.valid ? "" : " (INVALID: " + val.summary() + ")"));
                    report.rows.push_back(std::move(row));
                };

#if OCTRAY_HAVE_EMBREE
                if (embree) {
                    OracleHits truth;
                    arena.execute([&] { truth = oracle_hits_double(scene, set, oracle); });
                    for (const EmbreeScene* e : {embree.get(), embree_point.get()}) {
                        const bool user = e->geometry() == EmbreeGeometry::user;
                        for (EmbreeMode mode :
                             {EmbreeMode::packet16, EmbreeMode::packet8, EmbreeMode::single}) {
                            if (!user && mode == EmbreeMode::packet16) continue;
                            BenchRow row = base_row(w, v);
                            row.system = "embree";
                            row.mode = embree_mode_name(mode);
                            row.isa = embree_geometry_name(e->geometry());
                            measure(std::move(row), embree_tracer(arena, *e, mode), truth,
                                    kToleranceRule, false);
                        }
                    }
                }
#endif
                for (RenderPath path : o.paths) {
                    if (path == RenderPath::scalar) {
                        BenchRow row = base_row(w, v);
                        row.system = "octray";
                        row.mode = "single";
                        row.isa = "scalar";
                        measure(std::move(row), octray_scalar_tracer(arena, reference), oracle,
                                kExactRule, false);
                        continue;
                    }
                    for (Isa isa : isas) {
                        for (const SimdConfig& config : simd_configs) {
                            BenchRow row = base_row(w, v);
                            row.system = "octray";
                            row.mode = "packet8";
                            row.isa = isa_name(isa);
                            row.accel = config.bvh ? "bvh" : "none";
                            row.packet_min_lanes = config.lanes;
                            measure(std::move(row),
                                    octray_simd_tracer(arena, kernel_table(isa), config.view),
                                    oracle, kExactRule, w == Workload::shadow);
                        }
                    }
                }
            }
        }

        // Whole renders: the full Whitted workload, frame after frame.
        if (wants(Workload::whitted)) {
            std::map<std::pair<Isa, bool>, std::pair<bool, std::string>> render_validation;
            for (TileSize tile : o.tiles) {
                for (RenderPath path : o.paths) {
                    const std::vector<Isa> path_isas =
                        path == RenderPath::simd ? isas : std::vector<Isa>{Isa::automatic};
                    // Whole renders take --accel (one row each; the packet switch is the
                    // renderer's default).
                    std::vector<const SimdConfig*> configs;
                    for (const SimdConfig& c : simd_configs)
                        if (std::none_of(configs.begin(), configs.end(),
                                         [&](const SimdConfig* k) { return k->bvh == c.bvh; }))
                            configs.push_back(&c);
                    if (path == RenderPath::scalar || configs.empty()) configs = {nullptr};
                    for (Isa isa : path_isas)
                        for (const SimdConfig* config : configs) {
                            const Accel accel = config ? config->accel : Accel::none;
                            BenchRow row =
                                base_row(Workload::whitted, Variant{PixelOrder::tiled, tile});
                            row.system = "octray";
                            row.mode = path == RenderPath::simd ? "packet8" : "single";
                            row.isa = path == RenderPath::simd ? isa_name(isa) : "scalar";
                            if (config) row.accel = config->bvh ? "bvh" : "none";
                            if (path == RenderPath::simd) {
                                const auto key = std::make_pair(isa, config && config->bvh);
                                auto it = render_validation.find(key);
                                if (it == render_validation.end()) {
                                    bool ok = false;
                                    std::string text = validate_render(spec, o, isa, accel, ok);
                                    it =
                                        render_validation.emplace(key, std::make_pair(ok, text))
                                            .first;
                                }
                                row.valid = it->second.first;
                                row.validation = it->second.second;
                            } else {
                                row.valid = true;
                                row.validation = "the scalar reference is the oracle";
                            }
                            RenderOptions ro;
                            ro.threads = ctx.threads;
                            ro.tile_width = tile.width;
                            ro.tile_height = tile.height;
                            ro.accel = accel;
                            const auto render = [&] {
                                return path == RenderPath::simd
                                           ? render_packet(compiled, ro, isa)
                                           : render_reference(scene, ro);
                            };
                            time_frames(row, render, o);
                            log_line(log, "  whitted octray " + row.mode + " " + row.isa + " " +
                                              row.accel + " tile " + row.tile + ": " +
                                              format("%.3f frames/s", row.frames_per_second) +
                                              ", " +
                                              format("%.2f Mrays/s", row.timing.mrays_median));
                            report.rows.push_back(std::move(row));
                        }
                }
#if OCTRAY_HAVE_EMBREE
                // The same frames with Embree answering the hit queries (user geometry,
                // 16- and 8-wide packets of each generation's rays).
                if (embree) {
                    const Scene small = validation_scene(spec, o);
                    for (EmbreeMode mode : {EmbreeMode::packet16, EmbreeMode::packet8}) {
                        const EmbreeFrames frames(*embree, mode, isas.back());
                        BenchRow row =
                            base_row(Workload::whitted, Variant{PixelOrder::tiled, tile});
                        row.system = "embree";
                        row.mode = embree_mode_name(mode);
                        row.isa = embree_geometry_name(embree->geometry());
                        bool ok = false;
                        row.validation = validate_embree_render(small, frames, o, ok);
                        row.valid = ok;
                        RenderOptions ro;
                        ro.threads = ctx.threads;
                        ro.tile_width = tile.width;
                        ro.tile_height = tile.height;
                        // octray's frames build their BVH inside render_packet (an
                        // animation rebuilds it every frame); Embree's scene was built
                        // once before. So each Embree frame is charged one build, the
                        // median of the bench's builds of this scene, as octray's is.
                        const double build = info.embree_build_ms.value_or(0.0) * 1e-3;
                        time_frames(
                            row,
                            [&] {
                                RenderResult r = frames.render(compiled, ro);
                                r.seconds += build;
                                return r;
                            },
                            o);
                        log_line(log, "  whitted embree " + row.mode + " " + row.isa +
                                          " tile " + row.tile + ": " +
                                          format("%.3f frames/s", row.frames_per_second) +
                                          ", " +
                                          format("%.2f Mrays/s", row.timing.mrays_median) +
                                          (row.valid ? "" : " (" + row.validation + ")"));
                        report.rows.push_back(std::move(row));
                    }
                }
#endif
            }
        }
        report.scenes.push_back(std::move(info));
    }
    compute_ratios(report.rows);
    return report;
}

// ---- Output ------------------------------------------------------------------------------

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
        std::optional<double>& b = r.system == "embree" ? best[key].embree : best[key].octray;
        b = std::max(b.value_or(0.0), r.timing.mrays_median);
    }
    out << "Mrays/s, median of the repetitions; the best valid row of each system (the detail\n"
           "below has every configuration). octray/Embree > 1: octray is faster.\n";
    char line[256];
    std::snprintf(line, sizeof line, "%-14s %-9s %s%12s %12s %14s\n", "scene", "rays",
                  sweep ? "threads " : "", "octray", "Embree", "octray/Embree");
    out << line;
    for (const std::string& key : order) {
        const Best& b = best[key];
        const auto& [scene, rays, threads] = label[key];
        const auto cell = [](const std::optional<double>& v) {
            return v ? format("%.2f", *v) : std::string("-");
        };
        const std::string ratio = b.octray && b.embree && *b.embree > 0.0
                                      ? format("%.3f", *b.octray / *b.embree)
                                      : std::string("-");
        const std::string thread_cell = sweep ? format_threads(std::to_string(threads)) : "";
        std::snprintf(line, sizeof line, "%-14s %-9s %s%12s %12s %14s\n", scene.c_str(),
                      rays.c_str(), thread_cell.c_str(), cell(b.octray).c_str(),
                      cell(b.embree).c_str(), ratio.c_str());
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
        << c.warmup << " warm-up, load average at start " << format("%.2f", c.load_average)
        << "\n";
    if (!c.command_line.empty()) out << "command: " << c.command_line << "\n";
    for (const SceneInfo& s : report.scenes) {
        out << "scene " << s.spec << ": " << s.objects << " objects (" << s.spheres
            << " spheres, " << s.planes << " planes), " << s.lights << " lights; compile "
            << format("%.3f ms", s.compile_ms) << ", first pixel "
            << format("%.1f ms", s.first_pixel_ms);
        if (s.embree_build_ms) out << ", Embree BVH " << format("%.3f ms", *s.embree_build_ms);
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
    std::snprintf(line, sizeof line,
                  "%-14s %-9s %-6s %-7s %-6s %-6s %-8s %-5s %9s %6s %9s %9s %9s %8s %s\n",
                  "scene", "rays", "system", "mode", "isa", "accel", "order", "tile", "count",
                  "hit%", "Mrays/s", "min", "max", "oct/emb", "valid");
    if (sweep) out << format_threads("threads");
    out << line;
    for (const BenchRow& r : report.rows) {
        const std::string ratio = r.ratio ? format("%.3f", *r.ratio) : "-";
        const std::string hit =
            std::isnan(r.hit_fraction) ? "-" : format("%.1f", 100.0 * r.hit_fraction);
        std::snprintf(
            line, sizeof line,
            "%-14s %-9s %-6s %-7s %-6s %-6s %-8s %-5s %9llu %6s %9.2f %9.2f %9.2f %8s %s\n",
            r.scene.c_str(), workload_name(r.workload), r.system.c_str(), r.mode.c_str(),
            r.isa.c_str(), r.accel_label().c_str(), r.order.c_str(), r.tile.c_str(),
            static_cast<unsigned long long>(r.rays), hit.c_str(), r.timing.mrays_median,
            r.timing.mrays_min, r.timing.mrays_max, ratio.c_str(), r.valid ? "yes" : "NO");
        if (sweep) out << format_threads(std::to_string(r.threads));
        out << line;
        if (r.workload == Workload::whitted)
            out << "               frames/s " << format("%.3f", r.frames_per_second)
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
            r.workload == Workload::whitted ? json(r.frames_per_second) : json(nullptr);
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
