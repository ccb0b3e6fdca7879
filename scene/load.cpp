// JSON scene files (docs/scene-format.md) into the authored Scene, and the semantic
// checks every scene passes before it is rendered. Defaults and the exact rules are in
// scene/README.md; every message names the file, the JSON path and what was expected.

#include "scene/load.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "core/aligned.h"
#include "scene/builtin.h"
#include "scene/camera.h"
#include "scene/json_rules.h"
#include "scene/suggest.h"

namespace octray {
namespace {

// ordered_json keeps members in file order: named materials are indexed in the order the
// file lists them, and errors are reported in reading order.
using Json = nlohmann::ordered_json;

using json_rules::kMaxDepthLimit;
using json_rules::kMaxIntValue;
// Recursion is bounded by the scene schema anyway; this only stops absurd files early.
constexpr std::size_t kMaxNesting = 64;
// Pixel indices must fit in an int (the renderers and image writers index with int).
constexpr std::int64_t kMaxPixels = std::numeric_limits<int>::max();
constexpr std::int64_t kFramebufferBytesPerPixel = 12;  // three floats
// validate_scene is looser than json_rules::kUnitTolerance: it only has to catch normals
// that were never normalised.
constexpr double kValidateUnitTolerance = 1e-5;
// Refraction scales directions by the index ratio (or its inverse); far beyond real
// materials (1 to about 4) the float refraction vector loses its precision and degenerate
// directions render NaN (issue 23: ior 1e8 did, 1e7 too). 100 leaves a wide margin.
constexpr float kMinIor = 0.01f;
constexpr float kMaxIor = 100.0f;
// A thin lens much wider than its focus distance starts rays so far off the view axis that
// float precision breaks down: measured on the built-in and golden scenes, 10 x renders
// normal values, 100 x absurd ones and 300 x infinite or NaN pixels (issue 23: aperture
// 1e20 rendered 13915 of 14400 pixels NaN).
constexpr float kMaxApertureRatio = 10.0f;
// Beyond this the focal point's distance overflows float when squared (a focus distance
// of 1e20 renders every pixel NaN, even through a pinhole-sized lens).
constexpr float kMaxFocusDistance = 1e18f;

// ---------------------------------------------------------------------------------------
// Formatting helpers

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

// Keys, names and words longer than this are cut short in messages: a 100 MB key must
// not make a 100 MB message.
constexpr std::size_t kMaxQuotedLength = 64;

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

// ---------------------------------------------------------------------------------------
// JSON text to a DOM, with positions for syntax errors and paths for duplicate keys.
// nlohmann's own DOM parser silently keeps the last of two equal keys and reports number
// overflow without a position, so we build the DOM through our own SAX handler.

struct ParseFailure {
    std::string path;
    std::string message;
};

class DomBuilder final : public nlohmann::json_sax<Json> {
  public:
    explicit DomBuilder(std::string_view text) : text_(text) {}

    bool null() override { return add(Json(nullptr)); }
    bool boolean(bool value) override { return add(Json(value)); }
    bool number_integer(number_integer_t value) override { return add(Json(value)); }
    bool number_unsigned(number_unsigned_t value) override { return add(Json(value)); }
    bool number_float(number_float_t value, const string_t& /*text*/) override {
        return add(Json(value));
    }
    bool string(string_t& value) override { return add(Json(std::move(value))); }
    bool binary(binary_t& /*value*/) override {
        failure_ = ParseFailure{current_path(), "binary values are not JSON"};
        return false;
    }
    bool start_object(std::size_t /*elements*/) override {
        return add(Json::object()) && open(false);
    }
    bool key(string_t& name) override {
        Frame& frame = frames_.back();
        frame.key = name;
        if (!frame.keys.insert(name).second) {
            failure_ =
                ParseFailure{current_path(), "duplicate key " + quote_text(name) +
                                                 " (each key may appear once per object)"};
            return false;
        }
        return true;
    }
    bool end_object() override {
        frames_.pop_back();
        return true;
    }
    bool start_array(std::size_t /*elements*/) override {
        return add(Json::array()) && open(true);
    }
    bool end_array() override {
        frames_.pop_back();
        return true;
    }
    bool parse_error(std::size_t position, const std::string& last_token,
                     const Json::exception& ex) override {
        const auto [line, column] = line_and_column(position);
        const std::string where =
            "line " + std::to_string(line) + ", column " + std::to_string(column);
        if (ex.id == 406) {
            // nlohmann's "number overflow": a literal such as 1e999 that is no finite double.
            failure_ = ParseFailure{current_path(true), "expected a finite number, found " +
                                                            last_token + " (at " + where +
                                                            "), which overflows to infinity"};
            return false;
        }
        // Drop nlohmann's "[json.exception...] parse error at line L, column C: " prefix;
        // we give the position ourselves.
        std::string what = ex.what();
        const std::size_t col = what.find("column ");
        const std::size_t colon = col == std::string::npos ? col : what.find(": ", col);
        if (colon != std::string::npos) what = what.substr(colon + 2);
        failure_ = ParseFailure{"", "invalid JSON at " + where + ": " + what};
        return false;
    }

    Json& root() { return root_; }
    const std::optional<ParseFailure>& failure() const { return failure_; }

  private:
    struct Frame {
        Json* container;
        bool is_array;
        std::size_t count = 0;  // elements so far (arrays)
        std::string key;        // member being read (objects)
        std::unordered_set<std::string> keys;
    };

    bool add(Json value) {
        if (frames_.empty()) {
            root_ = std::move(value);
            current_ = &root_;
            return true;
        }
        Frame& frame = frames_.back();
        if (frame.is_array) {
            frame.container->push_back(std::move(value));
            ++frame.count;
            current_ = &frame.container->back();
        } else {
            Json& slot = (*frame.container)[frame.key];
            slot = std::move(value);
            current_ = &slot;
        }
        return true;
    }

    bool open(bool is_array) {
        if (frames_.size() >= kMaxNesting) {
            failure_ = ParseFailure{current_path(), "nesting deeper than " +
                                                        std::to_string(kMaxNesting) +
                                                        " levels; no scene needs that"};
            return false;
        }
        // The container just added stays put: its parent gains no element until it closes.
        frames_.push_back(Frame{current_, is_array, 0, {}, {}});
        return true;
    }

    // The path of the value read last, or with `pending` of the value being read (in an
    // array that is the element after the last one added).
    std::string current_path(bool pending = false) const {
        std::string path;
        for (std::size_t i = 0; i < frames_.size(); ++i) {
            const Frame& f = frames_[i];
            const bool next = pending && i + 1 == frames_.size();
            path = f.is_array
                       ? index_path(path, next ? f.count : (f.count == 0 ? 0 : f.count - 1))
                       : child_path(path, f.key);
        }
        return path;
    }

