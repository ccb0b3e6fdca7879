// read_image() (OpenEXR and PNG, told apart by their magic bytes) and the one OpenEXR
// reader, read_exr() below, that every OpenEXR file octray reads goes through: pixels,
// header or the checks alone. PNG decoding is in png.cpp.

#include "render/image/image_read.h"

#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfMultiPartInputFile.h>
#include <ImfRationalAttribute.h>
#include <ImfStdIO.h>
#include <ImfStringAttribute.h>
#include <ImfTileDescription.h>
#include <ImfVersion.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <new>
#include <set>
#include <system_error>
#include <utility>

#include "render/image/exr_chunks.h"
#include "render/image/image_io.h"
#include "render/image/png.h"

namespace octray {

void fail_reading(const std::string& path, std::string reason) {
    // Callers print the message as one line, and OpenEXR's own messages may hold newlines.
    std::replace(reason.begin(), reason.end(), '\n', ' ');
    throw IoError("cannot read '" + path + "': " + reason);
}

namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& path, std::string reason) {
    fail_reading(path, std::move(reason));
}

// Called in a catch block of an OpenEXR read: the exception in flight as an IoError.
[[noreturn]] void fail_reading_exr(const std::string& path) {
    try {
        throw;
    } catch (const IoError&) {
        throw;
    } catch (const std::bad_alloc&) {
        fail(path, "out of memory reading OpenEXR file");
    } catch (const std::exception& e) {
        // OpenEXR says the same things for a cut-off file and a damaged one.
        fail(path, std::string("truncated or corrupt OpenEXR file (") + e.what() + ")");
    }
}

enum class FileKind { exr, png, unknown };

constexpr std::array<unsigned char, 4> exr_magic{0x76, 0x2f, 0x31, 0x01};
constexpr std::array<unsigned char, 8> png_magic{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

// Opens `path` for reading, after the checks that give each common failure its own
// message.
std::ifstream open_checked(const std::string& path) {
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (ec || !fs::exists(status)) {
        if (ec && ec != std::errc::no_such_file_or_directory) fail(path, ec.message());
        fail(path, "no such file");
    }
    if (fs::is_directory(status)) fail(path, "is a directory, not an image");
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(path, std::generic_category().message(errno));
    return in;
}

// The first bytes of the file, enough for either signature.
std::vector<unsigned char> read_signature(const std::string& path) {
    std::ifstream in = open_checked(path);
    std::vector<unsigned char> bytes(8);
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (in.bad()) fail(path, "read error");
    bytes.resize(static_cast<std::size_t>(in.gcount()));
    return bytes;
}

std::vector<unsigned char> read_whole_file(const std::string& path) {
    std::ifstream in = open_checked(path);
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                     std::istreambuf_iterator<char>());
    if (in.bad()) fail(path, "read error");
    return bytes;
}

FileKind kind_of(const std::vector<unsigned char>& bytes) {
    if (bytes.size() >= png_magic.size() &&
        std::equal(png_magic.begin(), png_magic.end(), bytes.begin()))
        return FileKind::png;
    if (bytes.size() >= exr_magic.size() &&
        std::equal(exr_magic.begin(), exr_magic.end(), bytes.begin()))
        return FileKind::exr;
    return FileKind::unknown;
}

// ---- OpenEXR -------------------------------------------------------------------------

// Sort key that puts each layer's R, G, B, A first, in that order (the order people read
// them in), and the layer's other channels alphabetically after; OpenEXR itself stores
// channels alphabetically (A, B, G, R).
std::pair<std::string, std::pair<int, std::string>> exr_channel_key(const std::string& name) {
    const std::size_t dot = name.rfind('.');
    std::string layer = dot == std::string::npos ? std::string() : name.substr(0, dot);
    std::string suffix = dot == std::string::npos ? name : name.substr(dot + 1);
    static constexpr std::array<std::string_view, 4> rgba{"R", "G", "B", "A"};
    int rank = static_cast<int>(rgba.size());
    for (std::size_t i = 0; i < rgba.size(); ++i)
        if (suffix == rgba[i]) rank = static_cast<int>(i);
    return {std::move(layer), {rank, std::move(suffix)}};
}

