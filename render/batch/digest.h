#pragma once
// SHA-256 of a scene (`octray.sceneSha256`): the digest `sha256sum scene.json` prints, so a
// farm can tell which version of a scene file produced an image. octray's own (FIPS 180-4):
// with the CPU's SHA instructions where it has them (x86 SHA extensions: every Zen, Intel
// from Ice Lake and Goldmont on; checked once, at run time), portable C++ otherwise. It
// replaced OpenSSL's libcrypto, whose loading cost every command about 1 ms at start
// (docs/performance-log.md; an earlier portable-only version hashed at 130 MB/s, the SHA
// instructions at 2 GB/s).

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace octray::batch {

class Sha256 {
  public:
    void update(std::string_view bytes);
    // The digest as 64 lowercase hex digits. Call once.
    std::string hex_digest();

  private:
    std::uint32_t state_[8] = {0x6a09e667u, 0xbb67ae85u, 0x3c6ef372u, 0xa54ff53au,
                               0x510e527fu, 0x9b05688cu, 0x1f83d9abu, 0x5be0cd19u};
    std::uint64_t length_ = 0;  // bytes hashed so far
    unsigned char block_[64];   // a block's first length_ % 64 bytes
};

// The digest of `bytes` as 64 lowercase hex digits.
std::string sha256_hex(std::string_view bytes);

namespace detail {
// The compression function on `blocks` whole 64-byte blocks: the portable build, and the
// SHA-extensions build (digest_shani.cpp: only where sha256_use_shani()).
void sha256_blocks_portable(std::uint32_t state[8], const unsigned char* data,
                            std::size_t blocks);
void sha256_blocks_shani(std::uint32_t state[8], const unsigned char* data, std::size_t blocks);
bool sha256_use_shani();
// The round constants (FIPS 180-4, 4.2.2).
extern const std::uint32_t kSha256Round[64];
}  // namespace detail

}  // namespace octray::batch
