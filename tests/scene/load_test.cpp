// JSON scene loading: every key of docs/scene-format.md, the defaults of
// scene/README.md, and every error with its file, JSON path and expectation.

#include "scene/load.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

namespace octray {
namespace {

using Json = nlohmann::ordered_json;

const std::string kFile = "test.json";

// A scene using every key the format has (one camera and one background type at a time).
const char* const kFullScene = R"json({
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

Json full_scene() { return Json::parse(kFullScene); }

Scene parse(const Json& j) { return parse_scene_json(j.dump(), kFile); }

// Runs `f`, which must throw a SceneError for `file` at `path` whose message contains the
// file, the path and every one of `needles`.
void expect_error(const std::function<void()>& f, const std::string& file,
                  const std::string& path, std::initializer_list<std::string> needles) {
    try {
        f();
        ADD_FAILURE() << "expected a SceneError at \"" << path << "\"";
    } catch (const SceneError& e) {
        const std::string what = e.what();
        EXPECT_EQ(e.file(), file) << what;
        EXPECT_EQ(e.json_path(), path) << what;
        EXPECT_EQ(what.rfind(file + ": ", 0), 0u) << what;
        if (!path.empty()) {
            EXPECT_NE(what.find(": " + path + ": "), std::string::npos) << what;
        }
        for (const std::string& n : needles) {
            EXPECT_NE(what.find(n), std::string::npos)
                << "missing \"" << n << "\" in: " << what;
        }
    }
}

void expect_json_error(const Json& j, const std::string& path,
                       std::initializer_list<std::string> needles) {
    expect_error([&] { parse(j); }, kFile, path, needles);
}

void expect_text_error(const std::string& text, const std::string& path,
                       std::initializer_list<std::string> needles) {
    expect_error([&] { parse_scene_json(text, kFile); }, kFile, path, needles);
}

Json minimal_scene() { return Json{{"camera", {{"eye", {0, 0, 5}}, {"lookat", {0, 0, 0}}}}}; }

// ---------------------------------------------------------------------------------------
// Valid scenes

TEST(SceneLoad, FullSceneHasEveryValue) {
    const Scene s = parse_scene_json(kFullScene, kFile);
    EXPECT_EQ(s.source, kFile);
    EXPECT_EQ(s.image.width, 320);
    EXPECT_EQ(s.image.height, 200);
    EXPECT_EQ(s.image.spp, 4);
    EXPECT_EQ(s.camera.type, CameraType::pinhole);
    EXPECT_EQ(s.camera.eye, (Vec3{0, 1, 5}));
    EXPECT_EQ(s.camera.lookat, (Vec3{0, 0.5f, 0}));
    EXPECT_EQ(s.camera.up, (Vec3{0, 1, 0}));
    EXPECT_EQ(s.camera.fov, 50.0f);
    EXPECT_EQ(s.background.type, BackgroundType::gradient);
    EXPECT_EQ(s.background.bottom, Rgb(1.0f));
    EXPECT_EQ(s.background.top, (Rgb{0.5f, 0.7f, 1.0f}));
    EXPECT_EQ(s.ambient, (Rgb{0.05f, 0.06f, 0.07f}));
    EXPECT_EQ(s.render.max_depth, 7);
    EXPECT_EQ(s.render.seed, 42u);
    ASSERT_TRUE(s.render.epsilon.has_value());
    EXPECT_EQ(*s.render.epsilon, 0.001f);

    // Named materials in file order (not alphabetical), then inline ones.
    ASSERT_EQ(s.materials.size(), 4u);
    EXPECT_EQ(s.materials[0].name, "chrome");
    EXPECT_EQ(s.materials[1].name, "glass");
    EXPECT_EQ(s.materials[2].name, "floor");
    EXPECT_EQ(s.materials[3].name, "");
    const Material& chrome = s.materials[0].material;
    EXPECT_EQ(chrome.color, (Rgb{0.9f, 0.8f, 0.7f}));
    EXPECT_EQ(chrome.kd, 0.1f);
    EXPECT_EQ(chrome.ks, 0.5f);
    EXPECT_EQ(chrome.shininess, 64.0f);
    EXPECT_EQ(chrome.reflect, Rgb(0.8f));
    EXPECT_EQ(chrome.transmit, 0.0f);
    EXPECT_EQ(chrome.ior, 1.5f);
    EXPECT_FALSE(chrome.checker.has_value());
    const Material& glass = s.materials[1].material;
    EXPECT_EQ(glass.color, Rgb(1.0f));
    EXPECT_EQ(glass.kd, 0.0f);
    EXPECT_EQ(glass.shininess, 128.0f);
    EXPECT_EQ(glass.reflect, (Rgb{0.1f, 0.2f, 0.3f}));
    EXPECT_EQ(glass.transmit, 0.9f);
    EXPECT_EQ(glass.ior, 1.5f);
    const Material& floor = s.materials[2].material;
    ASSERT_TRUE(floor.checker.has_value());
    EXPECT_EQ(floor.checker->color, Rgb(0.1f));
    EXPECT_EQ(floor.checker->size, 2.0f);
    const Material& inline_red = s.materials[3].material;
    EXPECT_EQ(inline_red.color, (Rgb{1, 0, 0}));
    EXPECT_EQ(inline_red.ks, 0.25f);
    EXPECT_EQ(inline_red.kd, 1.0f);  // unset keys keep the material defaults

    ASSERT_EQ(s.objects.size(), 4u);
    EXPECT_EQ(s.objects[0].type, ObjectType::sphere);
    EXPECT_EQ(s.objects[0].name, "ball");
    EXPECT_EQ(s.objects[0].center, (Vec3{0, 1, 0}));
    EXPECT_EQ(s.objects[0].radius, 1.0f);
    EXPECT_EQ(s.objects[0].material, 0u);
    EXPECT_EQ(s.objects[1].type, ObjectType::plane);
    EXPECT_EQ(s.objects[1].point, (Vec3{0, 0, 0}));
    EXPECT_EQ(s.objects[1].normal, (Vec3{0, 1, 0}));
    EXPECT_EQ(s.objects[1].material, 2u);
    EXPECT_EQ(s.objects[1].name, "");
    EXPECT_EQ(s.objects[2].material, 1u);
    EXPECT_EQ(s.objects[2].radius, 0.5f);
    EXPECT_EQ(s.objects[3].material, 3u);

    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_EQ(s.lights[0].type, LightType::point);
    EXPECT_EQ(s.lights[0].position, (Vec3{5, 8, 5}));
    EXPECT_EQ(s.lights[0].color, (Rgb{1, 0.9f, 0.8f}));
    EXPECT_TRUE(s.lights[0].inverse_square);
    EXPECT_EQ(s.lights[1].type, LightType::directional);
    EXPECT_EQ(s.lights[1].direction, (Vec3{-1, -1, -0.5f}));
    EXPECT_EQ(s.lights[1].color, Rgb(0.3f));
}

TEST(SceneLoad, DefaultsOfAMinimalScene) {
    const Scene s = parse(minimal_scene());
    EXPECT_EQ(s.image.width, 640);
    EXPECT_EQ(s.image.height, 480);
    EXPECT_EQ(s.image.spp, 1);
    EXPECT_EQ(s.camera.type, CameraType::pinhole);
    EXPECT_EQ(s.camera.up, (Vec3{0, 1, 0}));
    EXPECT_EQ(s.camera.fov, 50.0f);
    EXPECT_EQ(s.background.type, BackgroundType::constant);
    EXPECT_EQ(s.background.color, Rgb(0.0f));
    EXPECT_EQ(s.ambient, Rgb(0.0f));
    EXPECT_EQ(s.render.max_depth, 5);
    EXPECT_EQ(s.render.seed, 0u);
    EXPECT_FALSE(s.render.epsilon.has_value());
    EXPECT_TRUE(s.materials.empty());
    EXPECT_TRUE(s.objects.empty());
    EXPECT_TRUE(s.lights.empty());
}

TEST(SceneLoad, ObjectsWithoutMaterialShareTheDefaultMaterial) {
    Json j = minimal_scene();
    j["materials"] = {{"red", {{"color", {1, 0, 0}}}}};
    j["objects"] = Json::array(
        {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1}},
         {{"type", "sphere"}, {"center", {1, 0, 0}}, {"radius", 1}, {"material", "red"}},
         {{"type", "plane"}, {"point", {0, -1, 0}}, {"normal", {0, 1, 0}}}});
    const Scene s = parse(j);
    ASSERT_EQ(s.materials.size(), 2u);
    EXPECT_EQ(s.objects[0].material, 1u);
    EXPECT_EQ(s.objects[1].material, 0u);
    EXPECT_EQ(s.objects[2].material, 1u);
    EXPECT_EQ(s.materials[1].name, "");
    const Material def;
    EXPECT_EQ(s.materials[1].material.color, def.color);
    EXPECT_EQ(s.materials[1].material.kd, 1.0f);
    EXPECT_EQ(s.materials[1].material.ks, 0.0f);
    EXPECT_EQ(s.materials[1].material.shininess, 32.0f);
    EXPECT_EQ(s.materials[1].material.ior, 1.5f);
}