    // nlohmann reports the number of bytes read, the offending one included.
    std::pair<std::size_t, std::size_t> line_and_column(std::size_t position) const {
        const std::size_t end = std::min(position == 0 ? 0 : position - 1, text_.size());
        std::size_t line = 1, line_start = 0;
        for (std::size_t i = 0; i < end; ++i) {
            if (text_[i] == '\n') {
                ++line;
                line_start = i + 1;
            }
        }
        return {line, end - line_start + 1};
    }

    std::string_view text_;
    Json root_;
    Json* current_ = nullptr;
    std::vector<Frame> frames_;
    std::optional<ParseFailure> failure_;
};

// ---------------------------------------------------------------------------------------
// Typed reads with JSON paths.

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
        if (!json_rules::fits_float(d)) {
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

// ---------------------------------------------------------------------------------------
// The sections of a scene file.

constexpr std::array<std::string_view, 9> kTopKeys = {"image",   "camera", "background",
                                                      "ambient", "render", "materials",
                                                      "objects", "lights", "animation"};

void read_image(const Reader& r, const Json& j, ImageSettings& image) {
    static constexpr std::array<std::string_view, 3> keys = {"width", "height", "spp"};
    r.require_object(j, "image", "width, height, spp");
    r.check_keys(j, "image", keys);
    if (j.contains("width"))
        image.width = static_cast<int>(r.integer(j["width"], "image.width", 1, kMaxIntValue));
    if (j.contains("height"))
        image.height =
            static_cast<int>(r.integer(j["height"], "image.height", 1, kMaxIntValue));
    if (j.contains("spp"))
        image.spp = static_cast<int>(r.integer(j["spp"], "image.spp", 1, kMaxIntValue));
}

void read_camera(const Reader& r, const Json& j, Camera& camera) {
    const std::string path = "camera";
    r.require_object(j, path, "type, eye, lookat, up, ...");
    static constexpr std::array<std::string_view, 4> types = {"pinhole", "orthographic",
                                                              "thinlens", "fisheye"};
    if (j.contains("type")) {
        camera.type = static_cast<CameraType>(r.choice(j["type"], "camera.type", types));
    }
    static constexpr std::array<ForeignKey, 5> foreign = {
        ForeignKey{"fov", "pinhole, thinlens and fisheye cameras"},
        ForeignKey{"fov_units", "pinhole, thinlens and fisheye cameras"},
        ForeignKey{"width", "orthographic cameras"}, ForeignKey{"aperture", "thinlens cameras"},
        ForeignKey{"focus_distance", "thinlens cameras"}};
    std::vector<std::string_view> allowed = {"type", "eye", "lookat", "up"};
    switch (camera.type) {
        case CameraType::pinhole:
        case CameraType::fisheye:
            allowed.insert(allowed.end(), {"fov", "fov_units"});
            break;
        case CameraType::orthographic:
            allowed.push_back("width");
            break;
        case CameraType::thinlens:
            allowed.insert(allowed.end(), {"fov", "fov_units", "aperture", "focus_distance"});
            break;
    }
    const std::string kind =
        "a " + std::string(types[static_cast<std::size_t>(camera.type)]) + " camera";
    r.check_keys(j, path, allowed, foreign, kind);

    camera.eye =
        r.vec3(r.require_key(j, path, "eye", "the eye position [x, y, z]"), "camera.eye");
    camera.lookat = r.vec3(r.require_key(j, path, "lookat", "the look-at point [x, y, z]"),
                           "camera.lookat");
    if (j.contains("up")) camera.up = r.vec3(j["up"], "camera.up");
    if (j.contains("fov")) camera.fov = r.number(j["fov"], "camera.fov");
    if (j.contains("fov_units")) {
        // Always degrees: the key states that a small fov (scene_warnings) is meant.
        static constexpr std::array<std::string_view, 1> units = {"degrees"};
        static_cast<void>(r.choice(j["fov_units"], "camera.fov_units", units));
        camera.fov_units_stated = true;
    }
    if (j.contains("width")) camera.width = r.number(j["width"], "camera.width");
    if (camera.type == CameraType::thinlens) {
        camera.aperture =
            r.number(r.require_key(j, path, "aperture", "the lens radius (a number >= 0)"),
                     "camera.aperture");
        if (j.contains("focus_distance")) {
            camera.focus_distance = r.number(j["focus_distance"], "camera.focus_distance");
        } else {
            camera.focus_distance =
                json_rules::default_focus_distance(camera.eye, camera.lookat);
        }
    }
}

void read_background(const Reader& r, const Json& j, Background& bg) {
    const std::string path = "background";
    r.require_object(j, path, "type constant with color, or type gradient with bottom and top");
    static constexpr std::array<std::string_view, 2> types = {"constant", "gradient"};
    bg.type = static_cast<BackgroundType>(
        r.choice(r.require_key(j, path, "type", "\"constant\" or \"gradient\""),
                 "background.type", types));
    static constexpr std::array<ForeignKey, 3> foreign = {
        ForeignKey{"color", "constant backgrounds"},
        ForeignKey{"bottom", "gradient backgrounds"},
        ForeignKey{"top", "gradient backgrounds"}};
    if (bg.type == BackgroundType::constant) {
        static constexpr std::array<std::string_view, 2> keys = {"type", "color"};
        r.check_keys(j, path, keys, foreign, "a constant background");
        bg.color = r.color(r.require_key(j, path, "color", "a color [r, g, b] or a number"),
                           "background.color");
    } else {
        static constexpr std::array<std::string_view, 3> keys = {"type", "bottom", "top"};
        r.check_keys(j, path, keys, foreign, "a gradient background");
        bg.bottom = r.color(r.require_key(j, path, "bottom", "a color [r, g, b] or a number"),
                            "background.bottom");
        bg.top = r.color(r.require_key(j, path, "top", "a color [r, g, b] or a number"),
                         "background.top");
    }
}

void read_render(const Reader& r, const Json& j, RenderSettings& render) {
    static constexpr std::array<std::string_view, 3> keys = {"max_depth", "seed", "epsilon"};
    r.require_object(j, "render", "max_depth, seed, epsilon");
    r.check_keys(j, "render", keys);
    if (j.contains("max_depth")) {
        render.max_depth =
            static_cast<int>(r.integer(j["max_depth"], "render.max_depth", 0, kMaxDepthLimit));
    }
    if (j.contains("seed")) render.seed = r.unsigned64(j["seed"], "render.seed");
    if (j.contains("epsilon")) render.epsilon = r.number(j["epsilon"], "render.epsilon");
}

Material read_material(const Reader& r, const Json& j, const std::string& path) {
    static constexpr std::array<std::string_view, 8> keys = {
        "color", "kd", "ks", "shininess", "reflect", "transmit", "ior", "checker"};
    r.require_object(j, path,
                     "a material: color, kd, ks, shininess, reflect, transmit, ior, checker");
    r.check_keys(j, path, keys);
    Material m;
    if (j.contains("color")) m.color = r.color(j["color"], child_path(path, "color"));
    if (j.contains("kd")) m.kd = r.number(j["kd"], child_path(path, "kd"));
    if (j.contains("ks")) m.ks = r.number(j["ks"], child_path(path, "ks"));
    if (j.contains("shininess"))
        m.shininess = r.number(j["shininess"], child_path(path, "shininess"));
    if (j.contains("reflect")) m.reflect = r.color(j["reflect"], child_path(path, "reflect"));
    if (j.contains("transmit"))
        m.transmit = r.number(j["transmit"], child_path(path, "transmit"));
    if (j.contains("ior")) m.ior = r.number(j["ior"], child_path(path, "ior"));
    if (j.contains("checker")) {
        const std::string cpath = child_path(path, "checker");
        const Json& c = j["checker"];
        r.require_object(c, cpath, "color and size");
        static constexpr std::array<std::string_view, 2> ckeys = {"color", "size"};
        r.check_keys(c, cpath, ckeys);
        Checker checker;
        checker.color =
            r.color(r.require_key(c, cpath, "color", "the second color of the checker"),
                    child_path(cpath, "color"));
        if (c.contains("size")) checker.size = r.number(c["size"], child_path(cpath, "size"));
        m.checker = checker;
    }
    return m;
}

// A plane normal made unit length (json_rules::unit_plane_normal), or the error for zero.
Vec3 normalized_normal(const Reader& r, Vec3 n, const std::string& path) {
    const std::optional<Vec3> unit = json_rules::unit_plane_normal(n);
    if (!unit) r.fail(path, "expected a non-zero normal vector, found " + format_vec(n));
    return *unit;
}

struct MaterialTable {
    std::unordered_map<std::string, std::uint32_t> by_name;
    std::vector<std::string_view> names;  // file order, for messages
    std::optional<std::uint32_t> default_slot;
};

std::uint32_t read_object_material(const Reader& r, const Json& j, const std::string& path,
                                   Scene& scene, MaterialTable& table) {
    const auto it = j.find("material");
    if (it == j.end()) {
        // Objects without a material share one default material, added on first use.
        if (!table.default_slot) {
            table.default_slot = static_cast<std::uint32_t>(scene.materials.size());
            scene.materials.push_back(NamedMaterial{"", Material{}});
        }
        return *table.default_slot;
    }
    const std::string mpath = child_path(path, "material");
    if (it->is_string()) {
        const std::string& name = it->get_ref<const std::string&>();
        const auto found = table.by_name.find(name);
        if (found == table.by_name.end()) {
            const std::string known = table.names.empty()
                                          ? "the scene defines no named materials"
                                          : "the scene defines " + join_quoted(table.names);
            r.fail(mpath, "unknown material " + quote_text(name) +
                              suggestion(name, table.names) +
                              "; expected the name of a material in \"materials\" (" + known +
                              ") or an inline material object");
        }
        return found->second;
    }
    if (!it->is_object()) {
        r.fail(mpath,
               "expected a material name or an inline material object, found " + describe(*it));
    }
    scene.materials.push_back(NamedMaterial{"", read_material(r, *it, mpath)});
    return static_cast<std::uint32_t>(scene.materials.size() - 1);
}

void read_objects(const Reader& r, const Json& j, Scene& scene, MaterialTable& table) {
    if (!j.is_array()) r.fail("objects", "expected an array of objects, found " + describe(j));
    static constexpr std::array<std::string_view, 2> types = {"sphere", "plane"};
    static constexpr std::array<ForeignKey, 4> foreign = {
        ForeignKey{"center", "spheres"}, ForeignKey{"radius", "spheres"},
        ForeignKey{"point", "planes"}, ForeignKey{"normal", "planes"}};
    static constexpr std::array<std::string_view, 5> sphere_keys = {"type", "name", "material",
                                                                    "center", "radius"};
    static constexpr std::array<std::string_view, 5> plane_keys = {"type", "name", "material",
                                                                   "point", "normal"};
    scene.objects.reserve(j.size());
    for (std::size_t i = 0; i < j.size(); ++i) {
        const std::string path = index_path("objects", i);
        const Json& o = j[i];
        r.require_object(o, path, "an object with type sphere or plane");
        Object obj;
        obj.type = static_cast<ObjectType>(
            r.choice(r.require_key(o, path, "type", "\"sphere\" or \"plane\""),
                     child_path(path, "type"), types));
        if (obj.type == ObjectType::sphere) {
            r.check_keys(o, path, sphere_keys, foreign, "a sphere");
            obj.center =
                r.vec3(r.require_key(o, path, "center", "the sphere's center [x, y, z]"),
                       child_path(path, "center"));
            obj.radius = r.number(r.require_key(o, path, "radius", "the sphere's radius (> 0)"),
                                  child_path(path, "radius"));
        } else {
            r.check_keys(o, path, plane_keys, foreign, "a plane");
            obj.point =
                r.vec3(r.require_key(o, path, "point", "a point on the plane [x, y, z]"),
                       child_path(path, "point"));
            const std::string npath = child_path(path, "normal");
            obj.normal = normalized_normal(
                r,
                r.vec3(r.require_key(o, path, "normal", "the plane's normal [x, y, z]"), npath),
                npath);
        }
        if (o.contains("name")) {
            obj.name = r.string(o["name"], child_path(path, "name"));
            if (obj.name.empty()) {
                r.fail(child_path(path, "name"), "expected a non-empty name, found \"\"");
            }
        }
        obj.material = read_object_material(r, o, path, scene, table);
        scene.objects.push_back(std::move(obj));
    }
}

void read_lights(const Reader& r, const Json& j, Scene& scene) {
    if (!j.is_array()) r.fail("lights", "expected an array of lights, found " + describe(j));
    static constexpr std::array<std::string_view, 2> types = {"point", "directional"};
    static constexpr std::array<ForeignKey, 3> foreign = {
        ForeignKey{"position", "point lights"}, ForeignKey{"falloff", "point lights"},
        ForeignKey{"direction", "directional lights"}};
    static constexpr std::array<std::string_view, 4> point_keys = {"type", "position", "color",
                                                                   "falloff"};
    static constexpr std::array<std::string_view, 3> directional_keys = {"type", "direction",
                                                                         "color"};
    static constexpr std::array<std::string_view, 2> falloffs = {"none", "inverse-square"};
    scene.lights.reserve(j.size());
    for (std::size_t i = 0; i < j.size(); ++i) {
        const std::string path = index_path("lights", i);
        const Json& l = j[i];
        r.require_object(l, path, "a light with type point or directional");
        Light light;
        light.type = static_cast<LightType>(
            r.choice(r.require_key(l, path, "type", "\"point\" or \"directional\""),
                     child_path(path, "type"), types));
        if (light.type == LightType::point) {
            r.check_keys(l, path, point_keys, foreign, "a point light");
            light.position =
                r.vec3(r.require_key(l, path, "position", "the light's position [x, y, z]"),
                       child_path(path, "position"));
            if (l.contains("falloff")) {
                light.inverse_square =
                    r.choice(l["falloff"], child_path(path, "falloff"), falloffs) == 1;
            }
        } else {
            r.check_keys(l, path, directional_keys, foreign, "a directional light");
            light.direction = r.vec3(r.require_key(l, path, "direction",
                                                   "the direction the light travels [x, y, z]"),
                                     child_path(path, "direction"));
        }
        if (l.contains("color")) light.color = r.color(l["color"], child_path(path, "color"));
        scene.lights.push_back(light);
    }
}

// The animation block: JSON types, key names and object names here; the rules on values
// (frame order, ranges, keys that do not fit the object or camera) in Validator::animation,
// so that a hand-built Animation is checked the same way.

// Keys a camera or object has that key frames cannot change: a clearer message than
// "unknown key".
void refuse_unanimated_keys(const Reader& r, const Json& key, const std::string& path,
                            std::span<const std::string_view> unanimated,
                            std::span<const std::string_view> animated, std::string_view what) {
    for (const auto& [name, value] : key.items()) {
        if (std::find(unanimated.begin(), unanimated.end(), name) == unanimated.end()) continue;
        r.fail(child_path(path, name), "key " + quote_text(name) + " cannot be animated; " +
                                           std::string(what) + " keys may set " +
                                           join_quoted(animated.subspan(1)) +
                                           " (besides \"frame\")");
    }
}

int read_key_frame(const Reader& r, const Json& key, const std::string& path) {
    return static_cast<int>(
        r.integer(r.require_key(key, path, "frame", "the key's frame number (an integer >= 0)"),
                  child_path(path, "frame"), 0, kMaxIntValue));
}

std::vector<CameraKey> read_camera_keys(const Reader& r, const Json& j) {
    const std::string path = "animation.camera";
    if (!j.is_array()) {
        r.fail(path,
               "expected an array of camera keys such as {\"frame\": 0, \"eye\": [0, 1, 5]}, "
               "found " +
                   describe(j));
    }
    static constexpr std::array<std::string_view, 5> keys = {"frame", "eye", "lookat", "up",
                                                             "fov"};
    static constexpr std::array<std::string_view, 4> unanimated = {"type", "width", "aperture",
                                                                   "focus_distance"};
    std::vector<CameraKey> out;
    out.reserve(j.size());
    for (std::size_t i = 0; i < j.size(); ++i) {
        const std::string kpath = index_path(path, i);
        const Json& k = j[i];
        r.require_object(k, kpath, "a camera key: frame, and any of eye, lookat, up, fov");
        refuse_unanimated_keys(r, k, kpath, unanimated, keys, "camera");
        r.check_keys(k, kpath, keys);
        CameraKey key;
        key.frame = read_key_frame(r, k, kpath);
        if (k.contains("eye")) key.eye = r.vec3(k["eye"], child_path(kpath, "eye"));
        if (k.contains("lookat")) key.lookat = r.vec3(k["lookat"], child_path(kpath, "lookat"));
        if (k.contains("up")) key.up = r.vec3(k["up"], child_path(kpath, "up"));
        if (k.contains("fov")) key.fov = r.number(k["fov"], child_path(kpath, "fov"));
        out.push_back(key);
    }
    return out;
}

// Object names in file order for messages: at most a dozen, then "and N more".
std::string known_object_names(const Scene& scene) {
    std::vector<std::string_view> names;
    std::size_t total = 0;
    for (const Object& o : scene.objects) {
        if (o.name.empty()) continue;
        if (names.size() < 12) names.push_back(o.name);
        ++total;
    }
    if (total == 0) return "the scene names no objects; give one a \"name\" to animate it";
    std::string out = "the scene names " + join_quoted(names);
    if (total > names.size()) out += " and " + std::to_string(total - names.size()) + " more";
    return out;
}

std::vector<ObjectTrack> read_object_tracks(const Reader& r, const Json& j,
                                            const Scene& scene) {
    const std::string path = "animation.objects";
    if (!j.is_object()) {
        r.fail(path,
               "expected an object mapping object names to key arrays, such as "
               "{\"ball\": [{\"frame\": 0, \"center\": [0, 1, 0]}]}, found " +
                   describe(j));
    }
    std::unordered_map<std::string_view, std::uint32_t> by_name;
    std::vector<std::string_view> names;
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        const std::string& name = scene.objects[i].name;
        if (name.empty()) continue;
        by_name.emplace(name, static_cast<std::uint32_t>(i));
        names.push_back(name);
    }
    static constexpr std::array<std::string_view, 3> keys = {"frame", "center", "radius"};
    static constexpr std::array<std::string_view, 5> unanimated = {"type", "name", "material",
                                                                   "point", "normal"};
    std::vector<ObjectTrack> out;
    for (const auto& [name, value] : j.items()) {
        const std::string tpath = child_path(path, name);
        const auto found = by_name.find(name);
        if (found == by_name.end()) {
            r.fail(tpath, "unknown object " + quote_text(name) + suggestion(name, names) +
                              "; expected the \"name\" of an object in \"objects\" (" +
                              known_object_names(scene) + ")");
        }
        if (!value.is_array()) {
            r.fail(tpath,
                   "expected an array of object keys such as {\"frame\": 0, \"center\": "
                   "[0, 1, 0]}, found " +
                       describe(value));
        }
        ObjectTrack track;
        track.name = name;
        track.object = found->second;
        track.keys.reserve(value.size());
        for (std::size_t i = 0; i < value.size(); ++i) {
            const std::string kpath = index_path(tpath, i);
            const Json& k = value[i];
            r.require_object(k, kpath, "an object key: frame, and center and/or radius");
            refuse_unanimated_keys(r, k, kpath, unanimated, keys, "object");
            r.check_keys(k, kpath, keys);
            ObjectKey key;
            key.frame = read_key_frame(r, k, kpath);
            if (k.contains("center"))
                key.center = r.vec3(k["center"], child_path(kpath, "center"));
            if (k.contains("radius"))
                key.radius = r.number(k["radius"], child_path(kpath, "radius"));
            track.keys.push_back(key);
        }
        out.push_back(std::move(track));
    }
    return out;
}

Animation read_animation(const Reader& r, const Json& j, const Scene& scene) {
    const std::string path = "animation";
    r.require_object(j, path, "frames, fps, camera, objects");
    static constexpr std::array<std::string_view, 4> keys = {"frames", "fps", "camera",
                                                             "objects"};
    r.check_keys(j, path, keys);
    Animation a;
    a.frames = static_cast<int>(
        r.integer(r.require_key(j, path, "frames", "the number of frames (an integer >= 1)"),
                  "animation.frames", 1, kMaxAnimationFrames));
    if (j.contains("fps")) {
        const Json& fps = j["fps"];
        if (!fps.is_number()) {
            r.fail("animation.fps",
                   "expected frames per second (a number > 0), found " + describe(fps));
        }
        a.fps = fps.get<double>();
    }
    if (j.contains("camera")) a.camera = read_camera_keys(r, j["camera"]);
    if (j.contains("objects")) a.objects = read_object_tracks(r, j["objects"], scene);
    return a;
}

// ---------------------------------------------------------------------------------------
// Semantic checks on an in-memory scene.

std::int64_t physical_memory_bytes() {
    const long pages = sysconf(_SC_PHYS_PAGES);
    const long page_size = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page_size <= 0) return 0;  // unknown: skip the check
    const auto total = static_cast<std::int64_t>(pages);
    if (total > std::numeric_limits<std::int64_t>::max() / page_size) {
        return std::numeric_limits<std::int64_t>::max();
    }
    return total * page_size;
}

std::string format_gib(std::int64_t bytes) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.1f GiB", static_cast<double>(bytes) / 1073741824.0);
    return buf;
}

