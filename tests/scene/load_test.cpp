// JSON scene loading: every key of docs/scene-format.md and its defaults, and the rules
// scene/README.md adds. Errors: load_error_test.cpp; validate_scene: validate_test.cpp.

#include "scene/load.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/scene/load_test_support.h"

namespace octray {
namespace {

using namespace testing;

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

}  // namespace
}  // namespace octray
