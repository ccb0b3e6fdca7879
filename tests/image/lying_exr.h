#pragma once
// OpenEXR files whose header lies about their pixel data, for the tests of the checked
// read (render/image/exr_chunks.h) and the fuzzer's seeds (tests/fuzz/make_image_seeds.cpp):
// written with OpenEXR in one pixel type, then the header's channel list patched to
// declare another, or one chunk's size field cut. Depends on OpenEXR and the standard
// library only, so that the seed generator can include it.

#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfTiledOutputFile.h>
#include <half.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

namespace octray::testing {

// Every compression OpenEXR 3.1 writes, with the name `octray render --compression` uses.
struct ExrCodec {
    Imf::Compression compression;
    const char* name;
};
inline const std::vector<ExrCodec>& all_exr_codecs() {
    static const std::vector<ExrCodec> codecs{
        {Imf::NO_COMPRESSION, "none"},   {Imf::RLE_COMPRESSION, "rle"},
        {Imf::ZIPS_COMPRESSION, "zips"}, {Imf::ZIP_COMPRESSION, "zip"},
        {Imf::PIZ_COMPRESSION, "piz"},   {Imf::PXR24_COMPRESSION, "pxr24"},
        {Imf::B44_COMPRESSION, "b44"},   {Imf::B44A_COMPRESSION, "b44a"},
        {Imf::DWAA_COMPRESSION, "dwaa"}, {Imf::DWAB_COMPRESSION, "dwab"}};
    return codecs;
}

// A smooth R, G, B, A image (it compresses under every codec, so no chunk is stored raw)
// of `type`, scan lines or 16 x 16 tiles.
inline void write_smooth_exr(const std::string& path, Imf::Compression compression,
                             Imf::PixelType type, bool tiled, int width = 37, int height = 45) {
    Imf::Header header(width, height);
    header.compression() = compression;
    if (tiled) header.setTileDescription(Imf::TileDescription(16, 16, Imf::ONE_LEVEL));
    const char* names[] = {"A", "B", "G", "R"};
    const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    std::vector<float> floats(4 * n);
    std::vector<half> halves(4 * n);
    std::vector<std::uint32_t> uints(4 * n);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int c = 0; c < 4; ++c) {
                const std::size_t i = 4 * (static_cast<std::size_t>(y) * width + x) + c;
                floats[i] = 0.1f + 0.01f * x + 0.02f * y + 0.2f * c;
                halves[i] = floats[i];
                uints[i] = static_cast<std::uint32_t>(x + y + c);
            }
    Imf::FrameBuffer fb;
    for (int c = 0; c < 4; ++c) {
        header.channels().insert(names[c], Imf::Channel(type));
        char* base = type == Imf::HALF    ? reinterpret_cast<char*>(halves.data() + c)
                     : type == Imf::FLOAT ? reinterpret_cast<char*>(floats.data() + c)
                                          : reinterpret_cast<char*>(uints.data() + c);
        const std::size_t size = type == Imf::HALF ? 2 : 4;
        fb.insert(names[c], Imf::Slice(type, base, 4 * size, 4 * size * width));
    }
    if (tiled) {
        Imf::TiledOutputFile out(path.c_str(), header);
        out.setFrameBuffer(fb);
        out.writeTiles(0, out.numXTiles() - 1, 0, out.numYTiles() - 1);
    } else {
        Imf::OutputFile out(path.c_str(), header);
        out.setFrameBuffer(fb);
        out.writePixels(height);
    }
}

