#include "render/image/image_io.h"

#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <half.h>
#include <png.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "render/image/srgb_table.h"
#include "tests/image/inflated_file.h"

namespace octray {
namespace {

namespace fs = std::filesystem;

// Each test gets its own empty directory, so "nothing else was left behind" is a plain
// directory listing.
class ImageIoTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        std::string name = std::string(info->test_suite_name()) + "." + info->name();
        for (char& c : name)
            if (c == '/') c = '_';
        dir_ = fs::path(OCTRAY_TEST_TMPDIR) / "image_io" /
               (name + "." + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        if (!HasFailure()) fs::remove_all(dir_);
    }

    std::vector<std::string> entries() const {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(dir_))
            names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }

    fs::path dir_;
};

// A smooth HDR image (lossy codecs are built for such content) whose rows and columns are
// all distinguishable: red grows to the right, green downwards, blue goes above 1.
Image gradient_image(int width, int height, float scale = 1.0f) {
    Image image(width, height, {"R", "G", "B"});
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            set_rgb(image, x, y,
                    Rgb(scale * (0.05f + 0.9f * static_cast<float>(x) / width),
                        scale * (0.05f + 0.9f * static_cast<float>(y) / height),
                        scale * (1.0f + 3.0f * static_cast<float>(x + y) / (width + height))));
    return image;
}

struct ReadExr {
    Image image;  // float32 R, G, B planes
    Imf::Header header;
    std::vector<Imf::PixelType> channel_types;
};

ReadExr read_exr(const std::string& path) {
    Imf::InputFile file(path.c_str());
    ReadExr out{Image(), file.header(), {}};
    const Imath::Box2i window = file.header().dataWindow();
    const int width = window.max.x - window.min.x + 1;
    const int height = window.max.y - window.min.y + 1;
    out.image = Image(width, height, {"R", "G", "B"});
    for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it)
        out.channel_types.push_back(it.channel().type);

    // Address each plane so that data-window row min.y lands in image row 0.
    Imf::FrameBuffer fb;
    const std::size_t xs = sizeof(float), ys = sizeof(float) * static_cast<std::size_t>(width);
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
        char* base = reinterpret_cast<char*>(out.image.plane(c)) -
                     (static_cast<std::ptrdiff_t>(window.min.x) +
                      static_cast<std::ptrdiff_t>(window.min.y) * width) *
                         static_cast<std::ptrdiff_t>(sizeof(float));
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, base, xs, ys));
    }
    file.setFrameBuffer(fb);
    file.readPixels(window.min.y, window.max.y);
    return out;
}

float as_half(float v) { return static_cast<float>(half(v)); }

const std::vector<ExrCompression> kAllCompressions = {
    ExrCompression::none, ExrCompression::rle,   ExrCompression::zips, ExrCompression::zip,
    ExrCompression::piz,  ExrCompression::pxr24, ExrCompression::b44,  ExrCompression::b44a,
    ExrCompression::dwaa, ExrCompression::dwab};

// Which codecs lose information for which channel type: B44 is lossy for HALF and stores
// FLOAT uncompressed; PXR24 rounds FLOAT to 24 bits and keeps HALF exact; DWA quantises
// R, G and B in the DCT domain whatever their type.
bool is_lossy(ExrCompression c, bool float32) {
    switch (c) {
        case ExrCompression::pxr24:
            return float32;
        case ExrCompression::b44:
        case ExrCompression::b44a:
            return !float32;
        case ExrCompression::dwaa:
        case ExrCompression::dwab:
            return true;
        default:
            return false;
    }
}

TEST(ExrCompressionNames, RoundTripEveryName) {
    const std::vector<std::string> names = {"none",  "rle", "zips", "zip",  "piz",
                                            "pxr24", "b44", "b44a", "dwaa", "dwab"};
    ASSERT_EQ(names.size(), kAllCompressions.size());
    for (std::size_t i = 0; i < names.size(); ++i) {
        const auto parsed = parse_exr_compression(names[i]);
        ASSERT_TRUE(parsed.has_value()) << names[i];
        EXPECT_EQ(*parsed, kAllCompressions[i]) << names[i];
        EXPECT_EQ(to_string(*parsed), names[i]);
    }
    EXPECT_FALSE(parse_exr_compression("").has_value());
    EXPECT_FALSE(parse_exr_compression("ZIP").has_value());
    EXPECT_FALSE(parse_exr_compression("zip ").has_value());
    EXPECT_FALSE(parse_exr_compression("jpeg").has_value());
}

