// Every PNG octray writes or reads: the sRGB preview of a render (write_png_preview), ready
// sRGB bytes (write_png_rgb8: the compare heatmap; encode_png_rgb8: `octray view`'s
// pictures, in memory), and the reader behind read_image().
// One libpng error handler serves them all.

#include "render/image/png.h"

#include <png.h>

#include <bit>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "render/image/image_io.h"

namespace octray {
namespace {

std::string errno_message(int error) { return std::generic_category().message(error); }

// ---- The libpng error handler ----------------------------------------------------------
// libpng reports errors by calling the handler and then longjmp-ing back to setjmp; the
// message is kept so it can become an exception once we are back in ordinary C++ control
// flow. The functions that call setjmp create no object with a destructor after it, so the
// jump never skips one; everything that owns memory lives in their callers.

// One libpng run: where the bytes go (writing) or come from (reading), and the error.
struct PngIo {
    std::FILE* file = nullptr;            // writing: the open temporary
    std::string* memory = nullptr;        // or writing into memory
    const unsigned char* data = nullptr;  // reading: the whole file
    std::size_t size = 0;
    std::size_t offset = 0;
    bool ran_out = false;  // reading past the end: a truncated file
    // libpng's own writer says only "Write Error"; ours keeps the OS reason (errno) of a
    // failed write so that the message can say it ("No space left on device").
    int write_errno = 0;
    char message[256] = {};
};

void on_png_error(png_structp png, png_const_charp message) {
    auto* io = static_cast<PngIo*>(png_get_error_ptr(png));
    if (io->write_errno != 0)
        std::snprintf(io->message, sizeof io->message, "%s: %s", message,
                      std::strerror(io->write_errno));
    else
        std::snprintf(io->message, sizeof io->message, "%s", message);
    png_longjmp(png, 1);
}

// libpng warns about harmless quirks (an sRGB profile it does not recognise, ...).
void on_png_warning(png_structp, png_const_charp) {}

// ---- Writing -----------------------------------------------------------------------------

void on_png_write(png_structp png, png_bytep data, png_size_t length) {
    auto* io = static_cast<PngIo*>(png_get_io_ptr(png));
    errno = 0;
    if (std::fwrite(data, 1, length, io->file) != length) {
        io->write_errno = errno != 0 ? errno : EIO;
        png_error(png, "Write Error");
    }
}

void on_png_append(png_structp png, png_bytep data, png_size_t length) {
    static_cast<PngIo*>(png_get_io_ptr(png))
        ->memory->append(reinterpret_cast<char*>(data), length);
}

void on_png_flush(png_structp png) {
    auto* io = static_cast<PngIo*>(png_get_io_ptr(png));
    errno = 0;
    if (std::fflush(io->file) != 0) {
        io->write_errno = errno != 0 ? errno : EIO;
        png_error(png, "Write Error");
    }
}

// How the file says its pixels are sRGB: the sRGB chunk alone (the heatmap), or with the
// gAMA and cHRM chunks that stand in for it in older viewers (the render preview).
enum class SrgbChunks { srgb, srgb_gama_chrm };

bool write_rgb8_rows(png_structp png, png_infop info, PngIo* io, png_uint_32 width,
                     png_uint_32 height, png_bytepp rows, SrgbChunks chunks) {
    if (setjmp(png_jmpbuf(png))) return false;
    if (io->memory != nullptr)
        png_set_write_fn(png, io, on_png_append, nullptr);
    else
        png_set_write_fn(png, io, on_png_write, on_png_flush);
    // zlib's fastest level and one filter (each byte minus its left neighbour's): a PNG
    // octray writes is wanted soon rather than small. On a 1280x720 whitted preview this
    // writes 4x faster than libpng's defaults (level 6, a filter chosen per row), for a
    // file 30 % larger (docs/performance-log.md, "The finished frame").
    png_set_compression_level(png, 1);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
    png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    if (chunks == SrgbChunks::srgb_gama_chrm)
        png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    else
        png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    png_write_image(png, rows);
    png_write_end(png, info);
    return true;
}

// Writes an 8-bit RGB PNG of `rows` (row 0 on top) through `io` (its file or its memory).
// Returns the reason it failed, or "".
std::string write_png(PngIo& io, int width, int height, png_bytepp rows, SrgbChunks chunks) {
    png_structp png =
        png_create_write_struct(PNG_LIBPNG_VER_STRING, &io, on_png_error, on_png_warning);
    png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
    std::string failure;
    if (png == nullptr)
        failure = "libpng: cannot create the write structure";
    else if (info == nullptr)
        failure = "libpng: cannot create the info structure";
    else if (!write_rgb8_rows(png, info, &io, static_cast<png_uint_32>(width),
                              static_cast<png_uint_32>(height), rows, chunks))
        failure = std::string("libpng: ") + io.message;
    if (png != nullptr) png_destroy_write_struct(&png, info != nullptr ? &info : nullptr);
    return failure;
}

// Writes an 8-bit RGB PNG of `rows` (row 0 on top) to a new file at `path`. Throws
// std::runtime_error with the reason.
void write_png_file(const std::string& path, int width, int height, png_bytepp rows,
                    SrgbChunks chunks) {
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (file == nullptr) throw std::runtime_error(errno_message(errno));
    PngIo io;
    io.file = file;
    std::string failure = write_png(io, width, height, rows, chunks);
    // A full disk may only show when buffered data is flushed, so check the close too.
    const bool stream_failed = std::ferror(file) != 0;
    const int close_errno = std::fclose(file) != 0 ? errno : 0;
    if (failure.empty() && close_errno != 0) failure = errno_message(close_errno);
    if (failure.empty() && stream_failed) failure = "write error";
    if (!failure.empty()) throw std::runtime_error(failure);
}

// The row pointers of packed RGB bytes; libpng wants mutable ones but only reads.
std::vector<png_bytep> rgb8_rows(int width, int height, const std::vector<std::uint8_t>& rgb) {
    std::vector<png_bytep> rows(static_cast<std::size_t>(height));
    for (std::size_t y = 0; y < rows.size(); ++y)
        rows[y] = const_cast<png_bytep>(rgb.data() + y * 3 * static_cast<std::size_t>(width));
    return rows;
}

bool rgb8_size_matches(int width, int height, const std::vector<std::uint8_t>& rgb) {
    return width > 0 && height > 0 &&
           rgb.size() == 3 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
}

// sRGB OETF (IEC 61966-2-1) of a linear value already clamped to [0, 1].
float srgb_encode(float linear) {
    return linear <= 0.0031308f ? 12.92f * linear
                                : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

}  // namespace

// The preview's byte by the formula: a power and a rounding per channel, which cost more
// than the trace of a simple scene at 1280x720. srgb8 finds the same byte in a table.
std::uint8_t srgb8_by_formula(float linear) {
    // NaN fails both comparisons and lands on 0, like negative values; +inf clamps to 1.
    const float clamped = linear > 0.0f ? (linear < 1.0f ? linear : 1.0f) : 0.0f;
    return static_cast<std::uint8_t>(std::lround(srgb_encode(clamped) * 255.0f));
}

namespace {

// threshold[v] (v = 1 ... 255): the smallest float that srgb8_formula maps to v or more.
// The formula never decreases as its argument grows, so the byte of x is the number of
// thresholds at or below x. Each is found by bisection over the bit patterns of the
// floats in [0, 1], which are ordered as their values. To find a byte without a search,
// the floats of (0, 1) are cut into buckets by their top 16 bits (1/128 of a power of two
// each): bucket_start holds the byte at each bucket's first float, and within a bucket the
// byte steps up at most once (the OETF's slope times a bucket's width stays below one
// step), which one comparison finds; the loop after it is for safety and never runs.
struct SrgbTable {
    static constexpr std::uint32_t kOneBits = 0x3F800000u;  // 1.0f
    float threshold[257];                                   // [256]: +inf, a sentinel
    std::uint8_t bucket_start[(kOneBits >> 16) + 1];
    SrgbTable() {
        threshold[0] = -std::numeric_limits<float>::infinity();
        threshold[256] = std::numeric_limits<float>::infinity();
        for (int v = 1; v < 256; ++v) {
            std::uint32_t lo = 0, hi = kOneBits;  // formula(lo) < v <= formula(hi)
            while (hi - lo > 1) {
                const std::uint32_t mid = lo + (hi - lo) / 2;
                (srgb8_by_formula(std::bit_cast<float>(mid)) >= v ? hi : lo) = mid;
            }
            threshold[v] = std::bit_cast<float>(hi);
        }
        for (std::uint32_t b = 0; b <= (kOneBits >> 16); ++b)
            bucket_start[b] = srgb8_by_formula(std::bit_cast<float>(b << 16));
    }
};

const SrgbTable& srgb_table() {
    static const SrgbTable table;
    return table;
}

inline std::uint8_t srgb8_in(const SrgbTable& table, float linear) {
    if (!(linear > 0.0f)) return 0;  // NaN too
    if (linear >= 1.0f) return 255;
    int v = table.bucket_start[std::bit_cast<std::uint32_t>(linear) >> 16];
    v += linear >= table.threshold[v + 1] ? 1 : 0;
    while (linear >= table.threshold[v + 1]) ++v;
    return static_cast<std::uint8_t>(v);
}

}  // namespace

std::uint8_t srgb8(float linear) { return srgb8_in(srgb_table(), linear); }

void srgb8_scaled(const float* linear, std::size_t count, float scale, std::uint8_t* out) {
    const SrgbTable& table = srgb_table();
    for (std::size_t i = 0; i < count; ++i) out[i] = srgb8_in(table, linear[i] * scale);
}

namespace {

// ---- Reading -----------------------------------------------------------------------------

struct PngLayout {
    png_uint_32 width = 0;
    png_uint_32 height = 0;
    int channels = 0;
    int bit_depth = 0;  // 8 or 16 after the transforms below
    std::size_t row_bytes = 0;
};

void on_png_read(png_structp png, png_bytep out, std::size_t length) {
    auto* io = static_cast<PngIo*>(png_get_io_ptr(png));
    if (length > io->size - io->offset) {
        io->ran_out = true;
        png_error(png, "unexpected end of file");
    }
    std::memcpy(out, io->data + io->offset, length);
    io->offset += length;
}

bool read_png_header(png_structp png, png_infop info, PngLayout& layout) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_read_info(png, info);
    const int color_type = png_get_color_type(png, info);
    // Palette and low-bit gray become 8-bit samples; a palette's transparency becomes an
    // alpha channel. 16-bit samples stay 16-bit, so no precision is lost.
    if (color_type == PNG_COLOR_TYPE_PALETTE) {
        png_set_palette_to_rgb(png);
        if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
    }
    if (color_type == PNG_COLOR_TYPE_GRAY && png_get_bit_depth(png, info) < 8)
        png_set_expand_gray_1_2_4_to_8(png);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    layout.width = png_get_image_width(png, info);
    layout.height = png_get_image_height(png, info);
    layout.channels = png_get_channels(png, info);
    layout.bit_depth = png_get_bit_depth(png, info);
    layout.row_bytes = png_get_rowbytes(png, info);
    return true;
}

bool read_png_rows(png_structp png, png_infop info, png_bytepp rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_read_image(png, rows);
    // Reading up to IEND is what tells a file cut off after its pixel data.
    png_read_end(png, info);
    return true;
}

// Owns libpng's two structures for the length of one read.
class PngReadHandle {
  public:
    explicit PngReadHandle(PngIo& io) {
        png_ = png_create_read_struct(PNG_LIBPNG_VER_STRING, &io, on_png_error, on_png_warning);
        if (png_) info_ = png_create_info_struct(png_);
    }
    ~PngReadHandle() { png_destroy_read_struct(&png_, info_ ? &info_ : nullptr, nullptr); }
    PngReadHandle(const PngReadHandle&) = delete;
    PngReadHandle& operator=(const PngReadHandle&) = delete;

