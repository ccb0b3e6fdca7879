#pragma once
// Checks every command shares: strict numbers for options, each failure a message saying
// what was given and what is expected.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace CLI {
class App;
class Validator;
}  // namespace CLI

namespace octray::tools {

// ---- Numbers on the command line -------------------------------------------------------

// Decimal digits only (as scene files have them): no sign, blank, "0x" prefix, fraction or
// exponent; nullopt for anything else or above 2^64 - 1 (nothing is clamped).
std::optional<std::uint64_t> parse_decimal_integer(std::string_view text);

// An integer option in [lo, hi], written as parse_decimal_integer reads it. Use with
// CLI::Option::transform: it hands CLI11 the number in canonical form (CLI11 alone would
// read "0x10" as 16, "010" as 8, " 5" as 5 and clamp 2^64 to 2^64 - 1).
CLI::Validator decimal_integer(std::uint64_t lo, std::uint64_t hi);

// A real option (a threshold): a decimal number in [lo, hi], or "inf" / "infinity" (any
// case) when `allow_infinity`. NaN, hex floats, signs other than a leading '-', blanks and
// values that overflow to infinity are refused. Use with CLI::Option::transform.
CLI::Validator real_number(double lo, double hi, bool allow_infinity);

}  // namespace octray::tools