class Validator {
  public:
    explicit Validator(const Scene& scene) : scene_(scene) {}

    [[noreturn]] void fail(const std::string& path, const std::string& message) const {
        throw SceneError(scene_.source, path, message);
    }

    void finite(float v, const std::string& path) const {
        if (!std::isfinite(v)) fail(path, "expected a finite number, found " + format_float(v));
    }
    void positive(float v, const std::string& path, std::string_view what) const {
        if (!(std::isfinite(v) && v > 0.0f)) {
            fail(path, "expected " + std::string(what) + " > 0, found " + format_float(v));
        }
    }
    void non_negative(float v, const std::string& path, std::string_view what) const {
        if (!(std::isfinite(v) && v >= 0.0f)) {
            fail(path, "expected " + std::string(what) + " >= 0, found " + format_float(v));
        }
    }
    void finite(Vec3 v, const std::string& path) const {
        if (!is_finite(v)) fail(path, "expected finite coordinates, found " + format_vec(v));
    }
    void color(Rgb c, const std::string& path) const {
        if (!(is_finite(c) && c.r >= 0.0f && c.g >= 0.0f && c.b >= 0.0f)) {
            fail(path, "expected a color with finite, non-negative components, found " +
                           format_rgb(c));
        }
    }
    void int_range(int v, const std::string& path, int lo, int hi) const {
        if (v < lo || v > hi) {
            fail(path, "expected an integer from " + std::to_string(lo) + " to " +
                           std::to_string(hi) + ", found " + std::to_string(v));
        }
    }

