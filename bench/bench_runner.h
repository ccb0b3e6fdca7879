#pragma once
// The engine of `octray bench`: rays per second of octray and Embree side by side on the
// same scenes and the same rays, each row validated against the scalar oracle before it is
// timed; whole Whitted renders too. Results as a human-readable table or JSON.
// How to run it and what each figure means: bench/README.md.

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bench/ray_sets.h"
#include "kernels/dispatch.h"
#include "kernels/isa.h"
#include "render/accel.h"
#include "render/prepare/scene_view.h"
#include "render/render_options.h"

namespace octray::bench {

// What a row measures: one kind of ray set, or a whole Whitted frame, measured two ways:
// - still: a picture from the scene as it comes: the scene made ready (octray: compile and
//   BVH build; Embree: the same compile and its BVH build at its faster quality for the
//   scene, LOW or MEDIUM) and its first frame rendered, every repetition from scratch;
// - frame: a frame of a scene made ready once before (octray: render_packet of a
//   PreparedScene; Embree: its HIGH-quality BVH built before), the render alone.
enum class Workload { primary, shadow, secondary, still, frame };
const char* workload_name(Workload workload);
std::optional<Workload> parse_workload(std::string_view name);
// A --rays word: a workload's name, or "whitted" for both whole-frame kinds ({} if unknown).
std::vector<Workload> parse_workloads(std::string_view name);
// Whole frames (still, frame) rather than ray sets.
bool whole_frame(Workload workload);

struct BenchOptions {
    std::vector<std::string> scenes{"whitted", "random:16", "random:1024", "sphereflake:4"};
    std::vector<Workload> workloads{Workload::primary, Workload::shadow, Workload::secondary,
                                    Workload::still, Workload::frame};
    int threads = 0;  // 0: every core TBB sees
    int reps = 5;     // timed repetitions per row
    int warmup = 1;  // untimed runs before them (0 allowed: the timed runs' hits are validated)
    // Each timed repetition repeats its ray set or frame until at least this many seconds
    // have passed, and counts the mean of its runs (Google Benchmark's min time, per
    // repetition): a 0.3 ms ray set is timed over ~300 runs, not one. 0: one run each.
    double min_time = kDefaultMinTime;
    static constexpr double kDefaultMinTime = 0.1;
    // A row whose slowest repetition took more than this many times its fastest is marked
    // unsteady (BenchRow::steady): its median is not to be trusted to a few percent.
    double max_spread = kDefaultMaxSpread;
    static constexpr double kDefaultMaxSpread = 1.25;
    int width = 1920, height = 1080;
    // Knobs; each list is measured in one run, every value a row of its own. The first
    // value of each list is the default configuration.
    std::vector<TileSize> tiles{TileSize{}};
    std::vector<PixelOrder> orders{PixelOrder::tiled};
    std::vector<Isa> isas{Isa::automatic};
    std::vector<RenderPath> paths{
        RenderPath::simd};  // which renderer (render/render_options.h)
    // The SIMD path's sphere acceleration (auto: a BVH from kBvhAutoMinSpheres spheres on)
    // and, with a BVH, the live lanes below which a packet goes on ray by ray.
    std::vector<Accel> accels{Accel::automatic};
    std::vector<std::uint32_t> packet_lanes{kBvhPacketMinLanes};
    // Whether packet_lanes also holds for secondary rays; if not (the default), they follow
    // the renderer's rule (kBvhSecondaryRayByRayMinSpheres and ...DenseMinSpheres: single
    // rays in large or dense BVHs).
    bool packet_lanes_for_secondary = false;
    // Brute force (accel none) is skipped on scenes with more spheres than this: on 10^6
    // spheres a frame of it would take hours.
    std::uint32_t brute_force_max_spheres = 1u << 14;
    bool embree = true;  // when compiled in
    // Rays checked against the scalar oracle per ray set (0: all of them).
    std::uint32_t validate_rays = 1u << 16;
    // Whole renders are validated image against image at this size.
    int validate_width = 320, validate_height = 180;
    std::string command_line;  // recorded in the report
};

struct Timing {
    double seconds_median = 0.0, seconds_min = 0.0, seconds_max = 0.0;
    double mrays_median = 0.0, mrays_min = 0.0, mrays_max = 0.0;
    double spread = 1.0;  // seconds_max / seconds_min (1 for a single repetition)
};
// Median / min / max over repetitions of `rays` rays each (the median of an even count is
// the mean of the middle two). Mrays/s min comes from the slowest repetition.
Timing summarize(std::vector<double> seconds, std::uint64_t rays);

// Timed repetitions: the seconds each counts (the mean of its runs) and its runs.
struct Repetitions {
    std::vector<double> seconds;
    std::vector<std::uint32_t> runs;
};
// Timed repetitions of several rows, in rounds: o.warmup untimed runs of every row, then
// o.reps rounds, each timing one repetition of every row in turn (the first row of a round
// is the one after the last round's first). A repetition repeats its row's run until the
// seconds its runs count add up to o.min_time (at least one run; Google Benchmark's min
// time); it also ends after 2 * o.min_time + 1 s of wall clock, should the runs count
// (nearly) nothing. Each `runs[k]` does one run and returns the seconds it counts (its wall
// clock, or a render's own figure). A host that slows down or speeds up during the run
// then charges every row alike, so the rows' ratios (octray against Embree on one ray set)
// are measured side by side rather than seconds or minutes apart. One row alone is timed
// the same way, its repetitions back to back.
std::vector<Repetitions> repeat_timed_in_rounds(
    const std::vector<std::function<double()>>& runs, const BenchOptions& o);

struct BenchRow {
    std::string scene;
    Workload workload = Workload::primary;
    std::string system;  // "octray" or "embree"
    std::string mode;    // "packet8", "packet16" (a simd packet) or "single"
    std::string isa;     // octray: the kernels' ISA or "scalar"; embree: "embree"
    std::string order;   // pixel order of the rays
    std::string tile;    // tile size (tiled order, whole renders), "-" where it plays no part
    std::string accel = "-";             // octray simd: "bvh" or "none"
    std::uint32_t packet_min_lanes = 0;  // octray simd with the BVH
    // "bvh/3" (the BVH, packets of fewer than 3 live lanes go on ray by ray), "none", "-".
    std::string accel_label() const {
        return accel == "bvh" ? "bvh/" + std::to_string(packet_min_lanes) : accel;
    }
    int threads = 0;
    std::uint64_t rays = 0;  // per repetition
    RayCounts counts;        // the rays of one repetition by kind
    double hit_fraction = 0.0;
    std::vector<double> seconds;  // per timed repetition: the mean of its runs
    // Runs per timed repetition (BenchOptions::min_time): more than 1 where one run is short.
    std::vector<std::uint32_t> runs;
    Timing timing;
    // timing.spread <= BenchOptions::max_spread: the repetitions agree.
    bool steady = true;
    double frames_per_second = 0.0;  // whole renders: 1 / median seconds
    // Embree's still rows: the build quality timed ("low" or "medium"); "-" elsewhere.
    std::string build_quality = "-";
    bool valid = false;
    std::string validation;  // what was checked, and how it came out
    // octray rows: this row's median over the best valid Embree row of the same scene,
    // workload, order and tile; Embree rows: the best valid octray row over this one.
    std::optional<double> ratio;
};

struct SceneInfo {
    std::string spec;
    std::uint32_t objects = 0, spheres = 0, planes = 0, lights = 0;
    float epsilon = 0.0f;
    double compile_ms = 0.0;                // compile_scene()
    std::optional<double> embree_build_ms;  // rtcCommitScene(), HIGH quality
    // Still rows (Workload::still): Embree's LOW and MEDIUM builds (the median of the
    // bench's builds) and the faster of the two, which its still rows use.
    std::optional<double> embree_build_low_ms, embree_build_medium_ms;
    std::string embree_still_quality;               // "low", "medium"; empty without still rows
    std::optional<double> embree_bytes_per_sphere;  // Embree's device memory after the build
    // octray's sphere BVH (render/prepare/bvh_build.h): build time, bytes per sphere (nodes and
    // its copy of the spheres), 8-wide nodes, leaves, depth. Absent without spheres.
    std::optional<double> bvh_build_ms, bvh_bytes_per_sphere;
    std::uint32_t bvh_nodes = 0, bvh_leaves = 0, bvh_depth = 0;
    // Time to first pixel: from the scene spec to the first finished tile of a render with
    // the bench's threads: load (generate or parse), validate, compile, build the BVH,
    // trace the tile (the median of three, each from scratch).
    double first_pixel_ms = 0.0;
    std::uint64_t primary_rays = 0, shadow_rays = 0, secondary_rays = 0;  // ray set sizes
};

struct BenchContext {
    std::string date;  // UTC, ISO 8601
    std::string cpu;
    int logical_cpus = 0;
    int threads = 0;  // resolved
    std::string isa;  // octray's default (best supported) ISA
    std::string compiler;
    std::string octray_version;
    std::string embree;  // version and device info, or why it is absent
    bool embree_available = false;
    double load_average = 0.0;  // 1-minute load when the run started
    int width = 0, height = 0, reps = 0, warmup = 0;
    double min_time = 0.0, max_spread = 0.0;
    // Where the run's wall-clock time went: timed repetitions (warm-up runs included),
    // validation (the oracles' hits, checking hits and images), the rest (loading and
    // compiling scenes, building BVHs, time to first pixel, making ray sets).
    double wall_seconds = 0.0, timed_seconds = 0.0, validation_seconds = 0.0;
    std::uint32_t validate_rays = 0;
    std::string command_line;
};

struct BenchReport {
    BenchContext context;
    std::vector<SceneInfo> scenes;
    std::vector<BenchRow> rows;
};

// Runs everything the options ask for; progress lines go to `log` when given. Throws
// SceneError for a scene that cannot be loaded, std::runtime_error for a forced ISA the
// CPU lacks.
BenchReport run_bench(const BenchOptions& options, std::ostream* log = nullptr);

// Fills in BenchRow::ratio for every row (run_bench does it; exposed for tests).
void compute_ratios(std::vector<BenchRow>& rows);

void print_table(const BenchReport& report, std::ostream& out);
std::string report_json(const BenchReport& report);
// A duration for people: "0.4 s", "42 s", "7 min 32 s", "1 h 5 min".
std::string format_duration(double seconds);

// Written atomically; throws IoError naming the file.
void write_json_file(const BenchReport& report, const std::string& path);

}  // namespace octray::bench