// A frame loop converts each frame into the last one's channels (make_exr_image's spare):
// the same storage, and values as from fresh storage, half or float, larger or smaller.
TEST(ExrChannels, SpareStorageIsTakenAndFullyOverwritten) {
    const Image first = gradient_image(9, 5), second = gradient_image(9, 5, 0.5f);
    for (const bool float32 : {false, true}) {
        SCOPED_TRACE(float32 ? "float" : "half");
        const ExrWriteOptions options{float32, ExrCompression::zip};
        Image a = make_exr_image(first, options);
        std::vector<const unsigned char*> storage;
        for (const ImageChannel& c : a.channels) storage.push_back(c.samples.data());
        const Image fresh = make_exr_image(second, options);
        const Image reused = make_exr_image(second, options, {}, std::move(a.channels));
        ASSERT_EQ(reused.channels.size(), 3u);
        for (std::size_t k = 0; k < 3; ++k) {
            EXPECT_EQ(reused.channels[k].samples.data(), storage[k]);
            EXPECT_EQ(reused.channels[k].name, fresh.channels[k].name);
            EXPECT_EQ(reused.channels[k].samples, fresh.channels[k].samples);
        }
    }
    // Spare channels of another size are not kept: the values are still the image's.
    const Image small = make_exr_image(gradient_image(2, 2), {});
    const Image big = make_exr_image(second, {}, {}, std::vector<ImageChannel>(small.channels));
    EXPECT_EQ(big.channels[0].samples, make_exr_image(second, {}).channels[0].samples);
}

// A render written as it is (write_exr(path, render, options): its chunks packed from the
// float32 planes, lines converted to half as they are packed) is the file make_exr_image's
// image makes, byte for byte: every compression, half and float, a data window off the
// origin (a crop), odd sizes (partial chunks and partial registers of halves), a -0.
TEST_F(ImageIoTest, ARenderWrittenAsItIsIsTheFileOfItsExrImage) {
    Image render = gradient_image(71, 53, 3.0f);
    render.display_window = PixelRect{0, 0, 90, 80};
    render.data_window = PixelRect{11, 17, 82, 70};
    render.channels[1].floats()[5] = -0.0f;  // a sign bit that rounding must keep
    ExrAttributes attributes;
    attributes.strings.emplace_back("octray.test", "a render");
    attributes.doubles.emplace_back("renderTimeSeconds", 0.25);
    for (const bool float32 : {false, true}) {
        for (const ExrCompression c : kAllCompressions) {
            SCOPED_TRACE(std::string(to_string(c)) + (float32 ? " float" : " half"));
            const ExrWriteOptions options{float32, c};
            write_exr((dir_ / "direct.exr").string(), render, options, attributes);
            write_exr((dir_ / "made.exr").string(),
                      make_exr_image(render, options, attributes));
            EXPECT_GT(fs::file_size(dir_ / "direct.exr"), 100u);
            // Byte for byte but for the compressed data, which must inflate to the same
            // bytes (tests/image/inflated_file.h says why).
            EXPECT_EQ(test::exr_inflated(dir_ / "direct.exr"),
                      test::exr_inflated(dir_ / "made.exr"));
        }
    }
}

TEST_F(ImageIoTest, ExrRoundTripsEveryCompressionHalfAndFloat) {
    const Image image = gradient_image(37, 21);  // odd sizes: partial codec blocks
    for (const bool float32 : {false, true}) {
        for (const ExrCompression c : kAllCompressions) {
            SCOPED_TRACE(std::string(to_string(c)) + (float32 ? " float" : " half"));
            const std::string path = (dir_ / "round_trip.exr").string();
            write_exr(path, image, {float32, c});
            const ReadExr read = read_exr(path);

            // ExrCompression lists the codecs in Imf::Compression's order.
            EXPECT_EQ(static_cast<int>(read.header.compression()), static_cast<int>(c));
            ASSERT_EQ(read.image.width(), image.width());
            ASSERT_EQ(read.image.height(), image.height());
            ASSERT_EQ(read.channel_types.size(), 3u);
            for (Imf::PixelType t : read.channel_types)
                EXPECT_EQ(t, float32 ? Imf::FLOAT : Imf::HALF);

            const bool lossy = is_lossy(c, float32);
            double max_relative_error = 0.0;
            for (int y = 0; y < image.height(); ++y) {
                for (int x = 0; x < image.width(); ++x) {
                    const Rgb in = rgb_at(image, x, y), out = rgb_at(read.image, x, y);
                    const float expected[3] = {in.r, in.g, in.b};
                    const float got[3] = {out.r, out.g, out.b};
                    for (int k = 0; k < 3; ++k) {
                        const float e = float32 ? expected[k] : as_half(expected[k]);
                        if (!lossy) {
                            ASSERT_EQ(got[k], e) << "pixel " << x << "," << y;
                        } else {
                            max_relative_error = std::max(
                                max_relative_error,
                                static_cast<double>(std::fabs(got[k] - e) / std::fabs(e)));
                        }
                    }
                }
            }
            // Lossy codecs still have to give back the picture, not noise.
            EXPECT_LT(max_relative_error, 0.05);
        }
    }
}

TEST_F(ImageIoTest, ExrCompressionIsTheOneAskedFor) {
    const Image image = gradient_image(8, 8);
    const std::string path = (dir_ / "c.exr").string();
    write_exr(path, image, {false, ExrCompression::piz});
    EXPECT_EQ(read_exr(path).header.compression(), Imf::PIZ_COMPRESSION);
    write_exr(path, image, {false, ExrCompression::none});
    EXPECT_EQ(read_exr(path).header.compression(), Imf::NO_COMPRESSION);
    write_exr(path, image, {});  // the default
    EXPECT_EQ(read_exr(path).header.compression(), Imf::ZIP_COMPRESSION);
}