TEST(SceneLoad, BareNumberIsGrey) {
    Json j = minimal_scene();
    j["ambient"] = 0.25;
    j["background"] = {{"type", "constant"}, {"color", 0.5}};
    j["materials"] = {{"m", {{"color", 0.75}, {"reflect", 0.125}}}};
    j["lights"] = Json::array({{{"type", "point"}, {"position", {0, 5, 0}}, {"color", 2}}});
    const Scene s = parse(j);
    EXPECT_EQ(s.ambient, (Rgb{0.25f, 0.25f, 0.25f}));
    EXPECT_EQ(s.background.color, (Rgb{0.5f, 0.5f, 0.5f}));
    EXPECT_EQ(s.materials[0].material.color, (Rgb{0.75f, 0.75f, 0.75f}));
    EXPECT_EQ(s.materials[0].material.reflect, (Rgb{0.125f, 0.125f, 0.125f}));
    EXPECT_EQ(s.lights[0].color, (Rgb{2, 2, 2}));
    EXPECT_FALSE(s.lights[0].inverse_square);  // falloff defaults to "none"
}

TEST(SceneLoad, InlineMaterialsGetOneEntryEach) {
    Json j = minimal_scene();
    j["objects"] =
        Json::array({{{"type", "sphere"},
                      {"center", {0, 0, 0}},
                      {"radius", 1},
                      {"material", {{"color", {0, 1, 0}}, {"checker", {{"color", 0}}}}}},
                     {{"type", "sphere"},
                      {"center", {3, 0, 0}},
                      {"radius", 1},
                      {"material", Json::object()}}});
    const Scene s = parse(j);
    ASSERT_EQ(s.materials.size(), 2u);
    EXPECT_EQ(s.objects[0].material, 0u);
    EXPECT_EQ(s.objects[1].material, 1u);
    EXPECT_EQ(s.materials[0].material.color, (Rgb{0, 1, 0}));
    ASSERT_TRUE(s.materials[0].material.checker.has_value());
    EXPECT_EQ(s.materials[0].material.checker->size, 1.0f);  // default checker size
    EXPECT_EQ(s.materials[1].material.color, Rgb(0.8f));
}