// The most pixel bytes one byte of the file can hold under each codec: upper bounds on the
// compression ratio, with margin. None: 1. RLE: a run of at most 128 bytes in 2. ZIP(S):
// deflate's limit is 1032:1; PXR24 first packs float to 24 bits (4/3), then deflates. PIZ:
// the Huffman coder spends at least 10 bits on a run of 256 16-bit values (about 410:1).
// B44(A): 32 bytes in at least 3. DWAA/DWAB: a 2-byte DC value per 8x8 block, deflated
// (64 x 1032). 0 means unknown, for codecs newer than this table: no bound but the cap.
unsigned long long max_expansion(Imf::Compression compression) {
    switch (compression) {
        case Imf::NO_COMPRESSION:
            return 1;
        case Imf::RLE_COMPRESSION:
            return 128;
        case Imf::ZIPS_COMPRESSION:
        case Imf::ZIP_COMPRESSION:
        case Imf::PXR24_COMPRESSION:
            return 2048;
        case Imf::PIZ_COMPRESSION:
            return 4096;
        case Imf::B44_COMPRESSION:
        case Imf::B44A_COMPRESSION:
            return 16;
        case Imf::DWAA_COMPRESSION:
        case Imf::DWAB_COMPRESSION:
            return 1ull << 17;
        default:
            return 0;
    }
}

// A header is a few hundred bytes, and it may claim any data window. The pixel data it
// claims must fit in the file under the best compression its codec can reach; otherwise
// the file is cut off or corrupt, and it is refused before the planes are allocated
// (a 449-byte fuzzer input claiming a huge window made compare allocate 260 MB, and the
// float cap alone would have allowed 4 GiB).
void check_pixel_data_fits(const std::string& path, const Imf::Header& header, long long w,
                           long long h) {
    const unsigned long long ratio = max_expansion(header.compression());
    if (ratio == 0) return;
    unsigned long long bytes_per_pixel = 0;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it)
        bytes_per_pixel += it.channel().type == Imf::HALF ? 2 : 4;
    // w, h < 2^31 and at most 2^30 values in all (checked above): no overflow.
    const unsigned long long pixel_bytes = static_cast<unsigned long long>(w) *
                                           static_cast<unsigned long long>(h) * bytes_per_pixel;
    std::error_code ec;
    const std::uintmax_t file_bytes = fs::file_size(path, ec);
    if (ec) return;  // OpenEXR reports an unreadable file itself
    if (pixel_bytes / ratio <= file_bytes) return;
    fail(path, "truncated or corrupt OpenEXR file (its header claims a " + std::to_string(w) +
                   " x " + std::to_string(h) + " data window, " + std::to_string(pixel_bytes) +
                   " bytes of pixel data, which cannot fit in " + "the file's " +
                   std::to_string(file_bytes) + " bytes" +
                   (ratio == 1 ? std::string(" uncompressed")
                               : " even at " + std::to_string(ratio) + ":1 compression") +
                   ")");
}

// The data window's width and height, after the checks both EXR readers need before they
// allocate: a non-empty window, channels that exist and are not subsampled, a sample count
// under max_read_float_values, and pixel data the file's size can hold.
std::pair<long long, long long> checked_data_window(const std::string& path,
                                                    const Imf::Header& header) {
    const Imath::Box2i window = header.dataWindow();
    const long long w = static_cast<long long>(window.max.x) - window.min.x + 1;
    const long long h = static_cast<long long>(window.max.y) - window.min.y + 1;
    if (w <= 0 || h <= 0) fail(path, "OpenEXR file has an empty data window");
    unsigned long long channels = 0;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
        if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
            fail(path, std::string("OpenEXR channel '") + it.name() +
                           "' is subsampled, which octray does not support");
        ++channels;
    }
    if (channels == 0) fail(path, "OpenEXR file has no channels");
    if (static_cast<unsigned long long>(w) * static_cast<unsigned long long>(h) * channels >
        max_read_float_values)
        fail(path, "image too large");
    check_pixel_data_fits(path, header, w, h);
    return {w, h};
}

ExrCompression from_imf(Imf::Compression compression) {
    switch (compression) {
        case Imf::NO_COMPRESSION:
            return ExrCompression::none;
        case Imf::RLE_COMPRESSION:
            return ExrCompression::rle;
        case Imf::ZIPS_COMPRESSION:
            return ExrCompression::zips;
        case Imf::ZIP_COMPRESSION:
            return ExrCompression::zip;
        case Imf::PIZ_COMPRESSION:
            return ExrCompression::piz;
        case Imf::PXR24_COMPRESSION:
            return ExrCompression::pxr24;
        case Imf::B44_COMPRESSION:
            return ExrCompression::b44;
        case Imf::B44A_COMPRESSION:
            return ExrCompression::b44a;
        case Imf::DWAA_COMPRESSION:
            return ExrCompression::dwaa;
        case Imf::DWAB_COMPRESSION:
            return ExrCompression::dwab;
        default:
            return ExrCompression::zip;  // a codec newer than this list
    }
}

