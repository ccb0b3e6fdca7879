#pragma once
// What the page shows of a linear image: scaled by 2^exposure, clamped to [0, 1],
// sRGB-encoded to 8 bits and packed as PNG in memory (the browser decodes PNG natively).

#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"

namespace octray::view {

// RGB bytes, row 0 on top: each channel min(max(v * 2^exposure, 0), 1) through the sRGB
// OETF (IEC 61966-2-1), rounded to nearest. NaN maps to 0.
std::vector<std::uint8_t> tone_map_srgb8(const Image& image, float exposure);

// An 8-bit RGB PNG of `rgb` (3 * width * height bytes) with an sRGB chunk, as a byte
// string for an HTTP body. Low zlib effort: the page wants it soon, not small. Throws
// std::runtime_error if libpng fails.
std::string encode_png_rgb8(int width, int height, const std::vector<std::uint8_t>& rgb);

}  // namespace octray::view