TEST(SceneLoad, PlaneNormalsAreNormalised) {
    Json j = minimal_scene();
    j["objects"] =
        Json::array({{{"type", "plane"}, {"point", {0, 0, 0}}, {"normal", {0, 2, 0}}},
                     {{"type", "plane"}, {"point", {0, 0, 0}}, {"normal", {3, 0, 4}}},
                     {{"type", "plane"}, {"point", {0, 0, 0}}, {"normal", {1e-30, 0, 0}}},
                     {{"type", "plane"}, {"point", {0, 0, 0}}, {"normal", {3e38, 3e38, 0}}}});
    const Scene s = parse(j);
    EXPECT_EQ(s.objects[0].normal, (Vec3{0, 1, 0}));
    EXPECT_FLOAT_EQ(s.objects[1].normal.x, 0.6f);
    EXPECT_FLOAT_EQ(s.objects[1].normal.z, 0.8f);
    EXPECT_EQ(s.objects[2].normal, (Vec3{1, 0, 0}));
    EXPECT_FLOAT_EQ(s.objects[3].normal.x, 0.70710678f);
    EXPECT_FLOAT_EQ(s.objects[3].normal.y, 0.70710678f);
}

TEST(SceneLoad, CameraTypesAndTheirKeys) {
    Json j = minimal_scene();
    j["camera"] = {
        {"type", "orthographic"}, {"eye", {0, 0, 5}}, {"lookat", {0, 0, 0}}, {"width", 4}};
    EXPECT_EQ(parse(j).camera.type, CameraType::orthographic);
    EXPECT_EQ(parse(j).camera.width, 4.0f);

    j["camera"] = {{"type", "thinlens"},
                   {"eye", {0, 3, 4}},
                   {"lookat", {0, 0, 0}},
                   {"fov", 40},
                   {"aperture", 0.1}};
    const Scene thin = parse(j);
    EXPECT_EQ(thin.camera.type, CameraType::thinlens);
    EXPECT_EQ(thin.camera.aperture, 0.1f);
    EXPECT_EQ(thin.camera.focus_distance, 5.0f);  // default: distance from eye to lookat
    j["camera"]["focus_distance"] = 2.5;
    EXPECT_EQ(parse(j).camera.focus_distance, 2.5f);

    j["camera"] = {
        {"type", "fisheye"}, {"eye", {0, 0, 5}}, {"lookat", {0, 0, 0}}, {"fov", 360}};
    EXPECT_EQ(parse(j).camera.type, CameraType::fisheye);
    EXPECT_EQ(parse(j).camera.fov, 360.0f);
}

TEST(SceneLoad, IntegersMayBeWrittenAsIntegralFloats) {
    Json j = minimal_scene();
    j["image"] = {{"width", 640.0}, {"height", 1e2}};
    const Scene s = parse(j);
    EXPECT_EQ(s.image.width, 640);
    EXPECT_EQ(s.image.height, 100);
}

TEST(SceneLoad, SeedTakesTheWholeUint64Range) {
    Json j = minimal_scene();
    j["render"] = {{"seed", std::numeric_limits<std::uint64_t>::max()}};
    EXPECT_EQ(parse(j).render.seed, std::numeric_limits<std::uint64_t>::max());
}

TEST(SceneLoad, LoadSceneFileAndLoadScene) {
    const std::filesystem::path dir = OCTRAY_TEST_TMPDIR;
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "load_test_full.json").string();
    {
        std::ofstream out(path, std::ios::binary);
        out << kFullScene;
    }
    const Scene s = load_scene_file(path);
    EXPECT_EQ(s.source, path);
    EXPECT_EQ(s.objects.size(), 4u);
    EXPECT_EQ(load_scene(path).objects.size(), 4u);
    // A built-in spec goes to the generator, not the file system.
    EXPECT_EQ(load_scene("random:3").objects.size(), 3u);
    std::filesystem::remove(path);
}

// ---------------------------------------------------------------------------------------
// Errors

TEST(SceneLoadError, InvalidJsonGivesLineAndColumn) {
    const std::string text = "{\n  \"image\": { \"width\": 640,, \"height\": 480 }\n}";
    // The second ',' is line 2, column 27.
    expect_text_error(text, "", {"invalid JSON at line 2, column 27", "expected"});
    expect_text_error("", "", {"invalid JSON at line 1, column 1"});
    expect_text_error("{\"camera\": {\"eye\": [0, 0, 5]", "",
                      {"invalid JSON at line 1, column 29"});
    expect_text_error("{ \"a\": tru }", "",
                      {"invalid JSON at line 1, column", "invalid literal"});
}