PixelFormat from_imf(Imf::PixelType type) {
    return type == Imf::HALF    ? PixelFormat::half
           : type == Imf::FLOAT ? PixelFormat::float32
                                : PixelFormat::uint32;
}

// "R, G, B float; id uint": the channels as the header declares them, for messages.
std::string declared_channels(const Imf::Header& header) {
    std::string out;
    std::string names;
    Imf::PixelType previous = Imf::NUM_PIXELTYPES;
    int shown = 0;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
        if (++shown > 8) {
            names += ", ...";
            break;
        }
        if (it.channel().type != previous && !names.empty()) {
            out += (out.empty() ? "" : "; ") + names + " " +
                   std::string(to_string(from_imf(previous)));
            names.clear();
        }
        names += (names.empty() ? "" : ", ") + std::string(it.name());
        previous = it.channel().type;
    }
    if (!names.empty())
        out += (out.empty() ? "" : "; ") + names + " " +
               std::string(to_string(from_imf(previous)));
    return out;
}

// Every chunk readPixels() will decode (level 0 of a tiled file) against the size its
// header implies (render/image/exr_chunks.h): OpenEXR 3.1 reads a file whose header declares
// FLOAT channels over ZIP-compressed HALF data as garbage, without an error.
void check_exr_chunks(const std::string& path, Imf::InputFile& file) {
    const Imf::Header& header = file.header();
    ExrChunkShape shape;
    shape.compression = from_imf(header.compression());
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it)
        shape.channels.push_back({it.name(), from_imf(it.channel().type)});
    const Imath::Box2i window = header.dataWindow();
    const std::int64_t w = std::int64_t{window.max.x} - window.min.x + 1;
    const std::int64_t h = std::int64_t{window.max.y} - window.min.y + 1;
    const auto check = [&](const char* data, int size, const std::string& where) {
        if (size < 0) fail(path, "corrupt OpenEXR file (" + where + " has a negative size)");
        const std::string problem =
            exr_chunk_problem(shape, reinterpret_cast<const unsigned char*>(data),
                              static_cast<std::size_t>(size));
        if (!problem.empty())
            fail(path, "corrupt OpenEXR file: " + where + " " + problem +
                           " (the header declares " + declared_channels(header) + ", " +
                           std::string(to_string(shape.compression)) + " compression)");
    };
    if (header.hasTileDescription()) {
        const Imf::TileDescription& tiles = header.tileDescription();
        const std::int64_t tw = tiles.xSize, th = tiles.ySize;
        if (tw <= 0 || th <= 0) fail(path, "corrupt OpenEXR file (an empty tile size)");
        for (std::int64_t ty = 0; ty * th < h; ++ty) {
            for (std::int64_t tx = 0; tx * tw < w; ++tx) {
                int dx = static_cast<int>(tx), dy = static_cast<int>(ty), lx = 0, ly = 0;
                const char* data = nullptr;
                int size = 0;
                file.rawTileData(dx, dy, lx, ly, data, size);
                shape.width = std::min(tw, w - tx * tw);
                shape.height = std::min(th, h - ty * th);
                check(data, size,
                      "the tile (" + std::to_string(tx) + ", " + std::to_string(ty) + ")");
            }
        }
        return;
    }
    const int lines = exr_lines_per_chunk(shape.compression);
    shape.width = w;
    for (std::int64_t y = window.min.y; y <= window.max.y; y += lines) {
        const char* data = nullptr;
        int size = 0;
        file.rawPixelData(static_cast<int>(y), data, size);
        shape.height = std::min<std::int64_t>(lines, window.max.y - y + 1);
        const std::int64_t last = y + shape.height - 1;
        check(data, size,
              shape.height == 1 ? "the chunk of scan line " + std::to_string(y)
                                : "the chunk of scan lines " + std::to_string(y) + " to " +
                                      std::to_string(last));
    }
}

// ---- The one OpenEXR reader ----------------------------------------------------------

