#pragma once
// SHA-256 of a scene (`octray.sceneSha256`): the digest `sha256sum scene.json` prints, so a
// farm can tell which version of a scene file produced an image. OpenSSL's libcrypto does
// the hashing; it uses the CPU's SHA instructions where there are some, far faster than a
// portable C++ implementation (measured: docs/performance-log.md, "Figures from source
// comments").

#include <memory>
#include <string>
#include <string_view>

struct evp_md_ctx_st;

namespace octray::batch {

class Sha256 {
  public:
    Sha256();  // throws std::runtime_error if libcrypto cannot start a digest
    Sha256(Sha256&&) noexcept = default;
    Sha256& operator=(Sha256&&) noexcept = default;

    void update(std::string_view bytes);
    // The digest as 64 lowercase hex digits. Call once.
    std::string hex_digest();

  private:
    std::unique_ptr<evp_md_ctx_st, void (*)(evp_md_ctx_st*)> ctx_;
};

// The digest of `bytes` as 64 lowercase hex digits.
std::string sha256_hex(std::string_view bytes);

}  // namespace octray::batch
