#pragma once
// What the page shows of a linear image: scaled by 2^exposure, clamped to [0, 1] and
// sRGB-encoded to 8 bits as the PNG preview is (render/image/image_io.h's srgb8), then
// packed as PNG in memory by encode_png_rgb8 there (the browser decodes PNG natively).

#include <cstdint>
#include <string>
#include <vector>

#include "render/image/image.h"
#include "view/view_session.h"

namespace octray::view {

// RGB bytes, row 0 on top: each channel min(max(v * 2^exposure, 0), 1) through the sRGB
// OETF (IEC 61966-2-1), rounded to nearest. NaN maps to 0.
// `image`: a render's picture (float32 R, G, B planes, render/image/image.h); else throws
// std::invalid_argument.
std::vector<std::uint8_t> tone_map_srgb8(const Image& image, float exposure);

// A picture as the page's picture stream sends it (README, "Transport"): tone-mapped at
// `exposure`; the refined picture (not a preview, the last pass, all of it rendered with
// its camera) as PNG, lossless, any other as JPEG (kStreamJpegQuality), which costs a
// fraction of PNG's time to encode and to decode.
struct PagePicture {
    std::string bytes;
    const char* format;  // "png" or "jpeg"
};
PagePicture encode_for_page(const ViewFrame& frame, float exposure);

}  // namespace octray::view
