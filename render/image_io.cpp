#include "render/image_io.h"

#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIntAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfOpaqueAttribute.h>
#include <ImfOutputFile.h>
#include <ImfRational.h>
#include <ImfRationalAttribute.h>
#include <ImfStdIO.h>
#include <ImfStringAttribute.h>
#include <ImfVersion.h>
#include <fcntl.h>
#include <half.h>
#include <png.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <random>
#include <set>
#include <stdexcept>
#include <system_error>

namespace octray {
namespace {

namespace fs = std::filesystem;

// Rgb is handed to OpenEXR as three interleaved float channels, so it must be exactly
// three packed floats.
static_assert(sizeof(Rgb) == 3 * sizeof(float));

std::string errno_message(int error) { return std::generic_category().message(error); }

std::string window_text(const PixelRect& r) {
    return "(" + std::to_string(r.x0) + ", " + std::to_string(r.y0) + ")-(" +
           std::to_string(r.x1) + ", " + std::to_string(r.y1) + ")";
}

// "<dir>/.<name>.<kind>.<pid>.<random>": hidden, in the target's directory so that the
// final rename stays on one file system (and so stays atomic), and unique per process and
// call. The kind is "new" while the file is being created and locked, "tmp" after.
std::string temporary_path_for(const fs::path& target, const char* kind, std::uint64_t salt) {
    fs::path dir = target.parent_path();
    if (dir.empty()) dir = ".";
    char suffix[80];
    std::snprintf(suffix, sizeof suffix, ".%s.%ld.%016llx", kind, static_cast<long>(::getpid()),
                  static_cast<unsigned long long>(salt));
    return (dir / ("." + target.filename().string() + suffix)).string();
}

// A temporary file, held by its writer: the open descriptor carries an exclusive flock(2)
// from before the file has its ".tmp." name until after it was renamed over the target.
// The lock ends with the descriptor, so also when the writer is killed: a ".tmp." file
// nobody holds the lock of is stale (remove_stale_temporaries).
struct HeldTemporary {
    std::string path;
    int fd = -1;
    HeldTemporary() = default;
    HeldTemporary(const HeldTemporary&) = delete;
    HeldTemporary& operator=(const HeldTemporary&) = delete;
    ~HeldTemporary() {
        if (fd >= 0) ::close(fd);
    }
};

// Creates the temporary file exclusively (O_EXCL: never clobber another writer's file),
// locks it, then gives it its ".tmp." name. The writer callback then truncates and fills
// it. Mode 0666 lets the umask decide the final permissions, as for any file the user
// creates.
void create_temporary_file(const fs::path& target, HeldTemporary& held) {
    std::random_device entropy;
    std::mt19937_64 generator((static_cast<std::uint64_t>(entropy()) << 32) ^ entropy());
    for (int attempt = 0; attempt < 16; ++attempt) {
        const std::uint64_t salt = generator();
        const std::string fresh = temporary_path_for(target, "new", salt);
        const int fd = ::open(fresh.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0) {
            if (errno != EEXIST) throw std::runtime_error(errno_message(errno));
            continue;
        }
        held.fd = fd;
        // Where locks do not work (some network file systems), the file is only not
        // provably stale: other runs leave it alone.
        (void)::flock(fd, LOCK_EX | LOCK_NB);
        const std::string tmp = temporary_path_for(target, "tmp", salt);
        if (std::rename(fresh.c_str(), tmp.c_str()) != 0) {
            const int error = errno;
            std::remove(fresh.c_str());
            throw std::runtime_error(errno_message(error));
        }
        held.path = tmp;
        return;
    }
    throw std::runtime_error("could not create a unique temporary file next to it");
}

Imf::Compression to_imf(ExrCompression compression) {
    switch (compression) {
        case ExrCompression::none:
            return Imf::NO_COMPRESSION;
        case ExrCompression::rle:
            return Imf::RLE_COMPRESSION;
        case ExrCompression::zips:
            return Imf::ZIPS_COMPRESSION;
        case ExrCompression::zip:
            return Imf::ZIP_COMPRESSION;
        case ExrCompression::piz:
            return Imf::PIZ_COMPRESSION;
        case ExrCompression::pxr24:
            return Imf::PXR24_COMPRESSION;
        case ExrCompression::b44:
            return Imf::B44_COMPRESSION;
        case ExrCompression::b44a:
            return Imf::B44A_COMPRESSION;
        case ExrCompression::dwaa:
            return Imf::DWAA_COMPRESSION;
        case ExrCompression::dwab:
            return Imf::DWAB_COMPRESSION;
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

// OpenEXR boxes are inclusive: [x0, x1) becomes min x0, max x1 - 1.
Imath::Box2i to_box(const PixelRect& r) {
    return Imath::Box2i({r.x0, r.y0}, {r.x1 - 1, r.y1 - 1});
}

Imf::PixelType to_imf(ExrPixelType type) {
    switch (type) {
        case ExrPixelType::uint32:
            return Imf::UINT;
        case ExrPixelType::half:
            return Imf::HALF;
        case ExrPixelType::float32:
            return Imf::FLOAT;
    }
    throw std::invalid_argument("unknown EXR pixel type");
}

// Attributes the writer derives from the image itself; a caller may not set them.
constexpr std::array<std::string_view, 11> kStructuralAttributes{
    "channels", "compression", "dataWindow", "displayWindow", "lineOrder",         "tiles",
    "type",     "name",        "version",    "chunkCount",    "maxSamplesPerPixel"};

void insert_attribute(Imf::Header& header, std::set<std::string>& seen, const std::string& name,
                      const Imf::Attribute& attribute) {
    if (name.empty()) throw std::invalid_argument("an attribute has an empty name");
    for (std::string_view structural : kStructuralAttributes)
        if (name == structural)
            throw std::invalid_argument("attribute '" + name +
                                        "' is set by the writer and cannot be given");
    if (!seen.insert(name).second)
        throw std::invalid_argument("attribute '" + name + "' is given twice");
    // Header::insert throws if the header already holds `name` with another type (the
    // defaults pixelAspectRatio, screenWindowCenter, screenWindowWidth).
    header.insert(name, attribute);
}

void insert_attributes(Imf::Header& header, const ExrAttributes& attributes) {
    std::set<std::string> seen;
    for (const auto& [name, value] : attributes.strings)
        insert_attribute(header, seen, name, Imf::StringAttribute(value));
    for (const auto& [name, value] : attributes.floats)
        insert_attribute(header, seen, name, Imf::FloatAttribute(value));
    for (const auto& [name, value] : attributes.ints)
        insert_attribute(header, seen, name, Imf::IntAttribute(value));
    for (const auto& [name, value] : attributes.doubles)
        insert_attribute(header, seen, name, Imf::DoubleAttribute(value));
    for (const auto& [name, m] : attributes.matrices) {
        const Imath::M44f matrix(m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8], m[9],
                                 m[10], m[11], m[12], m[13], m[14], m[15]);
        insert_attribute(header, seen, name, Imf::M44fAttribute(matrix));
    }
    for (const auto& [name, r] : attributes.rationals)
        insert_attribute(header, seen, name,
                         Imf::RationalAttribute(Imf::Rational(r.numerator, r.denominator)));
    for (const ExrOpaqueAttribute& a : attributes.opaque) {
        // Rebuilt from its stored bytes: a known type as that type (so that OpenEXR checks
        // it), any other as an opaque blob.
        std::unique_ptr<Imf::Attribute> attribute(
            Imf::Attribute::knownType(a.type.c_str())
                ? Imf::Attribute::newAttribute(a.type.c_str())
                : new Imf::OpaqueAttribute(a.type.c_str()));
        Imf::StdISStream in;
        in.str(std::string(a.value.begin(), a.value.end()));
        attribute->readValueFrom(in, static_cast<int>(a.value.size()), Imf::EXR_VERSION);
        insert_attribute(header, seen, a.name, *attribute);
    }
}

void check_exr_image(const ExrImage& image) {
    if (image.display_window.empty())
        throw std::invalid_argument("the display window " + window_text(image.display_window) +
                                    " is empty");
    if (image.data_window.empty())
        throw std::invalid_argument("the data window " + window_text(image.data_window) +
                                    " is empty");
    if (image.channels.empty()) throw std::invalid_argument("the image has no channels");
    std::set<std::string> names;
    for (const ExrChannel& c : image.channels) {
        if (c.name.empty()) throw std::invalid_argument("a channel has an empty name");
        if (!names.insert(c.name).second)
            throw std::invalid_argument("channel '" + c.name + "' is given twice");
        const std::size_t expected = image.data_window.pixel_count() * sample_size(c.type);
        if (c.samples.size() != expected)
            throw std::invalid_argument(
                "channel '" + c.name + "' holds " + std::to_string(c.samples.size()) +
                " bytes, but the data window " + window_text(image.data_window) + " needs " +
                std::to_string(expected));
    }
}

void write_exr_file(const std::string& path, const ExrImage& image) {
    // Line order INCREASING_Y: the file's first scan line is the top row.
    Imf::Header header(to_box(image.display_window), to_box(image.data_window));
    header.compression() = to_imf(image.compression);
    insert_attributes(header, image.attributes);

    const Imath::Box2i window = to_box(image.data_window);
    const std::size_t width = static_cast<std::size_t>(image.data_window.width());
    Imf::FrameBuffer frame_buffer;
    for (const ExrChannel& c : image.channels) {
        const Imf::PixelType type = to_imf(c.type);
        header.channels().insert(c.name, Imf::Channel(type));
        // OpenEXR only reads through the frame buffer when writing.
        char* base = reinterpret_cast<char*>(const_cast<unsigned char*>(c.samples.data()));
        const std::size_t element = sample_size(c.type);
        frame_buffer.insert(c.name,
                            Imf::Slice::Make(type, base, window, element, element * width));
    }
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frame_buffer);
    file.writePixels(image.data_window.height());
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
// libpng's own writer says only "Write Error"; ours keeps the OS reason (errno) of a
// failed write so that the message can say it ("No space left on device").
struct PngErrorState {
    char message[256] = "";
    std::FILE* file = nullptr;
    int write_errno = 0;
};

void png_error_handler(png_structp png, png_const_charp message) {
    auto* state = static_cast<PngErrorState*>(png_get_error_ptr(png));
    if (state->write_errno != 0)
        std::snprintf(state->message, sizeof state->message, "libpng: %s: %s", message,
                      std::strerror(state->write_errno));
    else
        std::snprintf(state->message, sizeof state->message, "libpng: %s", message);
    png_longjmp(png, 1);
}

void png_warning_handler(png_structp, png_const_charp) {}

void png_write_data(png_structp png, png_bytep data, png_size_t length) {
    auto* state = static_cast<PngErrorState*>(png_get_io_ptr(png));
    errno = 0;
    if (std::fwrite(data, 1, length, state->file) != length) {
        state->write_errno = errno != 0 ? errno : EIO;
        png_error(png, "Write Error");
    }
}

void png_flush_data(png_structp png) {
    auto* state = static_cast<PngErrorState*>(png_get_io_ptr(png));
    errno = 0;
    if (std::fflush(state->file) != 0) {
        state->write_errno = errno != 0 ? errno : EIO;
        png_error(png, "Write Error");
    }
}

// The libpng calls, in a function with only trivially destructible locals: longjmp must
// never skip a C++ destructor. Returns an empty string on success, else the reason.
std::string write_png_rows(std::FILE* file, int width, int height, png_bytepp rows) {
    PngErrorState error;
    error.file = file;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, png_error_handler,
                                              png_warning_handler);
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
    png_set_write_fn(png, &error, png_write_data, png_flush_data);
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
    HeldTemporary tmp;
    try {
        create_temporary_file(fs::path(path), tmp);
        write(tmp.path);
        if (std::rename(tmp.path.c_str(), path.c_str()) != 0)
            throw std::runtime_error(errno_message(errno));
    } catch (const std::exception& e) {
        if (!tmp.path.empty()) std::remove(tmp.path.c_str());
        throw IoError("cannot write " + path + ": " + e.what());
    } catch (...) {
        if (!tmp.path.empty()) std::remove(tmp.path.c_str());
        throw IoError("cannot write " + path + ": unknown error");
    }
}

std::vector<std::string> remove_stale_temporaries(const std::string& target) {
    const fs::path path(target);
    fs::path dir = path.parent_path();
    if (dir.empty()) dir = ".";
    const std::string prefix = "." + path.filename().string() + ".tmp.";
    std::vector<std::string> removed;
    std::error_code error;
    for (fs::directory_iterator it(dir, error), end; !error && it != end; it.increment(error)) {
        const std::string name = it->path().filename().string();
        if (name.compare(0, prefix.size(), prefix) != 0) continue;
        const std::string file = it->path().string();
        // O_NONBLOCK: a FIFO planted under such a name must not block the open.
        int fd = ::open(file.c_str(), O_RDWR | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
        if (fd < 0) fd = ::open(file.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
        if (fd < 0) continue;
        // The lock is free only when no writer holds it: its writer is gone. (Names are
        // never reused, so if the writer renamed it away meanwhile, the unlink finds
        // nothing.)
        if (::flock(fd, LOCK_EX | LOCK_NB) == 0 && ::unlink(file.c_str()) == 0)
            removed.push_back(file);
        ::close(fd);
    }
    return removed;
}

std::optional<ExrCompression> parse_exr_compression(std::string_view name) {
    for (const auto& [text, value] : kCompressionNames)
        if (text == name) return value;
    return std::nullopt;
}

int exr_lines_per_chunk(ExrCompression compression) {
    switch (compression) {
        case ExrCompression::none:
        case ExrCompression::rle:
        case ExrCompression::zips:
            return 1;
        case ExrCompression::zip:
        case ExrCompression::pxr24:
            return 16;
        case ExrCompression::piz:
        case ExrCompression::b44:
        case ExrCompression::b44a:
        case ExrCompression::dwaa:
            return 32;
        case ExrCompression::dwab:
            return 256;
    }
    return 256;
}

std::string_view to_string(ExrCompression compression) {
    for (const auto& [text, value] : kCompressionNames)
        if (value == compression) return text;
    return "unknown";
}

std::string_view to_string(ExrPixelType type) {
    switch (type) {
        case ExrPixelType::uint32:
            return "uint";
        case ExrPixelType::half:
            return "half";
        case ExrPixelType::float32:
            return "float";
    }
    return "unknown";
}

std::size_t sample_size(ExrPixelType type) { return type == ExrPixelType::half ? 2 : 4; }

float ExrChannel::value(std::size_t k) const {
    const unsigned char* p = samples.data() + k * sample_size(type);
    switch (type) {
        case ExrPixelType::half: {
            half h;
            std::uint16_t bits;
            std::memcpy(&bits, p, sizeof bits);
            h.setBits(bits);
            return static_cast<float>(h);
        }
        case ExrPixelType::float32: {
            float f;
            std::memcpy(&f, p, sizeof f);
            return f;
        }
        case ExrPixelType::uint32: {
            std::uint32_t u;
            std::memcpy(&u, p, sizeof u);
            return static_cast<float>(u);
        }
    }
    return 0.0f;
}

std::uint32_t ExrChannel::uint_value(std::size_t k) const {
    if (type == ExrPixelType::uint32) {
        std::uint32_t u;
        std::memcpy(&u, samples.data() + k * sizeof u, sizeof u);
        return u;
    }
    const float f = value(k);
    // NaN and negatives give 0, values past the range the largest uint32.
    if (!(f > 0.0f)) return 0;
    if (f >= 4294967296.0f) return 0xffffffffu;
    return static_cast<std::uint32_t>(f);
}

ExrChannel make_exr_channel(std::string name, ExrPixelType type, const float* values,
                            std::size_t count, std::size_t stride) {
    if (type == ExrPixelType::uint32)
        throw std::invalid_argument("make_exr_channel: floats make half or float channels");
    ExrChannel c{std::move(name), type, std::vector<unsigned char>(count * sample_size(type))};
    unsigned char* out = c.samples.data();
    for (std::size_t k = 0; k < count; ++k) {
        const float v = values[k * stride];
        if (type == ExrPixelType::half) {
            const std::uint16_t bits = half(v).bits();
            std::memcpy(out + 2 * k, &bits, sizeof bits);
        } else {
            std::memcpy(out + 4 * k, &v, sizeof v);
        }
    }
    return c;
}

ExrChannel make_exr_channel(std::string name, const std::vector<std::uint32_t>& values) {
    ExrChannel c{std::move(name), ExrPixelType::uint32,
                 std::vector<unsigned char>(values.size() * sizeof(std::uint32_t))};
    if (!values.empty()) std::memcpy(c.samples.data(), values.data(), c.samples.size());
    return c;
}

const ExrChannel* ExrImage::find_channel(std::string_view name) const {
    for (const ExrChannel& c : channels)
        if (c.name == name) return &c;
    return nullptr;
}

ExrRational exr_rational(double value) {
    const Imf::Rational r(value);
    return {r.n, r.d};
}

ExrImage make_exr_image(const Image& image, PixelRect data_window, int full_width,
                        int full_height, const ExrWriteOptions& options,
                        const ExrAttributes& attributes) {
    if (image.width() != data_window.width() || image.height() != data_window.height())
        throw std::invalid_argument("make_exr_image: a " + std::to_string(image.width()) + "x" +
                                    std::to_string(image.height()) +
                                    " image cannot fill the data window " +
                                    window_text(data_window));
    ExrImage exr;
    exr.display_window = PixelRect{0, 0, full_width, full_height};
    exr.data_window = data_window;
    exr.compression = options.compression;
    exr.attributes = attributes;
    const ExrPixelType type = options.float32 ? ExrPixelType::float32 : ExrPixelType::half;
    const float* rgb = reinterpret_cast<const float*>(image.data());
    const std::size_t n = image.pixel_count();
    exr.channels.push_back(make_exr_channel("R", type, rgb + 0, n, 3));
    exr.channels.push_back(make_exr_channel("G", type, rgb + 1, n, 3));
    exr.channels.push_back(make_exr_channel("B", type, rgb + 2, n, 3));
    return exr;
}

ExrImage make_exr_image(const RenderResult& result, const ExrWriteOptions& options,
                        const ExrAttributes& attributes) {
    return make_exr_image(result.image, result.rect, result.full_width, result.full_height,
                          options, attributes);
}

void write_exr(const std::string& path, const ExrImage& image) {
    try {
        check_exr_image(image);
    } catch (const std::exception& e) {
        throw IoError("cannot write " + path + ": " + e.what());
    }
    write_file_atomically(path, [&](const std::string& tmp) { write_exr_file(tmp, image); });
}

void write_exr(const std::string& path, const Image& image, const ExrWriteOptions& options,
               const ExrAttributes& attributes) {
    try {
        require_image(image);
    } catch (const std::exception& e) {
        throw IoError("cannot write " + path + ": " + e.what());
    }
    write_exr(path, make_exr_image(image, PixelRect{0, 0, image.width(), image.height()},
                                   image.width(), image.height(), options, attributes));
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
