// Every PNG octray writes or reads: the sRGB preview of a render (write_png_preview), ready
// sRGB bytes (write_png_rgb8: the compare heatmap; encode_png_rgb8: `octray view`'s
// pictures, in memory), encoded here in parallel bands (deflate.h), and the reader behind
// read_image(), which is libpng's.

#include "render/image/png.h"

#include <emmintrin.h>
#include <png.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
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

#include "core/cpu_features.h"
#include "render/image/deflate.h"
#include "render/image/image.h"
#include "render/image/image_io.h"
#include "render/image/srgb_table.h"

namespace octray {
namespace {

std::string errno_message(int error) { return std::generic_category().message(error); }

// ---- The libpng error handler (reading) --------------------------------------------------
// libpng reports errors by calling the handler and then longjmp-ing back to setjmp; the
// message is kept so it can become an exception once we are back in ordinary C++ control
// flow. The functions that call setjmp create no object with a destructor after it, so the
// jump never skips one; everything that owns memory lives in their callers.

// One libpng read: the whole file, how far it has been read, and the error.
struct PngIo {
    const unsigned char* data = nullptr;
    std::size_t size = 0;
    std::size_t offset = 0;
    bool ran_out = false;  // reading past the end: a truncated file
    char message[256] = {};
};

void on_png_error(png_structp png, png_const_charp message) {
    auto* io = static_cast<PngIo*>(png_get_error_ptr(png));
    std::snprintf(io->message, sizeof io->message, "%s", message);
    png_longjmp(png, 1);
}

// libpng warns about harmless quirks (an sRGB profile it does not recognise, ...).
void on_png_warning(png_structp, png_const_charp) {}

// ---- Writing -----------------------------------------------------------------------------
// octray encodes the PNGs it writes itself: a PNG octray writes is wanted soon rather than
// small. Every row but the first is filtered with one filter (each byte minus the byte
// above it, Up), and the rows are cut into bands of about kBandBytes that are made,
// filtered and compressed on all threads at once (deflate_band: igzip, each band ending
// on a byte boundary), then joined into the one zlib stream a PNG holds. The choices and
// their measurements: render/image/README.md, "Compression". libpng reads them back in
// the tests.

// Filtered bytes per band: enough that igzip's work per call (its hash table, a Huffman
// header) stays small, few enough to keep every thread busy (a 1280x720 preview makes 22
// bands; bands of 64 KB took 20-30 % longer, of 256 KB 5-10 % less, files within 1 %).
constexpr std::size_t kBandBytes = std::size_t{128} << 10;
// igzip's level for the bands: 1 (0 made files 20-40 % larger).
constexpr int kPngLevel = 1;

// How the file says its pixels are sRGB: the sRGB chunk alone (the heatmap), or with the
// gAMA and cHRM chunks that stand in for it in older viewers (the render preview).
enum class SrgbChunks { srgb, srgb_gama_chrm };

void append_u32(std::string& out, std::uint32_t value) {  // big-endian, as PNG stores it
    const char bytes[4] = {static_cast<char>(value >> 24), static_cast<char>(value >> 16),
                           static_cast<char>(value >> 8), static_cast<char>(value)};
    out.append(bytes, 4);
}

// A chunk: its length, type, data and the CRC-32 of type and data.
void append_chunk(std::string& out, const char (&type)[5], const void* data, std::size_t size) {
    append_u32(out, static_cast<std::uint32_t>(size));
    const std::size_t start = out.size();
    out.append(type, 4);
    out.append(static_cast<const char*>(data), size);
    append_u32(out, detail::crc32(0, out.data() + start, 4 + size));
}

// The sRGB, gAMA and cHRM values libpng's png_set_sRGB_gAMA_and_cHRM writes: rendering
// intent perceptual, gamma 1/2.2 (x 100000), the sRGB white point and primaries (x 100000).
constexpr std::uint32_t kSrgbGamma = 45455;
constexpr std::uint32_t kSrgbChromaticities[8] = {31270, 32900, 64000, 33000,
                                                  30000, 60000, 15000, 6000};

// The Up filter of one row: out[i] = in[i] - above[i] (the byte of the pixel above; the
// first row has none, and is stored unfiltered). SSE2 (every x86-64) 16 bytes at a time.
void up_filter(const std::uint8_t* in, const std::uint8_t* above, std::size_t size,
               std::uint8_t* out) {
    std::size_t i = 0;
    for (; i + 16 <= size; i += 16) {
        const __m128i now = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + i));
        const __m128i up = _mm_loadu_si128(reinterpret_cast<const __m128i*>(above + i));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i), _mm_sub_epi8(now, up));
    }
    for (; i < size; ++i) out[i] = static_cast<std::uint8_t>(in[i] - above[i]);
}