// Every OpenEXR file octray reads is opened here, and any exception while it is read
// becomes an IoError naming the file. With `check_pixel_data`, the file first gets the
// checks made before anything is decoded: a data window it can hold (checked_data_window)
// and chunks that hold what the header implies (check_exr_chunks). Then `use` gets the
// open file and returns what it makes of it.
template <class Use>
auto read_exr(const std::string& path, bool check_pixel_data, Use&& use) {
    try {
        Imf::InputFile file(path.c_str());
        // InputFile reads part 0 of a multi-part file as if it were the whole file: a
        // compare or an assemble would silently use one part of several.
        if (Imf::isMultiPart(file.version())) {
            const int parts = Imf::MultiPartInputFile(path.c_str()).parts();
            fail(path, "a multi-part OpenEXR file (" + std::to_string(parts) +
                           " parts); octray reads single-part files only, and would see part "
                           "0 alone (split it first, e.g. with exrmultipart -separate)");
        }
        if (check_pixel_data) {
            checked_data_window(path, file.header());
            check_exr_chunks(path, file);
        }
        return use(file);
    } catch (...) {
        fail_reading_exr(path);
    }
}

// The data window's width and height (checked by checked_data_window).
std::pair<long long, long long> window_size(const Imath::Box2i& window) {
    return {static_cast<long long>(window.max.x) - window.min.x + 1,
            static_cast<long long>(window.max.y) - window.min.y + 1};
}

// Decodes the whole data window into the slices of `frame_buffer`.
void read_exr_pixels(Imf::InputFile& file, const Imf::FrameBuffer& frame_buffer) {
    const Imath::Box2i window = file.header().dataWindow();
    file.setFrameBuffer(frame_buffer);
    file.readPixels(window.min.y, window.max.y);
}

PixelRect from_box(const Imath::Box2i& box) {
    return PixelRect{box.min.x, box.min.y, box.max.x + 1, box.max.y + 1};
}

// "OpenEXR half float": the pixel types of the file's channels, for reports.
std::string exr_format_text(const Imf::Header& header) {
    std::set<Imf::PixelType> types;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it)
        types.insert(it.channel().type);
    std::string format = "OpenEXR";
    for (Imf::PixelType type : types)
        format += type == Imf::HALF ? " half" : type == Imf::FLOAT ? " float" : " uint";
    return format;
}

Image read_exr_file(const std::string& path) {
    return read_exr(path, true, [&](Imf::InputFile& file) {
        const Imf::Header& header = file.header();
        const Imath::Box2i window = header.dataWindow();
        const auto [w, h] = window_size(window);

        std::vector<std::string> names;
        for (auto it = header.channels().begin(); it != header.channels().end(); ++it)
            names.emplace_back(it.name());
        std::sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) {
            return exr_channel_key(a) < exr_channel_key(b);
        });

        Image image(static_cast<int>(w), static_cast<int>(h), names);
        image.data_window = from_box(window);
        // A display window OpenEXR would refuse to write is the data window here: what is
        // compared is the pixels.
        const Imath::Box2i display = header.displayWindow();
        if (static_cast<long long>(display.max.x) >= display.min.x &&
            static_cast<long long>(display.max.y) >= display.min.y)
            image.display_window = from_box(display);
        else
            image.display_window = image.data_window;
        image.file_format = exr_format_text(header);

        // Every channel is read as FLOAT; OpenEXR converts HALF and UINT on the way.
        Imf::FrameBuffer frame_buffer;
        for (int c = 0; c < image.channel_count(); ++c)
            frame_buffer.insert(
                image.channels[static_cast<std::size_t>(c)].name,
                Imf::Slice::Make(Imf::FLOAT, image.plane(c), window, sizeof(float),
                                 sizeof(float) * static_cast<std::size_t>(w)));
        read_exr_pixels(file, frame_buffer);
        return image;
    });
}

// The attributes write_exr() derives from the image itself, and so does not carry.
bool is_structural(std::string_view name) {
    static constexpr std::array<std::string_view, 11> names{
        "channels", "compression", "dataWindow", "displayWindow", "lineOrder",         "tiles",
        "type",     "name",        "version",    "chunkCount",    "maxSamplesPerPixel"};
    return std::find(names.begin(), names.end(), name) != names.end();
}

