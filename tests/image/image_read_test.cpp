#include "render/image/image_read.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "render/image/image_io.h"
#include "tests/image/compare_fixtures.h"

namespace octray {
namespace {

using testing::make_image;
using testing::write_test_exr;
using testing::write_test_png;

class ImageReadTest : public testing::ScratchDirTest {};

// A different value in every channel of every pixel, exact in half precision.
Image numbered_image(int w, int h, std::vector<std::string> names) {
    Image image = make_image(w, h, std::move(names));
    for (int c = 0; c < image.channel_count(); ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) image.at(c, x, y) = c * 100.0f + y * 10.0f + x + 0.5f;
    return image;
}

// The message of the IoError read_image throws, or a test failure.
std::string read_error(const std::string& path) {
    try {
        read_image(path);
    } catch (const IoError& e) {
        return e.what();
    }
    ADD_FAILURE() << "read_image(" << path << ") did not throw";
    return "";
}

TEST_F(ImageReadTest, ExrFloatRoundTripsEveryValueAndOrdersRgbaFirst) {
    const Image written = numbered_image(5, 3, {"A", "B", "G", "R", "Z"});
    write_test_exr(path("f.exr"), written, Imf::FLOAT);
    const Image read = read_image(path("f.exr"));
    ASSERT_EQ(read.width(), 5);
    ASSERT_EQ(read.height(), 3);
    EXPECT_EQ(read.channel_names(), (std::vector<std::string>{"R", "G", "B", "A", "Z"}));
    EXPECT_EQ(read.file_format, "OpenEXR float");
    for (const std::string& name : read.channel_names())
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 5; ++x)
                EXPECT_EQ(read.at(read.channel_index(name), x, y),
                          written.at(written.channel_index(name), x, y))
                    << name << " at " << x << "," << y;
}

TEST_F(ImageReadTest, ExrHalfAndUintChannelsReadAsFloat) {
    const Image written = numbered_image(4, 2, {"R", "G", "B"});
    write_test_exr(path("h.exr"), written, Imf::HALF);
    const Image half_image = read_image(path("h.exr"));
    EXPECT_EQ(half_image.file_format, "OpenEXR half");
    EXPECT_EQ(half_image.at(2, 3, 1), 213.5f);  // exact in half

    Image ids = make_image(3, 1, {"id"});
    ids.at(0, 0, 0) = 7.0f;
    ids.at(0, 2, 0) = 65536.0f;
    write_test_exr(path("u.exr"), ids, Imf::UINT);
    const Image uint_image = read_image(path("u.exr"));
    EXPECT_EQ(uint_image.file_format, "OpenEXR uint");
    EXPECT_EQ(uint_image.at(0, 0, 0), 7.0f);
    EXPECT_EQ(uint_image.at(0, 2, 0), 65536.0f);
}

TEST_F(ImageReadTest, ExrLayersSortRgbaFirstWithinEachLayer) {
    write_test_exr(path("l.exr"),
                   make_image(2, 2, {"diffuse.B", "diffuse.R", "depth.Z", "G", "R", "B"}));
    EXPECT_EQ(read_image(path("l.exr")).channel_names(),
              (std::vector<std::string>{"R", "G", "B", "depth.Z", "diffuse.R", "diffuse.B"}));
}

TEST_F(ImageReadTest, ExrDataWindowOffsetIsHonored) {
    Image written = numbered_image(3, 2, {"Y"});
    written.data_window = PixelRect{10, -4, 10 + written.width(), -4 + written.height()};
    write_test_exr(path("dw.exr"), written);
    const Image read = read_image(path("dw.exr"));
    EXPECT_EQ(read.data_window.x0, 10);
    EXPECT_EQ(read.data_window.y0, -4);
    ASSERT_EQ(read.width(), 3);
    ASSERT_EQ(read.height(), 2);
    EXPECT_EQ(read.at(0, 0, 0), 0.5f);
    EXPECT_EQ(read.at(0, 2, 1), 12.5f);
}

TEST_F(ImageReadTest, ExrNanAndInfSurviveReading) {
    Image written = make_image(2, 1, {"R"});
    written.at(0, 0, 0) = std::numeric_limits<float>::quiet_NaN();
    written.at(0, 1, 0) = -std::numeric_limits<float>::infinity();
    write_test_exr(path("nan.exr"), written);
    const Image read = read_image(path("nan.exr"));
    EXPECT_TRUE(std::isnan(read.at(0, 0, 0)));
    EXPECT_EQ(read.at(0, 1, 0), -std::numeric_limits<float>::infinity());
}

TEST_F(ImageReadTest, Png8BitRgbIsRawValuesOver255) {
    // Not linearized: 128 reads as 128/255, not as sRGB-decoded 0.2158.
    write_test_png(path("rgb.png"), 2, 1, 3, 8, {0, 128, 255, 1, 2, 3});
    const Image read = read_image(path("rgb.png"));
    EXPECT_EQ(read.channel_names(), (std::vector<std::string>{"R", "G", "B"}));
    EXPECT_EQ(read.file_format, "PNG 8-bit");
    EXPECT_EQ(read.at(0, 0, 0), 0.0f);
    EXPECT_EQ(read.at(1, 0, 0), 128.0f / 255.0f);
    EXPECT_EQ(read.at(2, 0, 0), 1.0f);
    EXPECT_EQ(read.at(2, 1, 0), 3.0f / 255.0f);
}

TEST_F(ImageReadTest, Png16BitRgbaKeepsFullPrecisionAndUnpremultipliedAlpha) {
    write_test_png(path("rgba16.png"), 1, 2, 4, 16,
                   {65535, 257, 1, 0, /* row 1 */ 40000, 30000, 20000, 32768});
    const Image read = read_image(path("rgba16.png"));
    EXPECT_EQ(read.channel_names(), (std::vector<std::string>{"R", "G", "B", "A"}));
    EXPECT_EQ(read.file_format, "PNG 16-bit");
    EXPECT_EQ(read.at(0, 0, 0), 1.0f);
    EXPECT_EQ(read.at(1, 0, 0), 257.0f / 65535.0f);
    EXPECT_EQ(read.at(2, 0, 0), 1.0f / 65535.0f);
    EXPECT_EQ(read.at(3, 0, 0), 0.0f);  // colour of a transparent pixel kept as stored
    EXPECT_EQ(read.at(0, 0, 1), 40000.0f / 65535.0f);
    EXPECT_EQ(read.at(3, 0, 1), 32768.0f / 65535.0f);
}

TEST_F(ImageReadTest, PngGrayAndGrayAlphaAreYAndYA) {
    write_test_png(path("y.png"), 2, 2, 1, 8, {0, 51, 102, 255});
    const Image y = read_image(path("y.png"));
    EXPECT_EQ(y.channel_names(), (std::vector<std::string>{"Y"}));
    EXPECT_EQ(y.at(0, 1, 0), 51.0f / 255.0f);
    EXPECT_EQ(y.at(0, 0, 1), 102.0f / 255.0f);

    write_test_png(path("ya.png"), 1, 1, 2, 16, {1000, 2000});
    const Image ya = read_image(path("ya.png"));
    EXPECT_EQ(ya.channel_names(), (std::vector<std::string>{"Y", "A"}));
    EXPECT_EQ(ya.at(1, 0, 0), 2000.0f / 65535.0f);
}

TEST_F(ImageReadTest, FormatComesFromMagicBytesNotExtension) {
    write_test_png(path("actually_png.exr"), 1, 1, 1, 8, {255});
    EXPECT_EQ(read_image(path("actually_png.exr")).file_format, "PNG 8-bit");
    write_test_exr(path("actually_exr.png"), make_image(1, 1, {"R"}, 2.0f));
    EXPECT_EQ(read_image(path("actually_exr.png")).at(0, 0, 0), 2.0f);
}

// Issue 38: OpenEXR's InputFile reads part 0 of a multi-part file as the whole file, so a
// compare or an assemble silently used one part of two. Refused, naming the part count.
TEST_F(ImageReadTest, MultiPartExrIsRefusedNamingItsParts) {
    std::vector<Imf::Header> headers;
    for (const char* name : {"left", "right"}) {
        Imf::Header header(2, 2);
        header.setName(name);
        header.setType(Imf::SCANLINEIMAGE);
        header.channels().insert("R", Imf::Channel(Imf::FLOAT));
        headers.push_back(header);
    }
    const std::string file = path("two-parts.exr");
    {
        Imf::MultiPartOutputFile out(file.c_str(), headers.data(), 2);
        std::vector<float> pixels(4, 0.25f);
        for (int part = 0; part < 2; ++part) {
            Imf::OutputPart writer(out, part);
            Imf::FrameBuffer frame;
            frame.insert("R", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(pixels.data()),
                                         sizeof(float), 2 * sizeof(float)));
            writer.setFrameBuffer(frame);
            writer.writePixels(2);
        }
    }
    const std::string message = read_error(file);
    EXPECT_NE(message.find("multi-part OpenEXR file (2 parts)"), std::string::npos) << message;
    EXPECT_NE(message.find("two-parts.exr"), std::string::npos) << message;
}

