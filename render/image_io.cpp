#include "render/image_io.h"

#include <fcntl.h>
#include <png.h>
#include <unistd.h>

#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <half.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <system_error>

namespace octray {
namespace {

namespace fs = std::filesystem;

// Rgb is handed to OpenEXR as three interleaved float channels, so it must be exactly
// three packed floats.
static_assert(sizeof(Rgb) == 3 * sizeof(float));

std::string errno_message(int error) { return std::generic_category().message(error); }

// "<dir>/.<name>.tmp.<pid>.<random>": hidden, in the target's directory so that the final
// rename stays on one file system (and so stays atomic), and unique per process and call.
std::string temporary_path_for(const fs::path& target, std::uint64_t salt) {
    fs::path dir = target.parent_path();
    if (dir.empty()) dir = ".";
    char suffix[64];
    std::snprintf(suffix, sizeof suffix, ".tmp.%ld.%016llx", static_cast<long>(::getpid()),
                  static_cast<unsigned long long>(salt));
    return (dir / ("." + target.filename().string() + suffix)).string();
}

// Creates the temporary file exclusively (O_EXCL: never clobber another writer's file) and
// returns its path. The writer callback then truncates and fills it. Mode 0666 lets the
// umask decide the final permissions, as for any file the user creates.
std::string create_temporary_file(const fs::path& target) {
    std::random_device entropy;
    std::mt19937_64 generator((static_cast<std::uint64_t>(entropy()) << 32) ^ entropy());
    for (int attempt = 0; attempt < 16; ++attempt) {
        const std::string tmp = temporary_path_for(target, generator());
        const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0) {
            ::close(fd);
            return tmp;
        }
        if (errno != EEXIST) throw std::runtime_error(errno_message(errno));
    }
    throw std::runtime_error("could not create a unique temporary file next to it");
}

Imf::Compression to_imf(ExrCompression compression) {
    switch (compression) {
        case ExrCompression::none: return Imf::NO_COMPRESSION;
        case ExrCompression::rle: return Imf::RLE_COMPRESSION;
        case ExrCompression::zips: return Imf::ZIPS_COMPRESSION;
        case ExrCompression::zip: return Imf::ZIP_COMPRESSION;
        case ExrCompression::piz: return Imf::PIZ_COMPRESSION;
        case ExrCompression::pxr24: return Imf::PXR24_COMPRESSION;
        case ExrCompression::b44: return Imf::B44_COMPRESSION;
        case ExrCompression::b44a: return Imf::B44A_COMPRESSION;
        case ExrCompression::dwaa: return Imf::DWAA_COMPRESSION;
        case ExrCompression::dwab: return Imf::DWAB_COMPRESSION;
    }
    throw std::invalid_argument("unknown EXR compression");
}

constexpr std::array<std::pair<std::string_view, ExrCompression>, 10> kCompressionNames{{
    {"none", ExrCompression::none},
    {"rle", ExrCompression::rle},
    {"zips", ExrCompression::zips},
    {"zip", ExrCompression::zip},
    {"piz", ExrCompression::piz},
    {"pxr24", ExrCompression::pxr24},
    {"b44", ExrCompression::b44},
    {"b44a", ExrCompression::b44a},
    {"dwaa", ExrCompression::dwaa},
    {"dwab", ExrCompression::dwab},
}};

void write_exr_file(const std::string& path, const Image& image,
                    const ExrWriteOptions& options, const ExrAttributes& attributes) {
    const int width = image.width();
    const int height = image.height();
    // The default data window is (0, 0)-(W-1, H-1) and the line order INCREASING_Y, so
    // the file's first scan line is Image row 0, the top row.
    Imf::Header header(width, height);
    header.compression() = to_imf(options.compression);
    for (const auto& [name, value] : attributes.strings)
        header.insert(name, Imf::StringAttribute(value));
    for (const auto& [name, value] : attributes.floats)
        header.insert(name, Imf::FloatAttribute(value));
    for (const auto& [name, value] : attributes.ints)
        header.insert(name, Imf::IntAttribute(value));
    for (const auto& [name, value] : attributes.doubles)
        header.insert(name, Imf::DoubleAttribute(value));

    const Imf::PixelType type = options.float32 ? Imf::FLOAT : Imf::HALF;
    header.channels().insert("R", Imf::Channel(type));
    header.channels().insert("G", Imf::Channel(type));
    header.channels().insert("B", Imf::Channel(type));

    const std::size_t row_stride = static_cast<std::size_t>(width) * 3;
    Imf::FrameBuffer frame_buffer;
    std::vector<half> halves;  // interleaved RGB, converted once up front
    char* base = nullptr;
    std::size_t element = 0;
    if (options.float32) {
        // OpenEXR only reads through the frame buffer, so pointing it at the image's own
        // (const) floats is safe and saves a copy.
        base = reinterpret_cast<char*>(const_cast<Rgb*>(image.data()));
        element = sizeof(float);
    } else {
        halves.resize(row_stride * static_cast<std::size_t>(height));
        const float* source = reinterpret_cast<const float*>(image.data());
        std::transform(source, source + halves.size(), halves.begin(),
                       [](float v) { return half(v); });
        base = reinterpret_cast<char*>(halves.data());
        element = sizeof(half);
    }
    const std::size_t x_stride = 3 * element;
    const std::size_t y_stride = row_stride * element;
    frame_buffer.insert("R", Imf::Slice(type, base + 0 * element, x_stride, y_stride));
    frame_buffer.insert("G", Imf::Slice(type, base + 1 * element, x_stride, y_stride));
    frame_buffer.insert("B", Imf::Slice(type, base + 2 * element, x_stride, y_stride));

    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frame_buffer);
    file.writePixels(height);
}

