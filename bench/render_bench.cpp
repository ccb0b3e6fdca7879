// Whole-frame benchmarks: the scalar reference against the SIMD packet path at 1920x1080 on
// `whitted` and `random:64`, one and two threads, plus the packet path under each ISA the
// CPU runs. Each scene is validated before anything is timed: the packet image must equal
// the reference image bit for bit (at 320x180, to keep start-up short).
// Figures and the exact command: bench/README.md.

#include <benchmark/benchmark.h>

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
    const bool same = ref.image == simd.image && ref.rays.total() == simd.rays.total();
    if (!same)
        std::fprintf(stderr, "%s: packet image differs from the reference\n", spec.c_str());
    return same;
}

void frame(benchmark::State& state, const BenchScene& bs, bool simd, int threads, Isa isa) {
    RenderOptions options;
    options.threads = threads;
    std::uint64_t rays = 0;
    for (auto _ : state) {
        const RenderResult r = simd ? render_packet(bs.compiled, options, isa)
                                    : render_reference(bs.scene, options);
        rays += r.rays.total();
        benchmark::DoNotOptimize(r.image.data());
    }
    state.counters["rays/s"] =
        benchmark::Counter(static_cast<double>(rays), benchmark::Counter::kIsRate);
    state.counters["Mrays/frame"] =
        static_cast<double>(rays) / 1e6 / static_cast<double>(state.iterations());
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
