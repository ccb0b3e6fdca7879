#pragma once
// Typed reads with JSON paths for the diagnosing reader: every read names the file, the
// JSON path and what was expected (scene/README.md, "Error messages"); keys are checked against
// the allowed ones, with a suggestion for a misspelled key and a note for a key of another
// type.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/color.h"
#include "core/vec3.h"
#include "scene/json_messages.h"
#include "scene/json_rules.h"
#include "scene/scene_error.h"

namespace octray::scene_json {

struct ForeignKey {
    std::string_view key;
    std::string_view belongs_to;  // e.g. "orthographic cameras"
};

class Reader {
  public:
    explicit Reader(const std::string& file) : file_(file) {}

    [[noreturn]] void fail(const std::string& path, const std::string& message) const {
        throw SceneError(file_, path, message);
    }

    // Every key of `object` must be in `allowed`; keys of a sibling type get a message
    // saying where they belong.
    void check_keys(const Json& object, const std::string& path,
                    std::span<const std::string_view> allowed,
                    std::span<const ForeignKey> foreign = {},
                    std::string_view this_kind = {}) const {
        for (const auto& [key, value] : object.items()) {
            if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
            for (const ForeignKey& f : foreign) {
                if (f.key == key) {
                    fail(child_path(path, key), "key " + quote_text(key) + " applies only to " +
                                                    std::string(f.belongs_to) + ", not to " +
                                                    std::string(this_kind));
                }
            }
            std::vector<std::string_view> candidates(allowed.begin(), allowed.end());
            for (const ForeignKey& f : foreign) candidates.push_back(f.key);
            fail(child_path(path, key), "unknown key " + quote_text(key) +
                                            suggestion(key, candidates) +
                                            "; expected one of: " + join_quoted(allowed));
        }
    }

    const Json& require_object(const Json& v, const std::string& path,
                               std::string_view what) const {
        if (!v.is_object()) {
            fail(path, "expected an object (" + std::string(what) + "), found " + describe(v));
        }
        return v;
    }

    const Json& require_key(const Json& object, const std::string& path, std::string_view key,
                            std::string_view expectation) const {
        const auto it = object.find(key);
        if (it == object.end()) {
            fail(child_path(path, key), "missing required key " + quote_text(key) +
                                            "; expected " + std::string(expectation));
        }
        return *it;
    }

    float number(const Json& v, const std::string& path) const {
        if (!v.is_number()) fail(path, "expected a number, found " + describe(v));
        const double d = v.get<double>();
        if (!fits_float(d)) {
            fail(path,
                 "expected a finite number within float range (magnitude at most "
                 "3.4028235e38), found " +
                     describe(v));
        }
        return static_cast<float>(d);
    }

    // An integer in [lo, hi]; an integral float such as 640.0 counts.
    std::int64_t integer(const Json& v, const std::string& path, std::int64_t lo,
                         std::int64_t hi) const {
        const std::string expectation =
            "expected an integer from " + std::to_string(lo) + " to " + std::to_string(hi);
        std::int64_t value = 0;
        if (v.is_number_unsigned()) {
            const std::uint64_t u = v.get<std::uint64_t>();
            if (u > static_cast<std::uint64_t>(hi))
                fail(path, expectation + ", found " + describe(v));
            value = static_cast<std::int64_t>(u);
        } else if (v.is_number_integer()) {
            value = v.get<std::int64_t>();
        } else if (v.is_number_float()) {
            const double d = v.get<double>();
            if (d != std::floor(d)) fail(path, expectation + ", found " + describe(v));
            if (d < static_cast<double>(lo) || d > static_cast<double>(hi)) {
                fail(path, expectation + ", found " + describe(v));
            }
            value = static_cast<std::int64_t>(d);
        } else {
            fail(path, expectation + ", found " + describe(v));
        }
        if (value < lo || value > hi) fail(path, expectation + ", found " + describe(v));
        return value;
    }

    // A JSON integer in [0, 2^64 - 1]; floats are refused because above 2^53 they would
    // silently round to another seed.
    std::uint64_t unsigned64(const Json& v, const std::string& path) const {
        if (v.is_number_unsigned()) return v.get<std::uint64_t>();
        if (v.is_number_integer() && v.get<std::int64_t>() >= 0) {
            return static_cast<std::uint64_t>(v.get<std::int64_t>());
        }
        fail(path,
             "expected a non-negative integer from 0 to 18446744073709551615 written "
             "without a fraction or exponent, found " +
                 describe(v));
    }

    const std::string& string(const Json& v, const std::string& path) const {
        if (!v.is_string()) fail(path, "expected a string, found " + describe(v));
        return v.get_ref<const std::string&>();
    }

    // One of a fixed set of words; returns its index.
    std::size_t choice(const Json& v, const std::string& path,
                       std::span<const std::string_view> words) const {
        if (v.is_string()) {
            const std::string& s = v.get_ref<const std::string&>();
            for (std::size_t i = 0; i < words.size(); ++i) {
                if (words[i] == s) return i;
            }
            fail(path, "expected one of " + join_quoted(words) + ", found " + describe(v) +
                           suggestion(s, words));
        }
        fail(path, "expected one of " + join_quoted(words) + ", found " + describe(v));
    }

    Vec3 vec3(const Json& v, const std::string& path) const {
        if (!v.is_array() || v.size() != 3) {
            fail(path, "expected an array of 3 numbers [x, y, z], found " + describe(v));
        }
        return {number(v[0], index_path(path, 0)), number(v[1], index_path(path, 1)),
                number(v[2], index_path(path, 2))};
    }

    // A color: [r, g, b], or a bare number meaning grey.
    Rgb color(const Json& v, const std::string& path) const {
        if (v.is_number()) return Rgb(number(v, path));
        if (!v.is_array() || v.size() != 3) {
            fail(path, "expected a color: [r, g, b] or a number (grey), found " + describe(v));
        }
        return {number(v[0], index_path(path, 0)), number(v[1], index_path(path, 1)),
                number(v[2], index_path(path, 2))};
    }

  private:
    const std::string& file_;
};

}  // namespace octray::scene_json
