// JSON scene loading errors: every error with its file, JSON path and expectation. (An
// image too large for the machine is no scene error: the render command refuses it,
// tests/batch/memory_estimate_test.cpp.)

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "scene/json_positions.h"
#include "scene/load.h"
#include "tests/scene/load_test_support.h"

namespace octray {
namespace {

using namespace testing;

// ---------------------------------------------------------------------------------------
// Errors

TEST(SceneLoadError, InvalidJsonGivesLineAndColumn) {
    const std::string text = "{\n  \"image\": { \"width\": 640,, \"height\": 480 }\n}";
    // The second ',' is line 2, column 27.
    expect_text_error(text, "", {":2:27: invalid JSON", "expected"});
    expect_text_error("", "", {":1:1: invalid JSON"});
    expect_text_error("{\"camera\": {\"eye\": [0, 0, 5]", "", {":1:29: invalid JSON"});
    expect_text_error("{ \"a\": tru }", "", {":1:", "invalid JSON", "invalid literal"});
}

TEST(SceneLoadError, TopLevelMustBeAnObject) {
    expect_text_error("[1, 2]", "", {"expected a JSON object at the top level", "[1,2]"});
}

TEST(SceneLoadError, NonFiniteNumbers) {
    // nlohmann would turn 1e999 into infinity; it is refused where it is written.
    std::string text = kFullScene;
    text.replace(text.find("\"radius\": 1,"), 12, "\"radius\": 1e999,");
    expect_text_error(text, "objects[0].radius",
                      {"expected a finite number", "1e999", ":15:60: "});
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
    expect_json_error(j, "image.spp", {"expected an integer from 1 to 1048576, found 0"});
    // Issue 38: one spp limit everywhere, 2^20 as `--spp` (a file's 2^31 - 1 samples per
    // pixel ignored SIGTERM for minutes and could never finish).
    j["image"]["spp"] = 1048577;
    expect_json_error(j, "image.spp", {"expected an integer from 1 to 1048576, found 1048577"});
}

TEST(SceneLoadError, ImageTooManyPixels) {
    Json j = full_scene();
    j["image"] = {{"width", 65536}, {"height", 65536}};
    expect_json_error(
        j, "image",
        {"a 65536 x 65536 image has 4294967296 pixels", "expected at most 2147483647"});
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
    expect_text_error(valid + std::string("\0{\"garbage\":", 12), "", {"NUL byte", ":3:2: "});
    expect_text_error(valid + std::string(1, '\0'), "", {"NUL byte", ":3:2: "});
    std::string middle = valid;
    middle[13] = '\0';  // the blank after "camera":
    expect_text_error(middle, "", {"NUL byte", ":2:12: "});
    std::string in_string = valid;
    in_string.replace(in_string.find("eye"), 1, std::string(1, '\0'));
    expect_text_error(in_string, "", {"NUL byte", ":2:15: "});
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

}  // namespace
}  // namespace octray

namespace octray {
namespace {

// Issue 43: every error in a scene file, not only a syntax error, says where it is as
// "file:line:column:", the form editors jump to: the key of the member it concerns, the
// first byte of the element, or the object a missing key belongs in.
TEST(SceneLoadError, EveryErrorInAFilePointsAtItsLineAndColumn) {
    const std::string text =
        "{\n"                                                                  // 1
        "  \"camera\": {\"eye\": [0, 0, 5], \"lookat\": [0, 0, 0]},\n"         // 2
        "  \"objects\": [\n"                                                   // 3
        "    {\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1},\n"  // 4
        "    {\"type\": \"sphere\", \"center\": [1, 0, 0],\n"                  // 5
        "      \"raduis\": 2}\n"                                               // 6
        "  ]\n"                                                                // 7
        "}\n";
    const auto what_of = [](const std::string& scene) {
        try {
            (void)parse_scene_json(scene, "shot.json");
        } catch (const SceneError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_EQ(
        what_of(text).rfind("shot.json:6:7: objects[1].raduis: unknown key \"raduis\"", 0), 0u)
        << what_of(text);

    // A value the validator refuses: at its key.
    std::string negative = text;
    negative.replace(negative.find("\"raduis\": 2"), 11, "\"radius\": -2");
    EXPECT_EQ(what_of(negative).rfind("shot.json:6:7: objects[1].radius: ", 0), 0u)
        << what_of(negative);

    // A value of the wrong type inside an array: at the element.
    std::string element = text;
    element.replace(element.find("[1, 0, 0]"), 9, "[1, \"x\", 0]");
    element.replace(element.find("\"raduis\""), 8, "\"radius\"");
    EXPECT_EQ(
        what_of(element).rfind("shot.json:5:38: objects[1].center[1]: expected a number", 0),
        0u)
        << what_of(element);

    // A missing key: at the object that lacks it.
    std::string missing = text;
    missing.replace(missing.find("\"raduis\": 2"), 11, "\"name\": \"b\"");
    EXPECT_EQ(
        what_of(missing).rfind("shot.json:5:5: objects[1].radius: missing required key", 0), 0u)
        << what_of(missing);

    // A syntax error: at the offending byte.
    EXPECT_EQ(what_of("{\n  \"camera\": {,}\n}").rfind("shot.json:2:14: invalid JSON: ", 0), 0u)
        << what_of("{\n  \"camera\": {,}\n}");
}

}  // namespace
}  // namespace octray

namespace octray::scene_json {
namespace {

// The path lookup behind those positions: keys as child_path writes them (escapes decoded,
// odd keys quoted), the last of duplicate keys, a missing key's parent, nothing outside.
TEST(JsonPathPosition, FindsWhatThePathNames) {
    const std::string text =
        "{\"a\": {\"b\": [10, {\"c\": 1}]},\n"          // 1
        " \"x\\u0079\": 2, \"odd key\": {\"k\": 3},\n"  // 2
        " \"d\": 4, \"d\": 5}";                         // 3
    const auto at = [&](std::string_view path) {
        const std::optional<SourcePosition> p = json_path_position(text, path);
        return p ? std::to_string(p->line) + ":" + std::to_string(p->column) : "none";
    };
    EXPECT_EQ(at(""), "1:1");
    EXPECT_EQ(at("a"), "1:2");
    EXPECT_EQ(at("a.b[0]"), "1:14");
    EXPECT_EQ(at("a.b[1].c"), "1:19");
    EXPECT_EQ(at("xy"), "2:2");
    EXPECT_EQ(at("[\"odd key\"].k"), "2:28");
    EXPECT_EQ(at("d"), "3:10") << "the last of duplicate keys";
    EXPECT_EQ(at("a.b[1].missing"), "1:18") << "a missing key: its object";
    EXPECT_EQ(at("a.b[7]"), "1:8") << "past the array's end: the array's key";
    EXPECT_EQ(at("b"), "1:1") << "no such member: the root";
    EXPECT_EQ(json_path_position("", "a"), std::nullopt);
    // A byte order mark is not counted; a broken text stops the scan, keeping what it found.
    EXPECT_EQ(json_path_position("\xEF\xBB\xBF{\"a\": 1}", "a").value().column, 5u);
    EXPECT_EQ(json_path_position("{\"a\": [1, 2", "a[1]").value().column, 11u);
}

}  // namespace
}  // namespace octray::scene_json
