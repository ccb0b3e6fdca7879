#pragma once
// Writing images: OpenEXR (the product) and 8-bit PNG previews, and the types an OpenEXR
// image is made of. Every writer goes through write_file_atomically(), so an interrupted
// run never leaves a partial image behind. Every OpenEXR file octray writes goes through
// write_exr(path, ExrImage) (exr_write.cpp); every PNG through png.cpp.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/image.h"
#include "core/pixel_rect.h"

namespace octray {

// Any failure to read or write a file. Its message names the file and the reason.
class IoError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// Throws IoError naming `path` and what it is when an existing `path` is a device node
// (/dev/null, /dev/full), a FIFO or a socket, or a symlink to one. A write renames a new
// file over its target, which would replace such a node with a regular file (as root,
// /dev/full itself), so such targets are refused, before rendering by the commands (they
// call this on every output first) and again by write_file_atomically. A path that does
// not exist yet, a regular file and a directory (which a rename cannot replace) pass.
void check_output_target(const std::string& path);

// Calls write(tmp_path) with a fresh temporary path in the target's directory, then
// renames it over `path` (atomic on POSIX). On any exception the temporary is removed
// and the exception passes on as an IoError naming `path`. Refuses a device, FIFO or
// socket as the target first (check_output_target).
void write_file_atomically(const std::string& path,
                           const std::function<void(const std::string& tmp_path)>& write);

// Removes the temporaries ("<dir>/.<name>.tmp.*") that writers of `target` which are gone
// (killed mid-write) left behind, and returns their paths. A writer holds an flock(2) on
// its temporary until the rename, so a temporary of a live writer, in this process or any
// other, is never removed; one whose lock cannot be taken (a file system without locks)
// stays too.
std::vector<std::string> remove_stale_temporaries(const std::string& target);

enum class ExrCompression { none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa, dwab };

std::optional<ExrCompression> parse_exr_compression(std::string_view name);
// The scan lines the codec compresses as one block (OpenEXR's line buffer): none, rle and
// zips 1, zip and pxr24 16, piz, b44, b44a and dwaa 32, dwab 256.
int exr_lines_per_chunk(ExrCompression compression);
std::string_view to_string(ExrCompression compression);

struct ExrWriteOptions {
    bool float32 = false;  // 32-bit float channels instead of half
    ExrCompression compression = ExrCompression::zip;
};

// A 4x4 float matrix as OpenEXR's M44f (Imath) holds it: element (row, col) at
// [4 * row + col], applied to row vectors (p' = p * M, translation in the last row).
using Matrix44 = std::array<float, 16>;

// OpenEXR's Rational (the framesPerSecond attribute): numerator / denominator.
struct ExrRational {
    int numerator = 0;
    unsigned int denominator = 1;
    friend bool operator==(const ExrRational&, const ExrRational&) = default;
};

// OpenEXR's own "nice fraction" for a value: 24 -> 24/1, 30000.0/1001 -> 30000/1001.
ExrRational exr_rational(double value);

// A header attribute of a type octray does not interpret, kept as OpenEXR serialized it
// (read from one file, written to another unchanged: `octray assemble`).
struct ExrOpaqueAttribute {
    std::string name;
    std::string type;                  // OpenEXR's type name: "v2f", "chromaticities", ...
    std::vector<unsigned char> value;  // the attribute's bytes as stored in a file
};

// Extra header attributes, written as OpenEXR string / float / int / double / M44f /
// rational attributes, plus opaque ones carried over from a file. A name given twice, or
// one of the structural attributes the writer sets itself (channels, compression,
// dataWindow, displayWindow, lineOrder, ...), is refused by the writer.
struct ExrAttributes {
    std::vector<std::pair<std::string, std::string>> strings;
    std::vector<std::pair<std::string, float>> floats;
    std::vector<std::pair<std::string, int>> ints;
    std::vector<std::pair<std::string, double>> doubles;
    std::vector<std::pair<std::string, Matrix44>> matrices;      // M44f: worldToCamera, ...
    std::vector<std::pair<std::string, ExrRational>> rationals;  // framesPerSecond
    std::vector<ExrOpaqueAttribute> opaque;

    // The value of the int / string attribute called `name`, or nullptr.
    const int* find_int(std::string_view name) const;
    const std::string* find_string(std::string_view name) const;
};

// ---- Images of any channel set, with windows -----------------------------------------

// OpenEXR's pixel types: UINT, HALF, FLOAT.
enum class ExrPixelType { uint32, half, float32 };
std::string_view to_string(ExrPixelType type);  // "uint", "half", "float"
std::size_t sample_size(ExrPixelType type);     // 4, 2, 4 bytes

// One channel: a sample per pixel of the data window, row by row (top row first), each in
// the channel's own type and native byte order (half: the 16 bits of an IEEE binary16).
struct ExrChannel {
    std::string name;
    ExrPixelType type = ExrPixelType::half;
    std::vector<unsigned char> samples;

