#pragma once
// What a render is asked: the path (RenderPath), the limits, the sample range and the
// options both render paths take (RenderOptions), the ray counts they keep, and the
// exception a cancelled render ends with. What it gives back: render/render_result.h.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "core/pixel_rect.h"
#include "render/accel.h"
#include "scene/json_rules.h"

namespace octray {

struct Image;  // render/image/image.h

// Which renderer traces a frame: the SIMD packet path (render/packet_renderer.h) or the
// scalar reference (render/reference.h). `--path simd|scalar` of `render` and `bench`.
enum class RenderPath { simd, scalar };

inline const char* render_path_name(RenderPath path) {
    return path == RenderPath::simd ? "simd" : "scalar";
}

inline std::optional<RenderPath> parse_render_path(std::string_view name) {
    if (name == "simd") return RenderPath::simd;
    if (name == "scalar") return RenderPath::scalar;
    return std::nullopt;
}

// The most samples per pixel and worker threads a render takes from its user: `octray
// render --spp/--threads`, `octray view`'s switches (tools/cli_checks.h builds the options'
// checks and help from these). The spp limit is the scene format's (a scene file's
// image.spp, a built-in's spp=, the API's RenderOptions::spp): one limit wherever it is set.
inline constexpr int kMaxSamplesPerPixel = scene_json::kMaxSpp;
inline constexpr int kMaxRenderThreads = 4096;

struct RayCounts {
    std::uint64_t primary = 0;
    std::uint64_t shadow = 0;
    std::uint64_t reflected = 0;
    std::uint64_t refracted = 0;

    std::uint64_t total() const { return primary + shadow + reflected + refracted; }
    RayCounts& operator+=(const RayCounts& o) {
        primary += o.primary;
        shadow += o.shadow;
        reflected += o.reflected;
        refracted += o.refracted;
        return *this;
    }
};

// A range [begin, end) of the sample indices 0 .. spp-1 of every pixel (progressive passes).
struct SampleRange {
    int begin = 0;
    int end = 0;
};

struct RenderOptions {
    int threads = 0;                    // 0: every core TBB sees
    std::uint32_t frame = 0;            // the frame counter of the random hash
    int tile_width = TileSize{}.width;  // core/pixel_rect.h's default
    int tile_height = TileSize{}.height;
    // Batch rendering (render/batch/frame_loop.h), both optional: the renderers poll *cancel
    // between tiles and inside them (the simd path between chunks of packets, the scalar
    // one before each ray), so a frame of any size, spp and depth stops within a few
    // milliseconds of work once it is true, and throw RenderCancelled; they add each
    // finished tile's pixel count to *pixels_done (progress).
    const std::atomic<bool>* cancel = nullptr;
    std::atomic<std::uint64_t>* pixels_done = nullptr;
    // A spent image whose storage the render may take for its own (make_rgb_image's
    // `spare`: when the pixel counts agree); it is left empty. The frame loop hands back
    // each frame it has written, so a batch maps its frame's pages once, not once per frame.
    Image* spare_image = nullptr;
    // Render only these pixels of the full image (render/README.md, "Crops"): the result
    // image is crop-sized and each pixel equals the same pixel of the full render bit for
    // bit. Must be non-empty and inside the image (else std::invalid_argument).
    std::optional<PixelRect> crop;
    // Progressive passes (render/batch/progressive.h): trace only samples [begin, end) of each
    // pixel, adding them in sample order onto *sample_sums (the running sums of samples
    // [0, begin), crop-sized; nullptr when begin == 0). The result then also carries the
    // new sums; its image is sums / end. Unset: every sample, as a plain render.
    std::optional<SampleRange> samples;
    const Image* sample_sums = nullptr;
    // The SIMD path's acceleration structure for spheres (`--accel`, render/accel.h): auto
    // builds a BVH from kBvhAutoMinSpheres spheres on. The image is the same either way;
    // the scalar reference ignores it (brute force always).
    Accel accel = Accel::automatic;
    // The SIMD path traces each generation of a tile's ray tree at most this many rays at
    // a time, depth first (render/README.md, "Bounded memory"), rounded up to a multiple
    // of 16; 0: kDefaultRayChunk (4096). The image is the same for any value; tests make
    // it small to cross many chunk boundaries.
    std::uint32_t ray_chunk = 0;
};

// Thrown by a render stopped through RenderOptions::cancel: no image is returned.
class RenderCancelled : public std::runtime_error {
  public:
    RenderCancelled() : std::runtime_error("render cancelled") {}
};

}  // namespace octray
