// Microbenchmarks of the packet kernels against the scalar reference, each on 4096 rays
// (a 64 x 64 block of camera rays): ray-sphere and ray-plane intersection, the camera
// kernel, stream compaction, shading, and one 16 x 16 tile rendered end to end. Every
// kernel benchmark checks its packet result against the scalar one before timing and
// reports rays per second (benchmark::Counter::kIsRate). Also the sphere BVH's build on
// whole scenes, on 1 and 2 threads, in spheres per second. Figures: bench/README.md.

#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <cstring>
#include <string>
#include <vector>

#include "bench/compaction_kernels.h"
#include "bench/ray_sets.h"
#include "core/aligned.h"
#include "core/random.h"
#include "kernels/dispatch.h"
#include "render/packet_renderer.h"
#include "render/prepare/bvh_build.h"
#include "render/prepare/scene_view.h"
#include "render/reference.h"
#include "scene/compile.h"
#include "scene/load.h"

namespace {

using namespace octray;
using namespace octray::bench;

constexpr int kSide = 64;  // 4096 rays per iteration

// A scene of `spheres` spheres in front of the camera (random:N's layout) and/or a floor.
Scene make_scene(int spheres, bool plane) {
    Scene s = load_scene("random:" + std::to_string(spheres > 0 ? spheres : 1) +
                         ",width=64,height=64");
    if (spheres == 0) s.objects.clear();
    if (plane) {
        Object floor;
        floor.type = ObjectType::plane;
        floor.point = {0.0f, -0.5f, 0.0f};
        floor.normal = {0.0f, 1.0f, 0.0f};
        s.objects.push_back(floor);
    }
    validate_scene(s);
    return s;
}

struct Workbench {
    Scene scene;
    CompiledScene compiled;
    kernels::SceneView view;
    ReferenceTracer tracer;
    RaySet rays;
    explicit Workbench(Scene s)
        : scene(std::move(s)),
          compiled(compile_scene(scene)),
          view(make_scene_view(compiled)),
          tracer(scene),
          rays(make_primary_rays(tracer, kSide, kSide,
                                 pixel_order(kSide, kSide, PixelOrder::morton))) {}
};

// Packet closest hits must equal the scalar reference's bit for bit.
bool packet_matches_scalar(const Workbench& w, const kernels::KernelTable& k) {
    HitSet hits;
    hits.resize(static_cast<std::uint32_t>(w.rays.ox.size()));
    k.closest_hit(w.view, w.rays.ray_stream(0), w.rays.count, w.rays.t_min, hits.stream(0));
    return validate_hits(hits, oracle_hits(w.tracer, w.rays, 0), kExactRule).valid;
}

void set_rate(benchmark::State& state, std::uint64_t per_iteration,
              const char* name = "rays/s") {
    state.counters[name] = benchmark::Counter(
        static_cast<double>(per_iteration) * static_cast<double>(state.iterations()),
        benchmark::Counter::kIsRate);
}

// ---- Intersection ------------------------------------------------------------------------

void intersect_packet(benchmark::State& state, const Workbench& w, Isa isa) {
    const kernels::KernelTable& k = kernel_table(isa);
    if (!packet_matches_scalar(w, k)) {
        state.SkipWithError("packet hits differ from the scalar reference");
        return;
    }
    HitSet hits;
    hits.resize(static_cast<std::uint32_t>(w.rays.ox.size()));
    for (auto _ : state) {
        k.closest_hit(w.view, w.rays.ray_stream(0), w.rays.count, w.rays.t_min, hits.stream(0));
        benchmark::DoNotOptimize(hits.t.data());
        benchmark::ClobberMemory();
    }
    set_rate(state, w.rays.count);
    set_rate(state, std::uint64_t{w.rays.count} * w.scene.objects.size(), "tests/s");
}

void intersect_scalar(benchmark::State& state, const Workbench& w) {
    for (auto _ : state) {
        for (std::uint32_t i = 0; i < w.rays.count; ++i) {
            auto hit = w.tracer.intersect(w.rays.ray(i));
            benchmark::DoNotOptimize(hit);
        }
    }
    set_rate(state, w.rays.count);
    set_rate(state, std::uint64_t{w.rays.count} * w.scene.objects.size(), "tests/s");
}

// ---- Camera --------------------------------------------------------------------------------

struct CameraBench {
    Workbench w{make_scene(16, false)};
    AlignedVector<float> x, y, lu, lv;
    AlignedVector<std::uint32_t> pixel;
    AlignedVector<float> ox, oy, oz, dx, dy, dz, wr, wg, wb;
    AlignedVector<std::uint32_t> out_pixel;
    static constexpr std::uint32_t kCount = kSide * kSide;
    CameraBench() {
        for (auto* v : {&x, &y, &lu, &lv, &ox, &oy, &oz, &dx, &dy, &dz, &wr, &wg, &wb})
            v->assign(kCount + 8, 0.0f);
        pixel.assign(kCount + 8, 0);
        out_pixel.assign(kCount + 8, 0);
        for (std::uint32_t p = 0; p < kCount; ++p) {
            x[p] = film_x(static_cast<int>(p % kSide), 0.5f, kSide);
            y[p] = film_y(static_cast<int>(p / kSide), 0.5f, kSide);
            pixel[p] = p;
        }
    }
    kernels::RayStream out() {
        return {ox.data(), oy.data(), oz.data(), dx.data(), dy.data(),
                dz.data(), wr.data(), wg.data(), wb.data(), out_pixel.data()};
    }
};

void camera_packet(benchmark::State& state, Isa isa) {
    CameraBench c;
    const kernels::KernelTable& k = kernel_table(isa);
    const kernels::CameraSamples samples{c.x.data(), c.y.data(), c.lu.data(), c.lv.data(),
                                         c.pixel.data()};
    k.camera_rays(c.w.view, samples, CameraBench::kCount, c.out());
    for (std::uint32_t p = 0; p < CameraBench::kCount; ++p) {
        const Ray r =
            *c.w.tracer.camera_ray(static_cast<int>(p % kSide), static_cast<int>(p / kSide), 0);
        if (!(r.direction == Vec3{c.dx[p], c.dy[p], c.dz[p]})) {
            state.SkipWithError("packet camera rays differ from the reference's");
            return;
        }
    }
    for (auto _ : state) {
        benchmark::DoNotOptimize(
            k.camera_rays(c.w.view, samples, CameraBench::kCount, c.out()));
        benchmark::ClobberMemory();
    }
    set_rate(state, CameraBench::kCount);
}

void camera_scalar(benchmark::State& state) {
    CameraBench c;
    for (auto _ : state) {
        for (std::uint32_t p = 0; p < CameraBench::kCount; ++p) {
            auto r = c.w.tracer.camera_ray(static_cast<int>(p % kSide),
                                           static_cast<int>(p / kSide), 0);
            benchmark::DoNotOptimize(r);
        }
    }
    set_rate(state, CameraBench::kCount);
}

// ---- Compaction ----------------------------------------------------------------------------

// Keep every lane whose hash is below `keep_percent`: live rays scattered at random.
void compaction(benchmark::State& state, CompactFn packed) {
    const auto keep_percent = static_cast<std::uint32_t>(state.range(0));
    constexpr std::uint32_t n = 4096;
    AlignedVector<float> src(n), keep(n), dst(n + 8), want(n + 8);
    std::uint32_t expected = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
        src[i] = static_cast<float>(i);
        keep[i] = mix64(i) % 100 < keep_percent ? 1.0f : 0.0f;
        if (keep[i] != 0.0f) want[expected++] = src[i];
    }
    const auto scalar = [&](float* out) {
        std::uint32_t w = 0;
        for (std::uint32_t i = 0; i < n; ++i)
            if (keep[i] != 0.0f) out[w++] = src[i];
        return w;
    };
    const std::uint32_t got =
        packed ? packed(src.data(), keep.data(), n, dst.data()) : scalar(dst.data());
    if (got != expected ||
        std::memcmp(dst.data(), want.data(), expected * sizeof(float)) != 0) {
        state.SkipWithError("compaction result differs from the expected lanes");
        return;
    }
    for (auto _ : state) {
        benchmark::DoNotOptimize(packed ? packed(src.data(), keep.data(), n, dst.data())
                                        : scalar(dst.data()));
        benchmark::ClobberMemory();
    }
    set_rate(state, n, "lanes/s");
}