TEST(SceneLoadError, TopLevelMustBeAnObject) {
    expect_text_error("[1, 2]", "", {"expected a JSON object at the top level", "[1,2]"});
}

TEST(SceneLoadError, NonFiniteNumbers) {
    // nlohmann would turn 1e999 into infinity; it is refused where it is written.
    std::string text = kFullScene;
    text.replace(text.find("\"radius\": 1,"), 12, "\"radius\": 1e999,");
    expect_text_error(text, "objects[0].radius",
                      {"expected a finite number", "1e999", "line 15, column 60"});
    text = kFullScene;
    text.replace(text.find("[-1, -1, -0.5]"), 14, "[-1, -1e400, -0.5]");
    expect_text_error(text, "lights[1].direction[1]", {"expected a finite number", "-1e400"});
    // Finite as a double, infinite as a float.
    Json j = full_scene();
    j["objects"][0]["radius"] = 1e39;
    expect_json_error(j, "objects[0].radius",
                      {"expected a finite number within float range", "1e+39"});
}

TEST(SceneLoadError, UnknownKeysAreNamedWithTheirPath) {
    Json j = full_scene();
    j["objets"] = Json::array();
    expect_json_error(
        j, "objets", {"unknown key \"objets\"", "did you mean \"objects\"", "expected one of"});
    j = full_scene();
    j["objects"][1]["raduis"] = 1;
    expect_json_error(j, "objects[1].raduis",
                      {"unknown key \"raduis\"", "expected one of: \"type\""});
    j = full_scene();
    j["objects"][0]["raduis"] = 1;
    expect_json_error(j, "objects[0].raduis",
                      {"unknown key \"raduis\"", "did you mean \"radius\""});
    j = full_scene();
    j["materials"]["glass"]["transmitt"] = 1;
    expect_json_error(j, "materials.glass.transmitt", {"did you mean \"transmit\""});
    j = full_scene();
    j["materials"]["floor"]["checker"]["sise"] = 1;
    expect_json_error(j, "materials.floor.checker.sise", {"did you mean \"size\""});
    j = full_scene();
    j["camera"]["lokat"] = {0, 0, 0};
    expect_json_error(j, "camera.lokat", {"did you mean \"lookat\""});
    j = full_scene();
    j["camera"]["eey"] = {0, 0, 0};  // a swapped pair is one typo
    expect_json_error(j, "camera.eey", {"did you mean \"eye\""});
    j = full_scene();
    j["image"]["samples"] = 4;
    expect_json_error(j, "image.samples", {"unknown key \"samples\"", "\"spp\""});
    j = full_scene();
    j["render"]["depth"] = 4;
    expect_json_error(j, "render.depth", {"unknown key \"depth\"", "\"max_depth\""});
}

TEST(SceneLoadError, KeysOfAnotherTypeAreErrors) {
    Json j = full_scene();
    j["camera"]["width"] = 2;
    expect_json_error(
        j, "camera.width",
        {"\"width\" applies only to orthographic cameras", "not to a pinhole camera"});
    j = full_scene();
    j["camera"] = {
        {"type", "orthographic"}, {"eye", {0, 0, 5}}, {"lookat", {0, 0, 0}}, {"fov", 30}};
    expect_json_error(j, "camera.fov",
                      {"applies only to pinhole, thinlens and fisheye cameras"});
    j = full_scene();
    j["camera"]["aperture"] = 0.1;
    expect_json_error(j, "camera.aperture", {"applies only to thinlens cameras"});
    j = full_scene();
    j["lights"][1]["falloff"] = "none";
    expect_json_error(j, "lights[1].falloff", {"applies only to point lights"});
    j = full_scene();
    j["lights"][0]["direction"] = {0, -1, 0};
    expect_json_error(j, "lights[0].direction", {"applies only to directional lights"});
    j = full_scene();
    j["background"]["color"] = 1;
    expect_json_error(j, "background.color", {"applies only to constant backgrounds"});
    j = full_scene();
    j["objects"][1]["radius"] = 1;
    expect_json_error(j, "objects[1].radius", {"applies only to spheres", "not to a plane"});
    j = full_scene();
    j["objects"][0]["normal"] = {0, 1, 0};
    expect_json_error(j, "objects[0].normal", {"applies only to planes"});
}

TEST(SceneLoadError, DuplicateKeys) {
    std::string text = kFullScene;
    text.replace(text.find("\"radius\": 0.5,"), 14, "\"radius\": 0.5, \"radius\": 2,");
    expect_text_error(text, "objects[2].radius", {"duplicate key \"radius\""});
    text = kFullScene;
    text.replace(text.find("\"glass\":  {"), 11, "\"chrome\": {");
    expect_text_error(text, "materials.chrome", {"duplicate key \"chrome\""});
}

