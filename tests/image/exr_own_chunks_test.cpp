// write_exr packs and compresses the chunks of uncompressed, ZIPS and ZIP files itself
// (render/image/exr_write.cpp); these tests hold those files to OpenEXR: its reader gets
// every sample back, bit for bit, and an uncompressed file is OpenEXR's own byte for byte.

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfVersion.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "render/image/image_io.h"
#include "tests/image/inflated_file.h"

namespace octray {
namespace {

namespace fs = std::filesystem;

fs::path test_dir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    const fs::path dir = fs::path(OCTRAY_TEST_TMPDIR) / "exr_own_chunks" /
                         (std::string(info->name()) + "." + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

// A pseudo-random sample stream (a fixed LCG): noise does not compress.
struct Noise {
    std::uint32_t state = 12345;
    std::uint32_t next() { return state = state * 1664525u + 1013904223u; }
};

// Channels of every type, with names whose file order (by bytes) differs from the order
// given, one longer than 31 characters (the version field's long-names flag), smooth or
// noisy samples.
Image test_image(PixelRect display, PixelRect data, ExrCompression compression, bool noisy) {
    Image image;
    image.display_window = display;
    image.data_window = data;
    image.compression = compression;
    image.attributes.strings.emplace_back("octray.test", "own chunks");
    image.attributes.ints.emplace_back("octray.answer", 42);
    const std::size_t n = data.pixel_count();
    Noise noise;
    std::vector<float> values(n);
    const auto fill = [&](float scale) {
        for (std::size_t k = 0; k < n; ++k)
            values[k] = noisy ? static_cast<float>(noise.next() >> 8) / 16777216.0f * scale
                              : scale * static_cast<float>(k % 97) / 97.0f;
    };
    fill(1.0f);
    image.channels.push_back(make_channel("R", PixelFormat::half, values.data(), n));
    fill(3.0f);
    image.channels.push_back(make_channel("B", PixelFormat::float32, values.data(), n));
    fill(1e4f);
    image.channels.push_back(make_channel("depth.Z", PixelFormat::float32, values.data(), n));
    std::vector<std::uint32_t> ids(n);
    for (std::size_t k = 0; k < n; ++k)
        ids[k] = noisy ? noise.next() : static_cast<std::uint32_t>(k / 7);
    image.channels.push_back(make_channel("id", ids));
    fill(0.5f);
    image.channels.push_back(make_channel("a.channel.name.longer.than.thirty.one.characters",
                                          PixelFormat::half, values.data(), n));
    fill(2.0f);
    image.channels.push_back(make_channel("A", PixelFormat::half, values.data(), n));
    return image;
}

// Every channel's samples as OpenEXR's reader returns them, in the channel's own type.
std::map<std::string, std::vector<unsigned char>> read_samples(const fs::path& path,
                                                               const Image& expected) {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i window = file.header().dataWindow();
    EXPECT_EQ(window.min.x, expected.data_window.x0);
    EXPECT_EQ(window.min.y, expected.data_window.y0);
    EXPECT_EQ(window.max.x, expected.data_window.x1 - 1);
    EXPECT_EQ(window.max.y, expected.data_window.y1 - 1);
    const std::size_t width = static_cast<std::size_t>(window.max.x - window.min.x + 1);
    const std::size_t height = static_cast<std::size_t>(window.max.y - window.min.y + 1);
    std::map<std::string, std::vector<unsigned char>> samples;
    Imf::FrameBuffer frame_buffer;
    for (auto it = file.header().channels().begin(); it != file.header().channels().end();
         ++it) {
        const Imf::PixelType type = it.channel().type;
        const std::size_t size = type == Imf::HALF ? 2 : 4;
        std::vector<unsigned char>& data = samples[it.name()];
        data.resize(width * height * size);
        char* base =
            reinterpret_cast<char*>(data.data()) -
            (static_cast<std::ptrdiff_t>(window.min.x) +
             static_cast<std::ptrdiff_t>(window.min.y) * static_cast<std::ptrdiff_t>(width)) *
                static_cast<std::ptrdiff_t>(size);
        frame_buffer.insert(it.name(), Imf::Slice(type, base, size, size * width));
    }
    file.setFrameBuffer(frame_buffer);
    file.readPixels(window.min.y, window.max.y);
    return samples;
}

void expect_reads_back(const fs::path& path, const Image& image) {
    const auto samples = read_samples(path, image);
    ASSERT_EQ(samples.size(), image.channels.size());
    for (const ImageChannel& c : image.channels) {
        const auto it = samples.find(c.name);
        ASSERT_NE(it, samples.end()) << c.name;
        EXPECT_TRUE(std::equal(it->second.begin(), it->second.end(), c.samples.begin(),
                               c.samples.end()))
            << "channel " << c.name << " of " << path;
    }
}

// The windows: a whole picture whose height is no multiple of ZIP's 16 lines, and a crop
// whose data window starts inside the display window.
const PixelRect kWhole{0, 0, 37, 45};
const PixelRect kCropDisplay{0, 0, 64, 48};
const PixelRect kCrop{5, 3, 41, 30};

TEST(ExrOwnChunks, AnUncompressedFileIsOpenExrsOwnByteForByte) {
    const fs::path dir = test_dir();
    for (const auto& [display, data] :
         {std::pair{kWhole, kWhole}, std::pair{kCropDisplay, kCrop}}) {
        const Image image = test_image(display, data, ExrCompression::none, false);
        write_exr((dir / "ours.exr").string(), image);
        detail::write_exr_by_openexr((dir / "openexr.exr").string(), image);
        const std::string ours = test::whole_file(dir / "ours.exr");
        EXPECT_GT(ours.size(), 4 * data.pixel_count());
        EXPECT_TRUE(ours == test::whole_file(dir / "openexr.exr"))
            << "data window x " << data.x0 << ".." << data.x1 << ", y " << data.y0 << ".."
            << data.y1;
        // The long channel name sets the version field's long-names flag.
        std::int32_t version = 0;
        std::memcpy(&version, ours.data() + 4, sizeof version);
        EXPECT_EQ(version & Imf::LONG_NAMES_FLAG, Imf::LONG_NAMES_FLAG);
    }
    fs::remove_all(dir);
}

TEST(ExrOwnChunks, ZipAndZipsReadBackBitForBitLikeOpenExrsOwn) {
    const fs::path dir = test_dir();
    for (ExrCompression compression : {ExrCompression::zip, ExrCompression::zips})
        for (const auto& [display, data] :
             {std::pair{kWhole, kWhole}, std::pair{kCropDisplay, kCrop}})
            for (bool noisy : {false, true}) {
                SCOPED_TRACE(std::string(to_string(compression)) +
                             (noisy ? ", noise" : ", smooth") + ", y0 " +
                             std::to_string(data.y0));
                const Image image = test_image(display, data, compression, noisy);
                write_exr((dir / "ours.exr").string(), image);
                detail::write_exr_by_openexr((dir / "openexr.exr").string(), image);
                expect_reads_back(dir / "ours.exr", image);
                expect_reads_back(dir / "openexr.exr", image);
                Imf::InputFile ours((dir / "ours.exr").c_str());
                EXPECT_EQ(ours.header().compression(), compression == ExrCompression::zip
                                                           ? Imf::ZIP_COMPRESSION
                                                           : Imf::ZIPS_COMPRESSION);
                // No chunk is stored larger than raw; smooth samples compress.
                Image raw = image;
                raw.compression = ExrCompression::none;
                write_exr((dir / "raw.exr").string(), raw);
                const auto size = fs::file_size(dir / "ours.exr");
                const auto raw_size = fs::file_size(dir / "raw.exr");
                if (noisy)
                    EXPECT_LE(size, raw_size);
                else
                    EXPECT_LT(size, raw_size);
            }
    fs::remove_all(dir);
}

// Chunks that do not compress are stored raw, as OpenEXR stores them: 32 random bits per
// sample leave deflate nothing to find, and the file is the uncompressed file's size.
TEST(ExrOwnChunks, ChunksThatDoNotCompressAreStoredRaw) {
    const fs::path dir = test_dir();
    Noise noise;
    std::vector<std::uint32_t> ids(kWhole.pixel_count());
    for (std::uint32_t& id : ids) id = noise.next();
    for (ExrCompression compression :
         {ExrCompression::zip, ExrCompression::zips, ExrCompression::none}) {
        Image image;
        image.display_window = kWhole;
        image.data_window = kWhole;
        image.compression = compression;
        image.channels.push_back(make_channel("id", ids));
        const std::string name = std::string(to_string(compression)) + ".exr";
        write_exr((dir / name).string(), image);
        expect_reads_back(dir / name, image);
    }
    // The headers differ only in the compression's one byte.
    EXPECT_EQ(fs::file_size(dir / "zips.exr"), fs::file_size(dir / "none.exr"));
    // ZIP has 16 lines per chunk, so fewer chunks (and offsets) than one line per chunk.
    EXPECT_EQ(fs::file_size(dir / "zip.exr"),
              fs::file_size(dir / "none.exr") - (45 - 3) * (8 + 8));
    fs::remove_all(dir);
}

// More than one group of chunks (16 MB of samples are encoded at a time).
TEST(ExrOwnChunks, AnImageOfSeveralChunkGroupsReadsBack) {
    const fs::path dir = test_dir();
    const PixelRect window{0, 0, 1201, 1203};  // 17.3 MB of float RGB
    Image image;
    image.display_window = window;
    image.data_window = window;
    const std::size_t n = window.pixel_count();
    std::vector<float> values(n);
    for (const char* name : {"R", "G", "B"}) {
        for (std::size_t k = 0; k < n; ++k)
            values[k] = static_cast<float>((k * (name[0] - 'A' + 3)) % 1009) / 1009.0f;
        image.channels.push_back(make_channel(name, PixelFormat::float32, values.data(), n));
    }
    for (int threads : {0, 2}) {
        const int before = exr_thread_count();
        set_exr_thread_count(threads);
        write_exr((dir / ("t" + std::to_string(threads) + ".exr")).string(), image);
        set_exr_thread_count(before);
    }
    expect_reads_back(dir / "t2.exr", image);
    // The same header, chunks in the same order, the same bytes in each once inflated
    // (tests/image/inflated_file.h says why not the same compressed bytes).
    EXPECT_TRUE(test::exr_inflated(dir / "t0.exr") == test::exr_inflated(dir / "t2.exr"));
    fs::remove_all(dir);
}

// on_read (ExrSources, write_png_preview) comes once, as soon as the writer reads the
// pixels no more: the frame loop frees the run's last frame then, while its files are
// finished. Pixels overwritten at that moment must not reach the files, whichever way the
// chunks are packed (octray's own, or OpenEXR's for PIZ) and on any thread count.
TEST(ExrOwnChunks, OnReadComesOnceWhenThePixelsAreReadNoMore) {
    const fs::path dir = test_dir();
    Image render;
    render.display_window = render.data_window = PixelRect{0, 0, 211, 157};
    const std::size_t n = render.data_window.pixel_count();
    std::vector<float> values(n);
    for (const char* name : {"R", "G", "B"}) {
        for (std::size_t k = 0; k < n; ++k)
            values[k] =
                static_cast<float>((k * static_cast<std::size_t>(name[0])) % 1013) / 997.0f;
        render.channels.push_back(make_channel(name, PixelFormat::float32, values.data(), n));
    }
    const auto spoil = [](Image& image) {
        for (ImageChannel& c : image.channels)
            std::fill(c.samples.begin(), c.samples.end(), static_cast<unsigned char>(0x7f));
    };
    for (const ExrCompression compression :
         {ExrCompression::zip, ExrCompression::none, ExrCompression::piz}) {
        for (const int threads : {0, 2}) {
            SCOPED_TRACE(std::string(to_string(compression)) + ", " + std::to_string(threads) +
                         " threads");
            const int before = exr_thread_count();
            set_exr_thread_count(threads);
            write_exr((dir / "reference.exr").string(),
                      exr_sources(render, {false, compression}));
            Image copy = render;
            int calls = 0;
            ExrSources sources = exr_sources(copy, {false, compression});
            sources.on_read = [&] {
                ++calls;
                spoil(copy);
            };
            write_exr((dir / "spoiled.exr").string(), sources);
            set_exr_thread_count(before);
            EXPECT_EQ(calls, 1);
            EXPECT_TRUE(test::exr_inflated(dir / "reference.exr") ==
                        test::exr_inflated(dir / "spoiled.exr"));
        }
    }
    write_png_preview((dir / "reference.png").string(), render);
    Image copy = render;
    int calls = 0;
    write_png_preview((dir / "spoiled.png").string(), copy, [&] {
        ++calls;
        spoil(copy);
    });
    EXPECT_EQ(calls, 1);
    EXPECT_TRUE(test::png_inflated(dir / "reference.png") ==
                test::png_inflated(dir / "spoiled.png"));
    fs::remove_all(dir);
}

// A disk that fills up in the middle of an EXR: the message carries the OS's reason.
// RLIMIT_FSIZE makes write() fail with EFBIG past the limit, for this process only
// (SIGXFSZ, whose default action would kill the process, is ignored meanwhile). With
// threads, the chunk whose write fails is written by whichever thread encoded it last.
TEST(ExrOwnChunks, AWriteThatFailsSaysTheOsReasonAndLeavesNothing) {
    const fs::path dir = test_dir();
    const Image image = test_image(kWhole, kWhole, ExrCompression::zip, true);
    for (const int threads : {0, 2}) {
        SCOPED_TRACE(std::to_string(threads) + " threads");
        const int before = exr_thread_count();
        set_exr_thread_count(threads);
        struct rlimit saved {};
        ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &saved), 0);
        const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
        struct rlimit small = saved;
        small.rlim_cur = 4096;
        ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
        std::string error;
        try {
            write_exr((dir / "full.exr").string(), image);
        } catch (const IoError& e) {
            error = e.what();
        }
        ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &saved), 0);
        std::signal(SIGXFSZ, old_handler);
        set_exr_thread_count(before);
        EXPECT_NE(error.find("full.exr"), std::string::npos) << error;
        EXPECT_NE(error.find(std::strerror(EFBIG)), std::string::npos) << error;
        EXPECT_TRUE(fs::is_empty(dir)) << "a partial file or temporary was left";
    }
    fs::remove_all(dir);
}

}  // namespace
}  // namespace octray