// One band of the zlib stream: its compressed bytes and the Adler-32 of its filtered rows.
struct PngBand {
    SampleBytes stream;  // deflate_band_bound bytes, the first `size` of them written
    std::size_t size = 0;
    std::size_t filtered = 0;
    std::uint32_t adler = 1;
};

// An 8-bit RGB PNG, in memory, of the rows `row(y, scratch)` returns (3 * width bytes
// each, row 0 on top; a row may be made in `scratch`, 3 * width bytes of this thread's).
// The bands are made, filtered and compressed in parallel on the caller's arena.
template <class Row>
std::string encode_png(int width, int height, const Row& row, SrgbChunks chunks) {
    const std::size_t row_bytes = 3 * static_cast<std::size_t>(width);
    const std::size_t rows = static_cast<std::size_t>(height);
    const std::size_t band_rows = std::max<std::size_t>(1, kBandBytes / (1 + row_bytes));
    const std::size_t band_count = (rows + band_rows - 1) / band_rows;
    std::vector<PngBand> bands(band_count);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, band_count, 1),
        [&](const tbb::blocked_range<std::size_t>& range) {
            thread_local std::vector<std::uint8_t> filtered, scratch[2];
            scratch[0].resize(row_bytes);
            scratch[1].resize(row_bytes);
            for (std::size_t b = range.begin(); b != range.end(); ++b) {
                const std::size_t y0 = b * band_rows, y1 = std::min(rows, y0 + band_rows);
                filtered.resize((y1 - y0) * (1 + row_bytes));
                // Each row is made once, into the scratch the row before it is not in (the
                // band's first row needs the one above it made too).
                const std::uint8_t* above = y0 > 0 ? row(y0 - 1, scratch[1].data()) : nullptr;
                for (std::size_t y = y0; y < y1; ++y) {
                    const std::uint8_t* now = row(y, scratch[(y - y0) % 2].data());
                    std::uint8_t* out = filtered.data() + (y - y0) * (1 + row_bytes);
                    if (above == nullptr) {
                        out[0] = 0;  // None
                        std::memcpy(out + 1, now, row_bytes);
                    } else {
                        out[0] = 2;  // Up
                        up_filter(now, above, row_bytes, out + 1);
                    }
                    above = now;
                }
                PngBand& band = bands[b];
                band.filtered = filtered.size();
                band.stream.resize(detail::deflate_band_bound(filtered.size()));
                band.size = detail::deflate_band(kPngLevel, filtered.data(), filtered.size(),
                                                 b + 1 == band_count, band.stream.data());
                band.adler = detail::adler32(1, filtered.data(), filtered.size());
            }
        });
    // The zlib stream: its header (deflate with a 32 KB window, the fastest level, a
    // check that makes the two bytes a multiple of 31), the bands, the Adler-32 of all.
    std::size_t stream_size = 2 + 4;
    std::uint32_t adler = 1;
    for (const PngBand& band : bands) {
        stream_size += band.size;
        adler = detail::adler32_combine(adler, band.adler, band.filtered);
    }
    if (stream_size > 0x7fffffffu)  // a chunk holds at most 2^31 - 1 bytes
        throw std::runtime_error("the compressed pixels (" + std::to_string(stream_size) +
                                 " bytes) exceed a PNG chunk's 2^31 - 1");

    std::string out("\x89PNG\r\n\x1a\n", 8);
    std::string header;
    append_u32(header, static_cast<std::uint32_t>(width));
    append_u32(header, static_cast<std::uint32_t>(height));
    header +=
        std::string("\x08\x02\x00\x00\x00", 5);  // 8 bits, RGB, deflate, filters, no interlace
    append_chunk(out, "IHDR", header.data(), header.size());
    const char intent = 0;  // perceptual
    if (chunks == SrgbChunks::srgb_gama_chrm) {
        std::string gamma, chromaticities;
        append_u32(gamma, kSrgbGamma);
        for (std::uint32_t v : kSrgbChromaticities) append_u32(chromaticities, v);
        append_chunk(out, "gAMA", gamma.data(), gamma.size());
        append_chunk(out, "sRGB", &intent, 1);
        append_chunk(out, "cHRM", chromaticities.data(), chromaticities.size());
    } else {
        append_chunk(out, "sRGB", &intent, 1);
    }
    // One IDAT chunk.
    const std::size_t idat = out.size();
    out.reserve(idat + 12 + stream_size + 12);
    append_u32(out, static_cast<std::uint32_t>(stream_size));
    out += "IDAT";
    out += "\x78\x01";
    for (const PngBand& band : bands)
        out.append(reinterpret_cast<const char*>(band.stream.data()), band.size);
    append_u32(out, adler);
    append_u32(out, detail::crc32(0, out.data() + idat + 4, 4 + stream_size));
    append_chunk(out, "IEND", nullptr, 0);
    return out;
}

