// Tracing ray sets and whole frames for `octray bench`, timed: every system reads the same
// ray arrays and is scheduled the same way, chunks of kChunkRays rays spread over one TBB
// arena of the bench's threads.

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "bench/bench_detail.h"

namespace octray::bench::detail {

namespace {

// Rays per task: large enough to amortise scheduling, small enough to balance two cores.
constexpr std::uint32_t kChunkRays = 4096;
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

}  // namespace

}  // namespace octray::bench::detail

namespace octray::bench {

namespace {

// One timed repetition of `run` into `reps`: runs until the seconds they count reach
// o.min_time (repeat_timed_in_rounds).
void time_repetition(const std::function<double()>& run, const BenchOptions& o,
                     Repetitions& reps) {
    const auto start = detail::Clock::now();
    double counted = 0.0;
    std::uint32_t runs = 0;
    do {
        counted += run();
        ++runs;
    } while (counted < o.min_time && detail::seconds_since(start) < 2.0 * o.min_time + 1.0);
    reps.seconds.push_back(counted / runs);
    reps.runs.push_back(runs);
}

}  // namespace

std::vector<Repetitions> repeat_timed_in_rounds(
    const std::vector<std::function<double()>>& runs, const BenchOptions& o) {
    for (const auto& run : runs)
        for (int i = 0; i < o.warmup; ++i) (void)run();
    std::vector<Repetitions> reps(runs.size());
    for (int round = 0; round < o.reps; ++round)
        for (std::size_t k = 0; k < runs.size(); ++k) {
            const std::size_t row = (k + static_cast<std::size_t>(round)) % runs.size();
            time_repetition(runs[row], o, reps[row]);
        }
    return reps;
}

}  // namespace octray::bench

namespace octray::bench::detail {

std::function<double()> timed_trace(const Tracer& trace, const RaySet& rays, HitSet& hits) {
    return [&trace, &rays, &hits] {
        const auto start = Clock::now();
        trace(rays, hits);
        return seconds_since(start);
    };
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

void time_frames_in_rounds(std::vector<FrameRow>& rows, const BenchOptions& o) {
    std::vector<RenderResult> last(rows.size());
    std::vector<Image> spare(rows.size());
    std::vector<std::function<double()>> runs;
    for (std::size_t k = 0; k < rows.size(); ++k)
        runs.push_back([&rows, &last, &spare, k] {
            const FrameRow& r = rows[k];
            last[k] = r.render(r.reuse_storage ? &spare[k] : nullptr);
            if (r.reuse_storage) spare[k] = std::move(last[k].image);
            return last[k].seconds;
        });
    std::vector<Repetitions> reps = repeat_timed_in_rounds(runs, o);
    for (std::size_t k = 0; k < rows.size(); ++k) {
        BenchRow& row = rows[k].row;
        row.seconds = std::move(reps[k].seconds);
        row.runs = std::move(reps[k].runs);
        row.counts = last[k].rays;
        row.rays = last[k].rays.total();
        row.hit_fraction = std::nan("");
        set_timing(row, o);
        row.frames_per_second =
            row.timing.seconds_median > 0.0 ? 1.0 / row.timing.seconds_median : 0.0;
    }
}

void set_timing(BenchRow& row, const BenchOptions& o) {
    row.timing = summarize(row.seconds, row.rays);
    row.steady = row.timing.spread <= o.max_spread;
}

}  // namespace octray::bench::detail
