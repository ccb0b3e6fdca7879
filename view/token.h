#pragma once
// The access token of `octray view`, as Jupyter's: a random secret in the URL the command
// prints, which every request must carry (view/README.md, "Token").

#include <string>
#include <string_view>

namespace octray::view {

// 128 random bits from /dev/urandom (std::random_device where it cannot be read) as 32
// lowercase hex digits.
std::string random_token();

// a == b in a time that depends on their lengths only, not on where they first differ, so
// that timing the server's answers leaks nothing of the token.
bool tokens_equal(std::string_view a, std::string_view b);

}  // namespace octray::view
