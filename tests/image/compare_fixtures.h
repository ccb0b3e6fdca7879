#pragma once
// Test images for the compare suites, written with OpenEXR and libpng directly (never with
// the code under test), and a per-test scratch directory.

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <gtest/gtest.h>
#include <half.h>
#include <png.h>
#include <unistd.h>

#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "render/image/image_read.h"

namespace octray::testing {

namespace fs = std::filesystem;

// A fresh directory per test under the build tree; kept when the test fails.
class ScratchDirTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        std::string name = std::string(info->test_suite_name()) + "." + info->name();
        for (char& c : name)
            if (c == '/') c = '_';
        dir_ = fs::path(OCTRAY_TEST_TMPDIR) / "compare" /
               (name + "." + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        if (!HasFailure()) fs::remove_all(dir_);
    }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }

    fs::path dir_;
};

// A w x h image with the given channels, every value `fill`.
inline Image make_image(int w, int h, std::vector<std::string> names, float fill = 0.0f) {
    Image image(w, h, names);
    for (ImageChannel& c : image.channels) std::fill(c.floats(), c.floats() + c.size(), fill);
    return image;
}

// Writes every channel of `image` with pixel type `type` (values converted by OpenEXR),
// its data window where the image's is.
inline void write_test_exr(const std::string& path, const Image& image,
                           Imf::PixelType type = Imf::FLOAT,
                           Imf::Compression compression = Imf::ZIP_COMPRESSION) {
    const Imath::Box2i window(Imath::V2i(image.data_window.x0, image.data_window.y0),
                              Imath::V2i(image.data_window.x0 + image.width() - 1,
                                         image.data_window.y0 + image.height() - 1));
    Imf::Header header(window, window);
    header.compression() = compression;
    const std::size_t n = image.pixel_count();
    // Pixel data in the file's own type, so the writer does no conversion of its own.
    std::vector<std::vector<half>> halves;
    std::vector<std::vector<unsigned>> uints;
    Imf::FrameBuffer fb;
    for (int c = 0; c < image.channel_count(); ++c) {
        const std::string& name = image.channels[static_cast<std::size_t>(c)].name;
        header.channels().insert(name, Imf::Channel(type));
        const float* plane = image.plane(c);
        const char* base = nullptr;
        std::size_t size = 4;
        if (type == Imf::HALF) {
            halves.emplace_back(plane, plane + n);
            base = reinterpret_cast<const char*>(halves.back().data());
            size = sizeof(half);
        } else if (type == Imf::UINT) {
            uints.emplace_back();
            for (std::size_t i = 0; i < n; ++i)
                uints.back().push_back(static_cast<unsigned>(plane[i]));
            base = reinterpret_cast<const char*>(uints.back().data());
        } else {
            base = reinterpret_cast<const char*>(plane);
        }
        fb.insert(name, Imf::Slice::Make(type, base, window, size,
                                         size * static_cast<std::size_t>(image.width())));
    }
    // (The inner vectors' buffers survive the outer ones growing: a move keeps them.)
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(image.height());
}

namespace detail {
inline bool png_write_rows(png_structp png, png_infop info, std::FILE* f, int w, int h,
                           int color_type, int bit_depth, png_bytepp rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_init_io(png, f);
    png_set_IHDR(png, info, static_cast<png_uint_32>(w), static_cast<png_uint_32>(h), bit_depth,
                 color_type, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    png_write_image(png, rows);
    png_write_end(png, nullptr);
    return true;
}
}  // namespace detail

// Writes a PNG of `channels` (1 gray, 2 gray+alpha, 3 RGB, 4 RGBA) samples of `bit_depth`
// (8 or 16), interleaved, row 0 on top.
inline void write_test_png(const std::string& path, int w, int h, int channels, int bit_depth,
                           const std::vector<std::uint16_t>& samples) {
    static const int color_types[4] = {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA,
                                       PNG_COLOR_TYPE_RGB, PNG_COLOR_TYPE_RGB_ALPHA};
    const int bytes = bit_depth / 8;
    const std::size_t row_bytes = static_cast<std::size_t>(w) * channels * bytes;
    std::vector<png_byte> data(row_bytes * static_cast<std::size_t>(h));
    for (std::size_t i = 0; i < samples.size(); ++i) {
        if (bytes == 2) {
            data[2 * i] = static_cast<png_byte>(samples[i] >> 8);
            data[2 * i + 1] = static_cast<png_byte>(samples[i] & 0xff);
        } else {
            data[i] = static_cast<png_byte>(samples[i]);
        }
    }
    std::vector<png_bytep> rows(static_cast<std::size_t>(h));
    for (int y = 0; y < h; ++y) rows[static_cast<std::size_t>(y)] = data.data() + y * row_bytes;
    std::FILE* f = std::fopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png_create_info_struct(png);
    const bool ok = detail::png_write_rows(png, info, f, w, h, color_types[channels - 1],
                                           bit_depth, rows.data());
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
    ASSERT_TRUE(ok);
}

// Keeps the first `keep` bytes of a file.
inline void truncate_file(const std::string& path, std::uintmax_t keep) {
    fs::resize_file(path, keep);
}

inline void write_text_file(const std::string& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

}  // namespace octray::testing