    // Where a material came from: materials.<name>, or the first object that uses it inline.
    std::string material_path(std::size_t index) const {
        const NamedMaterial& nm = scene_.materials[index];
        if (!nm.name.empty()) return child_path("materials", nm.name);
        for (std::size_t i = 0; i < scene_.objects.size(); ++i) {
            if (scene_.objects[i].material == index) {
                return child_path(index_path("objects", i), "material");
            }
        }
        return index_path("materials", index);
    }

    void image() const {
        const ImageSettings& im = scene_.image;
        int_range(im.width, "image.width", 1, kMaxIntValue);
        int_range(im.height, "image.height", 1, kMaxIntValue);
        int_range(im.spp, "image.spp", 1, kMaxIntValue);
        // Both factors are below 2^31, so neither product overflows 64 bits (nor does the
        // sample count width * height * spp, which stays below 2^62).
        const std::int64_t pixels = static_cast<std::int64_t>(im.width) * im.height;
        const std::string size = std::to_string(im.width) + " x " + std::to_string(im.height);
        if (pixels > kMaxPixels) {
            fail("image", "a " + size + " image has " + std::to_string(pixels) +
                              " pixels; expected at most 2147483647 (2^31 - 1)");
        }
        const std::int64_t bytes = pixels * kFramebufferBytesPerPixel;
        const std::int64_t memory = physical_memory_bytes();
        if (memory > 0 && bytes > memory) {
            fail("image", "a " + size + " image needs about " + format_gib(bytes) +
                              " for its framebuffer alone (12 bytes per pixel); expected it to "
                              "fit in the " +
                              format_gib(memory) + " of physical memory");
        }
    }

