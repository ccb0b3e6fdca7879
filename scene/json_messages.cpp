// The message pieces of scene/json_messages.h.

#include "scene/json_messages.h"

#include <array>
#include <charconv>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <system_error>

#include "scene/suggest.h"

namespace octray::scene_json {

std::string format_float(float v) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    std::array<char, 32> buf{};
    const auto res = std::to_chars(buf.data(), buf.data() + buf.size(), v);
    return std::string(buf.data(), res.ptr);
}

std::string format_vec(Vec3 v) {
    return "[" + format_float(v.x) + ", " + format_float(v.y) + ", " + format_float(v.z) + "]";
}

std::string format_rgb(Rgb c) {
    return "[" + format_float(c.r) + ", " + format_float(c.g) + ", " + format_float(c.b) + "]";
}

std::string nul_byte_message() {
    return "invalid JSON: a NUL byte (\\0); expected JSON text, which has none (a NUL inside a "
           "string is written \\u0000)";
}

std::string abbreviated(std::string_view s) {
    if (s.size() <= kMaxQuotedLength) return std::string(s);
    return std::string(s.substr(0, kMaxQuotedLength - 3)) + "...";
}

std::string quote_text(std::string_view s) {
    // replace: a key or string with broken UTF-8 must still make a readable message.
    return Json(abbreviated(s)).dump(-1, ' ', false, Json::error_handler_t::replace);
}

// A short description of a JSON value for "found ..." in messages.
std::string describe(const Json& v) {
    switch (v.type()) {
        case Json::value_t::null:
            return "null";
        case Json::value_t::boolean:
            return v.get<bool>() ? "true" : "false";
        case Json::value_t::string: {
            std::string s = v.get<std::string>();
            if (s.size() > 40) s = s.substr(0, 37) + "...";
            return "the string " + quote_text(s);
        }
        case Json::value_t::number_integer:
        case Json::value_t::number_unsigned:
        case Json::value_t::number_float:
            return v.dump();
        case Json::value_t::array: {
            const std::string text = v.dump(-1, ' ', false, Json::error_handler_t::replace);
            if (text.size() <= 60) return text;
            return "an array of " + std::to_string(v.size()) + " elements";
        }
        case Json::value_t::object:
            return "an object";
        default:
            return "a binary value";
    }
}

// A path segment: .key for identifier-like keys, ["odd key"] otherwise.
std::string child_path(const std::string& path, std::string_view key) {
    const bool plain = !key.empty() && std::all_of(key.begin(), key.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
               c == '_' || c == '-';
    });
    if (!plain) return path + "[" + quote_text(key) + "]";
    return path.empty() ? abbreviated(key) : path + "." + abbreviated(key);
}

std::string index_path(const std::string& path, std::size_t i) {
    return path + "[" + std::to_string(i) + "]";
}

// " (did you mean "x"?)" when one candidate is close (scene/suggest.h), else "".
std::string suggestion(std::string_view word, std::span<const std::string_view> candidates) {
    const auto best = closest_word(word, candidates);
    if (!best) return "";
    return " (did you mean " + quote_text(*best) + "?)";
}

std::string join_quoted(std::span<const std::string_view> words) {
    std::string out;
    for (std::size_t i = 0; i < words.size(); ++i) {
        if (i) out += ", ";
        out += quote_text(words[i]);
    }
    return out;
}

}  // namespace octray::scene_json
