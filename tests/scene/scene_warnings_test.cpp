// Issue 26: what a scene may say but probably does not mean. A pinhole or thin-lens fov
// below 2 degrees is almost always radians by mistake: scene_warnings() names the file and
// the key, unless the camera states "fov_units": "degrees" (which only "degrees" may be).

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene/load.h"
#include "scene/scene.h"

namespace octray {
namespace {

using Json = nlohmann::ordered_json;

const std::string kFile = "shot.json";

Json camera_scene(Json camera) {
    return Json{{"camera", std::move(camera)},
                {"objects", Json::array({Json{{"type", "sphere"},
                                              {"center", {0, 0, 0}},
                                              {"radius", 1},
                                              {"material", Json{{"color", 0.5}}}}})}};
}

Json pinhole(double fov) {
    return Json{{"type", "pinhole"}, {"eye", {0, 0, 5}}, {"lookat", {0, 0, 0}}, {"fov", fov}};
}

std::vector<std::string> warnings_of(const Json& scene) {
    return scene_warnings(parse_scene_json(scene.dump(), kFile));
}

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

TEST(SceneWarnings, PinholeFovBelowTwoDegreesIsNamedWithFileAndKey) {
    const std::vector<std::string> w = warnings_of(camera_scene(pinhole(0.8)));
    ASSERT_EQ(w.size(), 1u);
    EXPECT_EQ(w[0].rfind("shot.json: camera.fov: fov 0.8 is below 2", 0), 0u) << w[0];
    EXPECT_TRUE(contains(w[0], "fov is in degrees")) << w[0];
    EXPECT_TRUE(contains(w[0], "45.8366 degrees")) << w[0];  // 0.8 rad
    EXPECT_TRUE(contains(w[0], "\"fov_units\": \"degrees\"")) << w[0];
}

TEST(SceneWarnings, ThinLensFovWarnsToo) {
    Json camera = pinhole(1.5);
    camera["type"] = "thinlens";
    camera["aperture"] = 0.1;
    const std::vector<std::string> w = warnings_of(camera_scene(camera));
    ASSERT_EQ(w.size(), 1u);
    EXPECT_TRUE(contains(w[0], "camera.fov: fov 1.5 is below 2")) << w[0];
}

TEST(SceneWarnings, TwoDegreesAndUpAndOtherCamerasAreQuiet) {
    EXPECT_TRUE(warnings_of(camera_scene(pinhole(2.0))).empty());
    EXPECT_TRUE(warnings_of(camera_scene(pinhole(50.0))).empty());
    EXPECT_TRUE(warnings_of(camera_scene(pinhole(1.9999))).size() == 1u);
    Json fisheye = pinhole(1.0);
    fisheye["type"] = "fisheye";
    EXPECT_TRUE(warnings_of(camera_scene(fisheye)).empty());
    // No fov key: the default 50.
    Json bare = pinhole(50.0);
    bare.erase("fov");
    EXPECT_TRUE(warnings_of(camera_scene(bare)).empty());
}

TEST(SceneWarnings, FovUnitsDegreesStatesTheSmallAngleIsMeant) {
    Json camera = pinhole(0.5);
    camera["fov_units"] = "degrees";
    const Scene scene = parse_scene_json(camera_scene(camera).dump(), kFile);
    EXPECT_TRUE(scene.camera.fov_units_stated);
    EXPECT_TRUE(scene_warnings(scene).empty());
    // Written back, the statement stays: the written file loads without a warning too.
    const Scene again = parse_scene_json(scene_to_json(scene), kFile);
    EXPECT_TRUE(again.camera.fov_units_stated);
    EXPECT_TRUE(scene_warnings(again).empty());
    // A scene that does not state it writes no such key.
    EXPECT_FALSE(contains(
        scene_to_json(parse_scene_json(camera_scene(pinhole(50)).dump(), kFile)), "fov_units"));
}

TEST(SceneWarnings, FovUnitsTakesOnlyDegrees) {
    for (const Json& bad : {Json("radians"), Json("Degrees"), Json(1), Json(true)}) {
        Json camera = pinhole(0.5);
        camera["fov_units"] = bad;
        try {
            parse_scene_json(camera_scene(camera).dump(), kFile);
            ADD_FAILURE() << "accepted fov_units " << bad.dump();
        } catch (const SceneError& e) {
            EXPECT_EQ(e.json_path(), "camera.fov_units") << e.what();
            EXPECT_TRUE(contains(e.what(), "expected one of \"degrees\"")) << e.what();
        }
    }
    // Where fov is foreign (an orthographic camera), so is fov_units.
    Json ortho = {{"type", "orthographic"},
                  {"eye", {0, 0, 5}},
                  {"lookat", {0, 0, 0}},
                  {"fov_units", "degrees"}};
    EXPECT_THROW(parse_scene_json(camera_scene(ortho).dump(), kFile), SceneError);
}

TEST(SceneWarnings, AnimatedCameraKeysWithASmallFovWarnEach) {
    Json scene = camera_scene(pinhole(50));
    scene["animation"] = Json{{"frames", 10},
                              {"camera", Json::array({Json{{"frame", 0}, {"fov", 40}},
                                                      Json{{"frame", 5}, {"fov", 0.6}},
                                                      Json{{"frame", 9}, {"fov", 1.0}}})}};
    const std::vector<std::string> w = warnings_of(scene);
    ASSERT_EQ(w.size(), 2u);
    EXPECT_TRUE(contains(w[0], "shot.json: animation.camera[1].fov: fov 0.6 is below 2"))
        << w[0];
    EXPECT_TRUE(contains(w[1], "animation.camera[2].fov: fov 1 is below 2")) << w[1];
    scene["camera"]["fov_units"] = "degrees";
    EXPECT_TRUE(warnings_of(scene).empty());
}

TEST(SceneWarnings, BuiltInScenesHaveNone) {
    for (const char* spec : {"whitted", "random:4", "sphereflake:1"})
        EXPECT_TRUE(scene_warnings(load_scene(spec)).empty()) << spec;
}

}  // namespace
}  // namespace octray
