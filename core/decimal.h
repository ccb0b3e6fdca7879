#pragma once
// The one reading of an integer that octray's users write on the command line: decimal
// digits only, as scene files have them. The command line's integer options (through
// tools/cli_checks.h) and the numbers inside its specs (frame lists, shards, crops:
// render/batch/spec.h) all read their digits here.

#include <charconv>
#include <cstdint>
#include <optional>
#include <string_view>
#include <system_error>

namespace octray {

// `text` as a decimal integer: digits only (no sign, blank, "0x" prefix, fraction or
// exponent; leading zeros are decimal, "010" is 10); nullopt for anything else and for
// values above 2^64 - 1 (nothing is clamped).
inline std::optional<std::uint64_t> parse_decimal_digits(std::string_view text) {
    if (text.empty()) return std::nullopt;
    for (const char c : text)
        if (c < '0' || c > '9') return std::nullopt;
    std::uint64_t value = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
    return value;
}

}  // namespace octray
