#pragma once
// What a render gives back: its pixels and windows (RenderResult), and the first hits the
// AOVs are made from (FirstHits). What it is asked: render/render_options.h.

#include <cstdint>
#include <vector>

#include "core/aligned.h"
#include "core/pixel_rect.h"
#include "render/image/image.h"
#include "render/render_options.h"

namespace octray {

// The closest hit of each pixel's sample-0 camera ray over `rect`, row by row (top row
// first): the first hits the AOVs read, traced by either path. object is the hit's
// Scene::objects index, or -1 (t = +inf) for a miss or a camera sample with no ray (a
// fisheye pixel outside its image circle).
// Sized without being written (UninitializedVector): the tracer writes every pixel.
struct FirstHits {
    PixelRect rect;
    UninitializedVector<float> t;
    UninitializedVector<std::int32_t> object;
};

struct RenderResult {
    // The pixels: float32 channels R, G, B (make_rgb_image, render/image/image.h) of the
    // pixels the render covered, its data window (the crop, or the whole image), inside a
    // display window of the whole image; pixel (0, 0) of the planes is the data window's
    // corner. A block render (render_packet_blocks) writes into its target instead and
    // leaves this without channels, its display window the whole image.
    Image image;
    // With RenderOptions::samples: the per-pixel sums of samples [0, samples->end), to pass
    // on as the next pass's sample_sums (an image like `image`). Empty otherwise.
    Image sample_sums;
    RayCounts rays;
    double seconds = 0.0;  // wall-clock time of the render itself
    // The parts of `seconds` spent compiling the scene and building its BVH (0 where the
    // render did neither: a precompiled scene, no BVH; summed over progressive passes).
    double compile_seconds = 0.0;
    double bvh_seconds = 0.0;
    // The SIMD path: the largest tile scratch (bytes) of a thread that rendered tiles, after
    // the render. A thread keeps its scratch from render to render and it never shrinks,
    // so this is that thread's high-water mark so far. 0 for the scalar reference.
    std::uint64_t scratch_bytes = 0;
};

}  // namespace octray
