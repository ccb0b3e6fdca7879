#include "render/batch/digest.h"

// libcrypto's own SHA-256 functions, not its EVP interface: OpenSSL 3 deprecates them, but
// the first EVP digest of a process loads the providers and reads openssl.cnf, 0.8 ms of
// every `octray render` (an empty program hashing "abc" through EVP took 2.2 ms, through
// SHA256_Update 1.3 ms; both hash 120 MB in 60 ms with the SHA instructions). The
// functions are what EVP calls for SHA-256 underneath.
#define OPENSSL_SUPPRESS_DEPRECATED
#include <openssl/sha.h>

namespace octray::batch {

struct Sha256::State {
    SHA256_CTX ctx;
};

Sha256::Sha256() : state_(std::make_unique<State>()) { SHA256_Init(&state_->ctx); }
Sha256::~Sha256() = default;
Sha256::Sha256(Sha256&&) noexcept = default;
Sha256& Sha256::operator=(Sha256&&) noexcept = default;

void Sha256::update(std::string_view bytes) {
    SHA256_Update(&state_->ctx, bytes.data(), bytes.size());
}

std::string Sha256::hex_digest() {
    unsigned char digest[SHA256_DIGEST_LENGTH];
    SHA256_Final(digest, &state_->ctx);
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    out.reserve(2 * SHA256_DIGEST_LENGTH);
    for (const unsigned char byte : digest) {
        out += kHex[byte >> 4];
        out += kHex[byte & 15];
    }
    return out;
}

std::string sha256_hex(std::string_view bytes) {
    Sha256 hash;
    hash.update(bytes);
    return hash.hex_digest();
}

}  // namespace octray::batch
