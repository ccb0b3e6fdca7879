// The two readers of scene files on the same text, so that the fast one's place is a
// measured one (scene/README.md, "Two readers"): parse_scene_json_fast (simdjson
// On-Demand, what `octray render` uses) against parse_scene_json_diagnosing (nlohmann
// through the SAX handler, which reads a file again only where the fast one declines).
// The text is `octray scene random:N` writes, read as read_scene_file reads it (the
// padding spares the fast reader its copy); the file read itself is not timed.

#include <benchmark/benchmark.h>

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

#include "scene/load.h"

namespace {

using namespace octray;

// random:N as JSON with kJsonPadding bytes of spare capacity after it, as from a file.
std::string scene_text(std::int64_t spheres) {
    std::string text = scene_to_json(load_scene("random:" + std::to_string(spheres)));
    text.reserve(text.size() + kJsonPadding);
    return text;
}

void fast(benchmark::State& state) {
    const std::string text = scene_text(state.range(0));
    for (auto _ : state) {
        std::optional<Scene> scene = parse_scene_json_fast(text, "bench.json", text.capacity());
        if (!scene) throw std::runtime_error("the fast reader declined a valid scene");
        benchmark::DoNotOptimize(scene);
    }
    state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(text.size()));
}

void diagnosing(benchmark::State& state) {
    const std::string text = scene_text(state.range(0));
    for (auto _ : state) {
        Scene scene = parse_scene_json_diagnosing(text, "bench.json");
        benchmark::DoNotOptimize(scene);
    }
    state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(text.size()));
}

BENCHMARK(fast)
    ->Name("read/fast")
    ->Arg(1024)
    ->Arg(65536)
    ->Arg(1048576)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(diagnosing)
    ->Name("read/diagnosing")
    ->Arg(1024)
    ->Arg(65536)
    ->Arg(1048576)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