TEST_F(ImageReadTest, MissingFileSaysSo) {
    const std::string message = read_error(path("nope.exr"));
    EXPECT_NE(message.find("nope.exr"), std::string::npos) << message;
    EXPECT_NE(message.find("no such file"), std::string::npos) << message;
}

TEST_F(ImageReadTest, DirectoryEmptyAndTextFilesAreNotImages) {
    EXPECT_NE(read_error(dir_.string()).find("is a directory"), std::string::npos);
    testing::write_text_file(path("empty.exr"), "");
    EXPECT_NE(read_error(path("empty.exr")).find("empty file"), std::string::npos);
    testing::write_text_file(path("notes.png"), "this is not a picture\n");
    const std::string message = read_error(path("notes.png"));
    EXPECT_NE(message.find("not an image"), std::string::npos) << message;
    EXPECT_NE(message.find("notes.png"), std::string::npos) << message;
}

TEST_F(ImageReadTest, TruncatedExrIsAClearIoError) {
    // Uncompressed, so that cutting the file in half cuts off pixel data for certain.
    write_test_exr(path("t.exr"), numbered_image(64, 64, {"R", "G", "B"}), Imf::FLOAT,
                   Imf::NO_COMPRESSION);
    testing::truncate_file(path("t.exr"), testing::fs::file_size(path("t.exr")) / 2);
    const std::string message = read_error(path("t.exr"));
    EXPECT_NE(message.find("t.exr"), std::string::npos) << message;
    EXPECT_NE(message.find("truncated"), std::string::npos) << message;
}

