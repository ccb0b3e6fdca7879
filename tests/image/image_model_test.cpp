// The image model (render/image/image.h): channels in their own formats, windows, lookups,
// conversion to float32, and the model reading, writing and comparing itself — an image
// of half channels compares as the floats it holds; 8-bit channels make PNGs, never EXRs.

#include <gtest/gtest.h>
#include <half.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "render/image/error_heatmap.h"
#include "render/image/image.h"
#include "render/image/image_compare.h"
#include "render/image/image_io.h"
#include "render/image/image_read.h"
#include "tests/image/compare_fixtures.h"

namespace octray {
namespace {

using ImageModelTest = testing::ScratchDirTest;

TEST(ImageModel, FloatChannelsOfANewImageAreZeroAndFoundByName) {
    Image image(3, 2, {"R", "G", "Z"});
    EXPECT_EQ(image.width(), 3);
    EXPECT_EQ(image.height(), 2);
    EXPECT_EQ(image.data_window, (PixelRect{0, 0, 3, 2}));
    EXPECT_EQ(image.display_window, image.data_window);
    EXPECT_EQ(image.channel_count(), 3);
    EXPECT_EQ(image.channel_names(), (std::vector<std::string>{"R", "G", "Z"}));
    EXPECT_EQ(image.channel_index("Z"), 2);
    EXPECT_EQ(image.channel_index("B"), -1);
    ASSERT_NE(image.find_channel("G"), nullptr);
    EXPECT_EQ(image.find_channel("G")->format, PixelFormat::float32);
    EXPECT_EQ(image.find_channel("B"), nullptr);
    EXPECT_TRUE(image.all_float32());
    for (int c = 0; c < 3; ++c)
        for (std::size_t k = 0; k < image.pixel_count(); ++k)
            EXPECT_EQ(image.plane(c)[k], 0.0f);
    image.at(2, 1, 1) = 7.5f;  // channel Z, column 1, row 1: sample 1 * 3 + 1
    EXPECT_EQ(image.channels[2].value(4), 7.5f);
}

TEST(ImageModel, EachFormatHoldsItsSamples) {
    const float values[4] = {0.1f, -2.0f, 65504.0f, std::numeric_limits<float>::infinity()};
    const ImageChannel h = make_channel("h", PixelFormat::half, values, 4);
    const ImageChannel f = make_channel("f", PixelFormat::float32, values, 4);
    const ImageChannel u = make_channel("u", std::vector<std::uint32_t>{0, 1, 4000000000u});
    const ImageChannel b = make_channel("b", std::vector<std::uint8_t>{0, 128, 255});
    EXPECT_EQ(h.samples.size(), 4u * 2);
    EXPECT_EQ(f.samples.size(), 4u * 4);
    EXPECT_EQ(u.size(), 3u);
    EXPECT_EQ(b.size(), 3u);
    for (std::size_t k = 0; k < 4; ++k) {
        EXPECT_EQ(h.value(k), static_cast<float>(half(values[k]))) << k;
        EXPECT_EQ(f.value(k), values[k]) << k;
    }
    EXPECT_EQ(u.uint_value(2), 4000000000u);
    EXPECT_EQ(b.value(1), 128.0f);
    EXPECT_EQ(sample_size(PixelFormat::uint8), 1u);
    EXPECT_EQ(to_string(PixelFormat::uint8), "uint8");
    EXPECT_EQ(to_string(PixelFormat::half), "half");
    // Integers cannot be made from floats.
    EXPECT_THROW(make_channel("x", PixelFormat::uint32, values, 4), std::invalid_argument);
    EXPECT_THROW(make_channel("x", PixelFormat::uint8, values, 4), std::invalid_argument);
}

TEST(ImageModel, ToFloat32KeepsWindowsMetadataAndValues) {
    Image image;
    image.display_window = PixelRect{0, 0, 8, 8};
    image.data_window = PixelRect{2, 3, 4, 4};
    image.attributes.ints.emplace_back("octray:frame", 3);
    const float values[2] = {0.333f, 1.0f};
    image.channels.push_back(make_channel("R", PixelFormat::half, values, 2));
    image.channels.push_back(make_channel("id", std::vector<std::uint32_t>{5, 9}));
    EXPECT_FALSE(image.all_float32());
    const Image f = to_float32(image);
    EXPECT_TRUE(f.all_float32());
    EXPECT_EQ(f.data_window, image.data_window);
    EXPECT_EQ(f.display_window, image.display_window);
    EXPECT_EQ(*f.attributes.find_int("octray:frame"), 3);
    EXPECT_EQ(f.at(0, 0, 0), static_cast<float>(half(0.333f)));
    EXPECT_EQ(f.at(1, 1, 0), 9.0f);
}

TEST(ImageModel, ChannelsAreEqualByNameFormatAndBits) {
    const float zero = 0.0f, negative_zero = -0.0f;
    EXPECT_EQ(make_channel("R", PixelFormat::float32, &zero, 1),
              make_channel("R", PixelFormat::float32, &zero, 1));
    EXPECT_NE(make_channel("R", PixelFormat::float32, &zero, 1),
              make_channel("R", PixelFormat::float32, &negative_zero, 1));
    EXPECT_NE(make_channel("R", PixelFormat::float32, &zero, 1),
              make_channel("G", PixelFormat::float32, &zero, 1));
    EXPECT_NE(make_channel("R", PixelFormat::float32, &zero, 1),
              make_channel("R", PixelFormat::half, &zero, 1));
}

// A half image against its float twin: the same figures as comparing the floats it holds.
TEST(ImageModel, HalfChannelsCompareAsTheirFloats) {
    Image floats(4, 4, {"R", "G"});
    for (int c = 0; c < 2; ++c)
        for (std::size_t k = 0; k < floats.pixel_count(); ++k)
            floats.plane(c)[k] = static_cast<float>(half(0.1f * static_cast<float>(k + c)));
    Image halves = floats;
    for (ImageChannel& c : halves.channels)
        c = make_channel(c.name, PixelFormat::half, c.floats(), c.size());
    Image shifted = floats;
    shifted.at(1, 2, 3) += 0.25f;
    const CompareResult same = compare_images(floats, halves);
    EXPECT_EQ(same.verdict, Verdict::pass) << same.reason;
    EXPECT_EQ(same.overall.max_abs_error, 0.0);
    const CompareResult a = compare_images(halves, shifted),
                        b = compare_images(floats, shifted);
    EXPECT_EQ(a.overall.max_abs_error, b.overall.max_abs_error);
    EXPECT_EQ(a.overall.worst.x, 2);
    EXPECT_EQ(a.overall.worst.y, 3);
    const Image diff = difference_image(halves, shifted, a);
    EXPECT_EQ(diff.at(1, 2, 3), 0.25f);
    EXPECT_EQ(diff.at(0, 2, 3), 0.0f);
}

TEST_F(ImageModelTest, AnImageWritesAndReadsItselfWithItsWindows) {
    Image image(2, 2, {"R", "G", "B"});
    image.display_window = PixelRect{0, 0, 10, 6};
    image.data_window = PixelRect{5, 1, 7, 3};
    for (int c = 0; c < 3; ++c)
        for (std::size_t k = 0; k < 4; ++k)
            image.plane(c)[k] = 0.25f * static_cast<float>(c + k);
    write_exr(path("w.exr"), image);
    const Image back = read_image(path("w.exr"));
    EXPECT_EQ(back.data_window, image.data_window);
    EXPECT_EQ(back.display_window, image.display_window);
    EXPECT_EQ(back.file_format, "OpenEXR float");
    EXPECT_TRUE(back.channels == image.channels);
    const Image stored = read_exr_image(path("w.exr"));
    EXPECT_EQ(stored.file_format, "OpenEXR float");
    EXPECT_EQ(stored.compression, ExrCompression::zip);
}

TEST_F(ImageModelTest, EightBitChannelsMakePngsAndNeverExrs) {
    Image rgb;
    rgb.display_window = rgb.data_window = PixelRect{0, 0, 2, 1};
    rgb.channels.push_back(make_channel("R", std::vector<std::uint8_t>{255, 0}));
    rgb.channels.push_back(make_channel("G", std::vector<std::uint8_t>{0, 51}));
    rgb.channels.push_back(make_channel("B", std::vector<std::uint8_t>{0, 102}));
    write_png(path("p.png"), rgb);
    const Image back = read_image(path("p.png"));
    EXPECT_EQ(back.file_format, "PNG 8-bit");
    EXPECT_EQ(back.at(0, 0, 0), 1.0f);
    EXPECT_EQ(back.at(1, 1, 0), 51.0f / 255.0f);
    EXPECT_EQ(back.at(2, 1, 0), 102.0f / 255.0f);
    EXPECT_EQ(encode_png(rgb).substr(1, 3), "PNG");
    try {
        write_exr(path("p.exr"), rgb);
        ADD_FAILURE() << "an 8-bit channel was written to an EXR";
    } catch (const IoError& e) {
        EXPECT_NE(std::string(e.what()).find("8-bit"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(std::filesystem::exists(path("p.exr")));
    Image floats(2, 1, {"R", "G", "B"});
    EXPECT_THROW(write_png(path("f.png"), floats), IoError);
    EXPECT_FALSE(std::filesystem::exists(path("f.png")));
}

// ---- A render's image --------------------------------------------------------------------

TEST(RenderImage, PlanesAreRowsFromTheTopInTheDataWindow) {
    const PixelRect crop{2, 1, 5, 3}, full{0, 0, 8, 6};
    Image image = make_rgb_image(crop, full);
    ASSERT_TRUE(is_rgb_image(image));
    EXPECT_EQ(image.data_window, crop);
    EXPECT_EQ(image.display_window, full);
    EXPECT_EQ(image.channel_names(), (std::vector<std::string>{"R", "G", "B"}));
    EXPECT_EQ(image.width(), 3);
    EXPECT_EQ(image.height(), 2);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 3; ++x) set_rgb(image, x, y, Rgb(0.0f));
    set_rgb(image, 0, 0, Rgb(1.0f, 2.0f, 3.0f));  // the crop's top-left
    set_rgb(image, 2, 1, Rgb(4.0f, 5.0f, 6.0f));  // bottom-right
    EXPECT_EQ(image.plane(0)[0], 1.0f);
    EXPECT_EQ(image.plane(2)[0], 3.0f);
    EXPECT_EQ(image.plane(1)[5], 5.0f);  // (2, 1): row 1 of 3 pixels, column 2
    EXPECT_EQ(rgb_at(image, 2, 1), Rgb(4.0f, 5.0f, 6.0f));
    EXPECT_EQ(rgb_at(image, std::size_t{5}), Rgb(4.0f, 5.0f, 6.0f));
    EXPECT_EQ(rgb_pixels(image).size(), 6u);
    EXPECT_EQ(rgb_pixels(image)[0], Rgb(1.0f, 2.0f, 3.0f));
}

// A batch renders each frame into the last one's storage (RenderOptions::spare_image).
TEST(RenderImage, SpareStorageIsTakenOnlyWhenThePixelCountsAgreeAndFreedElse) {
    Image spare = make_rgb_image(PixelRect{0, 0, 6, 4}, PixelRect{0, 0, 6, 4});
    const unsigned char* storage[3] = {spare.channels[0].samples.data(),
                                       spare.channels[1].samples.data(),
                                       spare.channels[2].samples.data()};
    const PixelRect other_shape{0, 0, 8, 3};  // 24 pixels either way
    EXPECT_TRUE(fits_rgb_storage(spare, other_shape));
    const Image taken = make_rgb_image(other_shape, other_shape, std::move(spare));
    for (int c = 0; c < 3; ++c)
        EXPECT_EQ(taken.channels[static_cast<std::size_t>(c)].samples.data(), storage[c]);
    EXPECT_EQ(taken.width(), 8);
    EXPECT_EQ(taken.height(), 3);

    Image small = make_rgb_image(PixelRect{0, 0, 5, 5}, PixelRect{0, 0, 5, 5});
    EXPECT_FALSE(fits_rgb_storage(small, other_shape));
    const Image fresh = make_rgb_image(other_shape, other_shape, std::move(small));
    EXPECT_TRUE(is_rgb_image(fresh));
    EXPECT_EQ(fresh.channels[0].samples.size(), 24 * sizeof(float));
}

TEST(RenderImage, OnlyFloatRgbInOrderIsARendersImage) {
    EXPECT_TRUE(is_rgb_image(Image(2, 2, {"R", "G", "B"})));
    EXPECT_FALSE(is_rgb_image(Image(2, 2, {"R", "G"})));
    EXPECT_FALSE(is_rgb_image(Image(2, 2, {"B", "G", "R"})));
    Image half = Image(2, 2, {"R", "G", "B"});
    half.channels[1] = make_channel("G", PixelFormat::half, half.plane(0), 4);
    EXPECT_FALSE(is_rgb_image(half));
    Image short_plane = Image(2, 2, {"R", "G", "B"});
    short_plane.channels[2].samples.resize(4);
    EXPECT_FALSE(is_rgb_image(short_plane));
}

TEST(RenderImage, SamePixelsComparesWindowsAndBitsNotMetadata) {
    Image a(3, 2, {"R", "G", "B"}), b(3, 2, {"R", "G", "B"});
    b.attributes.strings.emplace_back("software", "other");
    EXPECT_TRUE(same_pixels(a, b));
    set_rgb(b, 1, 1, Rgb(-0.0f, 0.0f, 0.0f));  // -0 is not +0 bit for bit
    EXPECT_FALSE(same_pixels(a, b));
    Image moved = a;
    moved.data_window = PixelRect{1, 0, 4, 2};
    EXPECT_FALSE(same_pixels(a, moved));
}

}  // namespace
}  // namespace octray