TEST(SceneLoadError, WrongTypes) {
    Json j = full_scene();
    j["objects"][0]["radius"] = "big";
    expect_json_error(j, "objects[0].radius", {"expected a number", "the string \"big\""});
    j = full_scene();
    j["camera"]["eye"] = {0, 1};
    expect_json_error(j, "camera.eye", {"expected an array of 3 numbers", "[0,1]"});
    j = full_scene();
    j["camera"]["lookat"][2] = nullptr;
    expect_json_error(j, "camera.lookat[2]", {"expected a number, found null"});
    j = full_scene();
    j["ambient"] = "dark";
    expect_json_error(j, "ambient", {"expected a color: [r, g, b] or a number (grey)"});
    j = full_scene();
    j["objects"][0]["type"] = "cube";
    expect_json_error(j, "objects[0].type",
                      {"expected one of \"sphere\", \"plane\"", "\"cube\""});
    j = full_scene();
    j["camera"]["type"] = "pinhol";
    expect_json_error(j, "camera.type",
                      {"expected one of \"pinhole\"", "did you mean \"pinhole\""});
    j = full_scene();
    j["lights"][0]["falloff"] = "quadratic";
    expect_json_error(j, "lights[0].falloff", {"expected one of \"none\", \"inverse-square\""});
    j = full_scene();
    j["objects"] = Json::object();
    expect_json_error(j, "objects", {"expected an array of objects", "an object"});
    j = full_scene();
    j["lights"][0] = 5;
    expect_json_error(j, "lights[0]", {"expected an object", "found 5"});
    j = full_scene();
    j["materials"] = Json::array();
    expect_json_error(j, "materials", {"expected an object mapping names to materials"});
    j = full_scene();
    j["objects"][0]["material"] = 3;
    expect_json_error(j, "objects[0].material",
                      {"expected a material name or an inline material"});
    j = full_scene();
    j["objects"][0]["name"] = 7;
    expect_json_error(j, "objects[0].name", {"expected a string, found 7"});
}

TEST(SceneLoadError, MissingRequiredKeys) {
    Json j = full_scene();
    j.erase("camera");
    expect_json_error(j, "camera",
                      {"missing required key \"camera\"", "\"eye\" and \"lookat\""});
    j = full_scene();
    j["camera"].erase("eye");
    expect_json_error(j, "camera.eye", {"missing required key \"eye\""});
    j = full_scene();
    j["objects"][2].erase("type");
    expect_json_error(j, "objects[2].type",
                      {"missing required key \"type\"", "\"sphere\" or \"plane\""});
    j = full_scene();
    j["objects"][0].erase("radius");
    expect_json_error(j, "objects[0].radius", {"missing required key \"radius\""});
    j = full_scene();
    j["lights"][0].erase("position");
    expect_json_error(j, "lights[0].position", {"missing required key \"position\""});
    j = full_scene();
    j["background"].erase("top");
    expect_json_error(j, "background.top", {"missing required key \"top\""});
    j = full_scene();
    j["materials"]["floor"]["checker"].erase("color");
    expect_json_error(j, "materials.floor.checker.color", {"missing required key \"color\""});
}

TEST(SceneLoadError, RadiusMustBePositive) {
    Json j = full_scene();
    j["objects"][2]["radius"] = 0;
    expect_json_error(j, "objects[2].radius", {"expected a radius > 0, found 0"});
    j["objects"][2]["radius"] = -1.5;
    expect_json_error(j, "objects[2].radius", {"expected a radius > 0, found -1.5"});
}

TEST(SceneLoadError, ZeroLengthNormal) {
    Json j = full_scene();
    j["objects"][1]["normal"] = {0, 0, 0};
    expect_json_error(j, "objects[1].normal",
                      {"expected a non-zero normal vector", "[0, 0, 0]"});
}

TEST(SceneLoadError, CameraUpParallelToView) {
    Json j = full_scene();
    j["camera"]["eye"] = {0, 5, 0};
    j["camera"]["lookat"] = {0, 0, 0};
    expect_json_error(j, "camera",
                      {"up vector is parallel to the view direction", "found pinhole camera"});
    j = full_scene();
    j["camera"]["lookat"] = j["camera"]["eye"];
    expect_json_error(j, "camera", {"eye and lookat coincide"});
    j = full_scene();
    j["camera"]["up"] = {0, 0, 0};
    expect_json_error(j, "camera.up", {"expected a non-zero up vector"});
}

TEST(SceneLoadError, FieldOfViewOutOfRange) {
    Json j = full_scene();
    j["camera"]["fov"] = 180;
    expect_json_error(j, "camera", {"field of view must lie in (0, 180) degrees", "fov 180"});
    j["camera"]["fov"] = 0;
    expect_json_error(j, "camera", {"field of view must lie in (0, 180)", "fov 0"});
    j["camera"]["type"] = "fisheye";
    j["camera"]["fov"] = 361;
    expect_json_error(j, "camera",
                      {"field of view must lie in (0, 360] degrees", "fisheye camera"});
}

TEST(SceneLoadError, UnknownMaterialName) {
    Json j = full_scene();
    j["objects"][0]["material"] = "chrme";
    expect_json_error(j, "objects[0].material",
                      {"unknown material \"chrme\"", "did you mean \"chrome\"",
                       "the scene defines \"chrome\", \"glass\", \"floor\""});
    j.erase("materials");
    j["objects"].erase(3);
    expect_json_error(j, "objects[0].material", {"the scene defines no named materials"});
}

TEST(SceneLoadError, EmptyNames) {
    Json j = full_scene();
    j["materials"][""] = Json::object();
    expect_json_error(j, "materials[\"\"]", {"expected a non-empty material name"});
    j = full_scene();
    j["objects"][1]["name"] = "";
    expect_json_error(j, "objects[1].name", {"expected a non-empty name"});
}