TEST_F(ImageReadTest, ExrCutInsideItsHeaderIsAClearIoError) {
    write_test_exr(path("h.exr"), numbered_image(8, 8, {"R"}));
    testing::truncate_file(path("h.exr"), 20);
    const std::string message = read_error(path("h.exr"));
    EXPECT_NE(message.find("truncated"), std::string::npos) << message;
}

// Rewrites the dataWindow attribute of an EXR written by write_test_exr in place, so that
// a file of a few hundred bytes claims a width x height image.
void claim_data_window(const std::string& path, int width, int height) {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    const std::string name("dataWindow\0box2i\0", 17);
    const std::size_t at = bytes.find(name);
    ASSERT_NE(at, std::string::npos);
    const std::int32_t window[4] = {0, 0, width - 1, height - 1};  // little-endian host
    f.seekp(static_cast<std::streamoff>(at + name.size() + 4));    // after the size field
    f.write(reinterpret_cast<const char*>(window), sizeof window);
}

// Fuzzer finding (tests/fuzz/README.md, Findings): a header that claims a huge data window
// must be refused before the planes are allocated, not after OpenEXR finds the pixel data
// missing. The rows stay 4, so the line offset table is whole and OpenEXR opens the file;
// without the check each of these allocates 48 million floats (192 MB) first.
TEST_F(ImageReadTest, ExrClaimingMorePixelDataThanTheFileHoldsIsRefusedUpFront) {
    for (const Imf::Compression compression : {Imf::NO_COMPRESSION, Imf::ZIP_COMPRESSION}) {
        SCOPED_TRACE(static_cast<int>(compression));
        write_test_exr(path("big.exr"), numbered_image(4, 4, {"R", "G", "B"}), Imf::HALF,
                       compression);
        claim_data_window(path("big.exr"), 4'000'000, 4);
        const std::string message = read_error(path("big.exr"));
        if (std::getenv("OCTRAY_KEEP_BIG_EXR"))
            testing::fs::copy_file(path("big.exr"), std::getenv("OCTRAY_KEEP_BIG_EXR"),
                                   testing::fs::copy_options::overwrite_existing);
        EXPECT_NE(message.find("big.exr"), std::string::npos) << message;
        EXPECT_NE(message.find("truncated or corrupt OpenEXR file"), std::string::npos)
            << message;
        EXPECT_NE(message.find("claims a 4000000 x 4 data window"), std::string::npos)
            << message;
    }
}

// The file the fuzzer kept (tests/fuzz/findings/): an IoError, not a long allocation.
TEST_F(ImageReadTest, FuzzFindingSlowExrLargeDataWindowIsAClearIoError) {
    const std::string finding =
        std::string(OCTRAY_SOURCE_DIR) + "/tests/fuzz/findings/slow-exr-large-data-window.exr";
    const std::string message = read_error(finding);
    EXPECT_NE(message.find("slow-exr-large-data-window.exr"), std::string::npos) << message;
    EXPECT_NE(message.find("truncated or corrupt OpenEXR file"), std::string::npos) << message;
}

