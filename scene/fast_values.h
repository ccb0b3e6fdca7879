#pragma once
// The value readers of the fast JSON scene reader (scene/load_fast.cpp): strings, numbers,
// vectors, colors, words and the keys of an object, read with simdjson's On-Demand API
// exactly as the diagnosing reader (nlohmann) would read them, or declined (Decline) where
// that reader would refuse or the two could differ. Internal to the fast reader.

#include <simdjson.h>

#include <array>
#include <cstdint>
#include <string_view>
#include <utility>

#include "core/color.h"
#include "core/vec3.h"

namespace octray::scene_json::fast {

namespace od = simdjson::ondemand;

// Thrown where the fast reader gives up; never leaves the fast reader.
struct Decline {};

template <typename T>
T take(simdjson::simdjson_result<T>&& result) {
    T value;
    if (std::move(result).get(value) != simdjson::SUCCESS) throw Decline{};
    return value;
}

// A key or string value as nlohmann would read it (valid UTF-8, unescaped).
std::string_view key_of(od::field& field);
std::string_view string_of(od::value& v);
// A number as nlohmann reads it (strtod's result where simdjson would not read it).
double number_of(od::value& v);
// A number that fits a float (scene_json::fits_float, json_rules.h).
float float_of(od::value& v);
// An integer in [lo, hi]; an integral double such as 640.0 counts.
std::int64_t integer_of(od::value& v, std::int64_t lo, std::int64_t hi);
// A seed: an integer token from 0 to 2^64 - 1 (no fraction or exponent).
std::uint64_t unsigned64_of(od::value& v);
// [x, y, z]; a color [r, g, b] or a bare number (grey).
Vec3 vec3_of(od::value& v);
Rgb color_of(od::value& v);

template <std::size_t N>
std::size_t choice_of(od::value& v, const std::array<std::string_view, N>& words) {
    const std::string_view s = string_of(v);
    for (std::size_t i = 0; i < N; ++i) {
        if (words[i] == s) return i;
    }
    throw Decline{};
}

// Keys met in one JSON object: each known key once (nlohmann refuses duplicates); an
// unknown key declines at once.
template <std::size_t N>
class KeySet {
  public:
    explicit KeySet(const std::array<std::string_view, N>& keys) : keys_(keys) {}

    // The index of `key` among the known keys, marking it seen.
    std::size_t see(std::string_view key) {
        for (std::size_t i = 0; i < N; ++i) {
            if (keys_[i] != key) continue;
            if (seen_ & (1u << i)) throw Decline{};
            seen_ |= 1u << i;
            return i;
        }
        throw Decline{};
    }
    bool has(std::size_t i) const { return (seen_ >> i) & 1u; }

  private:
    const std::array<std::string_view, N>& keys_;
    std::uint32_t seen_ = 0;
};

// Calls read(key, value) for each field of the JSON object `v` (a value or the document)
// in file order, `key` the field's index among `seen`'s keys (an unknown or repeated key
// declines).
template <class Object, std::size_t N, class Read>
void read_fields(Object& v, KeySet<N>& seen, Read&& read) {
    for (auto f : take(v.get_object())) {
        od::field field = take(std::move(f));
        const std::size_t key = seen.see(key_of(field));
        read(key, field.value());
    }
}

}  // namespace octray::scene_json::fast
