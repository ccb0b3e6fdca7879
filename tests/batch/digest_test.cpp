// SHA-256 (render/batch/digest.h) against the FIPS 180-4 examples and coreutils' sha256sum,
// and its two builds against each other.

#include "render/batch/digest.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

namespace octray::batch {
namespace {

TEST(Sha256, EmptyInput) {
    EXPECT_EQ(sha256_hex(""),
              "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
}

TEST(Sha256, Abc) {
    EXPECT_EQ(sha256_hex("abc"),
              "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(Sha256, TwoBlockMessage) {
    // 56 bytes: the padding needs a second block.
    EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
              "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

TEST(Sha256, MillionAsInPiecesEqualsOneUpdate) {
    Sha256 pieces;
    const std::string chunk(1000, 'a');
    for (int i = 0; i < 1000; ++i) pieces.update(chunk);
    EXPECT_EQ(pieces.hex_digest(),
              "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, FourBlockMessage) {
    EXPECT_EQ(sha256_hex("abcdefghbcdefghicdefghijdefghijkefghijklfghijklmghijklmnhijklmno"
                         "ijklmnopjklmnopqklmnopqrlmnopqrsmnopqrstnopqrstu"),
              "cf5b16a778af8380036ce59e7b0492370b249b11e8f07a51afac45037afee9d1");
}

std::string pseudo_random_bytes(std::size_t size, std::uint32_t seed) {
    std::string bytes(size, '\0');
    for (char& c : bytes) {
        seed = seed * 1664525u + 1013904223u;
        c = static_cast<char>(seed >> 24);
    }
    return bytes;
}

// Around every padding boundary (a block holds 55 bytes and the length, or spills into a
// second), against coreutils' sha256sum, an implementation of its own; and the same bytes
// in pieces of every size give the same digest.
TEST(Sha256, EveryPaddingCaseMatchesSha256sumAndPiecesMatchTheWhole) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::path(OCTRAY_TEST_TMPDIR) / "digest";
    fs::create_directories(dir);
    for (const std::size_t size :
         {0, 1, 54, 55, 56, 57, 63, 64, 65, 119, 120, 127, 128, 129, 1000, 100003}) {
        SCOPED_TRACE(std::to_string(size) + " bytes");
        const std::string bytes = pseudo_random_bytes(size, static_cast<std::uint32_t>(size));
        const fs::path file = dir / ("m" + std::to_string(size));
        std::ofstream(file, std::ios::binary) << bytes;
        const std::string command = "sha256sum '" + file.string() + "'";
        FILE* pipe = ::popen(command.c_str(), "r");
        ASSERT_NE(pipe, nullptr);
        char line[65] = {};
        ASSERT_EQ(std::fread(line, 1, 64, pipe), 64u);
        ::pclose(pipe);
        const std::string digest = sha256_hex(bytes);
        EXPECT_EQ(digest, std::string(line, 64));
        for (const std::size_t piece : {1, 3, 63, 64, 65, 200}) {
            if (size > 2000 && piece < 63) continue;
            Sha256 pieces;
            for (std::size_t at = 0; at < size; at += piece)
                pieces.update(std::string_view(bytes).substr(at, piece));
            EXPECT_EQ(pieces.hex_digest(), digest) << "pieces of " << piece;
        }
    }
}

// The two compression functions (portable C++ and the SHA extensions) give the same state
// for the same blocks, from any state.
TEST(Sha256, BothBuildsCompressAlike) {
    if (!detail::sha256_use_shani()) {
        std::cout << "[  SKIPPED ] the SHA-extensions build: this CPU has no SHA extensions\n";
        GTEST_SKIP();
    }
    for (const std::size_t blocks : {1, 2, 3, 17}) {
        const std::string data = pseudo_random_bytes(64 * blocks, 7 + blocks);
        std::uint32_t portable[8], shani[8];
        const std::string start = pseudo_random_bytes(32, 3 + blocks);
        for (int i = 0; i < 8; ++i)
            portable[i] = shani[i] =
                static_cast<std::uint32_t>(static_cast<unsigned char>(start[4 * i]) << 24 |
                                           static_cast<unsigned char>(start[4 * i + 1]) << 16 |
                                           static_cast<unsigned char>(start[4 * i + 2]) << 8 |
                                           static_cast<unsigned char>(start[4 * i + 3]));
        const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
        detail::sha256_blocks_portable(portable, bytes, blocks);
        detail::sha256_blocks_shani(shani, bytes, blocks);
        EXPECT_EQ(std::vector<std::uint32_t>(portable, portable + 8),
                  std::vector<std::uint32_t>(shani, shani + 8))
            << blocks << " blocks";
    }
}

// The portable build alone, on "abc" padded by hand (one block): FIPS 180-4's digest.
TEST(Sha256, ThePortableBuildGivesTheFipsDigest) {
    unsigned char block[64] = {'a', 'b', 'c', 0x80};
    block[63] = 24;  // the length in bits
    std::uint32_t state[8] = {0x6a09e667u, 0xbb67ae85u, 0x3c6ef372u, 0xa54ff53au,
                              0x510e527fu, 0x9b05688cu, 0x1f83d9abu, 0x5be0cd19u};
    detail::sha256_blocks_portable(state, block, 1);
    EXPECT_EQ(std::vector<std::uint32_t>(state, state + 8),
              (std::vector<std::uint32_t>{0xba7816bfu, 0x8f01cfeau, 0x414140deu, 0x5dae2223u,
                                          0xb00361a3u, 0x96177a9cu, 0xb410ff61u, 0xf20015adu}));
}

}  // namespace
}  // namespace octray::batch
