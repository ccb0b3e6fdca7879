// Writes the seed corpus of fuzz_image_read (tests/fuzz/corpus/fuzz_image_read/): tiny
// OpenEXR and PNG files covering the layouts render/image/image_read.h accepts. Written with
// OpenEXR and libpng directly, so the seeds do not depend on the reader under test.
// Also files that lie (tests/image/lying_exr.h): HALF data declared FLOAT for every codec,
// FLOAT declared HALF, tiled ones, and chunks cut short.
// Usage: octray_make_image_seeds DIR

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfTiledOutputFile.h>
#include <half.h>
#include <png.h>

#include <cstdio>
#include <string>
#include <vector>

#include "../image/lying_exr.h"

namespace {

void exr_rgb_half(const std::string& path) {
    Imf::Header header(2, 2);
    header.compression() = Imf::NO_COMPRESSION;
    for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::HALF));
    std::vector<half> px(2 * 2 * 3);
    for (std::size_t i = 0; i < px.size(); ++i) px[i] = half(0.25f * float(i));
    Imf::FrameBuffer fb;
    const char* names[] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c)
        fb.insert(names[c], Imf::Slice(Imf::HALF, reinterpret_cast<char*>(px.data() + c),
                                       3 * sizeof(half), 6 * sizeof(half)));
    Imf::OutputFile out(path.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(2);
}

// FLOAT RGBA, ZIP, data window off the origin; plus UINT and a layered HALF channel.
void exr_mixed(const std::string& path) {
    const Imath::Box2i display(Imath::V2i(0, 0), Imath::V2i(7, 7));
    const Imath::Box2i data(Imath::V2i(2, 3), Imath::V2i(4, 4));  // 3 x 2
    Imf::Header header(display, data);
    header.compression() = Imf::ZIP_COMPRESSION;
    header.channels().insert("R", Imf::Channel(Imf::FLOAT));
    header.channels().insert("A", Imf::Channel(Imf::FLOAT));
    header.channels().insert("id", Imf::Channel(Imf::UINT));
    header.channels().insert("diffuse.G", Imf::Channel(Imf::HALF));
    std::vector<float> r(6, 0.5f), a(6, 1.0f);
    std::vector<unsigned> id = {1, 2, 3, 4, 5, 6};
    std::vector<half> g(6, half(0.125f));
    const auto origin = [&](auto* p, std::size_t elem) {
        return reinterpret_cast<char*>(p) - (data.min.x + data.min.y * 3) * elem;
    };
    Imf::FrameBuffer fb;
    fb.insert("R", Imf::Slice(Imf::FLOAT, origin(r.data(), 4), 4, 12));
    fb.insert("A", Imf::Slice(Imf::FLOAT, origin(a.data(), 4), 4, 12));
    fb.insert("id", Imf::Slice(Imf::UINT, origin(id.data(), 4), 4, 12));
    fb.insert("diffuse.G", Imf::Slice(Imf::HALF, origin(g.data(), 2), 2, 6));
    Imf::OutputFile out(path.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(2);
}

void exr_tiled(const std::string& path) {
    Imf::Header header(4, 4);
    header.compression() = Imf::RLE_COMPRESSION;
    header.setTileDescription(Imf::TileDescription(2, 2, Imf::ONE_LEVEL));
    header.channels().insert("Y", Imf::Channel(Imf::HALF));
    std::vector<half> y(16, half(0.75f));
    Imf::FrameBuffer fb;
    fb.insert("Y", Imf::Slice(Imf::HALF, reinterpret_cast<char*>(y.data()), 2, 8));
    Imf::TiledOutputFile out(path.c_str(), header);
    out.setFrameBuffer(fb);
    out.writeTiles(0, out.numXTiles() - 1, 0, out.numYTiles() - 1);
}

void png(const std::string& path, int width, int height, int color_type, int bit_depth,
         bool interlaced = false) {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    png_structp p = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png_create_info_struct(p);
    png_init_io(p, f);
    png_set_IHDR(p, info, width, height, bit_depth, color_type,
                 interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    if (color_type == PNG_COLOR_TYPE_PALETTE) {
        png_color palette[3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}};
        png_set_PLTE(p, info, palette, 3);
        png_byte alpha[2] = {0, 128};
        png_set_tRNS(p, info, alpha, 2, nullptr);
    }
    png_write_info(p, info);
    const int channels = png_get_channels(p, info);
    const std::size_t row_bytes = (std::size_t(width) * channels * bit_depth + 7) / 8;
    std::vector<png_byte> row(row_bytes);
    for (int y = 0; y < height; ++y) {
        for (std::size_t i = 0; i < row_bytes; ++i)
            row[i] = static_cast<png_byte>(color_type == PNG_COLOR_TYPE_PALETTE ? (i + y) % 3
                                                                                : 37 * (i + y));
        if (interlaced) continue;
        png_write_row(p, row.data());
    }
    if (interlaced) {
        std::vector<png_bytep> rows(height, row.data());
        png_write_image(p, rows.data());
    }
    png_write_end(p, info);
    png_destroy_write_struct(&p, &info);
    std::fclose(f);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s DIR\n", argv[0]);
        return 2;
    }
    const std::string dir = argv[1];
    exr_rgb_half(dir + "/rgb_half.exr");
    exr_mixed(dir + "/mixed_window.exr");
    exr_tiled(dir + "/tiled_rle.exr");
    using namespace octray::testing;
    for (const ExrCodec& codec : all_exr_codecs()) {
        const std::string name = codec.name;
        write_lying_exr(dir + "/lie_half_as_float_" + name + ".exr", codec.compression, true,
                        false, 9, 7);
        write_lying_exr(dir + "/lie_float_as_half_" + name + ".exr", codec.compression, false,
                        false, 9, 7);
    }
    for (const Imf::Compression c : {Imf::ZIP_COMPRESSION, Imf::PIZ_COMPRESSION,
                                     Imf::B44A_COMPRESSION, Imf::DWAA_COMPRESSION}) {
        const std::string name = all_exr_codecs()[static_cast<std::size_t>(c)].name;
        write_lying_exr(dir + "/lie_tiled_" + name + ".exr", c, true, true, 9, 7);
        write_smooth_exr(dir + "/cut_" + name + ".exr", c, Imf::HALF, false, 9, 7);
        cut_first_chunk(dir + "/cut_" + name + ".exr", false);
    }
    png(dir + "/gray1.png", 5, 3, PNG_COLOR_TYPE_GRAY, 1);
    png(dir + "/gray16.png", 2, 2, PNG_COLOR_TYPE_GRAY, 16);
    png(dir + "/gray_alpha8.png", 2, 2, PNG_COLOR_TYPE_GRAY_ALPHA, 8);
    png(dir + "/rgb8.png", 3, 2, PNG_COLOR_TYPE_RGB, 8);
    png(dir + "/rgba16.png", 1, 1, PNG_COLOR_TYPE_RGBA, 16);
    png(dir + "/palette_trns.png", 2, 2, PNG_COLOR_TYPE_PALETTE, 8);
    png(dir + "/rgb8_interlaced.png", 5, 5, PNG_COLOR_TYPE_RGB, 8, true);
    return 0;
}
