// Whole-frame benchmarks: the scalar reference against the SIMD packet path at 1920x1080 on
// `whitted` and `random:64`, one and two threads, plus the packet path under each ISA the
// CPU runs. Each scene is validated before anything is timed: the packet image must equal
// the reference image bit for bit (at 320x180, to keep start-up short).
// Figures and the exact command: bench/README.md.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "kernels/dispatch.h"
#include "render/packet_renderer.h"
#include "render/reference.h"
#include "scene/compile.h"
#include "scene/load.h"

namespace {

using namespace octray;

struct BenchScene {
    std::string name;
    Scene scene;
    CompiledScene compiled;
};

// The scalar and packet paths must agree before their speeds mean anything.
bool validate(const std::string& spec) {
    const Scene small = load_scene(spec + ",width=320,height=180");
    const RenderResult ref = render_reference(small, {});
    const RenderResult simd = render_packet(small, {});
    const bool same =
        same_pixels(ref.image, simd.image) && ref.rays.total() == simd.rays.total();
    if (!same)
        std::fprintf(stderr, "%s: packet image differs from the reference\n", spec.c_str());
    return same;
}

RenderResult render_frame(const BenchScene& bs, bool simd, int threads, Isa isa) {
    RenderOptions options;
    options.threads = threads;
    return simd ? render_packet(bs.compiled, options, isa)
                : render_reference(bs.scene, options);
}

void frame(benchmark::State& state, const BenchScene& bs, bool simd, int threads, Isa isa) {
    std::uint64_t rays = 0;
    for (auto _ : state) {
        const RenderResult r = render_frame(bs, simd, threads, isa);
        rays += r.rays.total();
        benchmark::DoNotOptimize(r.image.plane(0));
    }
    state.counters["rays/s"] =
        benchmark::Counter(static_cast<double>(rays), benchmark::Counter::kIsRate);
    state.counters["Mrays/frame"] =
        static_cast<double>(rays) / 1e6 / static_cast<double>(state.iterations());
}

// Thread scaling as a ratio taken in one place: each iteration renders the frame on one
// thread and on two, back to back (which goes first alternates), so a host that speeds up
// or slows down over the run moves both halves of a pair alike. Counters: the medians of
// the one- and two-thread frames, the median of the per-pair ratios, and the ratio of the
// fastest frames (noise on a shared host only ever adds time).
void scaling(benchmark::State& state, const BenchScene& bs, bool simd) {
    const auto seconds = [&](int threads) {
        const auto start = std::chrono::steady_clock::now();
        const RenderResult r = render_frame(bs, simd, threads, Isa::automatic);
        benchmark::DoNotOptimize(r.image.plane(0));
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    std::vector<double> one, two, ratio;
    for (auto _ : state) {
        const bool one_first = one.size() % 2 == 0;
        const double a = seconds(one_first ? 1 : 2), b = seconds(one_first ? 2 : 1);
        one.push_back(one_first ? a : b);
        two.push_back(one_first ? b : a);
        ratio.push_back(one.back() / two.back());
    }
    const auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        const std::size_t n = v.size();
        return n == 0 ? 0.0 : n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    };
    state.counters["1T_ms"] = median(one) * 1e3;
    state.counters["2T_ms"] = median(two) * 1e3;
    state.counters["2T/1T"] = median(ratio);
    state.counters["2T/1T_best"] =
        *std::min_element(one.begin(), one.end()) / *std::min_element(two.begin(), two.end());
}

}  // namespace

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    static std::vector<BenchScene> scenes;
    for (const char* spec : {"whitted", "random:64"}) {
        if (!validate(spec)) return 1;
        Scene scene = load_scene(std::string(spec) + ",width=1920,height=1080");
        CompiledScene compiled = compile_scene(scene);
        std::fprintf(stderr, "%s: compiled in %.3f ms\n", spec, compiled.compile_seconds * 1e3);
        scenes.push_back({spec, std::move(scene), std::move(compiled)});
    }
    for (const BenchScene& bs : scenes) {
        for (int threads : {1, 2}) {
            benchmark::RegisterBenchmark(
                ("frame/" + bs.name + "/scalar/threads:" + std::to_string(threads)).c_str(),
                [&bs, threads](benchmark::State& s) {
                    frame(s, bs, false, threads, Isa::automatic);
                })
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime();
            benchmark::RegisterBenchmark(
                ("frame/" + bs.name + "/simd/threads:" + std::to_string(threads)).c_str(),
                [&bs, threads](benchmark::State& s) {
                    frame(s, bs, true, threads, Isa::automatic);
                })
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime();
        }
        for (bool simd : {false, true})
            benchmark::RegisterBenchmark(
                ("frame/" + bs.name + (simd ? "/simd" : "/scalar") + "/scaling").c_str(),
                [&bs, simd](benchmark::State& s) { scaling(s, bs, simd); })
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime()
                ->Iterations(simd ? 41 : 5);
        for (Isa isa : supported_isas())
            benchmark::RegisterBenchmark(
                ("frame/" + bs.name + "/simd-" + isa_name(isa) + "/threads:1").c_str(),
                [&bs, isa](benchmark::State& s) { frame(s, bs, true, 1, isa); })
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime();
    }
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
