#pragma once
// Writing images: OpenEXR (the product) and 8-bit PNG previews. Every writer goes through
// write_file_atomically(), so an interrupted run never leaves a partial image behind.

#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/image.h"

namespace octray {

// Any failure to read or write a file. Its message names the file and the reason.
class IoError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Calls write(tmp_path) with a fresh temporary path in the target's directory, then
// renames it over `path` (atomic on POSIX). On any exception the temporary is removed
// and the exception passes on as an IoError naming `path`.
void write_file_atomically(const std::string& path,
                           const std::function<void(const std::string& tmp_path)>& write);

enum class ExrCompression { none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa, dwab };

std::optional<ExrCompression> parse_exr_compression(std::string_view name);
std::string_view to_string(ExrCompression compression);

struct ExrWriteOptions {
    bool float32 = false;  // 32-bit float channels instead of half
    ExrCompression compression = ExrCompression::zip;
};

// Extra header attributes, written as OpenEXR string / float / int / double attributes.
struct ExrAttributes {
    std::vector<std::pair<std::string, std::string>> strings;
    std::vector<std::pair<std::string, float>> floats;
    std::vector<std::pair<std::string, int>> ints;
    std::vector<std::pair<std::string, double>> doubles;
};

// Writes R, G, B channels (row 0 on top). Throws IoError.
void write_exr(const std::string& path, const Image& image, const ExrWriteOptions& options,
               const ExrAttributes& attributes = {});

// An 8-bit sRGB preview: linear values clamped to [0, 1], sRGB-encoded. Throws IoError.
void write_png_preview(const std::string& path, const Image& image);

// An 8-bit RGB PNG of ready-made sRGB bytes (row 0 on top, rgb.size() == 3 * width *
// height), for pictures that are not renders: the compare heatmap. Throws IoError.
// (Implemented in png_write.cpp.)
void write_png_rgb8(const std::string& path, int width, int height,
                    const std::vector<std::uint8_t>& rgb);

}  // namespace octray