TEST(SceneLoadError, ImageSize) {
    Json j = full_scene();
    j["image"]["width"] = 0;
    expect_json_error(j, "image.width", {"expected an integer from 1 to 2147483647, found 0"});
    j["image"]["width"] = -640;
    expect_json_error(j, "image.width",
                      {"expected an integer from 1 to 2147483647, found -640"});
    j["image"]["width"] = 640.5;
    expect_json_error(j, "image.width", {"expected an integer", "found 640.5"});
    j["image"]["width"] = "640";
    expect_json_error(j, "image.width", {"expected an integer", "the string \"640\""});
    j["image"]["width"] = 3000000000u;
    expect_json_error(j, "image.width",
                      {"expected an integer from 1 to 2147483647", "3000000000"});
    j = full_scene();
    j["image"]["height"] = -1;
    expect_json_error(j, "image.height",
                      {"expected an integer from 1 to 2147483647, found -1"});
    j = full_scene();
    j["image"]["spp"] = 0;
    expect_json_error(j, "image.spp", {"expected an integer from 1 to 2147483647, found 0"});
}

TEST(SceneLoadError, ImageTooManyPixels) {
    Json j = full_scene();
    j["image"] = {{"width", 65536}, {"height", 65536}};
    expect_json_error(
        j, "image",
        {"a 65536 x 65536 image has 4294967296 pixels", "expected at most 2147483647"});
}

TEST(SceneLoadError, ImageLargerThanMemory) {
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    ASSERT_GT(pages, 0);
    ASSERT_GT(page, 0);
    const double memory = static_cast<double>(pages) * static_cast<double>(page);
    // The largest image the pixel limit allows needs 24 GiB; on machines with more memory
    // than that, the pixel limit is the one that applies.
    if (memory >= 2147483647.0 * 12.0)
        GTEST_SKIP() << "more memory than any allowed image needs";
    const int side = 46340;  // 46340^2 < 2^31 - 1
    ASSERT_GT(static_cast<double>(side) * side * 12.0, memory);
    Json j = full_scene();
    j["image"] = {{"width", side}, {"height", side}};
    expect_json_error(j, "image",
                      {"a 46340 x 46340 image needs about 24.0 GiB", "12 bytes per pixel",
                       "of physical memory"});
}

TEST(SceneLoadError, MaxDepthRange) {
    Json j = full_scene();
    j["render"]["max_depth"] = -1;
    expect_json_error(j, "render.max_depth", {"expected an integer from 0 to 64, found -1"});
    j["render"]["max_depth"] = 65;
    expect_json_error(j, "render.max_depth", {"expected an integer from 0 to 64, found 65"});
}

TEST(SceneLoadError, Seed) {
    Json j = full_scene();
    j["render"]["seed"] = -1;
    expect_json_error(j, "render.seed", {"expected a non-negative integer", "found -1"});
    j["render"]["seed"] = 1.5;
    expect_json_error(j, "render.seed", {"expected a non-negative integer", "found 1.5"});
    j["render"]["seed"] = "7";
    expect_json_error(j, "render.seed",
                      {"expected a non-negative integer", "the string \"7\""});
    // One past the uint64 range: nlohmann reads it as a float.
    std::string text = kFullScene;
    text.replace(text.find("\"seed\": 42"), 10, "\"seed\": 18446744073709551616");
    expect_text_error(text, "render.seed",
                      {"expected a non-negative integer", "18446744073709551615"});
}

TEST(SceneLoadError, Epsilon) {
    Json j = full_scene();
    j["render"]["epsilon"] = 0;
    expect_json_error(j, "render.epsilon", {"expected epsilon > 0, found 0"});
}

TEST(SceneLoadError, ThinLens) {
    Json j = full_scene();
    j["camera"] = {
        {"type", "thinlens"}, {"eye", {0, 0, 5}}, {"lookat", {0, 0, 0}}, {"aperture", -0.1}};
    expect_json_error(j, "camera.aperture", {"expected a lens radius >= 0, found -0.1"});
    j["camera"]["aperture"] = 0.1;
    j["camera"]["focus_distance"] = 0;
    expect_json_error(j, "camera.focus_distance", {"expected a focus distance > 0, found 0"});
    j["camera"].erase("aperture");
    j["camera"]["focus_distance"] = 1;
    expect_json_error(j, "camera.aperture",
                      {"missing required key \"aperture\"", "lens radius"});
}

// Issue 23: refraction divides by the index or multiplies by it; beyond a ratio of 100 the
// float refraction vector loses its precision and renders NaN pixels (ior 1e8 did). The
// scene is refused with the limit stated instead.
TEST(SceneLoadError, IndexOfRefractionHasStatedLimits) {
    for (const double ior : {1e8, 1e20, 100.5, 0.005, 1e-8}) {
        Json j = full_scene();
        j["materials"]["glass"]["ior"] = ior;
        expect_json_error(j, "materials.glass.ior",
                          {"expected an index of refraction from 0.01 to 100", "found "});
    }
    for (const double ior : {100.0, 0.01, 1.0}) {
        Json j = full_scene();
        j["materials"]["glass"]["ior"] = ior;
        EXPECT_NO_THROW(parse(j)) << ior;
    }
}