    void camera() const {
        const Camera& c = scene_.camera;
        finite(c.eye, "camera.eye");
        finite(c.lookat, "camera.lookat");
        finite(c.up, "camera.up");
        if (c.up == Vec3{}) fail("camera.up", "expected a non-zero up vector, found [0, 0, 0]");
        switch (c.type) {
            case CameraType::orthographic:
                positive(c.width, "camera.width", "a film width");
                break;
            case CameraType::thinlens:
                non_negative(c.aperture, "camera.aperture", "a lens radius");
                positive(c.focus_distance, "camera.focus_distance", "a focus distance");
                if (c.focus_distance > kMaxFocusDistance) {
                    fail("camera.focus_distance",
                         "expected a focus distance of at most " +
                             format_float(kMaxFocusDistance) +
                             " (farther, the focal point overflows float), found " +
                             format_float(c.focus_distance));
                }
                if (c.aperture > kMaxApertureRatio * c.focus_distance) {
                    fail("camera.aperture",
                         "expected a lens radius of at most 10 x the focus distance (here 10 "
                         "x " +
                             format_float(c.focus_distance) + " = " +
                             format_float(kMaxApertureRatio * c.focus_distance) +
                             "; a wider lens starts rays so far off the view axis that float "
                             "precision breaks down), found " +
                             format_float(c.aperture));
                }
                break;
            case CameraType::pinhole:
            case CameraType::fisheye:
                break;
        }
        // The camera frame is the one authority on what a usable camera is.
        try {
            (void)make_camera_frame(c, scene_.image.width, scene_.image.height);
        } catch (const std::invalid_argument& e) {
            static constexpr std::array<std::string_view, 4> names = {"pinhole", "orthographic",
                                                                      "thinlens", "fisheye"};
            std::string found = std::string(names[static_cast<std::size_t>(c.type)]) +
                                " camera, eye " + format_vec(c.eye) + ", lookat " +
                                format_vec(c.lookat) + ", up " + format_vec(c.up);
            if (c.type != CameraType::orthographic) found += ", fov " + format_float(c.fov);
            fail("camera", std::string(e.what()) + " (found " + found + ")");
        }
    }

