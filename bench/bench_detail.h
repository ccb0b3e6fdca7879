#pragma once
// The parts of `octray bench` that bench_runner.cpp's steps are built from, shared by the
// engine's own files only (not an interface for the CLI or the tests: bench_runner.h is):
// tracers and their timing (bench_tracers.cpp), validation against the oracles
// (bench_validation.cpp), the machine a run describes (bench_context.cpp), log lines.

#include <oneapi/tbb/task_arena.h>

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "bench/bench_runner.h"
#include "bench/embree_baseline.h"
#include "bench/embree_frames.h"
#include "bench/ray_sets.h"
#include "kernels/kernel_table.h"
#include "kernels/kernel_types.h"
#include "render/reference.h"
#include "scene/scene.h"

namespace octray::bench::detail {

// ---- bench_tracers.cpp: tracing ray sets and frames, timed ----

// One way of tracing a ray set into a hit set.
using Tracer = std::function<void(const RaySet&, HitSet&)>;

// One run of `trace` over the set, for repeat_timed_in_rounds: it returns the run's wall
// seconds; the hits of the last run stay in `hits`.
std::function<double()> timed_trace(const Tracer& trace, const RaySet& rays, HitSet& hits);

// octray's packet kernels over the set: closest_hit, or any_hit into the occluded flags.
Tracer octray_simd_tracer(tbb::task_arena& arena, const kernels::KernelTable& table,
                          const kernels::SceneView& view);
// any_hit's 0 / 1 flags (octray_simd_tracer on shadow rays) as kNoHit / kOccluded.
void occluded_to_hits(HitSet& hits, std::uint32_t count);
// The scalar reference, one ray at a time.
Tracer octray_scalar_tracer(tbb::task_arena& arena, const ReferenceTracer& tracer);
#if OCTRAY_HAVE_EMBREE
Tracer embree_tracer(tbb::task_arena& arena, const EmbreeScene& scene, EmbreeMode mode);
#endif

// A whole-frame row waiting for its repetitions. `render(spare)` renders one frame; with
// `reuse_storage` `spare` holds the row's frame before's pixels, for
// RenderOptions::spare_image (a sequence's frames render into the last one's storage, as
// octray render's frame loop does), otherwise it is nullptr and every frame maps fresh
// storage (a still's one picture).
struct FrameRow {
    BenchRow row;
    std::function<RenderResult(Image* spare)> render;
    bool reuse_storage = false;
};
// Whole-frame rows timed together, their repetitions in rounds (repeat_timed_in_rounds:
// each frame's own seconds), so that octray's and Embree's frames are timed side by side;
// each row gets the last frame's ray counts, the rates and frames per second, the spread.
void time_frames_in_rounds(std::vector<FrameRow>& rows, const BenchOptions& o);
// The row's timing from its seconds and rays, its spread against o.max_spread.
void set_timing(BenchRow& row, const BenchOptions& o);

// ---- bench_validation.cpp: scenes and their checks ----

// The rays of `exact` (the scalar reference's oracle) that the double-precision brute-force
// oracle answers for Embree's rows: all of them, or an even stride within its budget.
OracleHits double_oracle_rays(const OracleHits& exact, std::size_t objects);
// Loads the spec at the bench's resolution.
Scene load_bench_scene(const std::string& spec, int width, int height);
// Time to first pixel (SceneInfo::first_pixel_ms), the median of three runs.
double time_to_first_pixel_ms(const std::string& spec, const BenchOptions& o,
                              tbb::task_arena& arena, int threads);
// The scene at the validation size of whole renders.
Scene validation_scene(const std::string& spec, const BenchOptions& o);
// The packet render of the scene at the validation size (of the Scene, or with `prepared`
// of a PreparedScene) equals the reference render, image and ray counts: sets `valid`,
// returns what was checked and how it came out.
std::string validate_render(const std::string& spec, const BenchOptions& o, Isa isa,
                            Accel accel, bool prepared, bool& valid);
#if OCTRAY_HAVE_EMBREE
// An Embree frame at the validation size against the reference render, within tolerances.
std::string validate_embree_render(const Scene& small, const EmbreeFrames& frames,
                                   const BenchOptions& o, bool& valid);
#endif

// ---- bench_context.cpp: the machine and the run ----

// The report's context: date, CPU, threads, ISA, compiler, Embree, load, the options.
BenchContext make_context(const BenchOptions& o);

// ---- log lines and numbers (bench_context.cpp) ----

void log_line(std::ostream* log, const std::string& line);
// printf of one number.
std::string format(const char* fmt, double a);

// Adds the wall-clock time of its life to `total` (the run's time accounts).
class Stopwatch {
  public:
    explicit Stopwatch(double& total);
    ~Stopwatch();
    Stopwatch(const Stopwatch&) = delete;
    Stopwatch& operator=(const Stopwatch&) = delete;

  private:
    double& total_;
    std::int64_t start_ns_;
};

}  // namespace octray::bench::detail