TEST_F(ImageIoTest, ExrCarriesEveryAttribute) {
    ExrAttributes attributes;
    attributes.strings = {{"software", "octray test"}, {"octray.scene", "random:8"}};
    attributes.floats = {{"renderTimeSeconds", 1.25f}};
    attributes.ints = {{"samplesPerPixel", 16}};
    attributes.doubles = {{"octray.rays.primary", 12345678901234.0}};
    const std::string path = (dir_ / "attr.exr").string();
    write_exr(path, gradient_image(4, 3), {}, attributes);

    const Imf::Header header = read_exr(path).header;
    const auto* software = header.findTypedAttribute<Imf::StringAttribute>("software");
    ASSERT_NE(software, nullptr);
    EXPECT_EQ(software->value(), "octray test");
    const auto* scene = header.findTypedAttribute<Imf::StringAttribute>("octray.scene");
    ASSERT_NE(scene, nullptr);
    EXPECT_EQ(scene->value(), "random:8");
    const auto* time = header.findTypedAttribute<Imf::FloatAttribute>("renderTimeSeconds");
    ASSERT_NE(time, nullptr);
    EXPECT_EQ(time->value(), 1.25f);
    const auto* spp = header.findTypedAttribute<Imf::IntAttribute>("samplesPerPixel");
    ASSERT_NE(spp, nullptr);
    EXPECT_EQ(spp->value(), 16);
    const auto* rays = header.findTypedAttribute<Imf::DoubleAttribute>("octray.rays.primary");
    ASSERT_NE(rays, nullptr);
    EXPECT_EQ(rays->value(), 12345678901234.0);
}

TEST_F(ImageIoTest, ExrRowZeroIsTheTopRow) {
    // Only row 0 is bright; a flipped writer would put it at the bottom of the file.
    Image image(5, 4, {"R", "G", "B"});
    for (int x = 0; x < 5; ++x) set_rgb(image, x, 0, Rgb(1.0f, 0.5f, 0.25f));
    set_rgb(image, 4, 3, Rgb(0.0f, 0.0f, 2.0f));  // bottom-right marker
    const std::string path = (dir_ / "rows.exr").string();
    write_exr(path, image, {true, ExrCompression::none});

    Imf::InputFile file(path.c_str());
    const Imath::Box2i window = file.header().dataWindow();
    EXPECT_EQ(window.min.x, 0);
    EXPECT_EQ(window.min.y, 0);
    EXPECT_EQ(window.max.x, 4);
    EXPECT_EQ(window.max.y, 3);
    EXPECT_EQ(file.header().lineOrder(), Imf::INCREASING_Y);

    // Read scan line min.y alone: it must be image row 0.
    std::vector<float> line(5);
    Imf::FrameBuffer fb;
    fb.insert("R",
              Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(line.data()), sizeof(float), 0));
    file.setFrameBuffer(fb);
    file.readPixels(window.min.y);
    for (float v : line) EXPECT_EQ(v, 1.0f);
    file.readPixels(window.max.y);
    for (float v : line) EXPECT_EQ(v, 0.0f);

    const ReadExr read = read_exr(path);
    EXPECT_TRUE(same_pixels(read.image, image));
}

TEST_F(ImageIoTest, NonFinitePixelsSurviveInExr) {
    // The EXR is the HDR product: infinities and NaNs are stored, not clamped.
    Image image(3, 1, {"R", "G", "B"});
    set_rgb(image, 0, 0, Rgb(std::numeric_limits<float>::infinity(), 0.0f, 0.0f));
    set_rgb(image, 1, 0, Rgb(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f));
    set_rgb(image, 2, 0, Rgb(1.0e6f, 0.0f, 0.0f));  // above half's range
    const std::string path = (dir_ / "nonfinite.exr").string();
    write_exr(path, image, {true, ExrCompression::zip});
    const ReadExr read = read_exr(path);
    EXPECT_TRUE(std::isinf(rgb_at(read.image, 0, 0).r));
    EXPECT_TRUE(std::isnan(rgb_at(read.image, 1, 0).r));
    EXPECT_EQ(rgb_at(read.image, 2, 0).r, 1.0e6f);
}

TEST_F(ImageIoTest, WriteIntoMissingDirectoryThrowsAndLeavesNothing) {
    const fs::path missing = dir_ / "no" / "such" / "dir";
    const std::string exr = (missing / "out.exr").string();
    try {
        write_exr(exr, gradient_image(4, 4), {});
        FAIL() << "expected IoError";
    } catch (const IoError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(exr), std::string::npos) << message;
        EXPECT_NE(message.find("No such file or directory"), std::string::npos) << message;
    }
    EXPECT_THROW(write_png_preview((missing / "out.png").string(), gradient_image(4, 4)),
                 IoError);
    EXPECT_FALSE(fs::exists(dir_ / "no"));
    EXPECT_TRUE(entries().empty());
}