// Writes `bytes` to a new file at `path`. Throws std::runtime_error with the OS's reason.
void write_bytes(const std::string& path, const std::string& bytes) {
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (file == nullptr) throw std::runtime_error(errno_message(errno));
    errno = 0;
    const bool written = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
    int error = written ? 0 : (errno != 0 ? errno : EIO);
    // A full disk may only show when buffered data is flushed, so check the close too.
    errno = 0;
    if (std::fclose(file) != 0 && error == 0) error = errno != 0 ? errno : EIO;
    if (error != 0) throw std::runtime_error(errno_message(error));
}

// The rows of packed sRGB bytes, as encode_png takes them.
auto rgb8_row(int width, const std::vector<std::uint8_t>& rgb) {
    const std::size_t row_bytes = 3 * static_cast<std::size_t>(width);
    return
        [row_bytes, &rgb](std::size_t y, std::uint8_t*) { return rgb.data() + y * row_bytes; };
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

namespace detail {

SrgbTable::SrgbTable() {
    float threshold[257];  // [256]: +inf, a sentinel
    threshold[256] = std::numeric_limits<float>::infinity();
    for (int v = 1; v < 256; ++v) {
        std::uint32_t lo = 0, hi = kOneBits;  // formula(lo) < v <= formula(hi)
        while (hi - lo > 1) {
            const std::uint32_t mid = lo + (hi - lo) / 2;
            (srgb8_by_formula(std::bit_cast<float>(mid)) >= v ? hi : lo) = mid;
        }
        threshold[v] = std::bit_cast<float>(hi);
    }
    // The byte of a bucket's first float is the number of thresholds at or below it; the
    // next threshold steps up inside the bucket where its top 16 bits are the bucket's.
    int v = 0;
    for (std::uint32_t b = 0; b < kBuckets; ++b) {
        const float first = std::bit_cast<float>(b << 16);
        while (v < 255 && threshold[v + 1] <= first) ++v;
        const std::uint32_t next = std::bit_cast<std::uint32_t>(threshold[v + 1]);
        const std::uint32_t step = v < 255 && next >> 16 == b ? next & 0xFFFFu : kNoStep;
        bucket_word[b] = static_cast<std::uint32_t>(v) << 17 | step;
    }
    // Within a bucket the byte steps up at most once (so srgb8_in compares once): the
    // byte at the next bucket's first float is at most one above this one's.
    for (std::uint32_t b = 0; b + 1 < kBuckets; ++b)
        if ((bucket_word[b + 1] >> 17) > (bucket_word[b] >> 17) + 1)
            throw std::logic_error("srgb8: a bucket of the sRGB table holds two steps");
}

const SrgbTable& srgb_table() {
    static const SrgbTable table;
    return table;
}

bool srgb8_use_avx2() { return cpu_features().avx2; }

void srgb8_interleaved_scalar(const float* r, const float* g, const float* b, std::size_t count,
                              float scale, std::uint8_t* out) {
    const SrgbTable& table = srgb_table();
    for (std::size_t i = 0; i < count; ++i) {
        out[3 * i] = srgb8_in(table, r[i] * scale);
        out[3 * i + 1] = srgb8_in(table, g[i] * scale);
        out[3 * i + 2] = srgb8_in(table, b[i] * scale);
    }
}

}  // namespace detail

std::uint8_t srgb8(float linear) { return detail::srgb8_in(detail::srgb_table(), linear); }

void srgb8_interleaved(const float* r, const float* g, const float* b, std::size_t count,
                       float scale, std::uint8_t* out) {
    if (detail::srgb8_use_avx2())
        detail::srgb8_interleaved_avx2(r, g, b, count, scale, out);
    else
        detail::srgb8_interleaved_scalar(r, g, b, count, scale, out);
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

void require_render_image(const std::string& path, const Image& image) {
    if (!is_rgb_image(image))
        throw IoError("cannot write " + path +
                      ": the image is not a render's (float32 channels R, G and B)");
    if (image.width() <= 0 || image.height() <= 0)
        throw IoError("cannot write " + path + ": the image is empty (" +
                      std::to_string(image.width()) + "x" + std::to_string(image.height()) +
                      ")");
}

}  // namespace

void write_png_preview(const std::string& path, const Image& render,
                       const std::function<void()>& on_read) {
    require_render_image(path, render);
    const std::size_t width = static_cast<std::size_t>(render.width());
    const std::string bytes = encode_png(
        render.width(), render.height(),
        [&](std::size_t y, std::uint8_t* scratch) {
            const std::size_t row = y * width;
            srgb8_interleaved(render.plane(0) + row, render.plane(1) + row,
                              render.plane(2) + row, width, 1.0f, scratch);
            return static_cast<const std::uint8_t*>(scratch);
        },
        SrgbChunks::srgb_gama_chrm);
    if (on_read) on_read();
    write_file_atomically(path, [&](const std::string& tmp) { write_bytes(tmp, bytes); });
}

void write_png_rgb8(const std::string& path, int width, int height,
                    const std::vector<std::uint8_t>& rgb) {
    if (!rgb8_size_matches(width, height, rgb))
        throw IoError("cannot write '" + path + "': " + std::to_string(rgb.size()) +
                      " bytes do not make a " + std::to_string(width) + "x" +
                      std::to_string(height) + " RGB image");
    const std::string bytes = encode_png(width, height, rgb8_row(width, rgb), SrgbChunks::srgb);
    write_file_atomically(path, [&](const std::string& tmp) { write_bytes(tmp, bytes); });
}

namespace {

// The uint8 channels R, G, B of `image` interleaved; `what` names the target in the error.
std::vector<std::uint8_t> interleaved_rgb8(const Image& image, const std::string& what) {
    const ImageChannel* planes[3] = {image.find_channel("R"), image.find_channel("G"),
                                     image.find_channel("B")};
    for (const ImageChannel* c : planes)
        if (c == nullptr || c->format != PixelFormat::uint8 || c->size() != image.pixel_count())
            throw IoError(what + ": a PNG is made from uint8 channels R, G and B of the image");
    std::vector<std::uint8_t> rgb(3 * image.pixel_count());
    for (std::size_t i = 0; i < image.pixel_count(); ++i)
        for (std::size_t c = 0; c < 3; ++c) rgb[3 * i + c] = planes[c]->samples[i];
    return rgb;
}

}  // namespace

void write_png(const std::string& path, const Image& image) {
    write_png_rgb8(path, image.width(), image.height(),
                   interleaved_rgb8(image, "cannot write '" + path + "'"));
}

std::string encode_png(const Image& image) {
    return encode_png_rgb8(image.width(), image.height(),
                           interleaved_rgb8(image, "cannot encode a PNG"));
}

std::string encode_png_rgb8(int width, int height, const std::vector<std::uint8_t>& rgb) {
    if (!rgb8_size_matches(width, height, rgb))
        throw IoError("cannot encode a PNG: " + std::to_string(rgb.size()) +
                      " bytes do not make a " + std::to_string(width) + "x" +
                      std::to_string(height) + " RGB image");
    return encode_png(width, height, rgb8_row(width, rgb), SrgbChunks::srgb);
}

Image read_png_channels(const std::string& path, const std::vector<unsigned char>& bytes) {
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
    Image image(static_cast<int>(layout.width), static_cast<int>(layout.height),
                names_by_count[layout.channels - 1]);
    image.file_format = layout.bit_depth == 16 ? "PNG 16-bit" : "PNG 8-bit";

    // Raw samples scaled to [0, 1]; 16-bit samples are big-endian in the file.
    const int channels = layout.channels;
    for (int y = 0; y < image.height(); ++y) {
        const png_byte* row = rows[static_cast<std::size_t>(y)];
        for (int x = 0; x < image.width(); ++x) {
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
