// The fast reader's value readers (scene/fast_values.h).

#include "scene/fast_values.h"

#include <locale.h>  // newlocale
#include <stdlib.h>  // strtod_l

#include <cmath>
#include <string>

#include "scene/json_rules.h"

namespace octray::scene_json::fast {

// ---------------------------------------------------------------------------------------
// Strings. simdjson's stage 1 has validated the whole text as UTF-8 without unescaped
// control characters, so a string without a backslash is its raw bytes; only escaped
// strings are unescaped. An unescaped string must be valid UTF-8 too: nlohmann refuses a
// lone surrogate escape such as "\udc00", which simdjson may turn into bytes.

// The length of a plain string starting after its opening quote, or npos when it holds
// an escape. Stage 1 guarantees the closing quote.
std::size_t plain_length(const char* chars) {
    for (const char* p = chars;; ++p) {
        if (*p == '"') return static_cast<std::size_t>(p - chars);
        if (*p == '\\') return std::string_view::npos;
    }
}

std::string_view checked_utf8(std::string_view s) {
    if (!simdjson::validate_utf8(s.data(), s.size())) throw Decline{};
    return s;
}

std::string_view key_of(od::field& field) {
    const char* chars = field.key().raw();
    const std::size_t n = plain_length(chars);
    if (n != std::string_view::npos) return {chars, n};
    return checked_utf8(take(field.unescaped_key()));
}

std::string_view string_of(od::value& v) {
    const std::string_view token = v.raw_json_token();
    if (token.empty() || token.front() != '"') throw Decline{};
    const std::size_t n = plain_length(token.data() + 1);
    if (n == std::string_view::npos) return checked_utf8(take(v.get_string()));
    (void)take(v.get_raw_json_string());  // consumes the value
    return token.substr(1, n);
}

// ---------------------------------------------------------------------------------------
// Numbers, as nlohmann reads them: a token with a fraction or an exponent is a double
// (strtod: correctly rounded); one without is an int64 (negative) or uint64, a double if it
// overflows those. simdjson's get_double is correctly rounded too for up to 19 significant
// digits (checked against strtod on millions of random tokens), so it gives the same
// double there. Longer mantissas go to strtod: simdjson 3.0.1 misreads some of them
// (0.1000...0001 with 42 digits comes back as 1.7e-24), and so do the exponents of 20
// digits or more that it refuses.

// JSON's number grammar: -?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?
bool is_json_number(std::string_view s) {
    std::size_t i = 0;
    const auto digits = [&] {
        const std::size_t start = i;
        while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i;
        return i > start;
    };
    if (i < s.size() && s[i] == '-') ++i;
    if (i < s.size() && s[i] == '0') {
        ++i;
    } else if (!digits()) {
        return false;
    }
    if (i < s.size() && s[i] == '.') {
        ++i;
        if (!digits()) return false;
    }
    if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
        ++i;
        if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
        if (!digits()) return false;
    }
    return i == s.size();
}

std::string_view trimmed(std::string_view token) {
    while (!token.empty() && (token.back() == ' ' || token.back() == '\t' ||
                              token.back() == '\n' || token.back() == '\r')) {
        token.remove_suffix(1);
    }
    return token;
}

// A number token simdjson would not read (an exponent of 20 digits or more): strtod in the
// C locale, as nlohmann reads it. nlohmann refuses a result that overflows to infinity.
double strtod_number(std::string_view token) {
    if (!is_json_number(token)) throw Decline{};
    static const locale_t c_locale = newlocale(LC_ALL_MASK, "C", locale_t{});
    if (c_locale == locale_t{}) throw Decline{};
    const std::string text(token);
    char* end = nullptr;
    const double d = strtod_l(text.c_str(), &end, c_locale);
    if (end != text.c_str() + text.size() || std::isinf(d)) throw Decline{};
    return d;
}

// More than 19 digits before the exponent (leading zeros included).
bool long_mantissa(std::string_view token) {
    if (token.size() <= 19) return false;
    const auto exponent =
        std::find_if(token.begin(), token.end(), [](char c) { return c == 'e' || c == 'E'; });
    const auto digits =
        std::count_if(token.begin(), exponent, [](char c) { return c >= '0' && c <= '9'; });
    return digits > 19;
}

double number_of(od::value& v) {
    const std::string_view token = trimmed(v.raw_json_token());
    double d = 0.0;
    // A value left unread (the strtod cases) is skipped by the enclosing array or object.
    if (long_mantissa(token) || std::move(v.get_double()).get(d) != simdjson::SUCCESS) {
        d = strtod_number(token);
    }
    // nlohmann reads "-0" (no fraction, no exponent) as the integer 0, which is +0.0.
    if (d == 0.0 && std::signbit(d) && token.find_first_of(".eE") == std::string_view::npos) {
        d = 0.0;
    }
    return d;
}

float float_of(od::value& v) {
    const double d = number_of(v);
    if (!scene_json::fits_float(d)) throw Decline{};
    return static_cast<float>(d);
}

// An integer in [lo, hi]; an integral double such as 640.0 counts (as in json_reader.h).
std::int64_t integer_of(od::value& v, std::int64_t lo, std::int64_t hi) {
    std::int64_t value = 0;
    switch (take(v.get_number_type())) {
        case od::number_type::signed_integer:
            value = take(v.get_int64());
            break;
        case od::number_type::unsigned_integer:
            throw Decline{};  // above 2^63 - 1: beyond every range here
        case od::number_type::floating_point_number: {
            const double d = number_of(v);
            if (d != std::floor(d) || d < static_cast<double>(lo) ||
                d > static_cast<double>(hi)) {
                throw Decline{};
            }
            value = static_cast<std::int64_t>(d);
            break;
        }
    }
    if (value < lo || value > hi) throw Decline{};
    return value;
}

// A seed: an integer token from 0 to 2^64 - 1 (no fraction or exponent).
std::uint64_t unsigned64_of(od::value& v) {
    switch (take(v.get_number_type())) {
        case od::number_type::signed_integer: {
            const std::int64_t value = take(v.get_int64());
            if (value < 0) throw Decline{};
            return static_cast<std::uint64_t>(value);
        }
        case od::number_type::unsigned_integer:
            return take(v.get_uint64());
        default:
            throw Decline{};
    }
}

Vec3 vec3_of(od::value& v) {
    std::array<float, 3> xyz{};
    std::size_t n = 0;
    for (auto element : take(v.get_array())) {
        od::value e = take(std::move(element));
        if (n == 3) throw Decline{};
        xyz[n++] = float_of(e);
    }
    if (n != 3) throw Decline{};
    return {xyz[0], xyz[1], xyz[2]};
}

Rgb color_of(od::value& v) {
    if (take(v.type()) == od::json_type::number) return Rgb(float_of(v));
    const Vec3 c = vec3_of(v);
    return {c.x, c.y, c.z};
}

}  // namespace octray::scene_json::fast