// A disk that fills up in the middle of a PNG: libpng's own writer said only "libpng:
// Write Error". The message must carry the OS reason. RLIMIT_FSIZE makes write() fail
// with EFBIG once a file reaches the limit, for this process only and without privileges
// (SIGXFSZ, whose default action would kill the process, is ignored meanwhile).
TEST_F(ImageIoTest, PngWriteFailureSaysTheOsReason) {
    // Noise does not compress: both PNGs are far over the limit and over stdio's buffer.
    Image noise(128, 128, {"R", "G", "B"});
    std::vector<std::uint8_t> bytes(3 * 128 * 128);
    std::uint32_t state = 12345;
    const auto next = [&] { return state = state * 1664525u + 1013904223u; };
    for (int y = 0; y < 128; ++y)
        for (int x = 0; x < 128; ++x)
            set_rgb(noise, x, y,
                    Rgb(static_cast<float>(next() >> 8) / 16777216.0f,
                        static_cast<float>(next() >> 8) / 16777216.0f,
                        static_cast<float>(next() >> 8) / 16777216.0f));
    for (std::uint8_t& b : bytes) b = static_cast<std::uint8_t>(next() >> 24);

    struct rlimit saved {};
    ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &saved), 0);
    const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
    struct rlimit small = saved;
    small.rlim_cur = 2048;
    ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
    std::string preview_error, heatmap_error;
    try {
        write_png_preview((dir_ / "preview.png").string(), noise);
    } catch (const IoError& e) {
        preview_error = e.what();
    }
    try {
        write_png_rgb8((dir_ / "heatmap.png").string(), 128, 128, bytes);
    } catch (const IoError& e) {
        heatmap_error = e.what();
    }
    ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &saved), 0);
    std::signal(SIGXFSZ, old_handler);

    const std::string reason = std::strerror(EFBIG);  // "File too large"
    EXPECT_NE(preview_error.find("preview.png"), std::string::npos) << preview_error;
    EXPECT_NE(preview_error.find(reason), std::string::npos) << preview_error;
    EXPECT_NE(heatmap_error.find("heatmap.png"), std::string::npos) << heatmap_error;
    EXPECT_NE(heatmap_error.find(reason), std::string::npos) << heatmap_error;
    EXPECT_TRUE(entries().empty()) << "a partial file or temporary was left";
}

TEST_F(ImageIoTest, NoTemporaryLeftAfterSuccess) {
    write_exr((dir_ / "a.exr").string(), gradient_image(6, 5), {});
    write_png_preview((dir_ / "a.png").string(), gradient_image(6, 5));
    // Overwriting an existing file also goes through a temporary.
    write_exr((dir_ / "a.exr").string(), gradient_image(6, 5), {true, ExrCompression::piz});
    EXPECT_EQ(entries(), (std::vector<std::string>{"a.exr", "a.png"}));
}

TEST_F(ImageIoTest, FailedWriteRemovesTemporaryAndKeepsOldFile) {
    const fs::path target = dir_ / "keep.txt";
    { std::ofstream(target) << "old"; }
    std::string seen_tmp;
    try {
        write_file_atomically(target.string(), [&](const std::string& tmp) {
            seen_tmp = tmp;
            std::ofstream(tmp) << "half-written";
            throw std::runtime_error("disk on fire");
        });
        FAIL() << "expected IoError";
    } catch (const IoError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(target.string()), std::string::npos) << message;
        EXPECT_NE(message.find("disk on fire"), std::string::npos) << message;
    }
    // The temporary sat next to the target, hidden, and is gone now.
    EXPECT_EQ(fs::path(seen_tmp).parent_path(), dir_);
    EXPECT_EQ(fs::path(seen_tmp).filename().string().rfind(".keep.txt.tmp.", 0), 0u)
        << seen_tmp;
    EXPECT_EQ(entries(), std::vector<std::string>{"keep.txt"});
    std::ifstream in(target);
    std::stringstream content;
    content << in.rdbuf();
    EXPECT_EQ(content.str(), "old");
}

// The temporaries of every target, in one directory or two, whose writers are gone; a
// live writer's (it holds the lock), another file's and the targets themselves stay.
TEST_F(ImageIoTest, StaleTemporariesOfEveryTargetAreRemoved) {
    fs::create_directory(dir_ / "previews");
    const auto touch = [](const fs::path& p) { std::ofstream(p) << "x"; };
    const std::vector<fs::path> stale = {dir_ / ".f.0.exr.tmp.1.00000000000000aa",
                                         dir_ / ".f.0.exr.tmp.2.00000000000000bb",
                                         dir_ / ".f.0.png.tmp.1.00000000000000ab",
                                         dir_ / "previews/.p.png.tmp.1.00000000000000cc"};
    const fs::path live = dir_ / ".f.0.exr.tmp.3.00000000000000dd";
    const std::vector<fs::path> kept = {dir_ / "f.0.exr",
                                        dir_ / ".f.1.exr.tmp.1.00000000000000ee",
                                        dir_ / ".f.0.exr.new.1.00000000000000ff",
                                        dir_ / "previews/.f.0.exr.tmp.1.0000000000000011"};
    for (const fs::path& p : stale) touch(p);
    for (const fs::path& p : kept) touch(p);
    touch(live);
    const int fd = ::open(live.c_str(), O_RDWR | O_CLOEXEC);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::flock(fd, LOCK_EX), 0);
    std::vector<std::string> removed =
        remove_stale_temporaries({(dir_ / "f.0.exr").string(), (dir_ / "f.0.png").string(),
                                  (dir_ / "previews/p.png").string()});
    ::close(fd);
    std::sort(removed.begin(), removed.end());
    std::vector<std::string> expected;
    for (const fs::path& p : stale) expected.push_back(p.string());
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(removed, expected);
    for (const fs::path& p : stale) EXPECT_FALSE(fs::exists(p)) << p;
    for (const fs::path& p : kept) EXPECT_TRUE(fs::exists(p)) << p;
    EXPECT_TRUE(fs::exists(live)) << "a live writer's temporary was removed";
}