ExrAttributes read_attributes(const Imf::Header& header) {
    ExrAttributes out;
    for (auto it = header.begin(); it != header.end(); ++it) {
        const std::string name = it.name();
        if (is_structural(name)) continue;
        const Imf::Attribute& a = it.attribute();
        if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&a)) {
            out.strings.emplace_back(name, s->value());
        } else if (const auto* f = dynamic_cast<const Imf::FloatAttribute*>(&a)) {
            out.floats.emplace_back(name, f->value());
        } else if (const auto* i = dynamic_cast<const Imf::IntAttribute*>(&a)) {
            out.ints.emplace_back(name, i->value());
        } else if (const auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&a)) {
            out.doubles.emplace_back(name, d->value());
        } else if (const auto* m = dynamic_cast<const Imf::M44fAttribute*>(&a)) {
            Matrix44 matrix;
            for (int r = 0; r < 4; ++r)
                for (int c = 0; c < 4; ++c)
                    matrix[static_cast<std::size_t>(4 * r + c)] = m->value()[r][c];
            out.matrices.emplace_back(name, matrix);
        } else if (const auto* q = dynamic_cast<const Imf::RationalAttribute*>(&a)) {
            out.rationals.emplace_back(name, ExrRational{q->value().n, q->value().d});
        } else {
            Imf::StdOSStream stream;
            a.writeValueTo(stream, Imf::EXR_VERSION);
            const std::string bytes = stream.str();
            out.opaque.push_back({name, a.typeName(), {bytes.begin(), bytes.end()}});
        }
    }
    return out;
}

Image read_exr_image_file(const std::string& path) {
    return read_exr(path, true, [&](Imf::InputFile& file) {
        const Imf::Header& header = file.header();
        const Imath::Box2i window = header.dataWindow();
        const auto [w, h] = window_size(window);
        const Imath::Box2i display = header.displayWindow();
        if (static_cast<long long>(display.max.x) < display.min.x ||
            static_cast<long long>(display.max.y) < display.min.y)
            fail(path, "OpenEXR file has an empty display window");

        Image image;
        image.display_window = from_box(display);
        image.data_window = from_box(window);
        image.compression = from_imf(header.compression());
        image.attributes = read_attributes(header);
        image.file_format = exr_format_text(header);
        const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
        Imf::FrameBuffer frame_buffer;
        for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
            const Imf::PixelType t = it.channel().type;
            const PixelFormat type = from_imf(t);
            const std::size_t element = sample_size(type);
            image.channels.push_back(
                ImageChannel{it.name(), type, SampleBytes(pixels * element, 0)});
            frame_buffer.insert(
                it.name(), Imf::Slice::Make(t, image.channels.back().samples.data(), window,
                                            element, element * static_cast<std::size_t>(w)));
        }
        read_exr_pixels(file, frame_buffer);
        return image;
    });
}

}  // namespace

Image read_image(const std::string& path) {
    const std::vector<unsigned char> signature = read_signature(path);
    if (signature.empty()) fail(path, "empty file, not an image");
    switch (kind_of(signature)) {
        case FileKind::png:
            return read_png_channels(path, read_whole_file(path));
        case FileKind::exr:
            return read_exr_file(path);
        case FileKind::unknown:
            break;
    }
    fail(path, "not an image (neither an OpenEXR nor a PNG signature)");
}

ExrLayout read_exr_layout(const std::string& path) {
    return read_exr(path, false, [](Imf::InputFile& file) {
        const Imf::Header& header = file.header();
        ExrLayout layout;
        layout.data_window = from_box(header.dataWindow());
        layout.compression = from_imf(header.compression());
        layout.tiled = header.hasTileDescription();
        for (auto it = header.channels().begin(); it != header.channels().end(); ++it)
            layout.channels.push_back({it.name(), from_imf(it.channel().type)});
        return layout;
    });
}

ExrAttributes read_exr_attributes(const std::string& path) {
    return read_exr(path, false,
                    [](Imf::InputFile& file) { return read_attributes(file.header()); });
}

void check_exr_pixel_data(const std::string& path) {
    read_exr(path, true, [](Imf::InputFile&) {});
}

Image read_exr_image(const std::string& path) {
    const std::vector<unsigned char> signature = read_signature(path);
    if (signature.empty()) fail(path, "empty file, not an OpenEXR image");
    if (kind_of(signature) != FileKind::exr)
        fail(path, "not an OpenEXR file (no OpenEXR signature)");
    return read_exr_image_file(path);
}

}  // namespace octray
