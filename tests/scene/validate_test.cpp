// validate_scene on in-memory scenes: the same checks and messages as loading, with
// JSON-like paths.

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

#include "scene/load.h"
#include "tests/scene/load_test_support.h"

namespace octray {
namespace {

using namespace testing;

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

// The objects are checked on every core: of several invalid objects, the first in file
// order is the one reported, however the blocks fall; where objects are named (a map of
// names, checked in order), a name used twice before an invalid object is reported first,
// and an invalid object before a name used twice.
TEST(SceneValidate, ReportsTheFirstInvalidObjectOfAMillion) {
    Scene s = valid_scene();
    s.objects.resize(1u << 20, s.objects[0]);
    for (Object& o : s.objects) o.name.clear();
    s.objects[900000].radius = -1.0f;
    s.objects[700001].center.z = std::numeric_limits<float>::quiet_NaN();
    s.objects[16384].material = 99;
    expect_invalid(s, "objects[16384].material", {"found 99"});
    s.objects[16384].material = 0;
    expect_invalid(s, "objects[700001].center", {"expected finite coordinates", "nan"});
    s.objects[700001].center.z = 0.0f;
    expect_invalid(s, "objects[900000].radius", {"expected a radius > 0, found -1"});
    s.objects[900000].radius = 1.0f;
    EXPECT_NO_THROW(validate_scene(s));

    s.objects[500000].name = s.objects[800000].name = "twin";
    s.objects[900000].radius = -1.0f;
    expect_invalid(s, "objects[800000].name", {"unique object name", "objects[500000]"});
    s.objects[600000].radius = 0.0f;
    expect_invalid(s, "objects[600000].radius", {"expected a radius > 0, found 0"});
}

// Issue 38: a camera far from the origin was refused as "up vector is parallel to the view
// direction"; the cause is that the view vector's length overflows float.
TEST(SceneValidate, CameraFarAwaySaysItsLengthOverflowsFloat) {
    for (float far : {1e20f, 1e30f}) {
        Scene s = valid_scene();
        s.camera.type = CameraType::pinhole;
        s.camera.eye = {0.0f, 0.0f, far};
        s.camera.lookat = {0.0f, 0.0f, 0.0f};
        s.camera.up = {0.0f, 1.0f, 0.0f};
        expect_invalid(s, "camera", {"lookat - eye", "overflows float"});
        s.camera.eye = {0.0f, 0.0f, 5.0f};
        s.camera.up = {0.0f, far, 0.0f};
        expect_invalid(s, "camera", {"up vector", "overflows float"});
    }
    Scene s = valid_scene();
    s.camera.type = static_cast<CameraType>(7);
    expect_invalid(s, "camera.type", {"found the value 7"});
}

}  // namespace
}  // namespace octray