TEST_F(ImageIoTest, AtomicWriteReplacesExistingFile) {
    const fs::path target = dir_ / "f.txt";
    { std::ofstream(target) << "old content that is longer"; }
    write_file_atomically(target.string(),
                          [](const std::string& tmp) { std::ofstream(tmp) << "new"; });
    std::ifstream in(target);
    std::stringstream content;
    content << in.rdbuf();
    EXPECT_EQ(content.str(), "new");
    EXPECT_EQ(entries(), std::vector<std::string>{"f.txt"});
}

TEST_F(ImageIoTest, TargetThatIsADirectoryFailsCleanly) {
    fs::create_directory(dir_ / "taken.exr");
    EXPECT_THROW(write_exr((dir_ / "taken.exr").string(), gradient_image(2, 2), {}), IoError);
    EXPECT_EQ(entries(), std::vector<std::string>{"taken.exr"});
    EXPECT_TRUE(fs::is_directory(dir_ / "taken.exr"));
}

TEST_F(ImageIoTest, EmptyImageIsRefused) {
    EXPECT_THROW(write_exr((dir_ / "e.exr").string(), Image(0, 0, {"R", "G", "B"}), {}),
                 IoError);
    EXPECT_THROW(write_png_preview((dir_ / "e.png").string(), Image(0, 3, {"R", "G", "B"})),
                 IoError);
    // Not a render's image: 8-bit channels, or R, G, B out of order.
    Image bytes(2, 2, {"R", "G", "B"});
    for (ImageChannel& c : bytes.channels)
        c = make_channel(c.name, std::vector<std::uint8_t>(4));
    EXPECT_THROW(write_exr((dir_ / "b.exr").string(), bytes, {}), IoError);
    EXPECT_THROW(write_png_preview((dir_ / "b.png").string(), bytes), IoError);
    EXPECT_THROW(write_png_preview((dir_ / "c.png").string(), Image(2, 2, {"B", "G", "R"})),
                 IoError);
    EXPECT_TRUE(entries().empty());
}

TEST_F(ImageIoTest, BadAttributeNameIsAnIoErrorAndLeavesNothing) {
    ExrAttributes attributes;
    attributes.strings = {{"", "an attribute needs a name"}};
    EXPECT_THROW(write_exr((dir_ / "bad.exr").string(), gradient_image(2, 2), {}, attributes),
                 IoError);
    EXPECT_TRUE(entries().empty());
}

struct PngPixels {
    int width = 0, height = 0;
    std::vector<unsigned char> rgb;
};

// Decoded by libpng itself (the simplified API), as any viewer would.
PngPixels read_png(const std::string& path) {
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    EXPECT_NE(png_image_begin_read_from_file(&image, path.c_str()), 0) << image.message;
    PngPixels out;
    out.width = static_cast<int>(image.width);
    out.height = static_cast<int>(image.height);
    EXPECT_EQ(image.format & PNG_FORMAT_FLAG_COLOR, PNG_FORMAT_FLAG_COLOR);
    EXPECT_EQ(image.format & PNG_FORMAT_FLAG_ALPHA, 0u);
    image.format = PNG_FORMAT_RGB;
    out.rgb.resize(PNG_IMAGE_SIZE(image));
    EXPECT_NE(png_image_finish_read(&image, nullptr, out.rgb.data(), 0, nullptr), 0)
        << image.message;
    png_image_free(&image);
    return out;
}