    void background() const {
        const Background& bg = scene_.background;
        if (bg.type == BackgroundType::constant) {
            color(bg.color, "background.color");
        } else {
            color(bg.bottom, "background.bottom");
            color(bg.top, "background.top");
        }
        color(scene_.ambient, "ambient");
    }

    void render() const {
        int_range(scene_.render.max_depth, "render.max_depth", 0, kMaxDepthLimit);
        if (scene_.render.epsilon)
            positive(*scene_.render.epsilon, "render.epsilon", "epsilon");
    }

    void materials() const {
        std::unordered_set<std::string_view> names;
        for (std::size_t i = 0; i < scene_.materials.size(); ++i) {
            const std::string path = material_path(i);
            const NamedMaterial& nm = scene_.materials[i];
            if (!nm.name.empty() && !names.insert(nm.name).second) {
                fail(path, "duplicate material name " + quote_text(nm.name));
            }
            const Material& m = nm.material;
            color(m.color, child_path(path, "color"));
            non_negative(m.kd, child_path(path, "kd"), "kd");
            non_negative(m.ks, child_path(path, "ks"), "ks");
            non_negative(m.shininess, child_path(path, "shininess"), "a Phong exponent");
            color(m.reflect, child_path(path, "reflect"));
            non_negative(m.transmit, child_path(path, "transmit"), "transmit");
            positive(m.ior, child_path(path, "ior"), "an index of refraction");
            if (m.ior < kMinIor || m.ior > kMaxIor) {
                fail(child_path(path, "ior"),
                     "expected an index of refraction from " + format_float(kMinIor) + " to " +
                         format_float(kMaxIor) +
                         " (far beyond that ratio refraction loses float precision), found " +
                         format_float(m.ior));
            }
            if (m.checker) {
                const std::string cpath = child_path(path, "checker");
                color(m.checker->color, child_path(cpath, "color"));
                positive(m.checker->size, child_path(cpath, "size"), "a checker size");
            }
        }
    }

    void objects() const {
        // Paths are built only for a failing object: a valid scene of millions of spheres
        // would otherwise build several strings per object for nothing.
        std::unordered_map<std::string_view, std::size_t> names;
        for (std::size_t i = 0; i < scene_.objects.size(); ++i) {
            const auto path = [i] { return index_path("objects", i); };
            const Object& o = scene_.objects[i];
            if (o.material >= scene_.materials.size()) {
                fail(child_path(path(), "material"),
                     "expected a material index below " +
                         std::to_string(scene_.materials.size()) +
                         " (the scene's material count), found " + std::to_string(o.material));
            }
            if (o.type == ObjectType::sphere) {
                if (!is_finite(o.center)) finite(o.center, child_path(path(), "center"));
                if (!(std::isfinite(o.radius) && o.radius > 0.0f))
                    positive(o.radius, child_path(path(), "radius"), "a radius");
            } else {
                if (!is_finite(o.point)) finite(o.point, child_path(path(), "point"));
                if (!is_finite(o.normal)) finite(o.normal, child_path(path(), "normal"));
                const double len2 = static_cast<double>(o.normal.x) * o.normal.x +
                                    static_cast<double>(o.normal.y) * o.normal.y +
                                    static_cast<double>(o.normal.z) * o.normal.z;
                if (!(std::fabs(len2 - 1.0) <= kValidateUnitTolerance)) {
                    fail(child_path(path(), "normal"),
                         "expected a unit-length normal (scene files are normalised on load), "
                         "found " +
                             format_vec(o.normal));
                }
            }
            if (!o.name.empty()) {
                const auto [it, inserted] = names.emplace(o.name, i);
                if (!inserted) {
                    fail(child_path(path(), "name"), "expected a unique object name, found " +
                                                         quote_text(o.name) +
                                                         " again (first used by objects[" +
                                                         std::to_string(it->second) + "])");
                }
            }
        }
        // The self-intersection offset is derived from the spheres' bounding box; a box
        // that overflows float would make it infinite.
        const float eps = self_intersection_epsilon(scene_);
        if (!std::isfinite(eps)) {
            fail("objects",
                 "the spheres' bounding box overflows float range; expected "
                 "coordinates and radii small enough that its diagonal is finite");
        }
    }

    // Key frames strictly increasing, within [0, 2^31 - 1].
    template <typename Key>
    void key_frames(const std::vector<Key>& keys, const std::string& path) const {
        for (std::size_t i = 0; i < keys.size(); ++i) {
            const std::string fpath = child_path(index_path(path, i), "frame");
            if (keys[i].frame < 0) {
                fail(fpath,
                     "expected a frame number >= 0, found " + std::to_string(keys[i].frame));
            }
            if (i > 0 && keys[i].frame <= keys[i - 1].frame) {
                fail(fpath, "expected key frames in strictly increasing order, found frame " +
                                std::to_string(keys[i].frame) + " after frame " +
                                std::to_string(keys[i - 1].frame) + " (" +
                                index_path(path, i - 1) + ")");
            }
        }
    }

