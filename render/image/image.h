#pragma once
// octray's image: named channels, each in its own pixel format and stored planar, a data
// window inside a display window, and the metadata a file carries (compression and header
// attributes). Every image octray reads, writes, compares or shows is one: a render on its
// way to a file (make_exr_image, image_io.h), its AOVs (render/aov.h), a file read back
// (read_image, image_read.h), a difference image, the error heatmap (8-bit channels), a
// part of `octray assemble`, the viewer's pictures. The renderers fill one: a render's
// result is an Image of float32 R, G, B channels (render/render_result.h).
//
// Reading and writing: image_io.h (write_exr, write_png) and image_read.h (read_image,
// read_exr_image); comparing: image_compare.h (compare_images, difference_image).

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/aligned.h"
#include "core/color.h"
#include "core/pixel_rect.h"

namespace octray {

// A sample's type. half, float32 and uint32 are OpenEXR's HALF, FLOAT and UINT; uint8 is
// an 8-bit display value (a PNG's), which OpenEXR files cannot hold.
enum class PixelFormat { uint8, half, float32, uint32 };
std::string_view to_string(PixelFormat format);  // "uint8", "half", "float", "uint"
std::size_t sample_size(PixelFormat format);     // 1, 2, 4, 4 bytes

// A channel's bytes: 64-byte aligned, and resize() leaves new bytes unwritten, so that a
// renderer sizes a frame without zeroing it and its pages are first touched by the
// threads that fill them (core/aligned.h). SampleBytes(n, 0) is n zero bytes.
using SampleBytes = UninitializedVector<unsigned char>;

// One channel: a sample per pixel of the data window, row by row (top row first), each in
// the channel's own format and native byte order (half: the 16 bits of an IEEE binary16).
struct ImageChannel {
    std::string name;
    PixelFormat format = PixelFormat::half;
    SampleBytes samples;

    std::size_t size() const { return samples.size() / sample_size(format); }
    // Sample k as a float (a uint32 is converted and may round above 2^24; a uint8 is
    // its byte value, 0 to 255).
    float value(std::size_t k) const;
    // Sample k of a uint32 channel (else the float value truncated; negative -> 0).
    std::uint32_t uint_value(std::size_t k) const;
    // Same name, format and bytes (a NaN equals the same NaN; -0 differs from +0).
    friend bool operator==(const ImageChannel&, const ImageChannel&) = default;

    // The samples of a float32 channel (the storage is aligned for any scalar).
    float* floats() { return reinterpret_cast<float*>(samples.data()); }
    const float* floats() const { return reinterpret_cast<const float*>(samples.data()); }
};

// A half or float32 channel from `count` floats at `values`, `stride` floats apart
// (half rounds to nearest even, as OpenEXR's half does). Its samples go into `storage`
// (a written frame's, handed on) where it is of the right size, which is then neither
// zeroed nor mapped afresh; storage of another size is freed first. Throws
// std::invalid_argument for another format.
ImageChannel make_channel(std::string name, PixelFormat format, const float* values,
                          std::size_t count, std::size_t stride = 1, SampleBytes storage = {});
// A uint32 channel, and a uint8 one.
ImageChannel make_channel(std::string name, const std::vector<std::uint32_t>& values);
ImageChannel make_channel(std::string name, const std::vector<std::uint8_t>& values);

// ---- Metadata ---------------------------------------------------------------------------

// The compression an OpenEXR file's chunks are written with.
enum class ExrCompression { none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa, dwab };

std::optional<ExrCompression> parse_exr_compression(std::string_view name);
// The scan lines the codec compresses as one block (OpenEXR's line buffer): none, rle and
// zips 1, zip and pxr24 16, piz, b44, b44a and dwaa 32, dwab 256.
int exr_lines_per_chunk(ExrCompression compression);
std::string_view to_string(ExrCompression compression);

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

// ---- The image --------------------------------------------------------------------------

// The display window is the whole picture; the data window the pixels the image holds (a
// crop of a render: the crop inside the full image). Channel order is the image's own
// (an OpenEXR file stores them sorted by name; read_image orders them R, G, B, A first).
struct Image {
    PixelRect display_window;
    PixelRect data_window;
    std::vector<ImageChannel> channels;
    ExrCompression compression = ExrCompression::zip;  // how write_exr compresses it
    ExrAttributes attributes;
    // What a file held, for reports ("OpenEXR half", "PNG 8-bit", ...); empty for an image
    // that was not read.
    std::string file_format;