// sRGB OETF (IEC 61966-2-1) of a linear value already clamped to [0, 1].
float srgb_encode(float linear) {
    return linear <= 0.0031308f ? 12.92f * linear
                                : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

std::uint8_t to_srgb8(float linear) {
    // NaN fails both comparisons and lands on 0, like negative values; +inf clamps to 1.
    const float clamped = linear > 0.0f ? (linear < 1.0f ? linear : 1.0f) : 0.0f;
    return static_cast<std::uint8_t>(std::lround(srgb_encode(clamped) * 255.0f));
}

// libpng reports errors by calling this and then longjmp-ing back to setjmp; we keep the
// message so it can become an exception once we are back in ordinary C++ control flow.
struct PngErrorState {
    char message[256] = "";
};

void png_error_handler(png_structp png, png_const_charp message) {
    auto* state = static_cast<PngErrorState*>(png_get_error_ptr(png));
    std::snprintf(state->message, sizeof state->message, "libpng: %s", message);
    png_longjmp(png, 1);
}

void png_warning_handler(png_structp, png_const_charp) {}

// The libpng calls, in a function with only trivially destructible locals: longjmp must
// never skip a C++ destructor. Returns an empty string on success, else the reason.
std::string write_png_rows(std::FILE* file, int width, int height, png_bytepp rows) {
    PngErrorState error;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error,
                                              png_error_handler, png_warning_handler);
    if (png == nullptr) return "libpng: cannot create the write structure";
    png_infop info = png_create_info_struct(png);
    if (info == nullptr) {
        png_destroy_write_struct(&png, nullptr);
        return "libpng: cannot create the info structure";
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return error.message;
    }
    png_init_io(png, file);
    png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height),
                 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    // The pixels are sRGB-encoded; the sRGB chunk tells viewers so.
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    png_write_image(png, rows);
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    return {};
}

void write_png_file(const std::string& path, const Image& image) {
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
            row[3 * x + 0] = to_srgb8(c.r);
            row[3 * x + 1] = to_srgb8(c.g);
            row[3 * x + 2] = to_srgb8(c.b);
        }
    }

    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (file == nullptr) throw std::runtime_error(errno_message(errno));
    std::string failure = write_png_rows(file, width, height, rows.data());
    // A full disk may only show when buffered data is flushed, so check the close too.
    const bool stream_failed = std::ferror(file) != 0;
    const int close_errno = std::fclose(file) != 0 ? errno : 0;
    if (failure.empty() && close_errno != 0) failure = errno_message(close_errno);
    if (failure.empty() && stream_failed) failure = "write error";
    if (!failure.empty()) throw std::runtime_error(failure);
}

void require_image(const Image& image) {
    if (image.width() <= 0 || image.height() <= 0)
        throw std::invalid_argument("the image is empty (" + std::to_string(image.width()) +
                                    "x" + std::to_string(image.height()) + ")");
}

}  // namespace

void write_file_atomically(const std::string& path,
                           const std::function<void(const std::string& tmp_path)>& write) {
    std::string tmp;
    try {
        tmp = create_temporary_file(fs::path(path));
        write(tmp);
        if (std::rename(tmp.c_str(), path.c_str()) != 0)
            throw std::runtime_error(errno_message(errno));
    } catch (const std::exception& e) {
        if (!tmp.empty()) std::remove(tmp.c_str());
        throw IoError("cannot write " + path + ": " + e.what());
    } catch (...) {
        if (!tmp.empty()) std::remove(tmp.c_str());
        throw IoError("cannot write " + path + ": unknown error");
    }
}

std::optional<ExrCompression> parse_exr_compression(std::string_view name) {
    for (const auto& [text, value] : kCompressionNames)
        if (text == name) return value;
    return std::nullopt;
}

std::string_view to_string(ExrCompression compression) {
    for (const auto& [text, value] : kCompressionNames)
        if (value == compression) return text;
    return "unknown";
}

void write_exr(const std::string& path, const Image& image, const ExrWriteOptions& options,
               const ExrAttributes& attributes) {
    try {
        require_image(image);
    } catch (const std::exception& e) {
        throw IoError("cannot write " + path + ": " + e.what());
    }
    write_file_atomically(path, [&](const std::string& tmp) {
        write_exr_file(tmp, image, options, attributes);
    });
}

void write_png_preview(const std::string& path, const Image& image) {
    try {
        require_image(image);
    } catch (const std::exception& e) {
        throw IoError("cannot write " + path + ": " + e.what());
    }
    write_file_atomically(path, [&](const std::string& tmp) { write_png_file(tmp, image); });
}

}  // namespace octray