// Issue 23: a thin lens far wider than its focus distance breaks float precision (aperture
// 1e20 rendered 13915 of 14400 pixels NaN), as does a focal point beyond 1e18: refused,
// the limits stated.
TEST(SceneLoadError, ThinLensHasStatedLimits) {
    Json j = full_scene();
    // The focus distance defaults to |lookat - eye| = 5: the lens radius may be up to 50.
    j["camera"] = {
        {"type", "thinlens"}, {"eye", {0, 0, 5}}, {"lookat", {0, 0, 0}}, {"aperture", 1e20}};
    expect_json_error(j, "camera.aperture",
                      {"expected a lens radius of at most 10 x the focus distance",
                       "10 x 5 = 50", "found 1e+20"});
    j["camera"]["aperture"] = 50.5;
    expect_json_error(j, "camera.aperture", {"10 x 5 = 50", "found 50.5"});
    j["camera"]["aperture"] = 50;
    EXPECT_NO_THROW(parse(j));
    j["camera"]["focus_distance"] = 1e20;
    j["camera"]["aperture"] = 0;
    expect_json_error(j, "camera.focus_distance",
                      {"expected a focus distance of at most 1e+18", "found 1e+20"});
    j["camera"]["focus_distance"] = 1e18;
    j["camera"]["aperture"] = 1e19;
    EXPECT_NO_THROW(parse(j));
}

// Issue 23: strict JSON means the whole file: a NUL byte does not end the text (the JSON
// library stops at one), it is an error that says where it is.
TEST(SceneLoadError, NulBytesAreErrorsWithTheirPosition) {
    const std::string valid = "{\n  \"camera\": {\"eye\": [0, 0, 5], \"lookat\": [0, 0, 0]}\n}";
    ASSERT_NO_THROW(parse_scene_json(valid, kFile));
    expect_text_error(valid + std::string("\0{\"garbage\":", 12), "",
                      {"NUL byte", "line 3, column 2"});
    expect_text_error(valid + std::string(1, '\0'), "", {"NUL byte", "line 3, column 2"});
    std::string middle = valid;
    middle[13] = '\0';  // the blank after "camera":
    expect_text_error(middle, "", {"NUL byte", "line 2, column 12"});
    std::string in_string = valid;
    in_string.replace(in_string.find("eye"), 1, std::string(1, '\0'));
    expect_text_error(in_string, "", {"NUL byte", "line 2, column 15"});
}

TEST(SceneLoadError, OrthographicWidth) {
    Json j = full_scene();
    j["camera"] = {
        {"type", "orthographic"}, {"eye", {0, 0, 5}}, {"lookat", {0, 0, 0}}, {"width", 0}};
    expect_json_error(j, "camera.width", {"expected a film width > 0, found 0"});
    j["camera"]["width"] = -2;
    expect_json_error(j, "camera.width", {"expected a film width > 0, found -2"});
}

TEST(SceneLoadError, MaterialValues) {
    Json j = full_scene();
    j["materials"]["floor"]["checker"]["size"] = 0;
    expect_json_error(j, "materials.floor.checker.size",
                      {"expected a checker size > 0, found 0"});
    j = full_scene();
    j["materials"]["glass"]["ior"] = 0;
    expect_json_error(j, "materials.glass.ior",
                      {"expected an index of refraction > 0, found 0"});
    j["materials"]["glass"]["ior"] = -1.5;
    expect_json_error(j, "materials.glass.ior",
                      {"expected an index of refraction > 0, found -1.5"});
    j = full_scene();
    j["materials"]["chrome"]["color"] = {1, -1, 0};
    expect_json_error(j, "materials.chrome.color", {"non-negative components", "[1, -1, 0]"});
    j = full_scene();
    j["materials"]["chrome"]["kd"] = -0.5;
    expect_json_error(j, "materials.chrome.kd", {"expected kd >= 0, found -0.5"});
    j = full_scene();
    j["objects"][3]["material"]["transmit"] = -1;
    expect_json_error(j, "objects[3].material.transmit", {"expected transmit >= 0, found -1"});
    j = full_scene();
    j["lights"][0]["color"] = -1;
    expect_json_error(j, "lights[0].color", {"non-negative components"});
}

TEST(SceneLoadError, DirectionalLightNeedsADirection) {
    Json j = full_scene();
    j["lights"][1]["direction"] = {0, 0, 0};
    expect_json_error(j, "lights[1].direction", {"expected a non-zero direction"});
}

// The animation block is tested in tests/scene/animation_test.cpp.
TEST(SceneLoadError, AnimationNeedsAFrameCount) {
    Json j = full_scene();
    j["animation"] = {{"fps", 24}};
    expect_json_error(j, "animation.frames", {"missing required key \"frames\""});
}

TEST(SceneLoadError, ObjectNamesAreUnique) {
    Json j = full_scene();
    j["objects"][2]["name"] = "ball";
    expect_json_error(j, "objects[2].name",
                      {"expected a unique object name", "\"ball\"", "objects[0]"});
}

TEST(SceneLoadError, NestingDepth) {
    Json j = full_scene();
    Json deep = 1;
    for (int i = 0; i < 100; ++i) deep = Json::array({deep});
    j["objects"][0]["center"] = deep;
    // 64 containers are open when the 65th is refused: the root, "objects", objects[0],
    // then 61 arrays starting with "center"; the path names the one that was refused.
    std::string path = "objects[0].center";
    for (int i = 0; i < 61; ++i) path += "[0]";
    expect_json_error(j, path, {"nesting deeper than 64 levels"});
}