    // The animation's own rules, then the camera of every frame that can differ (the pose
    // is constant after the last camera key) through the same checks as the still camera.
    void animation() const {
        if (!scene_.animation) return;
        const Animation& a = *scene_.animation;
        int_range(a.frames, "animation.frames", 1, kMaxAnimationFrames);
        if (!(std::isfinite(a.fps) && a.fps > 0.0)) {
            char buf[64];
            std::snprintf(buf, sizeof buf, "%g", a.fps);
            fail("animation.fps", std::string("expected frames per second > 0, found ") + buf);
        }

        const Camera& c = scene_.camera;
        key_frames(a.camera, "animation.camera");
        for (std::size_t i = 0; i < a.camera.size(); ++i) {
            const CameraKey& k = a.camera[i];
            const std::string path = index_path("animation.camera", i);
            if (!k.eye && !k.lookat && !k.up && !k.fov) {
                fail(path,
                     "a camera key sets nothing; expected at least one of \"eye\", "
                     "\"lookat\", \"up\", \"fov\" besides \"frame\"");
            }
            if (k.eye) finite(*k.eye, child_path(path, "eye"));
            if (k.lookat) finite(*k.lookat, child_path(path, "lookat"));
            if (k.up) {
                finite(*k.up, child_path(path, "up"));
                if (*k.up == Vec3{}) {
                    fail(child_path(path, "up"),
                         "expected a non-zero up vector, found [0, 0, 0]");
                }
            }
            if (k.fov) {
                const std::string fpath = child_path(path, "fov");
                if (c.type == CameraType::orthographic) {
                    fail(fpath,
                         "key \"fov\" applies only to pinhole, thinlens and fisheye "
                         "cameras, not to an orthographic camera");
                }
                const float fov = *k.fov;
                const bool fisheye = c.type == CameraType::fisheye;
                const bool ok =
                    fisheye ? (fov > 0.0f && fov <= 360.0f) : (fov > 0.0f && fov < 180.0f);
                if (!ok) {
                    fail(fpath, std::string("expected a field of view in ") +
                                    (fisheye ? "(0, 360]" : "(0, 180)") + " degrees, found " +
                                    format_float(fov));
                }
            }
        }

        std::unordered_set<std::uint32_t> animated;
        for (const ObjectTrack& track : a.objects) {
            const std::string path = child_path("animation.objects", track.name);
            if (track.object >= scene_.objects.size()) {
                fail(path,
                     "expected an object index below " + std::to_string(scene_.objects.size()) +
                         " (the scene's object count), found " + std::to_string(track.object));
            }
            const Object& o = scene_.objects[track.object];
            const std::string opath = index_path("objects", track.object);
            if (o.name != track.name) {
                fail(path, "the track is for " + quote_text(track.name) + " but " + opath +
                               " is named " + quote_text(o.name));
            }
            if (!animated.insert(track.object).second) {
                fail(path, "expected one track per object, found a second one for " +
                               quote_text(track.name));
            }
            key_frames(track.keys, path);
            for (std::size_t i = 0; i < track.keys.size(); ++i) {
                const ObjectKey& k = track.keys[i];
                const std::string kpath = index_path(path, i);
                if (!k.center && !k.radius) {
                    fail(kpath,
                         "an object key sets nothing; expected \"center\" and/or "
                         "\"radius\" besides \"frame\"");
                }
                const auto sphere_only = [&](std::string_view key) {
                    fail(child_path(kpath, key),
                         "key " + quote_text(key) +
                             " applies only to spheres, not to a plane (" + opath + ", " +
                             quote_text(o.name) + ")");
                };
                if (k.center) {
                    if (o.type != ObjectType::sphere) sphere_only("center");
                    finite(*k.center, child_path(kpath, "center"));
                }
                if (k.radius) {
                    if (o.type != ObjectType::sphere) sphere_only("radius");
                    positive(*k.radius, child_path(kpath, "radius"), "a radius");
                }
            }
        }

        animated_bounds(a);
        animated_cameras(a);
    }

    // Interpolated centers and radii stay within the range of the keys' and the authored
    // values, so the box of all of them bounds every frame's spheres: if its diagonal is
    // finite, so is every frame's ε_s.
    void animated_bounds(const Animation& a) const {
        if (scene_.render.epsilon || a.objects.empty()) return;
        Scene hull;
        hull.objects = scene_.objects;
        for (const ObjectTrack& track : a.objects) {
            const Object& o = scene_.objects[track.object];
            float radius = o.radius;
            for (const ObjectKey& k : track.keys) {
                if (k.radius) radius = std::max(radius, *k.radius);
            }
            for (const ObjectKey& k : track.keys) {
                if (!k.center) continue;
                Object extra = o;
                extra.center = *k.center;
                extra.radius = radius;
                hull.objects.push_back(extra);
            }
            hull.objects[track.object].radius = radius;
        }
        if (!std::isfinite(self_intersection_epsilon(hull))) {
            fail("animation.objects",
                 "the spheres' bounding box over all frames overflows float range; expected "
                 "coordinates and radii small enough that its diagonal is finite");
        }
    }

    void animated_cameras(const Animation& a) const {
        if (a.camera.empty()) return;
        // After the last camera key every frame has the pose of that key's frame.
        const int last = std::min(a.frames - 1, a.camera.back().frame);
        Scene still;
        still.source = scene_.source;
        still.image = scene_.image;
        visit_camera_frames(scene_, 0, last, [&](int f, const Camera& camera) {
            still.camera = camera;
            try {
                Validator(still).camera();
            } catch (const SceneError& e) {
                std::string what = e.what();
                const std::string prefix = e.json_path() + ": ";
                const std::size_t at = what.find(prefix);
                if (at != std::string::npos) what.erase(0, at + prefix.size());
                fail("animation.camera", "at frame " + std::to_string(f) +
                                             " the interpolated camera is unusable: " + what);
            }
        });
    }

    void lights() const {
        for (std::size_t i = 0; i < scene_.lights.size(); ++i) {
            const std::string path = index_path("lights", i);
            const Light& l = scene_.lights[i];
            if (l.type == LightType::point) {
                finite(l.position, child_path(path, "position"));
            } else {
                finite(l.direction, child_path(path, "direction"));
                if (l.direction == Vec3{}) {
                    fail(child_path(path, "direction"),
                         "expected a non-zero direction, found [0, 0, 0]");
                }
            }
            color(l.color, child_path(path, "color"));
        }
    }

  private:
    const Scene& scene_;
};

}  // namespace

Scene parse_scene_json(std::string_view json_text, const std::string& source,
                       std::size_t readable) {
    if (std::optional<Scene> scene = parse_scene_json_fast(json_text, source, readable)) {
        return std::move(*scene);
    }
    return parse_scene_json_diagnosing(json_text, source);
}