// ---- Shading -------------------------------------------------------------------------------

// One generation of a scene's primary rays: closest hits once, then shade() timed. whitted
// mixes a plane and spheres of four materials in its packets; random:1024's spheres share
// one material.
void shade_packet(benchmark::State& state, const std::string& spec, Isa isa) {
    Scene scene = load_scene(spec + ",width=64,height=64");
    Workbench w(scene);
    const kernels::KernelTable& k = kernel_table(isa);
    const std::uint32_t n = w.rays.count;
    const std::size_t cap =
        2 * static_cast<std::size_t>(n) * (w.compiled.lights.count + 1) + 16;
    std::vector<AlignedVector<float>> f(40, AlignedVector<float>(cap, 0.0f));
    std::vector<AlignedVector<std::uint32_t>> u(4, AlignedVector<std::uint32_t>(cap, 0));
    AlignedVector<float> wr(w.rays.ox.size(), 1.0f);
    AlignedVector<std::uint32_t> pix(w.rays.ox.size(), 0);
    HitSet hits;
    hits.resize(static_cast<std::uint32_t>(w.rays.ox.size()));
    kernels::RayStream rays = w.rays.ray_stream(0);
    rays.wr = rays.wg = rays.wb = wr.data();
    rays.pixel = pix.data();
    k.closest_hit(w.view, rays, n, w.rays.t_min, hits.stream(0));
    if (!validate_hits(hits, oracle_hits(w.tracer, w.rays, 0), kExactRule).valid) {
        state.SkipWithError("packet hits differ from the scalar reference");
        return;
    }
    int i = 0;
    const auto next = [&] { return f[static_cast<std::size_t>(i++)].data(); };
    kernels::SurfaceColor color{next(), next(), next(), next(), next(),
                                next(), next(), next(), next()};
    kernels::ShadowStream shadows{next(), next(), next(), next(), next(),     next(),
                                  next(), next(), next(), next(), u[0].data()};
    kernels::RayStream out{next(), next(), next(), next(), next(),
                           next(), next(), next(), next(), u[1].data()};
    kernels::ChildLinks links{u[2].data(), next(), next(), next()};
    const kernels::ShadeInput in{rays, hits.stream(0), n, 0};
    const kernels::ShadeOutput output{color, shadows, out, links};
    kernels::ShadeCounts counts{};
    for (auto _ : state) {
        counts = k.shade(w.view, in, output);
        benchmark::DoNotOptimize(counts);
        benchmark::ClobberMemory();
    }
    set_rate(state, n);
    state.counters["shadow rays/ray"] = static_cast<double>(counts.shadow) / n;
}