TEST(SceneLoadError, UnreadableFile) {
    const std::string missing = "/nonexistent-octray-dir/scene.json";
    expect_error([&] { load_scene_file(missing); }, missing, "",
                 {"cannot open scene file", "No such file or directory"});
    expect_error([&] { load_scene(missing); }, missing, "", {"No such file or directory"});
    const std::filesystem::path dir = OCTRAY_TEST_TMPDIR;
    std::filesystem::create_directories(dir);
    expect_error([&] { load_scene_file(dir.string()); }, dir.string(), "",
                 {"cannot read scene file", "Is a directory"});
}

// A device or a pipe has no end (/dev/zero would be read forever, a FIFO blocks until a
// writer comes): refused before reading, naming what the path is.
TEST(SceneLoadError, NonRegularFilesAreRefusedBeforeReading) {
    expect_error([&] { load_scene_file("/dev/null"); }, "/dev/null", "",
                 {"a character device", "expected a regular file"});
    expect_error([&] { load_scene("/dev/zero"); }, "/dev/zero", "",
                 {"a character device", "expected a regular file"});
    const std::filesystem::path dir = OCTRAY_TEST_TMPDIR;
    std::filesystem::create_directories(dir);
    const std::string fifo = (dir / "load_test_fifo.json").string();
    std::filesystem::remove(fifo);
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    expect_error([&] { load_scene_file(fifo); }, fifo, "",
                 {"a pipe", "expected a regular file"});
    std::filesystem::remove(fifo);
}

TEST(SceneLoadError, ErrorsInAFileNameTheFile) {
    const std::filesystem::path dir = OCTRAY_TEST_TMPDIR;
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "load_test_bad.json").string();
    {
        Json j = full_scene();
        j["objects"][2]["radius"] = -2;
        std::ofstream out(path, std::ios::binary);
        out << j.dump(2);
    }
    expect_error([&] { load_scene_file(path); }, path, "objects[2].radius",
                 {"expected a radius > 0, found -2"});
    std::filesystem::remove(path);
}

// ---------------------------------------------------------------------------------------
// validate_scene on in-memory scenes (after command-line overrides, or built in code)

Scene valid_scene() { return parse_scene_json(kFullScene, kFile); }

void expect_invalid(const Scene& s, const std::string& path,
                    std::initializer_list<std::string> needles) {
    expect_error([&] { validate_scene(s); }, s.source, path, needles);
}

TEST(SceneValidate, AcceptsTheLoadedScene) { EXPECT_NO_THROW(validate_scene(valid_scene())); }

TEST(SceneValidate, ReportsJsonLikePaths) {
    Scene s = valid_scene();
    s.image.width = 0;
    expect_invalid(s, "image.width", {"expected an integer from 1 to 2147483647, found 0"});
    s = valid_scene();
    s.image.spp = -3;
    expect_invalid(s, "image.spp", {"found -3"});
    s = valid_scene();
    s.image.width = 100000;
    s.image.height = 100000;
    expect_invalid(s, "image", {"10000000000 pixels"});
    s = valid_scene();
    s.render.max_depth = 100;
    expect_invalid(s, "render.max_depth", {"from 0 to 64, found 100"});
    s = valid_scene();
    s.objects[2].radius = -1.0f;
    expect_invalid(s, "objects[2].radius", {"expected a radius > 0, found -1"});
    s = valid_scene();
    s.objects[0].center.y = std::numeric_limits<float>::infinity();
    expect_invalid(s, "objects[0].center", {"expected finite coordinates", "inf"});
    s = valid_scene();
    s.objects[1].normal = {0.0f, 2.0f, 0.0f};
    expect_invalid(s, "objects[1].normal", {"expected a unit-length normal", "[0, 2, 0]"});
    s = valid_scene();
    s.objects[1].material = 9;
    expect_invalid(s, "objects[1].material", {"expected a material index below 4", "found 9"});
    s = valid_scene();
    s.materials[3].material.ior = 0.0f;  // inline material: named by the object using it
    expect_invalid(s, "objects[3].material.ior", {"expected an index of refraction > 0"});
    s = valid_scene();
    s.materials[1].material.shininess = std::numeric_limits<float>::quiet_NaN();
    expect_invalid(s, "materials.glass.shininess",
                   {"expected a Phong exponent >= 0, found nan"});
    s = valid_scene();
    s.camera.fov = 200.0f;
    expect_invalid(s, "camera", {"field of view must lie in (0, 180)"});
    s = valid_scene();
    s.background.top = {0.0f, -1.0f, 0.0f};
    expect_invalid(s, "background.top", {"non-negative components"});
    s = valid_scene();
    s.render.epsilon = -1.0f;
    expect_invalid(s, "render.epsilon", {"expected epsilon > 0"});
    s = valid_scene();
    s.lights[1].direction = {};
    expect_invalid(s, "lights[1].direction", {"expected a non-zero direction"});
    s = valid_scene();
    s.materials[2].name = "chrome";
    expect_invalid(s, "materials.chrome", {"duplicate material name \"chrome\""});
    s = valid_scene();
    s.render.epsilon.reset();  // else the bounding box is not needed
    s.objects[0].center = {3e38f, 0.0f, 0.0f};
    s.objects[0].radius = 3e38f;
    expect_invalid(s, "objects", {"bounding box overflows float range"});
}

}  // namespace
}  // namespace octray
