#pragma once
// Resource limits on a render, checked before anything big is allocated: an estimate of
// the memory a render of a scene takes, a check against a limit (`octray render
// --max-memory`), and the parser for sizes such as "512M" or "4G".
//
// The estimate counts what the process really allocates, from the layouts in
// render/image/image.h, scene/compile.h, render/prepare/bvh_build.cpp,
// render/packet_renderer.cpp (its tile scratch: render/tile_layout.h),
// render/batch/progressive.cpp, render/aov.h, render/image/exr_write.cpp, render/image/png.cpp
// and render/batch/frame_loop.cpp, plus the process's own fixed footprint and the parse of a
// scene file; it is meant to be an upper bound of the peak resident set size
// (tests/batch/memory_estimate_test.cpp measures it). It errs on the high side: the packet
// path's per-thread ray streams are sized as if every generation of a tile held a full chunk of
// rays at once (tests/render/packet_renderer_test.cpp checks a thread's scratch against it),
// the BVH's build buffers as if they lived through the render.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "render/accel.h"
#include "render/render_config.h"
#include "scene/scene.h"

namespace octray::batch {

// How the render will run: what the per-thread terms depend on.
struct RenderMemoryParams {
    int threads = 0;                    // 0: std::thread::hardware_concurrency()
    int tile_width = TileSize{}.width;  // core/pixel_rect.h's default
    int tile_height = TileSize{}.height;
    bool packet_path = true;         // the SIMD renderer's per-tile ray streams (the default)
    Accel accel = Accel::automatic;  // the sphere BVH of either path (--accel)
    bool float32_output = false;     // EXR written as 32-bit floats instead of half
    int exr_lines_per_chunk = 16;    // the codec's scan lines per block (zip: 16, dwab: 256)
    bool png_preview = false;        // --png
    bool progressive = false;        // --progressive: a pass renders while the last is kept
    // A frame's image and files are written while the next frame renders: two frames'
    // images and EXR channels at once (BatchSettings::write_behind).
    bool write_behind = false;
    // --aov: the buffers of compute_aovs and their EXR channels.
    bool aov_depth = false, aov_normal = false, aov_albedo = false, aov_id = false;
    std::uint64_t scene_file_bytes = 0;  // the JSON file the scene was parsed from (0: none)
};

// Bytes, each term saturating at UINT64_MAX instead of overflowing.
struct RenderMemoryEstimate {
    std::uint64_t framebuffer = 0;  // the render's images: 12 bytes (three floats) per
                                    // pixel, two images and their sample sums if progressive
    std::uint64_t output = 0;       // the EXR writer's channels (color and AOVs) and line
                                    // buffers, and the PNG preview's bytes
    std::uint64_t aovs = 0;         // compute_aovs' buffers
    std::uint64_t scene = 0;        // the authored scene, its compiled SoA copy, the BVH
                                    // and what building it takes
    std::uint64_t load = 0;         // loading the scene: a file's text, JSON tree and the
                                    // scene built from it; a built-in's generation
    std::uint64_t fixed = 0;        // the process itself: code, libraries, thread pool
    std::uint64_t per_thread = 0;   // one thread's tile scratch (packet path)
    std::uint64_t threads = 1;      // the thread count the total assumes
    std::uint64_t total = 0;        // fixed + the larger of load and the rest (per_thread
                                    // times threads)

    // "about 1.2 GiB (framebuffer 0.9 GiB, EXR output 0.5 GiB, ...)".
    std::string describe() const;
};

// What the estimate takes from a render's description: threads, tiles, the path,
// acceleration and the AOVs; the caller adds what depends on the outputs (EXR type and
// codec, PNG, progressive passes, write behind, the scene file's size).
RenderMemoryParams memory_params(const RenderConfig& config);

RenderMemoryEstimate estimate_render_memory(const Scene& scene,
                                            const RenderMemoryParams& params = {});

// Throws SceneError (file: scene.source, path "image") with the estimate and its terms
// when the estimate exceeds `limit_bytes`.
void check_memory_limit(const Scene& scene, std::uint64_t limit_bytes,
                        const RenderMemoryParams& params = {});

// `octray render`'s check: the estimate of `scene` under `params`, where a frame written
// behind the next (params.write_behind) is kept only if both frames fit `limit_bytes`
// (else params.write_behind comes back false: the frames are written one after another),
// and check_memory_limit's error when even one frame does not fit. The scene's objects
// are counted once where the first estimate fits (2 ms for a million).
RenderMemoryEstimate fit_memory_limit(const Scene& scene, std::uint64_t limit_bytes,
                                      RenderMemoryParams& params);

// What loading a scene file of `file_bytes` bytes takes (its text, its JSON tree, the
// scene built from it and the process), known from the file's size before a byte of it is
// parsed.
RenderMemoryEstimate estimate_load_memory(std::uint64_t file_bytes);

// Throws SceneError (file: `path`) when loading a scene file of `file_bytes` bytes would
// exceed `limit_bytes`: a huge file is refused before it is read.
void check_load_memory_limit(const std::string& path, std::uint64_t file_bytes,
                             std::uint64_t limit_bytes);

// This machine's physical memory in bytes (sysconf), 0 if unknown: the limit for commands
// that render a whole scene without a --max-memory of their own (`octray verify`). Whether
// an image fits is the render's question, never the scene's (validate_scene).
std::uint64_t machine_memory_bytes();

// "1048576", "512K", "512M", "4G", "1T" (binary units, optional "iB"/"B" suffix, case
// insensitive); nullopt for anything else, zero, or a size over UINT64_MAX bytes.
std::optional<std::uint64_t> parse_memory_size(std::string_view text);

}  // namespace octray::batch