// ---- One tile end to end -------------------------------------------------------------------

void tile_end_to_end(benchmark::State& state, bool simd, Isa isa) {
    const Scene scene = load_scene("whitted,width=16,height=16");
    const CompiledScene compiled = compile_scene(scene);
    RenderOptions options;
    options.threads = 1;
    const RenderResult ref = render_reference(scene, options);
    if (simd && !(same_pixels(render_packet(compiled, options, isa).image, ref.image))) {
        state.SkipWithError("packet tile differs from the reference tile");
        return;
    }
    for (auto _ : state) {
        const RenderResult r =
            simd ? render_packet(compiled, options, isa) : render_reference(scene, options);
        benchmark::DoNotOptimize(r.image.plane(0));
    }
    set_rate(state, ref.rays.total());
    set_rate(state, 256, "pixels/s");
}

// ---- BVH build --------------------------------------------------------------------------

// The sphere BVH of a built-in scene, built on `threads` TBB threads (as `octray bench`
// times it), in spheres per second.
void bvh_build(benchmark::State& state, const std::string& spec, int threads) {
    const CompiledScene compiled = compile_scene(load_scene(spec));
    tbb::task_arena arena(threads);
    for (auto _ : state) {
        SphereBvh bvh;
        arena.execute([&] { bvh = build_sphere_bvh(compiled.spheres); });
        benchmark::DoNotOptimize(bvh.nodes.data());
    }
    set_rate(state, compiled.spheres.count, "spheres/s");
}

}  // namespace

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    static const Workbench spheres1(make_scene(1, false));
    static const Workbench spheres16(make_scene(16, false));
    static const Workbench plane1(make_scene(0, true));
    const std::vector<Isa> isas = supported_isas();
    const auto reg = [](const std::string& name, auto fn) {
        return benchmark::RegisterBenchmark(name.c_str(), fn)->MinTime(0.1);
    };

    for (const auto& [label, w] :
         {std::pair<const char*, const Workbench*>{"sphere1", &spheres1},
          {"sphere16", &spheres16},
          {"plane1", &plane1}}) {
        reg(std::string("intersect/") + label + "/scalar",
            [w = w](benchmark::State& s) { intersect_scalar(s, *w); });
        for (Isa isa : isas)
            reg(std::string("intersect/") + label + "/packet8-" + isa_name(isa),
                [w = w, isa](benchmark::State& s) { intersect_packet(s, *w, isa); });
    }
    reg("camera/scalar", [](benchmark::State& s) { camera_scalar(s); });
    for (Isa isa : isas)
        reg(std::string("camera/packet8-") + isa_name(isa),
            [isa](benchmark::State& s) { camera_packet(s, isa); });
    for (const auto& [name, fn] :
         {std::pair<const char*, CompactFn>{"scalar", nullptr},
          {"sse2", isa_supported(Isa::sse2) ? &compact_sse2 : nullptr},
          {"avx2", isa_supported(Isa::avx2) ? &compact_avx2 : nullptr}}) {
        if (std::string(name) != "scalar" && fn == nullptr) continue;
        reg(std::string("compaction/") + name,
            [fn = fn](benchmark::State& s) { compaction(s, fn); })
            ->Arg(10)
            ->Arg(50)
            ->Arg(90);
    }
    for (const char* spec : {"whitted", "random:1024"})
        for (Isa isa : isas)
            reg(std::string("shade/") + spec + "/packet8-" + isa_name(isa),
                [spec = std::string(spec), isa](benchmark::State& s) {
                    shade_packet(s, spec, isa);
                });
    reg("tile16x16/whitted/scalar", [](benchmark::State& s) {
        tile_end_to_end(s, false, Isa::automatic);
    })->UseRealTime();
    for (Isa isa : isas)
        reg(std::string("tile16x16/whitted/packet8-") + isa_name(isa),
            [isa](benchmark::State& s) { tile_end_to_end(s, true, isa); })
            ->UseRealTime();
    for (const char* spec : {"random:65536", "sphereflake:5", "random:1048576"})
        for (int threads : {1, 2})
            reg(std::string("bvh_build/") + spec + "/threads:" + std::to_string(threads),
                [spec = std::string(spec), threads](benchmark::State& s) {
                    bvh_build(s, spec, threads);
                })
                ->UseRealTime()
                ->Unit(benchmark::kMillisecond);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
