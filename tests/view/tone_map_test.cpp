// What the page is sent of a linear picture (view/tone_map.h).

#include "view/tone_map.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "render/image/image_io.h"

namespace {

using octray::encode_png_rgb8;
using octray::Image;
using octray::Rgb;
using octray::set_rgb;
using octray::view::tone_map_srgb8;

TEST(ViewToneMap, ScalesByTwoToTheExposureThenEncodesSrgb) {
    Image image(4, 1, {"R", "G", "B"});
    set_rgb(image, 0, 0, Rgb{0.0f, 0.25f, 0.5f});
    set_rgb(image, 1, 0, Rgb{1.0f, 2.0f, -1.0f});
    set_rgb(image, 2, 0, Rgb{std::numeric_limits<float>::quiet_NaN(), 0.001f, 0.2f});
    set_rgb(image, 3, 0, Rgb{std::numeric_limits<float>::infinity(), 0.0f, 0.0f});
    const std::vector<std::uint8_t> plain = tone_map_srgb8(image, 0.0f);
    // sRGB(0.25) = 137, sRGB(0.5) = 188; clamped above 1 and below 0; NaN is black;
    // 0.001 is on the linear segment: 12.92 * 0.001 * 255 = 3.29 -> 3.
    EXPECT_EQ(plain,
              (std::vector<std::uint8_t>{0, 137, 188, 255, 255, 0, 0, 3, 124, 255, 0, 0}));
    const std::vector<std::uint8_t> brighter = tone_map_srgb8(image, 1.0f);
    EXPECT_EQ(brighter[1], 188);  // 0.25 * 2
    EXPECT_EQ(brighter[2], 255);  // 0.5 * 2
    const std::vector<std::uint8_t> darker = tone_map_srgb8(image, -1.0f);
    EXPECT_EQ(darker[3], 188);  // 1 / 2
}

// Decodes `png` with libpng: width, height and the RGB bytes.
struct Decoded {
    png_uint_32 width = 0, height = 0;
    std::vector<std::uint8_t> rgb;
};

Decoded decode(const std::string& png) {
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    EXPECT_TRUE(png_image_begin_read_from_memory(&image, png.data(), png.size()));
    image.format = PNG_FORMAT_RGB;
    Decoded out;
    out.width = image.width;
    out.height = image.height;
    out.rgb.resize(PNG_IMAGE_SIZE(image));
    EXPECT_TRUE(png_image_finish_read(&image, nullptr, out.rgb.data(), 0, nullptr));
    return out;
}

TEST(ViewToneMap, ThePngHoldsExactlyTheBytes) {
    std::vector<std::uint8_t> rgb(3 * 5 * 3);
    for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<std::uint8_t>(i * 37);
    const Decoded decoded = decode(encode_png_rgb8(5, 3, rgb));
    EXPECT_EQ(decoded.width, 5u);
    EXPECT_EQ(decoded.height, 3u);
    EXPECT_EQ(decoded.rgb, rgb);
}

TEST(ViewToneMap, APngOfTheWrongSizeIsRefused) {
    EXPECT_THROW(encode_png_rgb8(5, 3, std::vector<std::uint8_t>(10)), std::runtime_error);
    EXPECT_THROW(encode_png_rgb8(0, 3, {}), std::runtime_error);
}

}  // namespace
