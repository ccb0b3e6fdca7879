#pragma once
// SHA-256 of a scene (`octray.sceneSha256`): the digest `sha256sum scene.json` prints, so a
// farm can tell which version of a scene file produced an image. OpenSSL's libcrypto does
// the hashing; it uses the CPU's SHA instructions where there are some, far faster than a
// portable C++ implementation (measured: docs/performance-log.md, "Figures from source
// comments").

#include <memory>
#include <string>
#include <string_view>

namespace octray::batch {

class Sha256 {
  public:
    Sha256();
    ~Sha256();
    Sha256(Sha256&&) noexcept;
    Sha256& operator=(Sha256&&) noexcept;

    void update(std::string_view bytes);
    // The digest as 64 lowercase hex digits. Call once.
    std::string hex_digest();

  private:
    struct State;  // libcrypto's SHA256_CTX
    std::unique_ptr<State> state_;
};

// The digest of `bytes` as 64 lowercase hex digits.
std::string sha256_hex(std::string_view bytes);

}  // namespace octray::batch
