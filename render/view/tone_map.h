#pragma once
// What the page shows of a linear image: scaled by 2^exposure, clamped to [0, 1] and
// sRGB-encoded to 8 bits as the PNG preview is (render/image/image_io.h's srgb8), then
// packed as PNG in memory by encode_png_rgb8 there (the browser decodes PNG natively).

#include <cstdint>
#include <vector>

#include "core/image.h"

namespace octray::view {

// RGB bytes, row 0 on top: each channel min(max(v * 2^exposure, 0), 1) through the sRGB
// OETF (IEC 61966-2-1), rounded to nearest. NaN maps to 0.
std::vector<std::uint8_t> tone_map_srgb8(const Image& image, float exposure);

}  // namespace octray::view
