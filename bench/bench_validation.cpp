// Validation for `octray bench`: the scenes at the bench's and the validation size, the
// double-precision oracle's budget, whole renders (packet and Embree frames) against the
// reference render, and the time to first pixel.

#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "bench/bench_detail.h"
#include "render/packet_renderer.h"
#include "render/reference.h"
#include "scene/compile.h"
#include "scene/load.h"

namespace octray::bench::detail {

namespace {

// The double-precision oracle is brute force: checking 65 536 rays against 10^6 spheres
// would take minutes per ray set. It answers at most kDoubleOracleBudget / objects rays
// (at least kDoubleOracleMinRays).
constexpr std::uint64_t kDoubleOracleBudget = 1ull << 30;  // ray-object tests per ray set
constexpr std::uint64_t kDoubleOracleMinRays = 1024;

}  // namespace

OracleHits double_oracle_rays(const OracleHits& exact, std::size_t objects) {
    const std::uint64_t n = exact.index.size();
    const std::uint64_t cap = std::max<std::uint64_t>(
        kDoubleOracleMinRays, kDoubleOracleBudget / std::max<std::uint64_t>(objects, 1));
    OracleHits out;
    if (n <= cap) {
        out.index = exact.index;
        return out;
    }
    // Even stride over the exact oracle's rays: k * n / cap, strictly increasing.
    out.index.resize(cap);
    for (std::uint64_t k = 0; k < cap; ++k) out.index[k] = exact.index[k * n / cap];
    return out;
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

// The scene at the validation size of whole renders. (The reference finds its spheres
// through a BVH of its own, so the size no longer shrinks with the sphere count.)
Scene validation_scene(const std::string& spec, const BenchOptions& o) {
    return load_bench_scene(spec, std::min(o.width, o.validate_width),
                            std::min(o.height, o.validate_height));
}

// The packet render of the scene at the validation size equals the reference render,
// image and ray counts.
std::string validate_render(const std::string& spec, const BenchOptions& o, Isa isa,
                            Accel accel, bool prepared, bool& valid) {
    const Scene small = validation_scene(spec, o);
    RenderOptions ro;
    ro.threads = o.threads;
    const RenderResult ref = render_reference(small, ro);  // through the reference's BVH
    ro.accel = accel;
    const RenderResult simd =
        prepared ? render_packet(PreparedScene(small, accel, o.threads), ro, isa)
                 : render_packet(small, ro, isa);
    valid = same_pixels(ref.image, simd.image) && ref.rays.total() == simd.rays.total();
    return std::string(valid ? "valid" : "INVALID") + ": " +
           (prepared ? "prepared-scene" : "packet") + " image " +
           (same_pixels(ref.image, simd.image) ? "equals" : "differs from") +
           " the reference image at " + std::to_string(small.image.width) + "x" +
           std::to_string(small.image.height) + ", ray counts " +
           (ref.rays.total() == simd.rays.total() ? "equal" : "differ");
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
        const Rgb a(ref.image.plane(0)[k], ref.image.plane(1)[k], ref.image.plane(2)[k]);
        const Rgb b(e.image.plane(0)[k], e.image.plane(1)[k], e.image.plane(2)[k]);
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

}  // namespace octray::bench::detail
