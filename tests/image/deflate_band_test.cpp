// deflate_band (render/image/deflate.h): bands compressed on their own and joined make one
// zlib stream that zlib itself (the inflater libpng and OpenEXR use) reads back byte for
// byte, whatever the data, the level and wherever the bands are cut; and the checksums
// and zlib_compress, igzip's too.

#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "render/image/deflate.h"

namespace octray {
namespace {

using Bytes = std::vector<std::uint8_t>;

std::uint32_t next_random(std::uint32_t& state) {
    return state = state * 1664525u + 1013904223u;
}

// in[0, size) cut into bands of `band` bytes, each compressed on its own, joined into one
// zlib stream: header, bands, the Adler-32 of the whole from the bands'.
Bytes zlib_stream_of_bands(const Bytes& in, std::size_t band, int level = 1) {
    Bytes out = {0x78, 0x01};
    std::uint32_t adler = 1;
    std::size_t at = 0;
    do {
        const std::size_t size = std::min(band, in.size() - at);
        const std::size_t start = out.size();
        out.resize(start + detail::deflate_band_bound(size));
        const std::size_t written = detail::deflate_band(
            level, in.data() + at, size, at + size == in.size(), out.data() + start);
        EXPECT_LE(written, detail::deflate_band_bound(size));
        out.resize(start + written);
        adler = detail::adler32_combine(adler, detail::adler32(1, in.data() + at, size), size);
        at += size;
    } while (at < in.size());
    for (int shift = 24; shift >= 0; shift -= 8)
        out.push_back(static_cast<std::uint8_t>(adler >> shift));
    return out;
}

// zlib's inflate of a whole stream (it checks the Adler-32 too); `expected` bytes or fails.
Bytes inflate(const Bytes& stream, std::size_t expected) {
    Bytes out(expected + 1);
    uLongf size = static_cast<uLongf>(out.size());
    const int result =
        ::uncompress(out.data(), &size, stream.data(), static_cast<uLong>(stream.size()));
    EXPECT_EQ(result, Z_OK) << "zlib could not read the stream back";
    out.resize(size);
    return out;
}

// Cut into bands of several sizes (of one and seven bytes only when there are few), at
// each of igzip's levels.
void expect_round_trip(const Bytes& in, const std::string& what) {
    for (int level = 0; level <= 3; ++level)
        for (std::size_t band : {std::size_t{1}, std::size_t{7}, std::size_t{1000},
                                 std::size_t{65536}, std::size_t{131072}, in.size() + 1}) {
            if (band < 1000 && in.size() > 5000) continue;
            SCOPED_TRACE(what + ", bands of " + std::to_string(band) + " bytes, level " +
                         std::to_string(level));
            EXPECT_TRUE(inflate(zlib_stream_of_bands(in, band, level), in.size()) == in);
        }
}

TEST(DeflateBand, EmptyAndTinyInputs) {
    expect_round_trip({}, "no bytes");
    expect_round_trip({42}, "one byte");
    expect_round_trip({9, 9}, "two equal bytes");
    expect_round_trip({9, 9, 9, 9}, "a run of three after its first byte");
}

// Runs of every length up to 600, each of a byte other than its neighbours', and a
// megabyte of zeros.
TEST(DeflateBand, RunsOfEveryLength) {
    Bytes in;
    for (std::size_t length = 1; length <= 600; ++length)
        in.insert(in.end(), length, static_cast<std::uint8_t>(length % 251 + 1));
    expect_round_trip(in, "runs of 1 ... 600");
    expect_round_trip(Bytes(in.begin() + 4000, in.begin() + 9000), "runs of 89 ... 134");
    const Bytes zeros(std::size_t{1} << 20, 0);
    expect_round_trip(zeros, "1 MB of zeros");
    EXPECT_LT(zlib_stream_of_bands(zeros, zeros.size()).size(), 8000u);
}

// Noise does not compress: it is stored, within deflate_band_bound.
TEST(DeflateBand, NoiseIsStored) {
    Bytes in(300000);
    std::uint32_t state = 5;
    for (std::uint8_t& b : in) b = static_cast<std::uint8_t>(next_random(state) >> 24);
    expect_round_trip(in, "noise");
    const Bytes whole = zlib_stream_of_bands(in, in.size());
    EXPECT_LE(whole.size(), detail::deflate_band_bound(in.size()) + 6);
    EXPECT_THROW(zlib_stream_of_bands(in, in.size(), 4), std::invalid_argument);
}

// Filtered pixel rows as the PNG writer makes them: flat areas, gradients and noise; and
// repeated pixels, which a match finder codes at a pixel's distance.
TEST(DeflateBand, PictureLikeBytes) {
    Bytes in;
    std::uint32_t state = 3;
    for (int row = 0; row < 400; ++row)
        for (int x = 0; x < 1500; ++x) {
            const int area = (row / 50 + x / 300) % 3;
            in.push_back(area == 0   ? 0
                         : area == 1 ? static_cast<std::uint8_t>(x / 7 % 2)
                                     : static_cast<std::uint8_t>(next_random(state) >> 28));
        }
    expect_round_trip(in, "picture-like rows");
    EXPECT_LT(zlib_stream_of_bands(in, 131072).size(), in.size() / 4);
    Bytes pixels;
    for (int stretch = 0; stretch < 3000; ++stretch) {
        const std::uint8_t pixel[3] = {static_cast<std::uint8_t>(next_random(state) >> 24),
                                       static_cast<std::uint8_t>(next_random(state) >> 24),
                                       static_cast<std::uint8_t>(next_random(state) >> 24)};
        const std::uint32_t repeats = 1 + (next_random(state) >> 27);
        for (std::uint32_t k = 0; k < repeats; ++k)
            pixels.insert(pixels.end(), pixel, pixel + 3);
    }
    expect_round_trip(pixels, "repeated pixels");
    EXPECT_LT(zlib_stream_of_bands(pixels, pixels.size()).size(), pixels.size() / 2);
}

TEST(Adler32, CombinedSumsAreTheSumOfTheWhole) {
    Bytes in(200000);
    std::uint32_t state = 17;
    for (std::uint8_t& b : in) b = static_cast<std::uint8_t>(next_random(state) >> 24);
    for (std::size_t cut : {std::size_t{0}, std::size_t{1}, std::size_t{65521},
                            std::size_t{131042}, std::size_t{199999}, in.size()}) {
        const std::uint32_t first = detail::adler32(1, in.data(), cut);
        const std::uint32_t second = detail::adler32(1, in.data() + cut, in.size() - cut);
        EXPECT_EQ(detail::adler32_combine(first, second, in.size() - cut),
                  detail::adler32(1, in.data(), in.size()))
            << "cut at " << cut;
    }
    EXPECT_EQ(detail::adler32(1, in.data(), 0), 1u);
}

// The checksums are ISA-L's; a PNG reader checks zlib's: the same sums, whole and
// continued piece by piece (a PNG chunk's CRC runs over its type, then its data).
TEST(Checksums, AreZlibsWholeAndInPieces) {
    Bytes in(100003);
    std::uint32_t state = 5;
    for (std::uint8_t& b : in) b = static_cast<std::uint8_t>(next_random(state) >> 24);
    for (std::size_t cut : {std::size_t{0}, std::size_t{1}, std::size_t{4}, std::size_t{63},
                            std::size_t{65537}, in.size()}) {
        SCOPED_TRACE("cut at " + std::to_string(cut));
        const uLong zlib_crc = ::crc32(0, in.data(), static_cast<uInt>(in.size()));
        const uLong zlib_adler = ::adler32(1, in.data(), static_cast<uInt>(in.size()));
        EXPECT_EQ(
            detail::crc32(detail::crc32(0, in.data(), cut), in.data() + cut, in.size() - cut),
            zlib_crc);
        EXPECT_EQ(detail::adler32(detail::adler32(1, in.data(), cut), in.data() + cut,
                                  in.size() - cut),
                  zlib_adler);
    }
    EXPECT_EQ(detail::crc32(0, in.data(), 0), 0u);
}

// zlib_compress (the EXR's ZIP chunks): a whole zlib stream zlib reads back, at every level,
// for empty, tiny, picture-like and random input; 0 when the stream does not fit.
TEST(ZlibCompress, StreamsReadBackByZlibAtEveryLevel) {
    Bytes picture;
    std::uint32_t state = 9;
    for (int row = 0; row < 200; ++row)
        for (int x = 0; x < 1000; ++x)
            picture.push_back(row / 40 % 2 == 0
                                  ? static_cast<std::uint8_t>(128 + x / 100 % 3)
                                  : static_cast<std::uint8_t>(next_random(state) >> 29));
    Bytes noise(70000);
    for (std::uint8_t& b : noise) b = static_cast<std::uint8_t>(next_random(state) >> 24);
    const std::vector<std::pair<std::string, Bytes>> inputs = {
        {"empty", {}}, {"one byte", {42}}, {"picture-like", picture}, {"noise", noise}};
    for (int level = 0; level <= 3; ++level)
        for (const auto& [what, in] : inputs) {
            SCOPED_TRACE(what + " at level " + std::to_string(level));
            Bytes out(in.size() + 1024);
            const std::size_t size =
                detail::zlib_compress(level, in.data(), in.size(), out.data(), out.size());
            ASSERT_GT(size, 0u);
            out.resize(size);
            EXPECT_TRUE(inflate(out, in.size()) == in);
            if (what == "picture-like") {
                EXPECT_LT(size, in.size() / 4);
            }
        }
    // Noise does not compress: in size - 1 bytes it does not fit, and the caller stores it.
    Bytes out(noise.size() - 1);
    EXPECT_EQ(detail::zlib_compress(1, noise.data(), noise.size(), out.data(), out.size()), 0u);
    EXPECT_THROW(detail::zlib_compress(4, noise.data(), noise.size(), out.data(), out.size()),
                 std::invalid_argument);
    EXPECT_THROW(detail::zlib_compress(-1, noise.data(), noise.size(), out.data(), out.size()),
                 std::invalid_argument);
}

}  // namespace
}  // namespace octray
