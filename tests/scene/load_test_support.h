#pragma once
// What the scene loading tests share (load_test.cpp, load_error_test.cpp,
// validate_test.cpp): a scene using every key, and checks that a SceneError names the
// file, the JSON path and what was expected.

#include <gtest/gtest.h>

#include <functional>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>

#include "scene/load.h"

namespace octray::testing {

using Json = nlohmann::ordered_json;

inline const std::string kFile = "test.json";

// A scene using every key the format has (one camera and one background type at a time).
inline const char* const kFullScene = R"json({
  "image":  { "width": 320, "height": 200, "spp": 4 },
  "camera": { "type": "pinhole", "eye": [0, 1, 5], "lookat": [0, 0.5, 0],
              "up": [0, 1, 0], "fov": 50 },
  "background": { "type": "gradient", "bottom": [1, 1, 1], "top": [0.5, 0.7, 1.0] },
  "ambient": [0.05, 0.06, 0.07],
  "render": { "max_depth": 7, "seed": 42, "epsilon": 0.001 },
  "materials": {
    "chrome": { "color": [0.9, 0.8, 0.7], "kd": 0.1, "ks": 0.5, "shininess": 64, "reflect": 0.8 },
    "glass":  { "color": 1, "kd": 0, "ks": 0.5, "shininess": 128,
                "reflect": [0.1, 0.2, 0.3], "transmit": 0.9, "ior": 1.5 },
    "floor":  { "color": [0.9, 0.9, 0.9], "checker": { "color": [0.1, 0.1, 0.1], "size": 2 } }
  },
  "objects": [
    { "type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "chrome", "name": "ball" },
    { "type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "floor" },
    { "type": "sphere", "center": [2, 1, 0], "radius": 0.5, "material": "glass" },
    { "type": "sphere", "center": [-2, 1, 0], "radius": 0.25,
      "material": { "color": [1, 0, 0], "ks": 0.25 } }
  ],
  "lights": [
    { "type": "point", "position": [5, 8, 5], "color": [1, 0.9, 0.8], "falloff": "inverse-square" },
    { "type": "directional", "direction": [-1, -1, -0.5], "color": 0.3 }
  ]
})json";

inline Json full_scene() { return Json::parse(kFullScene); }

inline Scene parse(const Json& j) { return parse_scene_json(j.dump(), kFile); }

// Runs `f`, which must throw a SceneError for `file` at `path` whose message contains the
// file, the path and every one of `needles`.
inline void expect_error(const std::function<void()>& f, const std::string& file,
                         const std::string& path, std::initializer_list<std::string> needles) {
    try {
        f();
        ADD_FAILURE() << "expected a SceneError at \"" << path << "\"";
    } catch (const SceneError& e) {
        const std::string what = e.what();
        EXPECT_EQ(e.file(), file) << what;
        EXPECT_EQ(e.json_path(), path) << what;
        // "file: " or, for an error in a file's text, "file:line:column: ".
        const SourcePosition at = e.position();
        const std::string prefix = file + (at.line > 0 ? ":" + std::to_string(at.line) + ":" +
                                                             std::to_string(at.column) + ": "
                                                       : ": ");
        EXPECT_EQ(what.rfind(prefix, 0), 0u) << what;
        if (!path.empty()) {
            EXPECT_NE(what.find(": " + path + ": "), std::string::npos) << what;
        }
        for (const std::string& n : needles) {
            EXPECT_NE(what.find(n), std::string::npos)
                << "missing \"" << n << "\" in: " << what;
        }
    }
}

inline void expect_json_error(const Json& j, const std::string& path,
                              std::initializer_list<std::string> needles) {
    expect_error([&] { parse(j); }, kFile, path, needles);
}

inline void expect_text_error(const std::string& text, const std::string& path,
                              std::initializer_list<std::string> needles) {
    expect_error([&] { parse_scene_json(text, kFile); }, kFile, path, needles);
}

inline Json minimal_scene() {
    return Json{{"camera", {{"eye", {0, 0, 5}}, {"lookat", {0, 0, 0}}}}};
}

}  // namespace octray::testing