TEST_F(ImageIoTest, PngEncodesKnownValues) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    Image image(4, 2, {"R", "G", "B"});
    set_rgb(image, 0, 0, Rgb(0.0f, 1.0f, 0.5f));
    set_rgb(image, 1, 0, Rgb(2.0f, -1.0f, nan));
    set_rgb(image, 2, 0, Rgb(0.002f, 0.0031308f, 0.2f));
    set_rgb(image, 3, 0, Rgb(inf, -inf, 1.0001f));
    set_rgb(image, 0, 1, Rgb(0.25f, 0.75f, 0.1f));
    const std::string path = (dir_ / "known.png").string();
    write_png_preview(path, image);

    const PngPixels png = read_png(path);
    ASSERT_EQ(png.width, 4);
    ASSERT_EQ(png.height, 2);
    auto px = [&](int x, int y, int k) {
        return static_cast<int>(png.rgb[(y * 4 + x) * 3 + k]);
    };
    EXPECT_EQ(px(0, 0, 0), 0);    // 0 -> 0
    EXPECT_EQ(px(0, 0, 1), 255);  // 1 -> 255
    EXPECT_EQ(px(0, 0, 2), 188);  // 0.5 linear -> 0.7354 sRGB -> 187.5 -> 188
    EXPECT_EQ(px(1, 0, 0), 255);  // > 1 clamps
    EXPECT_EQ(px(1, 0, 1), 0);    // < 0 clamps
    EXPECT_EQ(px(1, 0, 2), 0);    // NaN -> 0
    EXPECT_EQ(px(2, 0, 0), 7);    // linear segment: 12.92 * 0.002 * 255 = 6.59
    EXPECT_EQ(px(2, 0, 1), 10);   // the knee: 12.92 * 0.0031308 * 255 = 10.31
    EXPECT_EQ(px(2, 0, 2), 124);  // 1.055 * 0.2^(1/2.4) - 0.055 = 0.4845 -> 123.5 -> 124
    EXPECT_EQ(px(3, 0, 0), 255);  // +inf clamps
    EXPECT_EQ(px(3, 0, 1), 0);    // -inf clamps
    EXPECT_EQ(px(3, 0, 2), 255);
    // Row 1 (the second row from the top) is where row 1 of the image went.
    EXPECT_EQ(px(0, 1, 0), 137);  // 0.25 -> 0.5371 -> 136.96
    EXPECT_EQ(px(0, 1, 1), 225);  // 0.75 -> 0.8808 -> 224.6
    EXPECT_EQ(px(0, 1, 2), 89);   // 0.1 -> 0.3492 -> 89.05
    EXPECT_EQ(px(1, 1, 0), 0);
}

TEST_F(ImageIoTest, PngOfLargerImageIsReadable) {
    const Image image = gradient_image(320, 200);
    const std::string path = (dir_ / "big.png").string();
    write_png_preview(path, image);
    const PngPixels png = read_png(path);
    ASSERT_EQ(png.width, 320);
    ASSERT_EQ(png.height, 200);
    // Red grows to the right and green downwards, as in the image; blue is clamped.
    auto px = [&](int x, int y, int k) {
        return static_cast<int>(png.rgb[(static_cast<std::size_t>(y) * 320 + x) * 3 + k]);
    };
    EXPECT_LT(px(0, 0, 0), px(319, 0, 0));
    EXPECT_LT(px(0, 0, 1), px(0, 199, 1));
    EXPECT_EQ(px(100, 100, 2), 255);
}

// What libpng's low-level reader finds in a PNG's colour chunks (it checks every chunk's
// CRC and fails on a wrong one).
struct ColourChunks {
    png_uint_32 srgb = 0, gama = 0, chrm = 0;  // the PNG_INFO_ bit when present
    int intent = -1;
    double gamma = 0.0;
    double white_x = 0, white_y = 0, red_x = 0, red_y = 0, green_x = 0, green_y = 0, blue_x = 0,
           blue_y = 0;
    int bit_depth = 0, color_type = 0;
};

// setjmp's function holds nothing with a destructor, so libpng's longjmp skips none.
bool read_colour_chunks(png_structp png, png_infop info, std::FILE* file, ColourChunks& out) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_init_io(png, file);
    png_read_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
    out.srgb = png_get_sRGB(png, info, &out.intent);
    out.gama = png_get_gAMA(png, info, &out.gamma);
    out.chrm = png_get_cHRM(png, info, &out.white_x, &out.white_y, &out.red_x, &out.red_y,
                            &out.green_x, &out.green_y, &out.blue_x, &out.blue_y);
    out.bit_depth = png_get_bit_depth(png, info);
    out.color_type = png_get_color_type(png, info);
    return true;
}