Scene parse_scene_json_diagnosing(std::string_view json_text, const std::string& source) {
    // The JSON library ends its input at a NUL byte, which would let anything after one
    // pass unread; strict JSON means the whole file, and JSON text never holds a NUL.
    if (const std::size_t nul = json_text.find('\0'); nul != std::string_view::npos) {
        std::size_t line = 1, line_start = 0;
        for (std::size_t i = 0; i < nul; ++i) {
            if (json_text[i] == '\n') {
                ++line;
                line_start = i + 1;
            }
        }
        throw SceneError(source, "",
                         "invalid JSON at line " + std::to_string(line) + ", column " +
                             std::to_string(nul - line_start + 1) +
                             ": a NUL byte (\\0); expected JSON text, which has none (a "
                             "NUL inside a string is written \\u0000)");
    }
    DomBuilder builder(json_text);
    const bool ok = Json::sax_parse(json_text, &builder, Json::input_format_t::json,
                                    /*strict=*/true, /*ignore_comments=*/false);
    if (!ok || builder.failure()) {
        const ParseFailure failure =
            builder.failure() ? *builder.failure() : ParseFailure{"", "invalid JSON"};
        throw SceneError(source, failure.path, failure.message);
    }
    const Json& root = builder.root();
    const Reader r(source);
    if (!root.is_object()) {
        r.fail("", "expected a JSON object at the top level, found " + describe(root));
    }
    r.check_keys(root, "", kTopKeys);

    Scene scene;
    scene.source = source;
    if (root.contains("image")) read_image(r, root["image"], scene.image);
    read_camera(
        r, r.require_key(root, "", "camera", "an object with at least \"eye\" and \"lookat\""),
        scene.camera);
    if (root.contains("background")) read_background(r, root["background"], scene.background);
    if (root.contains("ambient")) scene.ambient = r.color(root["ambient"], "ambient");
    if (root.contains("render")) read_render(r, root["render"], scene.render);

    MaterialTable table;
    if (root.contains("materials")) {
        const Json& mats = root["materials"];
        if (!mats.is_object()) {
            r.fail("materials",
                   "expected an object mapping names to materials, found " + describe(mats));
        }
        for (const auto& [name, value] : mats.items()) {
            const std::string path = child_path("materials", name);
            if (name.empty()) r.fail(path, "expected a non-empty material name");
            table.by_name.emplace(name, static_cast<std::uint32_t>(scene.materials.size()));
            scene.materials.push_back(NamedMaterial{name, read_material(r, value, path)});
        }
        for (const NamedMaterial& nm : scene.materials) table.names.push_back(nm.name);
    }
    if (root.contains("objects")) read_objects(r, root["objects"], scene, table);
    if (root.contains("lights")) read_lights(r, root["lights"], scene);
    if (root.contains("animation"))
        scene.animation = read_animation(r, root["animation"], scene);

    validate_scene(scene);
    return scene;
}

std::string read_scene_file(const std::string& path) { return read_scene_file(path, {}); }

std::string read_scene_file(const std::string& path,
                            const std::function<void(std::string_view)>& on_chunk) {
    // O_NONBLOCK: opening a FIFO must not wait for a writer; it is refused below anyway.
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        throw SceneError(path, "",
                         "cannot open scene file: " + std::generic_category().message(errno));
    }
    const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(::fdopen(fd, "rb"),
                                                               &std::fclose);
    if (!file) {
        const int error = errno;
        ::close(fd);
        throw SceneError(path, "",
                         "cannot read scene file: " + std::generic_category().message(error));
    }
    // Only a regular file has an end: /dev/zero, /dev/urandom or a pipe would be read
    // forever (or block), so they are refused before the first byte is read.
    struct stat info {};
    if (::fstat(fd, &info) != 0) {
        throw SceneError(path, "",
                         "cannot read scene file: " + std::generic_category().message(errno));
    }
    if (S_ISDIR(info.st_mode)) {
        throw SceneError(path, "",
                         "cannot read scene file: " + std::generic_category().message(EISDIR) +
                             "; expected a regular file");
    }
    if (!S_ISREG(info.st_mode)) {
        const char* kind = S_ISCHR(info.st_mode)    ? "a character device"
                           : S_ISBLK(info.st_mode)  ? "a block device"
                           : S_ISFIFO(info.st_mode) ? "a pipe (FIFO)"
                           : S_ISSOCK(info.st_mode) ? "a socket"
                                                    : "not a plain file";
        throw SceneError(path, "",
                         std::string("cannot read scene file: it is ") + kind +
                             "; expected a regular file (a JSON scene)");
    }
    // Read straight into the string (no bounce buffer), a chunk at a time so that the
    // caller's hash sees each chunk while it is in cache. The string holds the size fstat
    // gave plus the padding; it grows only if the file grows while it is read.
    constexpr std::size_t kChunk = std::size_t{1} << 20;
    std::string text;
    text.reserve(static_cast<std::size_t>(info.st_size) + kJsonPadding);
    offer_huge_pages(text.data(), text.capacity());  // fewer page faults while filled
    std::size_t size = 0;
    for (;;) {
        const std::size_t room = text.capacity() - kJsonPadding - size;
        if (room == 0) {
            // Full: at the end of the file, unless it grew since fstat.
            char byte = 0;
            if (std::fread(&byte, 1, 1, file.get()) == 0) break;
            text.reserve(text.capacity() * 2);
            text.push_back(byte);
            if (on_chunk) on_chunk(std::string_view(&text[size], 1));
            ++size;
            continue;
        }
        const std::size_t want = std::min(kChunk, room);
        text.resize(size + want);
        const std::size_t n = std::fread(text.data() + size, 1, want, file.get());
        if (on_chunk && n > 0) on_chunk(std::string_view(text.data() + size, n));
        size += n;
        text.resize(size);
        if (n < want) break;
    }
    if (std::ferror(file.get())) {
        throw SceneError(path, "",
                         "cannot read scene file: " + std::generic_category().message(errno));
    }
    // Zeroed padding: the fast reader's blocks past the end read defined bytes.
    text.append(kJsonPadding, '\0');
    text.resize(size);
    return text;
}

Scene load_scene_file(const std::string& path) {
    const std::string text = read_scene_file(path);
    return parse_scene_json(text, path, text.capacity());
}

Scene load_scene(const std::string& spec) {
    if (is_builtin_scene(spec)) return make_builtin_scene(spec);
    return load_scene_file(spec);
}

void validate_scene(const Scene& scene) {
    const Validator v(scene);
    v.image();
    v.camera();
    v.background();
    v.render();
    v.materials();
    v.objects();
    v.lights();
    v.animation();
}

}  // namespace octray
