#pragma once
// The checks both renderers make of RenderOptions::crop and RenderOptions::samples
// (render/README.md, "Crops"; render/batch/README.md, "Progressive passes"), in one place so
// that the two paths accept and refuse the same options with the same messages.

#include <stdexcept>
#include <string>

#include "render/types.h"

namespace octray {

// The pixels a render covers: options.crop, or the whole width x height image. Throws
// std::invalid_argument for an empty crop or one that reaches outside the image.
inline PixelRect render_rect(const RenderOptions& options, int width, int height) {
    const PixelRect full{0, 0, width, height};
    if (!options.crop) return full;
    const PixelRect& c = *options.crop;
    if (c.empty() || !full.contains(c)) {
        std::string message = "crop ";
        message += to_string(c);
        message += c.empty() ? " is empty" : " is not inside the image";
        message += " (the image is ";
        message += std::to_string(width);
        message += "x";
        message += std::to_string(height);
        message +=
            "; a crop is x0,y0,x1,y1 with 0 <= x0 < x1 <= width, 0 <= y0 < y1 <= height)";
        throw std::invalid_argument(message);
    }
    return c;
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
    if (r.begin > 0 &&
        (options.sample_sums == nullptr || options.sample_sums->width() != rect.width() ||
         options.sample_sums->height() != rect.height()))
        throw std::invalid_argument(
            "a sample range that starts after sample 0 needs the previous pass's sums "
            "(RenderOptions::sample_sums) at the size of the rendered rectangle");
    return r;
}

}  // namespace octray
