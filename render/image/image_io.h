#pragma once
// Writing images: OpenEXR (the product) and 8-bit PNG previews, and a render's image made
// the Image a file stores (make_exr_image). Every writer goes through write_file_atomically(),
// so an interrupted run never leaves a partial image behind. Every OpenEXR file octray writes
// goes through write_exr(path, Image) (exr_write.cpp); every PNG through png.cpp.

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

#include "core/pixel_rect.h"
#include "render/image/image.h"

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

// Removes the temporaries ("<dir>/.<name>.tmp.*") that writers of the `targets` which are
// gone (killed mid-write) left behind, and returns their paths. A writer holds an flock(2)
// on its temporary until the rename, so a temporary of a live writer, in this process or
// any other, is never removed; one whose lock cannot be taken (a file system without
// locks) stays too. Each directory is read once.
std::vector<std::string> remove_stale_temporaries(const std::vector<std::string>& targets);

struct ExrWriteOptions {
    bool float32 = false;  // 32-bit float channels instead of half
    ExrCompression compression = ExrCompression::zip;
};

// ---- From a render to a file ----------------------------------------------------------

// A render's image (render/render_result.h: float32 channels R, G, B) as a file stores it:
// each channel half, or float32 with options.float32, in the render's order; the windows
// kept; the compression and `attributes` set. Throws std::invalid_argument for a channel
// that is not float32.
// `spare`: channels of an image already written, whose storage the channels take in turn
// (make_channel), for a caller that converts frame after frame into the same memory.
// (octray's own writers no longer make this image for ZIP, ZIPS or uncompressed files:
// exr_sources below.)
Image make_exr_image(const Image& render, const ExrWriteOptions& options,
                     const ExrAttributes& attributes = {},
                     std::vector<ImageChannel> spare = {});

// Writes `image` as a scanline OpenEXR file, atomically. Throws IoError naming the path
// and the reason (an empty window, a channel whose sample count is not the data window's,
// two channels or attributes of one name, ...).
void write_exr(const std::string& path, const Image& image);

// Writes a render's image (float32 R, G, B; row 0 on top) as make_exr_image makes it, the
// same file byte for byte, through write_exr(path, ExrSources) (no EXR image is made).
// Throws IoError, also for an image that is not a render's.
void write_exr(const std::string& path, const Image& render, const ExrWriteOptions& options,
               const ExrAttributes& attributes = {});

// ---- Writing from samples held elsewhere -------------------------------------------------

// A channel of an EXR written from samples the caller holds: the file stores them in
// `format`, theirs or, for float32 samples, half (each line converted as it is packed).
struct ExrChannelSource {
    const ImageChannel* samples;
    PixelFormat format;
};

// An EXR to write from channels held elsewhere (a render's planes, its AOVs): an Image's
// windows, compression and attributes, and its channels as sources.
struct ExrSources {
    PixelRect display_window, data_window;
    ExrCompression compression = ExrCompression::zip;
    ExrAttributes attributes;
    std::vector<ExrChannelSource> channels;
    // If set, called once as soon as the writer reads the channels' samples no more (the
    // last chunk encoded), while the file is still being finished: their storage may go
    // then. Not called where the write fails before that.
    std::function<void()> on_read;
};

// The sources of a render's image (float32 R, G, B) as make_exr_image converts it: each
// channel half, or float32 with options.float32. Throws std::invalid_argument for a
// channel that is not float32.
ExrSources exr_sources(const Image& render, const ExrWriteOptions& options,
                       const ExrAttributes& attributes = {});

// Writes the EXR `sources` describe, atomically: the file write_exr(path, Image) writes
// of the Image whose channels are the sources converted, byte for byte. With ZIP, ZIPS or
// no compression (the chunks octray packs itself) that Image is never made: each line is
// converted as its chunk is packed; other compressions make it first. Throws IoError as
// write_exr does (also for a source whose sample count is not the data window's, or a
// conversion other than float32 to half).
void write_exr(const std::string& path, const ExrSources& sources);

// An 8-bit sRGB preview of a render's image (float32 R, G, B): linear values clamped to
// [0, 1], sRGB-encoded. Throws IoError, also for an image that is not a render's.
// `on_read`, if set, is called once as soon as the render's samples are read no more (the
// PNG's bands encoded), before its file is written; not where the write fails before.
void write_png_preview(const std::string& path, const Image& render,
                       const std::function<void()>& on_read = {});

// A linear value clamped to [0, 1] (NaN and negatives to 0) through the sRGB OETF
// (IEC 61966-2-1), rounded to 8 bits: what the PNG preview stores. Found in a table of the
// values where the byte steps up; srgb8_by_formula computes the same byte with the
// OETF's power (the tests hold the two equal).
std::uint8_t srgb8(float linear);
std::uint8_t srgb8_by_formula(float linear);
// srgb8's bytes of three planes, interleaved: out[3 i + c] = srgb8(plane c's [i] * scale)
// for r, g, b: a render's rows (planar float32) as a PNG or JPEG row (`octray view`
// tone-maps a 1280x720 picture per camera move this way).
void srgb8_interleaved(const float* r, const float* g, const float* b, std::size_t count,
                       float scale, std::uint8_t* out);

// An 8-bit RGB PNG of `rgb` (3 * width * height bytes, row 0 on top) with an sRGB chunk,
// in memory (`octray view` sends it to the browser): zlib's fastest level, since it is
// wanted soon rather than small. Throws IoError for a size that does not match or a
// failure of libpng.
std::string encode_png_rgb8(int width, int height, const std::vector<std::uint8_t>& rgb);

// An 8-bit RGB PNG of ready-made sRGB bytes (row 0 on top, rgb.size() == 3 * width *
// height), for pictures that are not renders: the compare heatmap. Throws IoError.
void write_png_rgb8(const std::string& path, int width, int height,
                    const std::vector<std::uint8_t>& rgb);
// The same of an image of uint8 channels R, G, B (sRGB values; the data window is the
// picture): the compare heatmap. Throws IoError for other channels.
void write_png(const std::string& path, const Image& image);
std::string encode_png(const Image& image);

// The threads OpenEXR compresses and decompresses the blocks of a file on (its global
// pool, Imf::setGlobalThreadCount): 0 means none, the calling thread does the work. The
// chunks octray compresses itself (uncompressed, ZIPS, ZIP) are compressed in parallel on
// the caller's TBB arena when the count is 2 or more, on the calling thread alone else.
// The file's bytes are the same for any count.
void set_exr_thread_count(int threads);
int exr_thread_count();

namespace detail {
// write_exr packs and compresses the chunks of uncompressed, ZIPS and ZIP files itself
// (ISA-L's igzip, in parallel) and leaves the other compressions to OpenEXR. For the tests
// that hold the first to OpenEXR's writer: `image` written by OpenEXR's OutputFile, with
// the same header, not atomically.
void write_exr_by_openexr(const std::string& path, const Image& image);
}  // namespace detail

}  // namespace octray
