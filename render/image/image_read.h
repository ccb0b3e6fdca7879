#pragma once
// Reading images for comparison: OpenEXR (any channel set, HALF/FLOAT/UINT) and PNG
// (8/16-bit gray, gray+alpha, RGB, RGBA, palette), all turned into planar float channels.
// The format is told by the file's magic bytes, never by its extension.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "render/image/exr_chunks.h"
#include "render/image/image_io.h"

namespace octray {

// Reads an OpenEXR or PNG file. Values are raw: PNG samples are scaled to [0, 1] but not
// linearized from sRGB and alpha is not premultiplied (idiff compares stored values, and so
// do we). EXR channels come back ordered R, G, B, A within each layer ("", then
// "diffuse.", ...), other names alphabetically after them; a PNG's channels are Y, YA, RGB
// or RGBA. Throws IoError naming the path and the reason: missing, unreadable, not an image
// (unknown magic bytes), truncated or corrupt.
Image read_image(const std::string& path);

// Reads a scanline or tiled OpenEXR file (its first part) as it is stored: the display and
// data windows, every channel in its own pixel type (half stays half, bit for bit), the
// compression and every other header attribute (strings, floats, ints, doubles, M44f and
// rationals by type, any other type as an opaque blob), so that write_exr() can write
// the same image again. Throws IoError naming the path and the reason, as read_image()
// does; also for a PNG or a subsampled channel.
Image read_exr_image(const std::string& path);

// What an OpenEXR file's header declares, read without the pixels: its data window, its
// channels (in the file's order) and codec, and whether it is tiled.
struct ExrLayout {
    PixelRect data_window;
    std::vector<ExrChunkChannel> channels;
    ExrCompression compression = ExrCompression::none;
    bool tiled = false;
};
ExrLayout read_exr_layout(const std::string& path);

// The header attributes of an OpenEXR file (its first part) other than the structural
// ones, as read_exr_image() gives them, read without the pixels (`octray render` reads
// whether an existing image is an unfinished progressive one, and whose). Throws IoError
// naming the path and the reason.
ExrAttributes read_exr_attributes(const std::string& path);

// The check read_image() and read_exr_image() make before decoding: every chunk they
// decode (level 0 of a tiled file) holds what its header implies (render/image/exr_chunks.h).
// Throws IoError naming the path and the first chunk that does not.
void check_exr_pixel_data(const std::string& path);

}  // namespace octray
