#pragma once
// Resource limits on a render, checked before anything big is allocated: an estimate of
// the memory a render of a scene takes, a check against a limit (`octray render
// --max-memory`), and the parser for sizes such as "512M" or "4G".
//
// The estimate counts what grows with the input, from the layouts in core/image.h,
// scene/compile.h, render/packet_renderer.cpp and render/image_io.cpp; fixed costs
// (code, thread stacks, OpenEXR's line buffers, a few MB) are not counted. It errs on the
// high side for the packet path's per-thread ray streams, which it sizes as if every ray
// of every generation of a tile lived at once.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "scene/scene.h"

namespace octray {

// How the render will run: what the per-thread terms depend on.
struct RenderMemoryParams {
    int threads = 0;  // 0: std::thread::hardware_concurrency()
    int tile_width = 16;
    int tile_height = 16;
    bool packet_path = true;      // the SIMD renderer's per-tile ray streams (the default)
    bool float32_output = false;  // EXR written as 32-bit floats instead of half
};

// Bytes, each term saturating at UINT64_MAX instead of overflowing.
struct RenderMemoryEstimate {
    std::uint64_t framebuffer = 0;  // 12 bytes (three floats) per pixel
    std::uint64_t output = 0;       // the EXR writer's converted copy of the image
    std::uint64_t scene = 0;        // the authored scene plus its compiled SoA copy
    std::uint64_t per_thread = 0;   // one thread's tile scratch (packet path)
    std::uint64_t threads = 1;      // the thread count the total assumes
    std::uint64_t total = 0;        // framebuffer + output + scene + threads * per_thread

    // "about 1.2 GiB (framebuffer 0.9 GiB, EXR output 0.5 GiB, ...)".
    std::string describe() const;
};

RenderMemoryEstimate estimate_render_memory(const Scene& scene,
                                            const RenderMemoryParams& params = {});

// Throws SceneError (file: scene.source, path "image") with the estimate and its terms
// when the estimate exceeds `limit_bytes`.
void check_memory_limit(const Scene& scene, std::uint64_t limit_bytes,
                        const RenderMemoryParams& params = {});

// "1048576", "512K", "512M", "4G", "1T" (binary units, optional "iB"/"B" suffix, case
// insensitive); nullopt for anything else, zero, or a size over UINT64_MAX bytes.
std::optional<std::uint64_t> parse_memory_size(std::string_view text);

}  // namespace octray