// The preview says sRGB with gAMA and cHRM beside it (for older viewers), the heatmap
// sRGB alone.
TEST_F(ImageIoTest, PngsCarryTheirSrgbChunks) {
    write_png_preview((dir_ / "preview.png").string(), gradient_image(9, 7));
    write_png_rgb8((dir_ / "heatmap.png").string(), 2, 1, {0, 64, 128, 255, 32, 16});
    for (const std::string name : {"preview.png", "heatmap.png"}) {
        SCOPED_TRACE(name);
        std::FILE* file = std::fopen((dir_ / name).c_str(), "rb");
        ASSERT_NE(file, nullptr);
        png_structp png =
            png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
        png_infop info = png_create_info_struct(png);
        ColourChunks chunks;
        const bool read = read_colour_chunks(png, info, file, chunks);
        png_destroy_read_struct(&png, &info, nullptr);
        std::fclose(file);
        ASSERT_TRUE(read);
        EXPECT_EQ(chunks.srgb, PNG_INFO_sRGB);
        EXPECT_EQ(chunks.intent, PNG_sRGB_INTENT_PERCEPTUAL);
        EXPECT_EQ(chunks.bit_depth, 8);
        EXPECT_EQ(chunks.color_type, PNG_COLOR_TYPE_RGB);
        if (name == "preview.png") {
            EXPECT_EQ(chunks.gama, PNG_INFO_gAMA);
            EXPECT_NEAR(chunks.gamma, 0.45455, 1e-6);
            EXPECT_EQ(chunks.chrm, PNG_INFO_cHRM);
            EXPECT_NEAR(chunks.white_x, 0.3127, 1e-6);
            EXPECT_NEAR(chunks.white_y, 0.3290, 1e-6);
            EXPECT_NEAR(chunks.red_y, 0.33, 1e-6);
            EXPECT_NEAR(chunks.green_x, 0.30, 1e-6);
            EXPECT_NEAR(chunks.blue_x, 0.15, 1e-6);
        }
    }
    // libpng derives gAMA and cHRM from sRGB when reading, so the chunks are listed.
    const auto chunk_types = [](const fs::path& path) {
        const std::string b = test::whole_file(path);
        std::vector<std::string> types;
        for (std::size_t at = 8; at + 12 <= b.size();) {
            const std::size_t length =
                (std::size_t{static_cast<unsigned char>(b[at])} << 24) |
                (std::size_t{static_cast<unsigned char>(b[at + 1])} << 16) |
                (std::size_t{static_cast<unsigned char>(b[at + 2])} << 8) |
                static_cast<unsigned char>(b[at + 3]);
            types.push_back(b.substr(at + 4, 4));
            at += 12 + length;
        }
        return types;
    };
    EXPECT_EQ(chunk_types(dir_ / "preview.png"),
              (std::vector<std::string>{"IHDR", "gAMA", "sRGB", "cHRM", "IDAT", "IEND"}));
    EXPECT_EQ(chunk_types(dir_ / "heatmap.png"),
              (std::vector<std::string>{"IHDR", "sRGB", "IDAT", "IEND"}));
}

// A picture whose pixels do not compress (noise: 3 MB of it, the compressed data as large
// as the pixels): every byte comes back.
TEST_F(ImageIoTest, PngOfIncompressiblePixelsReadsBack) {
    const int width = 1000, height = 1000;
    std::vector<std::uint8_t> bytes(3 * static_cast<std::size_t>(width) * height);
    std::uint32_t state = 777;
    for (std::uint8_t& b : bytes)
        b = static_cast<std::uint8_t>((state = state * 1664525u + 1013904223u) >> 24);
    const std::string path = (dir_ / "noise.png").string();
    write_png_rgb8(path, width, height, bytes);
    EXPECT_GT(fs::file_size(path), std::size_t{2} << 20);
    const PngPixels png = read_png(path);
    ASSERT_EQ(png.width, width);
    ASSERT_EQ(png.height, height);
    EXPECT_TRUE(png.rgb == bytes);
}

// A picture of flat areas, stripes and noise, tall enough for its rows to be compressed in
// many bands (render/image/png.cpp): libpng reads every byte back, and the flat areas
// compress.
TEST_F(ImageIoTest, PngOfManyBandsReadsBack) {
    const int width = 333, height = 777;
    std::vector<std::uint8_t> bytes(3 * static_cast<std::size_t>(width) * height);
    std::uint32_t state = 99;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int k = 0; k < 3; ++k) {
                const int area = (y / 40 + x / 100) % 3;
                const std::uint32_t noise = (state = state * 1664525u + 1013904223u) >> 24;
                bytes[(static_cast<std::size_t>(y) * width + x) * 3 + k] =
                    static_cast<std::uint8_t>(area == 0   ? 40 * k
                                              : area == 1 ? (x / 3 + y) % 256
                                                          : noise);
            }
    const std::string path = (dir_ / "bands.png").string();
    write_png_rgb8(path, width, height, bytes);
    EXPECT_LT(fs::file_size(path), bytes.size() / 2);
    const PngPixels png = read_png(path);
    ASSERT_EQ(png.width, width);
    ASSERT_EQ(png.height, height);
    EXPECT_TRUE(png.rgb == bytes);
}

// OpenEXR's pool of compression threads, as `octray render` sets it; what a file holds does
// not depend on it.
TEST_F(ImageIoTest, ExrThreadCountIsSetAndDoesNotChangeTheBytes) {
    const int before = exr_thread_count();
    const Image image = gradient_image(64, 48);
    set_exr_thread_count(0);
    EXPECT_EQ(exr_thread_count(), 0);
    write_exr((dir_ / "serial.exr").string(), image, ExrWriteOptions{});
    set_exr_thread_count(3);
    EXPECT_EQ(exr_thread_count(), 3);
    EXPECT_EQ(Imf::globalThreadCount(), 3);
    write_exr((dir_ / "threaded.exr").string(), image, ExrWriteOptions{});
    set_exr_thread_count(before);
    EXPECT_EQ(exr_thread_count(), before);
    // The same header and chunks, inflated (tests/image/inflated_file.h says why).
    EXPECT_EQ(test::exr_inflated(dir_ / "serial.exr"),
              test::exr_inflated(dir_ / "threaded.exr"));
}

