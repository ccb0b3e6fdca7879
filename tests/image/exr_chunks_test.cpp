// Files that lie: an EXR whose header declares other pixel types than its data hold, or
// whose chunk is cut, is a file error for every codec, scan lines and tiles; honest files
// of every codec and pixel type still read (render/image/exr_chunks.h).
#include "render/image/exr_chunks.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "render/image/image_read.h"
#include "tests/image/compare_fixtures.h"
#include "tests/image/lying_exr.h"

namespace octray {
namespace {

using testing::all_exr_codecs;

class ExrChunksTest : public testing::ScratchDirTest {};

template <typename Read>
std::string error_of(Read read) {
    try {
        read();
    } catch (const IoError& e) {
        return e.what();
    }
    return "";
}

TEST_F(ExrChunksTest, HalfDataDeclaredFloatIsAFileErrorForEveryCodec) {
    for (const bool tiled : {false, true}) {
        for (const auto& codec : all_exr_codecs()) {
            SCOPED_TRACE(std::string(codec.name) + (tiled ? " tiled" : " scan lines"));
            const std::string file = path(std::string("lie_") + codec.name + ".exr");
            testing::write_lying_exr(file, codec.compression, true, tiled);
            const std::string message = error_of([&] { read_image(file); });
            EXPECT_NE(message.find("cannot read '" + file + "'"), std::string::npos) << message;
            EXPECT_NE(message.find("corrupt OpenEXR file"), std::string::npos) << message;
            // An uncompressed file is found short by its size before its chunks are read.
            if (codec.compression != Imf::NO_COMPRESSION) {
                EXPECT_NE(message.find("(the header declares A, B, G, R float, "),
                          std::string::npos)
                    << message;
            }
            EXPECT_NE(error_of([&] { read_exr_image(file); }).find(file), std::string::npos);
        }
    }
}

TEST_F(ExrChunksTest, FloatDataDeclaredHalfIsAFileErrorForEveryCodec) {
    for (const bool tiled : {false, true}) {
        for (const auto& codec : all_exr_codecs()) {
            SCOPED_TRACE(std::string(codec.name) + (tiled ? " tiled" : " scan lines"));
            const std::string file = path(std::string("lie_") + codec.name + ".exr");
            testing::write_lying_exr(file, codec.compression, false, tiled);
            const std::string message = error_of([&] { read_image(file); });
            EXPECT_NE(message.find(file), std::string::npos) << message;
            EXPECT_NE(message.find("OpenEXR file"), std::string::npos) << message;
            EXPECT_NE(error_of([&] { read_exr_image(file); }).find(file), std::string::npos);
        }
    }
}

TEST_F(ExrChunksTest, ACutChunkIsAFileErrorForEveryCodec) {
    for (const bool tiled : {false, true}) {
        for (const auto& codec : all_exr_codecs()) {
            SCOPED_TRACE(std::string(codec.name) + (tiled ? " tiled" : " scan lines"));
            const std::string file = path(std::string("cut_") + codec.name + ".exr");
            testing::write_smooth_exr(file, codec.compression, Imf::HALF, tiled);
            testing::cut_first_chunk(file, tiled);
            const std::string message = error_of([&] { read_image(file); });
            EXPECT_NE(message.find(file), std::string::npos) << message;
        }
    }
}

// No false alarms: every codec, every pixel type, scan lines and tiles, odd sizes.
TEST_F(ExrChunksTest, HonestFilesOfEveryCodecAndTypeRead) {
    for (const bool tiled : {false, true}) {
        for (const auto& codec : all_exr_codecs()) {
            for (const Imf::PixelType type : {Imf::HALF, Imf::FLOAT, Imf::UINT}) {
                SCOPED_TRACE(std::string(codec.name) + (tiled ? " tiled " : " scan lines ") +
                             std::to_string(static_cast<int>(type)));
                const std::string file = path("honest.exr");
                testing::write_smooth_exr(file, codec.compression, type, tiled, 41, 70);
                const Image image = read_image(file);
                EXPECT_EQ(image.width(), 41);
                EXPECT_EQ(image.height(), 70);
                const float expected =
                    type == Imf::UINT ? 40.0f + 69.0f + 3.0f : 0.1f + 0.4f + 1.38f + 0.6f;
                const float got = image.at(image.channel_index("R"), 40, 69);
                // Lossy codecs (B44, DWA) keep values near.
                EXPECT_NEAR(got, expected, 0.05f * expected);
                EXPECT_NO_THROW(read_exr_image(file));
            }
        }
    }
}

// Channels of mixed types and names: DWA sorts them into lossy, RLE and zlib sections by
// name and type, B44 packs HALF and stores the others raw.
TEST_F(ExrChunksTest, HonestMixedChannelFilesRead) {
    for (const auto& codec : all_exr_codecs()) {
        SCOPED_TRACE(codec.name);
        testing::write_mixed_exr(path("mixed.exr"), codec.compression);
        const Image image = read_image(path("mixed.exr"));
        EXPECT_EQ(image.channel_count(), 7);
        EXPECT_EQ(image.at(image.channel_index("id"), 18, 34), static_cast<float>(664 % 13));
        EXPECT_NO_THROW(read_exr_image(path("mixed.exr")));
    }
}

// Black frames, constant ones and single pixels: runs, flat B44 blocks, one-symbol PIZ.
TEST_F(ExrChunksTest, ConstantAndTinyImagesRead) {
    for (const auto& codec : all_exr_codecs()) {
        for (const Imf::PixelType type : {Imf::HALF, Imf::FLOAT, Imf::UINT}) {
            for (const float value : {0.0f, 3.0f}) {
                for (const int size : {1, 3, 64}) {
                    SCOPED_TRACE(std::string(codec.name) + " type " +
                                 std::to_string(static_cast<int>(type)) + " value " +
                                 std::to_string(value) + " size " + std::to_string(size));
                    const Image image =
                        testing::make_image(size, size + 1, {"R", "G", "B", "A"}, value);
                    testing::write_test_exr(path("flat.exr"), image, type, codec.compression);
                    const Image read = read_image(path("flat.exr"));
                    EXPECT_NEAR(read.at(0, size - 1, size), value, 0.01f);  // B44, DWA: lossy
                }
            }
        }
    }
}

TEST(ExrChunkProblem, SizesAgainstTheHeader) {
    ExrChunkShape shape;
    shape.compression = ExrCompression::zip;
    shape.channels = {{"R", PixelFormat::float32}, {"Y", PixelFormat::half}};
    shape.width = 3;
    shape.height = 2;
    EXPECT_EQ(exr_unpacked_size(shape), 36u);
    const std::vector<unsigned char> raw(36, 7);
    EXPECT_EQ(exr_chunk_problem(shape, raw.data(), raw.size()), "");  // stored raw
    const std::vector<unsigned char> more(37, 7);
    EXPECT_NE(exr_chunk_problem(shape, more.data(), more.size()).find("even uncompressed"),
              std::string::npos);
    shape.compression = ExrCompression::none;
    EXPECT_NE(exr_chunk_problem(shape, raw.data(), 30).find("need 36 bytes"),
              std::string::npos);
    // RLE: 18 bytes repeated twice = 36 (count byte 17: 18 copies).
    shape.compression = ExrCompression::rle;
    const std::vector<unsigned char> rle{17, 1, 17, 2};
    EXPECT_EQ(exr_chunk_problem(shape, rle.data(), rle.size()), "");
    const std::vector<unsigned char> short_rle{17, 1, 16, 2};
    EXPECT_NE(exr_chunk_problem(shape, short_rle.data(), short_rle.size())
                  .find("unpack to 35 bytes, where the header's channels need 36"),
              std::string::npos);
    const std::vector<unsigned char> cut_rle{17, 1, static_cast<unsigned char>(-5), 2};
    EXPECT_NE(exr_chunk_problem(shape, cut_rle.data(), cut_rle.size()).find("past"),
              std::string::npos);
}

}  // namespace
}  // namespace octray
