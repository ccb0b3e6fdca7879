// `octray bench`: scenes -> ray sets -> (validate, warm up, time) per system and mode ->
// rows -> table / JSON. run_bench walks the scenes in named steps: set the scene up (load,
// compile, build both BVHs, choose the SIMD configurations), measure its ray sets (octray
// and Embree rows, each validated against an oracle), measure whole renders, and finally
// relate each row to the other system's best (compute_ratios). The tracers and timing live
// in bench_tracers.cpp, the checks in bench_validation.cpp, the output in bench_output.cpp.

#include "bench/bench_runner.h"

#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "bench/bench_detail.h"
#include "bench/embree_baseline.h"
#include "bench/embree_frames.h"
#include "kernels/dispatch.h"
#include "render/packet_renderer.h"
#include "render/prepare/bvh_build.h"
#include "render/prepare/scene_view.h"
#include "render/reference.h"
#include "scene/compile.h"

namespace octray::bench {

const char* workload_name(Workload workload) {
    switch (workload) {
        case Workload::primary:
            return "primary";
        case Workload::shadow:
            return "shadow";
        case Workload::secondary:
            return "secondary";
        case Workload::still:
            return "still";
        case Workload::frame:
            return "frame";
    }
    return "?";
}

std::optional<Workload> parse_workload(std::string_view name) {
    for (Workload w : {Workload::primary, Workload::shadow, Workload::secondary,
                       Workload::still, Workload::frame})
        if (name == workload_name(w)) return w;
    return std::nullopt;
}

std::vector<Workload> parse_workloads(std::string_view name) {
    if (name == "whitted") return {Workload::still, Workload::frame};
    const std::optional<Workload> w = parse_workload(name);
    return w ? std::vector<Workload>{*w} : std::vector<Workload>{};
}

bool whole_frame(Workload workload) {
    return workload == Workload::still || workload == Workload::frame;
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
    t.spread = t.seconds_min > 0.0 ? t.seconds_max / t.seconds_min : 1.0;
    t.mrays_median = rate(t.seconds_median);
    t.mrays_min = rate(t.seconds_max);
    t.mrays_max = rate(t.seconds_min);
    return t;
}

namespace {

using detail::format;
using detail::log_line;
using detail::Tracer;

// Builds of each BVH per scene. One build's time moves by a third from run to run on a VM
// (the first touch of fresh memory costs the most there, and the first build of a run
// pays for it more than the others); the median of five is steadier than of three.
constexpr int kBuildReps = 5;

struct Variant {
    PixelOrder order;
    TileSize tile;
};

// One configuration of the SIMD rows: brute force or the BVH with a packet/single switch.
struct SimdConfig {
    bool bvh;
    std::uint32_t lanes;
    kernels::SceneView view;
    Accel accel;  // as asked (a whole render resolves it itself)
};

// What one run_bench call shares between its steps.
struct BenchRun {
    const BenchOptions& o;
    std::ostream* log;
    BenchReport& report;
    tbb::task_arena& arena;
    std::vector<Isa> isas;     // resolved, without duplicates
    std::size_t variants = 1;  // pixel orders and tiles of the ray-set rows
    // Progress: rows measured, and rows planned (the scenes not yet set up are guessed to
    // have as many rows as the last one that was).
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
    int rows_done = 0, rows_planned = 0;
    bool wants(Workload w) const {
        return std::find(o.workloads.begin(), o.workloads.end(), w) != o.workloads.end();
    }
    // Some ray set is measured (primary, shadow or secondary rays).
    bool ray_sets() const {
        return wants(Workload::primary) || wants(Workload::shadow) ||
               wants(Workload::secondary);
    }
};

// One scene and everything built from it once, for every row of the scene.
struct BenchScene {
    BenchScene(const std::string& spec_, const BenchOptions& o)
        : spec(spec_),
          scene(detail::load_bench_scene(spec, o.width, o.height)),
          compiled(compile_scene(scene)),
          view(make_scene_view(compiled)),
          reference(scene) {}
    std::string spec;
    Scene scene;
    CompiledScene compiled;
    kernels::SceneView view;  // brute force
    ReferenceTracer reference;
    SphereBvh bvh;  // the last of the builds timed
#if OCTRAY_HAVE_EMBREE
    // Embree's best configuration (user geometry: its build is the one timed), and its
    // built-in sphere primitive, built once.
    std::unique_ptr<EmbreeScene> embree, embree_point;
    // The still rows' scene: Embree's faster build quality for this scene, LOW or MEDIUM.
    std::unique_ptr<EmbreeScene> embree_still;
#endif
    // Primary hits (the origins of shadow and mirror rays) come from the fastest view.
    kernels::SceneView fast_view;
    std::uint32_t validate_rays = 0;  // rays per set checked against the reference (0: all)
    std::vector<SimdConfig> simd_configs;
    SceneInfo info;
};

// ---- Run setup ----

// Forced ISAs are checked before any work.
std::vector<Isa> resolve_isas(const BenchOptions& o) {
    std::vector<Isa> isas;
    for (Isa isa : o.isas) {
        const Isa resolved = resolve_isa(isa);
        if (std::find(isas.begin(), isas.end(), resolved) == isas.end())
            isas.push_back(resolved);
    }
    return isas;
}

// Pixel orders; a tile size matters to the tiled order only.
std::vector<Variant> pixel_variants(const BenchOptions& o) {
    std::vector<Variant> variants;
    for (PixelOrder order : o.orders) {
        if (order == PixelOrder::tiled)
            for (TileSize tile : o.tiles) variants.push_back({order, tile});
        else
            variants.push_back({order, o.tiles.front()});
    }
    return variants;
}

// ---- Scene setup ----

// Both BVHs, on the bench's threads, kBuildReps times each (Embree's, then octray's): the
// median build time goes into the scene's info, the last builds are kept.
void build_bvhs(BenchRun& run, BenchScene& bs) {
    const CompiledScene& compiled = bs.compiled;
    std::vector<double> embree_builds, octray_builds;
#if OCTRAY_HAVE_EMBREE
    const bool with_embree =
        run.report.context.embree_available &&
        (run.ray_sets() || run.wants(Workload::still) || run.wants(Workload::frame));
    if (with_embree)
        run.arena.execute([&] {
            bs.embree_point = std::make_unique<EmbreeScene>(bs.scene, compiled, run.o.threads,
                                                            EmbreeGeometry::sphere_point);
        });
#endif
    for (int build = 0; build < kBuildReps; ++build) {
#if OCTRAY_HAVE_EMBREE
        if (with_embree) {
            bs.embree.reset();
            run.arena.execute([&] {
                bs.embree = std::make_unique<EmbreeScene>(bs.scene, compiled, run.o.threads,
                                                          EmbreeGeometry::user);
            });
            embree_builds.push_back(bs.embree->build_seconds());
        }
#endif
        if (compiled.spheres.count > 0) {
            bs.bvh = SphereBvh{};
            run.arena.execute([&] { bs.bvh = build_sphere_bvh(compiled.spheres); });
            octray_builds.push_back(bs.bvh.build_seconds);
        }
    }
    SceneInfo& info = bs.info;
#if OCTRAY_HAVE_EMBREE
    // The still rows charge Embree a build per frame: at its faster quality, LOW or MEDIUM,
    // for this scene (the median of kBuildReps builds of each, rebuilt as a frame would).
    if (with_embree && run.wants(Workload::still)) {
        double best = 0.0;
        for (EmbreeBuildQuality q : {EmbreeBuildQuality::low, EmbreeBuildQuality::medium}) {
            std::unique_ptr<EmbreeScene> e;
            std::vector<double> builds;
            run.arena.execute([&] {
                e = std::make_unique<EmbreeScene>(bs.scene, compiled, run.o.threads,
                                                  EmbreeGeometry::user, q);
                for (int build = 0; build < kBuildReps; ++build) builds.push_back(e->rebuild());
            });
            const double ms = summarize(builds, 0).seconds_median * 1e3;
            (q == EmbreeBuildQuality::low ? info.embree_build_low_ms
                                          : info.embree_build_medium_ms) = ms;
            if (!bs.embree_still || ms < best) {
                best = ms;
                bs.embree_still = std::move(e);
                info.embree_still_quality = embree_build_quality_name(q);
            }
        }
    }
    if (bs.embree) {
        info.embree_build_ms = summarize(embree_builds, 0).seconds_median * 1e3;
        if (run.report.scenes.empty()) run.report.context.embree = bs.embree->device_info();
    }
#endif
    if (compiled.spheres.count > 0) {
        info.bvh_build_ms = summarize(octray_builds, 0).seconds_median * 1e3;
        info.bvh_bytes_per_sphere = bs.bvh.bytes_per_sphere();
        info.bvh_nodes = static_cast<std::uint32_t>(bs.bvh.nodes.size());
        info.bvh_leaves = bs.bvh.leaf_count;
        info.bvh_depth = bs.bvh.depth;
    }
#if OCTRAY_HAVE_EMBREE
    if (bs.embree && compiled.spheres.count > 0)
        info.embree_bytes_per_sphere =
            static_cast<double>(bs.embree->memory_bytes()) / compiled.spheres.count;
#endif
}

// The SIMD rows: each --accel value resolved for this scene (and each --packet-lanes value
// with the BVH), without duplicates. Brute force is skipped on too many spheres.
void choose_simd_configs(const BenchRun& run, BenchScene& bs) {
    const BenchOptions& o = run.o;
    const CompiledScene& compiled = bs.compiled;
    for (Accel accel : o.accels) {
        const bool use_bvh = accel_uses_bvh(accel, compiled.spheres.count);
        if (!use_bvh && compiled.spheres.count > o.brute_force_max_spheres) {
            log_line(run.log, bs.spec + ": skipping brute force (--accel " +
                                  std::string(accel_name(accel)) + ") on " +
                                  std::to_string(compiled.spheres.count) + " spheres");
            continue;
        }
        const std::vector<std::uint32_t> lanes =
            use_bvh ? o.packet_lanes : std::vector<std::uint32_t>{0};
        for (std::uint32_t l : lanes) {
            const bool seen = std::any_of(
                bs.simd_configs.begin(), bs.simd_configs.end(),
                [&](const SimdConfig& c) { return c.bvh == use_bvh && c.lanes == l; });
            if (seen) continue;
            const std::uint32_t secondary =
                o.packet_lanes_for_secondary ? l : kBvhSecondaryLanesAuto;
            bs.simd_configs.push_back(
                {use_bvh, l,
                 use_bvh ? make_scene_view(compiled, bs.bvh, l, secondary) : bs.view, accel});
        }
    }
}

void log_scene(const BenchRun& run, const BenchScene& bs) {
    const SceneInfo& info = bs.info;
    const std::string& spec = bs.spec;
    if (bs.bvh.sphere_count > 0)
        log_line(
            run.log,
            spec + ": octray BVH built in " + format("%.3f ms", *info.bvh_build_ms) + ", " +
                format("%.1f bytes/sphere", *info.bvh_bytes_per_sphere) +
                (info.embree_bytes_per_sphere
                     ? ", Embree " + format("%.1f bytes/sphere", *info.embree_bytes_per_sphere)
                     : std::string()));
    log_line(run.log, spec + ": " + std::to_string(info.objects) + " objects, compiled in " +
                          format("%.3f ms", info.compile_ms) + ", first pixel after " +
                          format("%.1f ms", info.first_pixel_ms) +
                          (info.embree_build_ms ? ", Embree BVH built in " +
                                                      format("%.3f ms", *info.embree_build_ms)
                                                : std::string()));
    if (!info.embree_still_quality.empty())
        log_line(run.log, spec + ": Embree builds LOW " +
                              format("%.3f ms", *info.embree_build_low_ms) + ", MEDIUM " +
                              format("%.3f ms", *info.embree_build_medium_ms) +
                              ": its stills use " + info.embree_still_quality);
}

// The rows a scene will have (for the progress line).
int planned_rows(const BenchRun& run, const BenchScene& bs) {
    const BenchOptions& o = run.o;
    bool embree = false;
#if OCTRAY_HAVE_EMBREE
    embree = bs.embree != nullptr;
#endif
    const int isas = static_cast<int>(run.isas.size());
    int octray_set = 0, octray_still = 0, octray_frame = 0;
    // Whole frames: one row per BVH-or-not among the SIMD configurations.
    bool with_bvh = false, without = false;
    for (const SimdConfig& c : bs.simd_configs) (c.bvh ? with_bvh : without) = true;
    const int frame_configs = int{with_bvh} + int{without};
    for (RenderPath path : o.paths) {
        if (path == RenderPath::scalar) {
            ++octray_set, ++octray_still;
            continue;
        }
        octray_set += isas * static_cast<int>(bs.simd_configs.size());
        octray_still += isas * std::max(1, frame_configs);
        octray_frame += isas * std::max(1, frame_configs);
    }
    int rows = 0;
    for (Workload w : {Workload::primary, Workload::shadow, Workload::secondary})
        if (run.wants(w))
            rows += static_cast<int>(run.variants) * ((embree ? 5 : 0) + octray_set);
    const int tiles = static_cast<int>(o.tiles.size());
    if (run.wants(Workload::still)) rows += tiles * ((embree ? 2 : 0) + octray_still);
    if (run.wants(Workload::frame)) rows += tiles * ((embree ? 2 : 0) + octray_frame);
    return rows;
}

// "  [12/48 rows, 42 s, about 2 min 10 s left]" after each row's log line.
std::string progress(const BenchRun& run) {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - run.start).count();
    std::string text = "  [" + std::to_string(run.rows_done) + "/" +
                       std::to_string(std::max(run.rows_planned, run.rows_done)) + " rows, " +
                       format_duration(elapsed);
    const int left = run.rows_planned - run.rows_done;
    if (left > 0 && run.rows_done > 0)
        text += ", about " + format_duration(elapsed / run.rows_done * left) + " left";
    return text + "]";
}

// Everything a scene's rows need: the scene info (sizes, compile and first-pixel times),
// both BVHs, the fast view and the SIMD configurations.
void set_up_scene(BenchRun& run, BenchScene& bs) {
    SceneInfo& info = bs.info;
    info.spec = bs.spec;
    info.first_pixel_ms =
        detail::time_to_first_pixel_ms(bs.spec, run.o, run.arena, run.report.context.threads);
    info.objects = static_cast<std::uint32_t>(bs.scene.objects.size());
    info.spheres = bs.compiled.spheres.count;
    info.planes = bs.compiled.planes.count;
    info.lights = bs.compiled.lights.count;
    info.epsilon = bs.compiled.epsilon;
    info.compile_ms = bs.compiled.compile_seconds * 1e3;
    build_bvhs(run, bs);
    bs.fast_view = bs.bvh.nodes.empty() ? bs.view : make_scene_view(bs.compiled, bs.bvh);
    bs.validate_rays = run.o.validate_rays;
    choose_simd_configs(run, bs);
    log_scene(run, bs);
}

// ---- Rows ----

// The packets octray's kernels trace in: the ISA's traversal packets (16 rays with AVX-512,
// kernels/bvh/bvh_packet.h), through the BVH and in brute force alike.
std::string octray_mode(Isa isa, bool /*bvh*/) {
    return "packet" + std::to_string(kernel_table(isa).traversal_width);
}

BenchRow base_row(const BenchRun& run, const std::string& spec, Workload w, const Variant& v) {
    BenchRow row;
    row.scene = spec;
    row.workload = w;
    row.order = whole_frame(w) ? "tiled" : pixel_order_name(v.order);
    row.tile = whole_frame(w) || v.order == PixelOrder::tiled ? tile_size_name(v.tile) : "-";
    row.threads = run.report.context.threads;
    return row;
}

// One ray set, one system and mode.
struct RaySetRun {
    Workload workload;
    const RaySet& set;
};

// A row of a ray set waiting for its repetitions: how it traces, and what its hits are
// checked against.
struct RaySetRow {
    BenchRow row;
    detail::Tracer trace;
    const OracleHits* truth;
    ValidationRule rule;
    bool octray_any_hit;  // octray's any_hit flags, mapped to hits after timing
};

// Times every row of the set in rounds (repeat_timed_in_rounds: octray's and Embree's
// repetitions alternate), then validates each row's hits against its truth and adds it.
void measure_ray_set_rows(BenchRun& run, const RaySetRun& rs, std::vector<RaySetRow> rows) {
    const RaySet& set = rs.set;
    const Workload w = rs.workload;
    std::vector<HitSet> hits(rows.size());
    std::vector<std::function<double()>> runs;
    for (std::size_t k = 0; k < rows.size(); ++k) {
        hits[k].resize(static_cast<std::uint32_t>(set.ox.size()));
        runs.push_back(detail::timed_trace(rows[k].trace, set, hits[k]));
    }
    std::vector<Repetitions> reps;
    {
        detail::Stopwatch timed(run.report.context.timed_seconds);
        reps = repeat_timed_in_rounds(runs, run.o);
    }
    for (std::size_t k = 0; k < rows.size(); ++k) {
        BenchRow& row = rows[k].row;
        row.rays = set.count;
        (w == Workload::primary  ? row.counts.primary
         : w == Workload::shadow ? row.counts.shadow
                                 : row.counts.reflected) = set.count;
        row.seconds = std::move(reps[k].seconds);
        row.runs = std::move(reps[k].runs);
        if (rows[k].octray_any_hit) detail::occluded_to_hits(hits[k], set.count);
        detail::set_timing(row, run.o);
        row.hit_fraction = hit_fraction(hits[k], set.count);
        Validation val;
        {
            detail::Stopwatch checking(run.report.context.validation_seconds);
            val = validate_hits(hits[k], *rows[k].truth, rows[k].rule);
        }
        row.valid = val.valid;
        ++run.rows_done;
        row.validation =
            std::string(rows[k].rule.exact ? "exact vs scalar oracle, "
                                           : "tolerance vs double-precision oracle, ") +
            val.summary();
        log_line(run.log,
                 "  " + std::string(workload_name(w)) + " " + row.system + " " + row.mode +
                     " " + row.isa + " " + row.accel_label() + " " + row.order + " " +
                     row.tile + ": " + format("%.2f Mrays/s", row.timing.mrays_median) +
                     (row.valid ? "" : " (INVALID: " + val.summary() + ")") + progress(run));
        run.report.rows.push_back(std::move(row));
    }
}

#if OCTRAY_HAVE_EMBREE
// Embree's rows of a ray set: user geometry (16-, 8-wide packets and single rays) and its
// built-in spheres (8-wide and single), within tolerance of the double-precision oracle
// (`truth`, made here; it must outlive the rows).
void add_embree_rows(BenchRun& run, const BenchScene& bs, const RaySetRun& rs, const Variant& v,
                     const OracleHits& oracle, OracleHits& truth,
                     std::vector<RaySetRow>& rows) {
    {
        detail::Stopwatch checking(run.report.context.validation_seconds);
        run.arena.execute([&] {
            truth = oracle_hits_double(
                bs.scene, rs.set, detail::double_oracle_rays(oracle, bs.scene.objects.size()));
        });
    }
    for (const EmbreeScene* e : {bs.embree.get(), bs.embree_point.get()}) {
        const bool user = e->geometry() == EmbreeGeometry::user;
        for (EmbreeMode mode :
             {EmbreeMode::packet16, EmbreeMode::packet8, EmbreeMode::single}) {
            if (!user && mode == EmbreeMode::packet16) continue;
            BenchRow row = base_row(run, bs.spec, rs.workload, v);
            row.system = "embree";
            row.mode = embree_mode_name(mode);
            row.isa = embree_geometry_name(e->geometry());
            rows.push_back({std::move(row), detail::embree_tracer(run.arena, *e, mode), &truth,
                            kToleranceRule, false});
        }
    }
}
#endif

// octray's rows of a ray set: the scalar reference and the packet kernels (each ISA and
// SIMD configuration), exactly as the scalar oracle.
void add_octray_rows(BenchRun& run, const BenchScene& bs, const RaySetRun& rs, const Variant& v,
                     const OracleHits& oracle, std::vector<RaySetRow>& rows) {
    for (RenderPath path : run.o.paths) {
        if (path == RenderPath::scalar) {
            BenchRow row = base_row(run, bs.spec, rs.workload, v);
            row.system = "octray";
            row.mode = "single";
            row.isa = "scalar";
            row.accel = "bvh";  // the reference's own
            rows.push_back({std::move(row),
                            detail::octray_scalar_tracer(run.arena, bs.reference), &oracle,
                            kExactRule, false});
            continue;
        }
        for (Isa isa : run.isas) {
            for (const SimdConfig& config : bs.simd_configs) {
                BenchRow row = base_row(run, bs.spec, rs.workload, v);
                row.system = "octray";
                row.mode = octray_mode(isa, config.bvh);
                row.isa = isa_name(isa);
                row.accel = config.bvh ? "bvh" : "none";
                // The lanes rule the rays were traced under (secondary rays: their own).
                row.packet_min_lanes = config.bvh && rs.workload == Workload::secondary
                                           ? config.view.bvh_secondary_min_lanes
                                           : config.lanes;
                rows.push_back(
                    {std::move(row),
                     detail::octray_simd_tracer(run.arena, kernel_table(isa), config.view),
                     &oracle, kExactRule, rs.workload == Workload::shadow});
            }
        }
    }
}

// The ray-set rows of one pixel order: primary rays, then the shadow and mirror rays from
// their hits, each against the scalar oracle's hits of its rays.
void measure_ray_sets(BenchRun& run, BenchScene& bs, const Variant& v) {
    const BenchOptions& o = run.o;
    const RaySet primary = make_primary_rays(bs.reference, o.width, o.height,
                                             pixel_order(o.width, o.height, v.order, v.tile));
    // Shadow and mirror rays start at the primary hits (octray's packet hits, which the
    // primary rows validate against the oracle).
    HitSet primary_hits;
    primary_hits.resize(static_cast<std::uint32_t>(primary.ox.size()));
    detail::octray_simd_tracer(run.arena, kernel_table(run.isas.back()), bs.fast_view)(
        primary, primary_hits);

    for (Workload w : {Workload::primary, Workload::shadow, Workload::secondary}) {
        if (!run.wants(w)) continue;
        const RaySet rays = w == Workload::primary ? RaySet{}
                            : w == Workload::shadow
                                ? make_shadow_rays(bs.scene, primary, primary_hits)
                                : make_secondary_rays(bs.scene, primary, primary_hits);
        const RaySet& set = w == Workload::primary ? primary : rays;
        (w == Workload::primary  ? bs.info.primary_rays
         : w == Workload::shadow ? bs.info.shadow_rays
                                 : bs.info.secondary_rays) = set.count;
        OracleHits oracle;
        {
            detail::Stopwatch checking(run.report.context.validation_seconds);
            run.arena.execute(
                [&] { oracle = oracle_hits(bs.reference, set, bs.validate_rays); });
        }
        const RaySetRun rs{w, set};
        std::vector<RaySetRow> rows;
#if OCTRAY_HAVE_EMBREE
        OracleHits embree_truth;
        if (bs.embree) add_embree_rows(run, bs, rs, v, oracle, embree_truth, rows);
#endif
        add_octray_rows(run, bs, rs, v, oracle, rows);
        measure_ray_set_rows(run, rs, std::move(rows));
    }
}

// ---- Whole renders ----

// Validation of whole packet renders, by workload, ISA and BVH or not: checked once per
// scene.
using RenderValidation =
    std::map<std::tuple<Workload, Isa, bool>, std::pair<bool, std::string>>;

RenderOptions frame_options(const BenchRun& run, TileSize tile) {
    RenderOptions ro;
    ro.threads = run.report.context.threads;
    ro.tile_width = tile.width;
    ro.tile_height = tile.height;
    return ro;
}

// The distinct BVH-or-not configurations of the scene's SIMD rows (the packet switch is
// the renderer's default in whole frames).
std::vector<const SimdConfig*> frame_configs(const BenchScene& bs) {
    std::vector<const SimdConfig*> configs;
    for (const SimdConfig& c : bs.simd_configs)
        if (std::none_of(configs.begin(), configs.end(),
                         [&](const SimdConfig* k) { return k->bvh == c.bvh; }))
            configs.push_back(&c);
    return configs;
}

void log_frame_row(BenchRun& run, const BenchRow& row) {
    log_line(run.log, "  " + std::string(workload_name(row.workload)) + " " + row.system + " " +
                          row.mode + " " + row.isa + " " + row.accel +
                          (row.build_quality != "-" ? " build " + row.build_quality : "") +
                          " tile " + row.tile + ": " +
                          format("%.3f frames/s", row.frames_per_second) + ", " +
                          format("%.2f Mrays/s", row.timing.mrays_median) +
                          (row.valid ? "" : " (" + row.validation + ")") + progress(run));
}

// octray's whole-frame rows of one tile size and workload: each path, ISA and --accel
// value. A still renders the Scene (render_packet compiles it and builds the BVH, both
// inside its seconds); a frame renders a PreparedScene made once per --accel value (the
// ISAs share it). The scalar reference is measured as a still only (it has no prepared
// form).
void add_octray_render_rows(BenchRun& run, const BenchScene& bs, TileSize tile, Workload w,
                            RenderValidation& render_validation,
                            std::vector<detail::FrameRow>& rows) {
    const BenchOptions& o = run.o;
    std::map<Accel, std::shared_ptr<const PreparedScene>> prepared_by_accel;
    for (RenderPath path : o.paths) {
        if (path == RenderPath::scalar && w == Workload::frame) continue;
        const std::vector<Isa> path_isas =
            path == RenderPath::simd ? run.isas : std::vector<Isa>{Isa::automatic};
        std::vector<const SimdConfig*> configs = frame_configs(bs);
        if (path == RenderPath::scalar || configs.empty()) configs = {nullptr};
        for (Isa isa : path_isas)
            for (const SimdConfig* config : configs) {
                // The scalar path finds its spheres through the reference's own BVH.
                const Accel accel = config ? config->accel : Accel::automatic;
                BenchRow row = base_row(run, bs.spec, w, Variant{PixelOrder::tiled, tile});
                row.system = "octray";
                row.mode = path == RenderPath::simd ? octray_mode(isa, config && config->bvh)
                                                    : "single";
                row.isa = path == RenderPath::simd ? isa_name(isa) : "scalar";
                if (config) row.accel = config->bvh ? "bvh" : "none";
                if (path == RenderPath::scalar) row.accel = "bvh";
                if (path == RenderPath::simd) {
                    const auto key = std::make_tuple(w, isa, config && config->bvh);
                    auto it = render_validation.find(key);
                    if (it == render_validation.end()) {
                        detail::Stopwatch checking(run.report.context.validation_seconds);
                        bool ok = false;
                        std::string text = detail::validate_render(bs.spec, o, isa, accel,
                                                                   w == Workload::frame, ok);
                        it = render_validation.emplace(key, std::make_pair(ok, text)).first;
                    }
                    row.valid = it->second.first;
                    row.validation = it->second.second;
                } else {
                    row.valid = true;
                    row.validation = "the scalar reference is the oracle";
                }
                RenderOptions ro = frame_options(run, tile);
                ro.accel = accel;
                std::shared_ptr<const PreparedScene> prepared;
                if (w == Workload::frame) {
                    std::shared_ptr<const PreparedScene>& made = prepared_by_accel[accel];
                    if (!made)
                        run.arena.execute([&] {
                            made = std::make_shared<const PreparedScene>(bs.scene, accel,
                                                                         ro.threads);
                        });
                    prepared = made;
                }
                auto render = [&bs, ro, path, isa, prepared](Image* spare) {
                    RenderOptions frame_ro = ro;
                    frame_ro.spare_image = spare;
                    if (path == RenderPath::scalar) return render_reference(bs.scene, frame_ro);
                    return prepared ? render_packet(*prepared, frame_ro, isa)
                                    : render_packet(bs.scene, frame_ro, isa);
                };
                rows.push_back({std::move(row), std::move(render), w == Workload::frame});
            }
    }
}

#if OCTRAY_HAVE_EMBREE
// The same frames with Embree answering the hit queries (user geometry, 16- and 8-wide
// packets of each generation's rays). A still is charged what octray's is: compiling the
// scene, then Embree's BVH build at its faster quality for this scene (EmbreeScene::rebuild,
// every repetition), then the frame. A frame traces the HIGH-quality scene built before.
void add_embree_render_rows(BenchRun& run, BenchScene& bs, TileSize tile, Workload w,
                            std::vector<detail::FrameRow>& rows) {
    const Scene small = detail::validation_scene(bs.spec, run.o);
    EmbreeScene& scene = w == Workload::still ? *bs.embree_still : *bs.embree;
    for (EmbreeMode mode : {EmbreeMode::packet16, EmbreeMode::packet8}) {
        const auto frames = std::make_shared<const EmbreeFrames>(scene, mode, run.isas.back());
        BenchRow row = base_row(run, bs.spec, w, Variant{PixelOrder::tiled, tile});
        row.system = "embree";
        row.mode = embree_mode_name(mode);
        row.isa = embree_geometry_name(scene.geometry());
        if (w == Workload::still)
            row.build_quality = embree_build_quality_name(scene.build_quality());
        bool ok = false;
        {
            detail::Stopwatch checking(run.report.context.validation_seconds);
            row.validation = detail::validate_embree_render(small, *frames, run.o, ok);
        }
        row.valid = ok;
        const RenderOptions ro = frame_options(run, tile);
        auto render = [&run, &bs, &scene, ro, w, frames](Image* spare) {
            RenderOptions frame_ro = ro;
            frame_ro.spare_image = spare;
            if (w == Workload::frame) return frames->render(bs.compiled, frame_ro);
            const auto start = std::chrono::steady_clock::now();
            const CompiledScene compiled = compile_scene(bs.scene);  // as octray's still
            const double compile =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            double build = 0.0;
            run.arena.execute([&] { build = scene.rebuild(); });
            RenderResult r = frames->render(bs.compiled, frame_ro);
            r.compile_seconds = compile;
            r.bvh_seconds = build;
            r.seconds += compile + build;
            return r;
        };
        rows.push_back({std::move(row), std::move(render), w == Workload::frame});
    }
}
#endif

// Whole renders: the full Whitted workload, frame after frame, per tile size, as stills
// and as frames of a prepared scene.
void measure_whole_renders(BenchRun& run, BenchScene& bs) {
    RenderValidation render_validation;
    for (TileSize tile : run.o.tiles)
        for (Workload w : {Workload::still, Workload::frame}) {
            if (!run.wants(w)) continue;
            std::vector<detail::FrameRow> rows;
            add_octray_render_rows(run, bs, tile, w, render_validation, rows);
#if OCTRAY_HAVE_EMBREE
            if (bs.embree) add_embree_render_rows(run, bs, tile, w, rows);
#endif
            // octray's and Embree's frames in rounds (repeat_timed_in_rounds).
            {
                detail::Stopwatch timed(run.report.context.timed_seconds);
                detail::time_frames_in_rounds(rows, run.o);
            }
            for (detail::FrameRow& r : rows) {
                run.report.rows.push_back(std::move(r.row));
                ++run.rows_done;
                log_frame_row(run, run.report.rows.back());
            }
        }
}

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
    report.context = detail::make_context(o);
    tbb::task_arena arena(report.context.threads);
    BenchRun run{o, log, report, arena, resolve_isas(o)};
    const std::vector<Variant> variants = pixel_variants(o);
    run.variants = variants.size();
    for (std::size_t k = 0; k < o.scenes.size(); ++k) {
        const std::string& spec = o.scenes[k];
        BenchScene bs(spec, o);
        set_up_scene(run, bs);
        run.rows_planned =
            run.rows_done + planned_rows(run, bs) * static_cast<int>(o.scenes.size() - k);
        if (run.ray_sets())
            for (const Variant& v : variants) measure_ray_sets(run, bs, v);
        if (run.wants(Workload::still) || run.wants(Workload::frame))
            measure_whole_renders(run, bs);
        report.scenes.push_back(std::move(bs.info));
    }
    compute_ratios(report.rows);
    report.context.wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - run.start).count();
    return report;
}

}  // namespace octray::bench
