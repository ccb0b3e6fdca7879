#pragma once
// JPEG in memory for the picture stream (view/README.md, "Transport"): a moving
// camera's previews and the passes before the last are sent as JPEG, which costs a few
// milliseconds to encode and to decode at 1280x720 where PNG costs tens (measured there);
// the refined picture stays PNG, lossless. libjpeg-turbo (Debian's libjpeg62-turbo-dev).

#include <cstdint>
#include <string>
#include <vector>

namespace octray::view {

// The quality of the stream's JPEG pictures: at 85 a preview shows no blocks at 100% zoom,
// and the refined picture that follows is PNG anyway.
constexpr int kStreamJpegQuality = 85;

// Baseline JPEG of `rgb` (width x height x 3 bytes, row 0 on top) at `quality` (1 to 100),
// 4:2:0 chroma. Throws std::runtime_error if libjpeg fails (out of memory).
std::string encode_jpeg_rgb8(int width, int height, const std::vector<std::uint8_t>& rgb,
                             int quality);

}  // namespace octray::view