    std::size_t size() const { return samples.size() / sample_size(type); }
    // Sample k as a float (a uint32 is converted and may round above 2^24).
    float value(std::size_t k) const;
    // Sample k of a uint32 channel (else the float value truncated; negative -> 0).
    std::uint32_t uint_value(std::size_t k) const;
};

// A half or float32 channel from `count` floats at `values`, `stride` floats apart
// (half rounds to nearest even, as OpenEXR's half does). Its samples go into `storage`
// (a written frame's, handed on) where it is of the right size, which is then neither
// zeroed nor mapped afresh; storage of another size is freed first.
ExrChannel make_exr_channel(std::string name, ExrPixelType type, const float* values,
                            std::size_t count, std::size_t stride = 1,
                            std::vector<unsigned char> storage = {});
// A uint32 channel.
ExrChannel make_exr_channel(std::string name, const std::vector<std::uint32_t>& values);

// A scanline OpenEXR image: its windows, channels, compression and extra attributes.
// The display window is the whole picture; the data window the pixels the file holds
// (a crop of a render: the crop inside the full image).
struct ExrImage {
    PixelRect display_window;
    PixelRect data_window;
    std::vector<ExrChannel> channels;  // any order: OpenEXR stores them sorted by name
    ExrCompression compression = ExrCompression::zip;
    ExrAttributes attributes;

    // The channel called `name`, or nullptr.
    const ExrChannel* find_channel(std::string_view name) const;
};

// R, G, B channels (half, or float32 with options.float32) of `image`; the data window is
// `data_window` (the image's size) inside a display window of (0, 0)-(full_width,
// full_height). Throws std::invalid_argument if the sizes disagree.
// `spare`: channels of an image already written, whose storage R, G and B take in turn
// (make_exr_channel), so that a frame loop converts each frame into the same memory.
ExrImage make_exr_image(const Image& image, PixelRect data_window, int full_width,
                        int full_height, const ExrWriteOptions& options,
                        const ExrAttributes& attributes = {},
                        std::vector<ExrChannel> spare = {});
// (A render's make_exr_image(RenderResult, ...) is in render/batch/result_exr.h.)

// Writes `image` as a scanline OpenEXR file, atomically. Throws IoError naming the path
// and the reason (an empty window, a channel whose sample count is not the data window's,
// two channels or attributes of one name, ...).
void write_exr(const std::string& path, const ExrImage& image);

// Writes R, G, B channels (row 0 on top); data window = display window = the image.
// Throws IoError.
void write_exr(const std::string& path, const Image& image, const ExrWriteOptions& options,
               const ExrAttributes& attributes = {});

// An 8-bit sRGB preview: linear values clamped to [0, 1], sRGB-encoded. Throws IoError.
void write_png_preview(const std::string& path, const Image& image);

// A linear value clamped to [0, 1] (NaN and negatives to 0) through the sRGB OETF
// (IEC 61966-2-1), rounded to 8 bits: what the PNG preview stores. Found in a table of the
// values where the byte steps up; srgb8_by_formula computes the same byte with the
// OETF's power (the tests hold the two equal).
std::uint8_t srgb8(float linear);
std::uint8_t srgb8_by_formula(float linear);
// srgb8(linear[i] * scale) for i < count, into out[i]: the same bytes, the table looked up
// once for the whole run (`octray view` tone-maps a 1280x720 picture per camera move).
void srgb8_scaled(const float* linear, std::size_t count, float scale, std::uint8_t* out);

// An 8-bit RGB PNG of `rgb` (3 * width * height bytes, row 0 on top) with an sRGB chunk,
// in memory (`octray view` sends it to the browser): zlib's fastest level, since it is
// wanted soon rather than small. Throws IoError for a size that does not match or a
// failure of libpng.
std::string encode_png_rgb8(int width, int height, const std::vector<std::uint8_t>& rgb);

// An 8-bit RGB PNG of ready-made sRGB bytes (row 0 on top, rgb.size() == 3 * width *
// height), for pictures that are not renders: the compare heatmap. Throws IoError.
void write_png_rgb8(const std::string& path, int width, int height,
                    const std::vector<std::uint8_t>& rgb);

// The threads OpenEXR compresses and decompresses the blocks of a file on (its global
// pool, Imf::setGlobalThreadCount): 0 means none, the calling thread does the work. The
// chunks octray compresses itself (uncompressed, ZIPS, ZIP) are compressed in parallel on
// the caller's TBB arena when the count is 2 or more, on the calling thread alone else.
// The file's bytes are the same for any count.
void set_exr_thread_count(int threads);
int exr_thread_count();

namespace detail {
// write_exr packs and compresses the chunks of uncompressed, ZIPS and ZIP files itself
// (libdeflate, in parallel) and leaves the other compressions to OpenEXR. For the tests
// that hold the first to OpenEXR's writer: `image` written by OpenEXR's OutputFile, with
// the same header, not atomically.
void write_exr_by_openexr(const std::string& path, const ExrImage& image);
}  // namespace detail

}  // namespace octray
