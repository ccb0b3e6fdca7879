#pragma once
// The checks both renderers make of RenderOptions::crop and RenderOptions::samples
// (render/README.md, "Crops"; render/batch/README.md, "Progressive passes"), in one place so
// that the two paths accept and refuse the same options with the same messages.

#include <climits>
#include <span>
#include <stdexcept>
#include <string>

#include "render/image/image.h"
#include "render/render_options.h"

namespace octray {

// `rect` when it is non-empty and inside the width x height image; else throws
// std::invalid_argument naming it as `what` ("crop", "block").
inline const PixelRect& check_rect_inside(const PixelRect& rect, int width, int height,
                                          const char* what) {
    const PixelRect full{0, 0, width, height};
    if (!rect.empty() && full.contains(rect)) return rect;
    std::string message = what;
    message += " ";
    message += to_string(rect);
    message += rect.empty() ? " is empty" : " is not inside the image";
    message += " (the image is ";
    message += std::to_string(width);
    message += "x";
    message += std::to_string(height);
    message += "; a ";
    message += what;
    message += " is x0,y0,x1,y1 with 0 <= x0 < x1 <= width, 0 <= y0 < y1 <= height)";
    throw std::invalid_argument(message);
}

// The pixels a render covers: options.crop, or the whole width x height image. Throws
// std::invalid_argument for an empty crop or one that reaches outside the image.
inline PixelRect render_rect(const RenderOptions& options, int width, int height) {
    if (!options.crop) return PixelRect{0, 0, width, height};
    return check_rect_inside(*options.crop, width, height, "crop");
}

// The checks of a render of blocks into `target`, the width x height picture
// (render_packet_blocks, render_reference_blocks): each block non-empty and inside it, and
// neither a crop nor a sample range (a block render traces every sample of its pixels).
// Throws std::invalid_argument.
inline void check_block_render(std::span<const PixelRect> blocks, const Image& target,
                               int width, int height, const RenderOptions& options) {
    if (!is_rgb_image(target))
        throw std::invalid_argument(
            "a block render writes into a render's image (float32 channels R, G and B)");
    if (target.width() != width || target.height() != height)
        throw std::invalid_argument("a block render writes into the whole " +
                                    std::to_string(width) + "x" + std::to_string(height) +
                                    " picture, not a " + std::to_string(target.width()) + "x" +
                                    std::to_string(target.height()) + " one");
    if (options.crop || options.samples)
        throw std::invalid_argument(
            "a block render takes neither a crop nor a sample range (RenderOptions::crop, "
            "::samples): its blocks say which pixels, and it traces all their samples");
    if (blocks.size() > static_cast<std::size_t>(INT_MAX))
        throw std::invalid_argument("a block render takes at most 2^31 - 1 blocks");
    for (const PixelRect& block : blocks) check_rect_inside(block, width, height, "block");
}

// The samples a render traces: options.samples, or [0, spp). Throws std::invalid_argument
// unless 0 <= begin < end <= spp and, for begin > 0, sample_sums is a rect-sized image.
inline SampleRange render_sample_range(const RenderOptions& options, int spp,
                                       const PixelRect& rect) {
    if (!options.samples) return SampleRange{0, spp};
    const SampleRange r = *options.samples;
    if (r.begin < 0 || r.begin >= r.end || r.end > spp) {
        std::string message = "sample range [";
        message += std::to_string(r.begin);
        message += ", ";
        message += std::to_string(r.end);
        message += ") is not a non-empty part of [0, ";
        message += std::to_string(spp);
        message += ")";
        throw std::invalid_argument(message);
    }
    if (r.begin > 0 && (options.sample_sums == nullptr || !is_rgb_image(*options.sample_sums) ||
                        options.sample_sums->width() != rect.width() ||
                        options.sample_sums->height() != rect.height()))
        throw std::invalid_argument(
            "a sample range that starts after sample 0 needs the previous pass's sums "
            "(RenderOptions::sample_sums: float32 R, G, B) at the size of the rendered "
            "rectangle");
    return r;
}

}  // namespace octray