// The bound is a lower bound on the file size: a large image that is really there loads.
TEST_F(ImageReadTest, LargeUncompressedExrStillLoads) {
    Image image = make_image(1024, 512, {"R", "G", "B", "A"});
    image.at(3, 1023, 511) = 0.25f;
    write_test_exr(path("large.exr"), image, Imf::FLOAT, Imf::NO_COMPRESSION);
    const Image read = read_image(path("large.exr"));
    EXPECT_EQ(read.width(), 1024);
    EXPECT_EQ(read.at(read.channel_index("A"), 1023, 511), 0.25f);
}

TEST_F(ImageReadTest, TruncatedPngIsAClearIoError) {
    std::vector<std::uint16_t> samples(32 * 32 * 3);
    for (std::size_t i = 0; i < samples.size(); ++i)
        samples[i] = static_cast<std::uint16_t>(i * 7919 % 256);
    write_test_png(path("t.png"), 32, 32, 3, 8, samples);
    testing::truncate_file(path("t.png"), testing::fs::file_size(path("t.png")) / 2);
    const std::string message = read_error(path("t.png"));
    EXPECT_NE(message.find("t.png"), std::string::npos) << message;
    EXPECT_NE(message.find("truncated PNG"), std::string::npos) << message;
}

TEST_F(ImageReadTest, PngWithBrokenDataIsAnIoErrorNotACrash) {
    write_test_png(path("c.png"), 16, 16, 3, 8, std::vector<std::uint16_t>(16 * 16 * 3, 77));
    {
        // Flip bytes in the middle of the file (inside IDAT): a CRC or zlib error.
        std::fstream f(path("c.png"), std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(60);
        f.write("\xde\xad\xbe\xef\xde\xad\xbe\xef", 8);
    }
    const std::string message = read_error(path("c.png"));
    EXPECT_NE(message.find("corrupt PNG"), std::string::npos) << message;
}

// What `octray render` reads of an existing image to resume: its int and string header
// attributes, by name and type, without decoding its pixels.
TEST_F(ImageReadTest, ExrAttributesAreReadByNameAndType) {
    ExrAttributes written;
    written.ints = {{"octray.samplesSoFar", 3}};
    written.strings = {{"octray.claimOwner", "host:1234"}};
    written.floats = {{"octray.samples", 2.5f}};
    Image image(4, 2, {"R", "G", "B"});
    set_rgb(image, 3, 1, Rgb(1.0f, 0.5f, 0.25f));
    write_exr(path("a.exr"), image, ExrWriteOptions{}, written);

    const ExrAttributes read = read_exr_attributes(path("a.exr"));
    ASSERT_NE(read.find_int("octray.samplesSoFar"), nullptr);
    EXPECT_EQ(*read.find_int("octray.samplesSoFar"), 3);
    ASSERT_NE(read.find_string("octray.claimOwner"), nullptr);
    EXPECT_EQ(*read.find_string("octray.claimOwner"), "host:1234");
    // By type: a float attribute is not an int, an int is not a string.
    EXPECT_EQ(read.find_int("octray.samples"), nullptr);
    EXPECT_EQ(read.find_string("octray.samplesSoFar"), nullptr);
    EXPECT_EQ(read.find_int("octray.missing"), nullptr);
    // The structural attributes are the writer's, not carried.
    EXPECT_EQ(read.find_string("compression"), nullptr);
    // The float is there too, with OpenEXR's defaults (pixelAspectRatio, ...).
    const auto samples =
        std::find_if(read.floats.begin(), read.floats.end(),
                     [](const auto& f) { return f.first == "octray.samples"; });
    ASSERT_NE(samples, read.floats.end());
    EXPECT_EQ(samples->second, 2.5f);
}

TEST_F(ImageReadTest, ExrAttributesOfAMissingOrNonExrFileAreAClearIoError) {
    try {
        read_exr_attributes(path("missing.exr"));
        ADD_FAILURE() << "no IoError";
    } catch (const IoError& e) {
        EXPECT_NE(std::string(e.what()).find("missing.exr"), std::string::npos) << e.what();
    }
    write_test_png(path("p.png"), 2, 2, 3, 8, std::vector<std::uint16_t>(2 * 2 * 3, 9));
    try {
        read_exr_attributes(path("p.png"));
        ADD_FAILURE() << "no IoError";
    } catch (const IoError& e) {
        EXPECT_NE(std::string(e.what()).find("p.png"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace octray