// srgb8 looks the byte up in a table of the values where it steps up; it must give the
// formula's byte for every float. Every 61st float of [0, 1] (17 million), every float
// within 4 ulps of each step, and the values outside [0, 1].
TEST(Srgb8, TheTableGivesTheFormulasByteForEveryFloat) {
    const std::uint32_t one = std::bit_cast<std::uint32_t>(1.0f);
    std::size_t mismatches = 0;
    const auto check = [&](float x) {
        if (srgb8(x) != srgb8_by_formula(x) && ++mismatches <= 5)
            ADD_FAILURE() << "x = " << x << " (bits " << std::bit_cast<std::uint32_t>(x)
                          << "): table " << int(srgb8(x)) << ", formula "
                          << int(srgb8_by_formula(x));
    };
    for (std::uint32_t bits = 0; bits <= one; bits += 61) check(std::bit_cast<float>(bits));
    std::uint8_t last = 0;
    for (std::uint32_t bits = 0; bits <= one; bits += 4096) {  // the steps, coarsely
        const std::uint8_t v = srgb8_by_formula(std::bit_cast<float>(bits));
        if (v != last)
            for (std::uint32_t b = bits > 4100 ? bits - 4100 : 0; b <= bits + 4; ++b)
                check(std::bit_cast<float>(b));
        last = v;
    }
    for (const float x :
         {-0.0f, -1e-30f, -1.0f, 1.0f, 1.0000001f, 2.0f, 1e30f,
          std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::infinity(),
          -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()})
        check(x);
    EXPECT_EQ(mismatches, 0u);
    EXPECT_EQ(srgb8(1.0f), 255);
    EXPECT_EQ(srgb8(std::numeric_limits<float>::quiet_NaN()), 0);
}

// srgb8_interleaved (three planes into one row of bytes, as the preview and the viewer's
// pictures make them) gives srgb8's byte of each sample times the scale: every 997th float's
// bits (NaNs, infinities, negatives and denormals included) and every float within 4 ulps of a
// step, in planes of several lengths (around the AVX2 build's blocks of 8 and its 10-pixel
// tail), from both builds.
TEST(Srgb8, InterleavedPlanesGiveSrgb8sBytes) {
    std::vector<float> values;
    for (std::uint64_t bits = 0; bits <= 0xFFFFFFFFu; bits += 997)
        values.push_back(std::bit_cast<float>(static_cast<std::uint32_t>(bits)));
    std::uint8_t last = 0;
    for (std::uint32_t bits = 0; bits <= std::bit_cast<std::uint32_t>(1.0f); bits += 4096) {
        const std::uint8_t v = srgb8(std::bit_cast<float>(bits));
        if (v != last)
            for (std::uint32_t s = bits > 4100 ? bits - 4100 : 0; s <= bits + 4; ++s)
                values.push_back(std::bit_cast<float>(s));
        last = v;
    }
    // The product's choice, and each build (the AVX2 one where the CPU has it).
    using Build =
        void (*)(const float*, const float*, const float*, std::size_t, float, std::uint8_t*);
    std::vector<std::pair<std::string, Build>> builds = {
        {"srgb8_interleaved", srgb8_interleaved}, {"scalar", detail::srgb8_interleaved_scalar}};
    if (detail::srgb8_use_avx2())
        builds.emplace_back("avx2", detail::srgb8_interleaved_avx2);
    else
        std::cout << "[  SKIPPED ] the AVX2 build: this CPU has no AVX2\n";
    for (const auto& [name, build] : builds)
        for (const float scale : {1.0f, 0.5f, 4.0f}) {
            for (std::size_t count :
                 {values.size() / 3, std::size_t{7}, std::size_t{8}, std::size_t{9},
                  std::size_t{10}, std::size_t{13}, std::size_t{18}, std::size_t{19}}) {
                SCOPED_TRACE(name + ", " + std::to_string(count) + " pixels");
                const float* r = values.data() + 1;  // not 32-byte aligned
                const float* g = values.data() + values.size() / 3;
                const float* b = values.data() + 2 * (values.size() / 3);
                std::vector<std::uint8_t> out(3 * count + 1, 77);
                build(r, g, b, count, scale, out.data());
                std::size_t mismatches = 0;
                for (std::size_t i = 0; i < count; ++i)
                    for (const auto& [plane, k] :
                         {std::pair{r, 0}, std::pair{g, 1}, std::pair{b, 2}})
                        if (out[3 * i + k] != srgb8(plane[i] * scale) && ++mismatches <= 5)
                            ADD_FAILURE() << "scale " << scale << ", sample " << i
                                          << " of plane " << k << ": " << plane[i];
                EXPECT_EQ(mismatches, 0u);
                EXPECT_EQ(out[3 * count], 77) << "nothing written past the last pixel";
            }
        }
}

}  // namespace
}  // namespace octray
