#include "view/token.h"

#include <array>
#include <cstdint>
#include <fstream>
#include <random>

namespace octray::view {

std::string random_token() {
    std::array<unsigned char, 16> bytes{};
    std::ifstream urandom("/dev/urandom", std::ios::binary);
    if (!urandom.read(reinterpret_cast<char*>(bytes.data()), bytes.size())) {
        std::random_device device;
        for (auto& byte : bytes) byte = static_cast<unsigned char>(device() & 0xff);
    }
    static constexpr char kHex[] = "0123456789abcdef";
    std::string token;
    for (unsigned char byte : bytes) {
        token += kHex[byte >> 4];
        token += kHex[byte & 15];
    }
    return token;
}

bool tokens_equal(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    unsigned char difference = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        difference |= static_cast<unsigned char>(a[i] ^ b[i]);
    return difference == 0;
}

}  // namespace octray::view
