// The "animation" block of a scene file for the diagnosing reader (docs/scene-format.md,
// "animation"; scene/read_animation.h).

#include "scene/read_animation.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "scene/animation.h"

namespace octray::scene_json {
namespace {

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

}  // namespace

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

}  // namespace octray::scene_json
