#pragma once
// Inside the image library: what image_read.cpp and png.cpp share for reading. Not for
// other callers (they use read_image(), render/image/image_read.h).

#include <cstddef>
#include <string>
#include <vector>

#include "render/image/image_read.h"

namespace octray {

// A bound on what one read may allocate (4 GiB of floats): a corrupt header that claims a
// gigantic image must fail as a file error, not as an out-of-memory crash.
inline constexpr std::size_t max_read_float_values = std::size_t{1} << 30;

// Throws IoError "cannot read '<path>': <reason>", the reason on one line (image_read.cpp).
[[noreturn]] void fail_reading(const std::string& path, std::string reason);

// The PNG file `path`, whose bytes are `bytes`, as read_image() returns it (png.cpp).
Image read_png_channels(const std::string& path, const std::vector<unsigned char>& bytes);

}  // namespace octray