// Channels of mixed types and names, scan lines: R, B, a.Y half; G, Z float; A, id uint.
inline void write_mixed_exr(const std::string& path, Imf::Compression compression,
                            int width = 19, int height = 35) {
    struct Spec {
        const char* name;
        Imf::PixelType type;
    };
    const Spec specs[] = {{"R", Imf::HALF},  {"B", Imf::HALF},  {"a.Y", Imf::HALF},
                          {"G", Imf::FLOAT}, {"Z", Imf::FLOAT}, {"A", Imf::UINT},
                          {"id", Imf::UINT}};
    Imf::Header header(width, height);
    header.compression() = compression;
    const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    std::vector<std::vector<char>> planes;
    Imf::FrameBuffer fb;
    for (const Spec& spec : specs) {
        header.channels().insert(spec.name, Imf::Channel(spec.type));
        const std::size_t size = spec.type == Imf::HALF ? 2 : 4;
        planes.emplace_back(n * size);
        for (std::size_t i = 0; i < n; ++i) {
            const float v = 0.3f + 0.001f * static_cast<float>(i % 97);
            char* at = planes.back().data() + i * size;
            if (spec.type == Imf::HALF) {
                const half h(v);
                std::memcpy(at, &h, 2);
            } else if (spec.type == Imf::FLOAT) {
                std::memcpy(at, &v, 4);
            } else {
                const auto u = static_cast<std::uint32_t>(i % 13);
                std::memcpy(at, &u, 4);
            }
        }
        fb.insert(spec.name, Imf::Slice(spec.type, planes.back().data(), size, size * width));
    }
    Imf::OutputFile out(path.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(height);
}

inline std::vector<char> read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void write_bytes(const std::string& path, const std::vector<char>& bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// The offset of the byte after the header's attributes (the terminating zero), and of
// the "channels" attribute's value, in a single-part file.
struct HeaderLayout {
    std::size_t channels_value = 0;
    std::size_t end = 0;
};

inline HeaderLayout header_layout(const std::vector<char>& b) {
    HeaderLayout layout;
    std::size_t i = 8;  // magic and version
    while (i < b.size() && b[i] != 0) {
        const std::string name(&b[i]);
        i += name.size() + 1;
        const std::string type(&b[i]);
        i += type.size() + 1;
        std::int32_t size = 0;
        std::memcpy(&size, &b[i], 4);
        i += 4;
        if (name == "channels") layout.channels_value = i;
        i += static_cast<std::size_t>(size);
    }
    layout.end = i + 1;
    return layout;
}

// Declares every channel of type `from` as `to` in the file's header; the pixel data
// stay as written.
inline void declare_channels_as(const std::string& path, Imf::PixelType from,
                                Imf::PixelType to) {
    std::vector<char> b = read_bytes(path);
    std::size_t j = header_layout(b).channels_value;
    if (j == 0) throw std::runtime_error(path + ": no channels attribute");
    while (b[j] != 0) {
        j += std::strlen(&b[j]) + 1;
        std::int32_t type = 0;
        std::memcpy(&type, &b[j], 4);
        if (type == static_cast<std::int32_t>(from)) {
            const auto t = static_cast<std::int32_t>(to);
            std::memcpy(&b[j], &t, 4);
        }
        j += 16;  // type, pLinear and 3 reserved bytes, x and y sampling
    }
    write_bytes(path, b);
}

// Halves the size field of the file's first chunk: the chunk then holds half its bytes
// as far as a reader can tell, the rest reads as the gap before the next chunk.
inline void cut_first_chunk(const std::string& path, bool tiled) {
    std::vector<char> b = read_bytes(path);
    std::uint64_t offset = 0;
    std::memcpy(&offset, &b[header_layout(b).end], 8);
    const std::size_t size_field = static_cast<std::size_t>(offset) + (tiled ? 16 : 4);
    std::int32_t size = 0;
    std::memcpy(&size, &b[size_field], 4);
    size /= 2;
    std::memcpy(&b[size_field], &size, 4);
    write_bytes(path, b);
}

// A file of HALF data declared FLOAT (declared_float) or of FLOAT data declared HALF.
inline void write_lying_exr(const std::string& path, Imf::Compression compression,
                            bool declared_float, bool tiled, int width = 37, int height = 45) {
    write_smooth_exr(path, compression, declared_float ? Imf::HALF : Imf::FLOAT, tiled, width,
                     height);
    declare_channels_as(path, declared_float ? Imf::HALF : Imf::FLOAT,
                        declared_float ? Imf::FLOAT : Imf::HALF);
}

}  // namespace octray::testing