    Image() = default;
    // float32 channels called `names`, every sample 0, of a width x height image whose
    // data window is its display window.
    Image(int width, int height, const std::vector<std::string>& names);

    // The data window's size.
    int width() const { return data_window.width(); }
    int height() const { return data_window.height(); }
    std::size_t pixel_count() const { return data_window.pixel_count(); }
    int channel_count() const { return static_cast<int>(channels.size()); }

    // The channel called `name` (nullptr / -1 when there is none).
    const ImageChannel* find_channel(std::string_view name) const;
    int channel_index(std::string_view name) const;
    // The channels' names, in the image's order.
    std::vector<std::string> channel_names() const;
    // Whether every channel is float32: what plane() and at() read.
    bool all_float32() const;

    // Channel c of a float32 image, as a plane: pixel (x, y) of the data window at
    // plane(c)[y * width() + x].
    float* plane(int c) { return channels[static_cast<std::size_t>(c)].floats(); }
    const float* plane(int c) const { return channels[static_cast<std::size_t>(c)].floats(); }
    float& at(int c, int x, int y) { return plane(c)[index(x, y)]; }
    float at(int c, int x, int y) const { return plane(c)[index(x, y)]; }

  private:
    std::size_t index(int x, int y) const {
        return static_cast<std::size_t>(y) * static_cast<std::size_t>(width()) +
               static_cast<std::size_t>(x);
    }
};

// ---- A render's pixels -----------------------------------------------------------------

// What a renderer hands back: float32 channels "R", "G", "B" (channels 0, 1, 2) of the
// pixels of `data_window` (a crop, or the whole image) inside `display_window` (the whole
// image). The samples are unwritten: the renderer writes every one. Each channel takes
// the storage of `spare`'s channel of its index where that holds exactly its bytes (a
// frame loop hands back the frame it has written, and the next frame then maps no fresh
// pages); `spare` is freed first otherwise, so two frames are never held at once.
Image make_rgb_image(PixelRect data_window, PixelRect display_window, Image spare = {});
// Whether make_rgb_image(data_window, ..., spare) takes all of its storage from `spare`.
bool fits_rgb_storage(const Image& spare, PixelRect data_window);
// Whether `image` is one: channels R, G, B, float32, sized to its data window.
bool is_rgb_image(const Image& image);
// Pixel (x, y) of its data window (0, 0 its first pixel), and setting it.
inline Rgb rgb_at(const Image& image, int x, int y) {
    return Rgb(image.at(0, x, y), image.at(1, x, y), image.at(2, x, y));
}
inline void set_rgb(Image& image, int x, int y, const Rgb& value) {
    image.at(0, x, y) = value.r, image.at(1, x, y) = value.g, image.at(2, x, y) = value.b;
}
// Pixel k of the planes (k = y * width() + x).
inline Rgb rgb_at(const Image& image, std::size_t k) {
    return Rgb(image.plane(0)[k], image.plane(1)[k], image.plane(2)[k]);
}
// Every pixel as an Rgb, row by row from the top (a copy).
std::vector<Rgb> rgb_pixels(const Image& image);

// Whether `a` and `b` hold the same pixels: the same windows and channels (names, formats
// and bytes, in order; a NaN equals the same NaN). Metadata is not compared.
bool same_pixels(const Image& a, const Image& b);

// `image` with every channel converted to float32 (values as ImageChannel::value gives
// them); windows, metadata and names kept.
Image to_float32(const Image& image);

}  // namespace octray