    png_structp png() const { return png_; }
    png_infop info() const { return info_; }

  private:
    png_structp png_ = nullptr;
    png_infop info_ = nullptr;
};

void require_image(const std::string& path, const Image& image) {
    if (image.width() <= 0 || image.height() <= 0)
        throw IoError("cannot write " + path + ": the image is empty (" +
                      std::to_string(image.width()) + "x" + std::to_string(image.height()) +
                      ")");
}

}  // namespace

void write_png_preview(const std::string& path, const Image& image) {
    require_image(path, image);
    const int width = image.width();
    const int height = image.height();
    const std::size_t row_bytes = static_cast<std::size_t>(width) * 3;
    std::vector<png_byte> pixels(row_bytes * static_cast<std::size_t>(height));
    std::vector<png_bytep> rows(static_cast<std::size_t>(height));
    for (int y = 0; y < height; ++y) {
        png_bytep row = pixels.data() + static_cast<std::size_t>(y) * row_bytes;
        rows[static_cast<std::size_t>(y)] = row;
        for (int x = 0; x < width; ++x) {
            const Rgb c = image.at(x, y);
            row[3 * x + 0] = srgb8(c.r);
            row[3 * x + 1] = srgb8(c.g);
            row[3 * x + 2] = srgb8(c.b);
        }
    }
    write_file_atomically(path, [&](const std::string& tmp) {
        write_png_file(tmp, width, height, rows.data(), SrgbChunks::srgb_gama_chrm);
    });
}

void write_png_rgb8(const std::string& path, int width, int height,
                    const std::vector<std::uint8_t>& rgb) {
    if (!rgb8_size_matches(width, height, rgb))
        throw IoError("cannot write '" + path + "': " + std::to_string(rgb.size()) +
                      " bytes do not make a " + std::to_string(width) + "x" +
                      std::to_string(height) + " RGB image");
    std::vector<png_bytep> rows = rgb8_rows(width, height, rgb);
    write_file_atomically(path, [&](const std::string& tmp) {
        write_png_file(tmp, width, height, rows.data(), SrgbChunks::srgb);
    });
}

std::string encode_png_rgb8(int width, int height, const std::vector<std::uint8_t>& rgb) {
    if (!rgb8_size_matches(width, height, rgb))
        throw IoError("cannot encode a PNG: " + std::to_string(rgb.size()) +
                      " bytes do not make a " + std::to_string(width) + "x" +
                      std::to_string(height) + " RGB image");
    std::vector<png_bytep> rows = rgb8_rows(width, height, rgb);
    std::string out;
    PngIo io;
    io.memory = &out;
    const std::string failure = write_png(io, width, height, rows.data(), SrgbChunks::srgb);
    if (!failure.empty()) throw IoError("cannot encode a PNG: " + failure);
    return out;
}

ChannelImage read_png_channels(const std::string& path,
                               const std::vector<unsigned char>& bytes) {
    PngIo io;
    io.data = bytes.data();
    io.size = bytes.size();
    PngReadHandle handle(io);
    if (!handle.png() || !handle.info()) fail_reading(path, "out of memory starting libpng");
    png_set_read_fn(handle.png(), &io, on_png_read);

    const auto png_failure = [&]() -> std::string {
        if (io.ran_out) return "truncated PNG file (unexpected end of file)";
        return std::string("corrupt PNG file (") + io.message + ")";
    };

    PngLayout layout;
    if (!read_png_header(handle.png(), handle.info(), layout))
        fail_reading(path, png_failure());
    if (layout.channels < 1 || layout.channels > 4 ||
        (layout.bit_depth != 8 && layout.bit_depth != 16))
        fail_reading(path, "unsupported PNG sample layout");
    const std::size_t pixels = static_cast<std::size_t>(layout.width) * layout.height;
    if (pixels == 0) fail_reading(path, "PNG file has no pixels");
    if (pixels * static_cast<std::size_t>(layout.channels) > max_read_float_values)
        fail_reading(path, "image too large to compare");

    std::vector<png_byte> raw(layout.row_bytes * layout.height);
    std::vector<png_bytep> rows(layout.height);
    for (png_uint_32 y = 0; y < layout.height; ++y) rows[y] = raw.data() + y * layout.row_bytes;
    if (!read_png_rows(handle.png(), handle.info(), rows.data()))
        fail_reading(path, png_failure());

    static const std::vector<std::string> names_by_count[4] = {
        {"Y"}, {"Y", "A"}, {"R", "G", "B"}, {"R", "G", "B", "A"}};
    ChannelImage image(static_cast<int>(layout.width), static_cast<int>(layout.height),
                       names_by_count[layout.channels - 1]);
    image.format = layout.bit_depth == 16 ? "PNG 16-bit" : "PNG 8-bit";

    // Raw samples scaled to [0, 1]; 16-bit samples are big-endian in the file.
    const int channels = layout.channels;
    for (int y = 0; y < image.height; ++y) {
        const png_byte* row = rows[static_cast<std::size_t>(y)];
        for (int x = 0; x < image.width; ++x) {
            for (int c = 0; c < channels; ++c) {
                const std::size_t sample = static_cast<std::size_t>(x) * channels + c;
                float value;
                if (layout.bit_depth == 16) {
                    const unsigned v = (unsigned{row[2 * sample]} << 8) | row[2 * sample + 1];
                    value = static_cast<float>(v) / 65535.0f;
                } else {
                    value = static_cast<float>(row[sample]) / 255.0f;
                }
                image.at(c, x, y) = value;
            }
        }
    }
    return image;
}

}  // namespace octray
