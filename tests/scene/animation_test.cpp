// Key-frame animation (scene/animation.h): loading and validating the "animation" block,
// per-property interpolation, holding outside the keys, writing it back, and rendering
// posed frames of scene/examples/bounce.json.

#include "scene/animation.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "render/reference.h"
#include "scene/load.h"

namespace octray {
namespace {

using Json = nlohmann::ordered_json;

const std::string kFile = "anim.json";
const std::string kBounce = std::string(OCTRAY_SOURCE_DIR) + "/scene/examples/bounce.json";

// A small animated scene: a pinhole camera, a plane "floor", spheres "ball" and "moon".
Json base_scene() {
    return Json::parse(R"json({
      "image": { "width": 64, "height": 48 },
      "camera": { "eye": [0, 1, 5], "lookat": [0, 0.5, 0], "up": [0, 1, 0], "fov": 50 },
      "objects": [
        { "type": "plane", "name": "floor", "point": [0, 0, 0], "normal": [0, 1, 0] },
        { "type": "sphere", "name": "ball", "center": [-1, 0.5, 0], "radius": 0.5 },
        { "type": "sphere", "name": "moon", "center": [0, 3, -4], "radius": 1 },
        { "type": "sphere", "center": [3, 1, -3], "radius": 1 }
      ],
      "lights": [ { "type": "point", "position": [4, 6, 5] } ],
      "animation": { "frames": 48, "fps": 24,
        "camera": [ { "frame": 0, "eye": [0, 1, 5] },
                    { "frame": 47, "eye": [3, 2, 4], "fov": 40 } ],
        "objects": { "ball": [ { "frame": 0, "center": [-1, 0.5, 0] },
                               { "frame": 47, "center": [1, 0.5, 0] } ] } }
    })json");
}

Scene parse(const Json& j) { return parse_scene_json(j.dump(), kFile); }

bool same_bits(float a, float b) {
    return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b);
}
bool same_bits(Vec3 a, Vec3 b) {
    return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z);
}

// The interpolation the implementation promises: linear in double, rounded once.
float lerp_expected(float a, float b, double t) {
    return static_cast<float>(std::lerp(static_cast<double>(a), static_cast<double>(b), t));
}
Vec3 lerp_expected(Vec3 a, Vec3 b, double t) {
    return {lerp_expected(a.x, b.x, t), lerp_expected(a.y, b.y, t), lerp_expected(a.z, b.z, t)};
}

void expect_error(const Json& j, const std::string& path,
                  std::initializer_list<std::string> needles) {
    try {
        (void)parse(j);
        ADD_FAILURE() << "expected a SceneError at \"" << path << "\"";
    } catch (const SceneError& e) {
        const std::string what = e.what();
        EXPECT_EQ(e.file(), kFile) << what;
        EXPECT_EQ(e.json_path(), path) << what;
        for (const std::string& n : needles) {
            EXPECT_NE(what.find(n), std::string::npos)
                << "missing \"" << n << "\" in: " << what;
        }
    }
}

// ---------------------------------------------------------------------------------------
// Loading

TEST(AnimationLoad, ReadsFramesFpsAndKeys) {
    const Scene s = parse(base_scene());
    ASSERT_TRUE(s.animation);
    const Animation& a = *s.animation;
    EXPECT_EQ(a.frames, 48);
    EXPECT_EQ(a.fps, 24.0);
    ASSERT_EQ(a.camera.size(), 2u);
    EXPECT_EQ(a.camera[1].frame, 47);
    EXPECT_TRUE(a.camera[1].eye && a.camera[1].fov);
    EXPECT_FALSE(a.camera[0].fov || a.camera[0].lookat || a.camera[0].up);
    EXPECT_EQ(*a.camera[1].fov, 40.0f);
    ASSERT_EQ(a.objects.size(), 1u);
    EXPECT_EQ(a.objects[0].name, "ball");
    EXPECT_EQ(a.objects[0].object, 1u);  // objects[1]
    ASSERT_EQ(a.objects[0].keys.size(), 2u);
    EXPECT_TRUE(same_bits(*a.objects[0].keys[1].center, Vec3{1.0f, 0.5f, 0.0f}));
    EXPECT_FALSE(a.objects[0].keys[1].radius);
}

TEST(AnimationLoad, FpsDefaultsTo24AndMayBeFractional) {
    Json j = base_scene();
    j["animation"].erase("fps");
    EXPECT_EQ(parse(j).animation->fps, 24.0);
    j["animation"]["fps"] = 29.97;
    EXPECT_EQ(parse(j).animation->fps, 29.97);
}

TEST(AnimationLoad, CameraAndObjectTracksAreOptional) {
    Json j = base_scene();
    j["animation"] = {{"frames", 3}};
    const Scene s = parse(j);
    ASSERT_TRUE(s.animation);
    EXPECT_TRUE(s.animation->camera.empty());
    EXPECT_TRUE(s.animation->objects.empty());
    EXPECT_EQ(default_frames(s), (std::vector<int>{0, 1, 2}));
}

TEST(AnimationLoad, StillSceneHasNoAnimation) {
    Json j = base_scene();
    j.erase("animation");
    const Scene s = parse(j);
    EXPECT_FALSE(s.animation);
    EXPECT_EQ(default_frames(s), std::vector<int>{0});
    EXPECT_EQ(frame_time(s, 48), 2.0);
    // A still scene is its own pose at every frame.
    EXPECT_EQ(scene_to_json(scene_at_frame(s, 17)), scene_to_json(s));
}

TEST(AnimationLoad, FrameTimeIsFrameOverFps) {
    Json j = base_scene();
    j["animation"]["fps"] = 30;
    const Scene s = parse(j);
    EXPECT_EQ(frame_time(s, 0), 0.0);
    EXPECT_EQ(frame_time(s, 45), 1.5);
    EXPECT_EQ(default_frames(s).size(), 48u);
    EXPECT_EQ(default_frames(s).back(), 47);
}

TEST(AnimationLoad, BounceExampleLoads) {
    const Scene s = load_scene_file(kBounce);
    ASSERT_TRUE(s.animation);
    EXPECT_EQ(s.animation->frames, 48);
    ASSERT_EQ(s.animation->objects.size(), 1u);
    EXPECT_EQ(s.objects[s.animation->objects[0].object].name, "ball");
    for (int f : default_frames(s)) EXPECT_NO_THROW((void)scene_at_frame(s, f)) << f;
}

// ---------------------------------------------------------------------------------------
// Interpolation

TEST(AnimationPose, ExactAtKeysAndLinearBetween) {
    const Scene s = parse(base_scene());
    const Vec3 e0{0, 1, 5}, e1{3, 2, 4};
    EXPECT_TRUE(same_bits(camera_at_frame(s, 0).eye, e0));
    EXPECT_TRUE(same_bits(camera_at_frame(s, 47).eye, e1));
    EXPECT_TRUE(same_bits(camera_at_frame(s, 47).fov, 40.0f));
    for (int f : {1, 10, 23, 24, 46}) {
        const double t = f / 47.0;
        EXPECT_TRUE(same_bits(camera_at_frame(s, f).eye, lerp_expected(e0, e1, t))) << f;
        const Scene posed = scene_at_frame(s, f);
        EXPECT_TRUE(same_bits(posed.objects[1].center,
                              lerp_expected(Vec3{-1, 0.5f, 0}, Vec3{1, 0.5f, 0}, t)))
            << f;
    }
    // fov has one key (frame 47): held at 40 on every frame.
    EXPECT_EQ(camera_at_frame(s, 0).fov, 40.0f);
    // Nothing keys lookat or up: the scene's values.
    EXPECT_TRUE(same_bits(camera_at_frame(s, 20).lookat, s.camera.lookat));
    EXPECT_TRUE(same_bits(camera_at_frame(s, 20).up, s.camera.up));
}

TEST(AnimationPose, MidpointBetweenTwoKeys) {
    Json j = base_scene();
    j["animation"]["frames"] = 11;
    j["animation"]["camera"] =
        Json::array({{{"frame", 0}, {"fov", 30}}, {{"frame", 10}, {"fov", 60}}});
    j["animation"]["objects"]["ball"] = Json::array(
        {{{"frame", 0}, {"center", {0, 0, 0}}}, {{"frame", 10}, {"center", {2, 4, -6}}}});
    const Scene s = parse(j);
    EXPECT_EQ(camera_at_frame(s, 5).fov, 45.0f);
    EXPECT_TRUE(same_bits(scene_at_frame(s, 5).objects[1].center, Vec3{1, 2, -3}));
}

TEST(AnimationPose, HeldBeforeTheFirstAndAfterTheLastKey) {
    Json j = base_scene();
    j["animation"]["objects"]["ball"] = Json::array(
        {{{"frame", 10}, {"center", {0, 1, 0}}}, {{"frame", 20}, {"center", {0, 2, 0}}}});
    const Scene s = parse(j);
    for (int f : {0, 5, 10}) {
        EXPECT_TRUE(same_bits(scene_at_frame(s, f).objects[1].center, Vec3{0, 1, 0})) << f;
    }
    for (int f : {20, 30, 47}) {
        EXPECT_TRUE(same_bits(scene_at_frame(s, f).objects[1].center, Vec3{0, 2, 0})) << f;
    }
    EXPECT_TRUE(same_bits(scene_at_frame(s, 15).objects[1].center, Vec3{0, 1.5f, 0}));
}

TEST(AnimationPose, FramesOutsideTheSequenceHoldTheEndPoses) {
    Json j = base_scene();
    // A key beyond the last frame: frame 47 is posed, frames after it are not extrapolated.
    j["animation"]["objects"]["ball"][1]["frame"] = 94;
    const Scene s = parse(j);
    EXPECT_EQ(scene_to_json(scene_at_frame(s, -5)), scene_to_json(scene_at_frame(s, 0)));
    EXPECT_EQ(scene_to_json(scene_at_frame(s, 48)), scene_to_json(scene_at_frame(s, 47)));
    EXPECT_EQ(scene_to_json(scene_at_frame(s, 1000000)), scene_to_json(scene_at_frame(s, 47)));
    EXPECT_TRUE(same_bits(scene_at_frame(s, 47).objects[1].center, Vec3{0, 0.5f, 0}));
}

TEST(AnimationPose, PartialKeysInterpolateEachPropertyBetweenTheKeysThatSetIt) {
    Json j = base_scene();
    j["animation"]["camera"] = Json::array({
        {{"frame", 0}, {"eye", {0, 1, 5}}},
        {{"frame", 10}, {"fov", 30}},
        {{"frame", 20}, {"eye", {2, 1, 5}}, {"lookat", {1, 0, 0}}},
    });
    const Scene s = parse(j);
    // eye: between frames 0 and 20, the fov-only key at 10 does not pin it.
    EXPECT_TRUE(same_bits(camera_at_frame(s, 10).eye, Vec3{1, 1, 5}));
    // fov: one key, held everywhere.
    for (int f : {0, 10, 40}) EXPECT_EQ(camera_at_frame(s, f).fov, 30.0f) << f;
    // lookat: keyed at 20 only, so frames before it hold that key too.
    EXPECT_TRUE(same_bits(camera_at_frame(s, 0).lookat, Vec3{1, 0, 0}));
    // up: never keyed, the scene's value.
    EXPECT_TRUE(same_bits(camera_at_frame(s, 5).up, Vec3{0, 1, 0}));
}

TEST(AnimationPose, RadiusKeysLeaveTheCenterAlone) {
    Json j = base_scene();
    j["animation"]["objects"] = {
        {"moon", Json::array({{{"frame", 0}, {"radius", 1}}, {{"frame", 40}, {"radius", 3}}})}};
    const Scene s = parse(j);
    const Scene posed = scene_at_frame(s, 10);
    EXPECT_EQ(posed.objects[2].radius, 1.5f);
    EXPECT_TRUE(same_bits(posed.objects[2].center, s.objects[2].center));
    EXPECT_EQ(scene_at_frame(s, 47).objects[2].radius, 3.0f);
    // Other objects are untouched.
    EXPECT_TRUE(same_bits(posed.objects[1].center, s.objects[1].center));
}

TEST(AnimationPose, VisitingFramesGivesTheCamerasOfCameraAtFrame) {
    Json j = base_scene();
    j["animation"]["camera"] = Json::array({
        {{"frame", 2}, {"eye", {0, 1, 5}}, {"fov", 30}},
        {{"frame", 9}, {"up", {0.1, 1, 0}}},
        {{"frame", 20}, {"eye", {2, 1, 5}}, {"lookat", {1, 0, 0}}},
        {{"frame", 21}, {"fov", 60}},
    });
    const Scene s = parse(j);
    std::vector<int> visited;
    visit_camera_frames(s, -3, 50, [&](int f, const Camera& c) {
        visited.push_back(f);
        const Camera expected = camera_at_frame(s, f);
        EXPECT_TRUE(same_bits(c.eye, expected.eye) && same_bits(c.lookat, expected.lookat) &&
                    same_bits(c.up, expected.up) && same_bits(c.fov, expected.fov))
            << f;
    });
    EXPECT_EQ(visited.size(), 54u);
    EXPECT_TRUE(
        same_bits(camera_at_frame(s, 20).fov, lerp_expected(30.0f, 60.0f, 18.0 / 19.0)));
}

TEST(AnimationPose, PosedSceneIsAStillAndDeterministic) {
    const Scene s = parse(base_scene());
    const Scene a = scene_at_frame(s, 17);
    const Scene b = scene_at_frame(s, 17);
    EXPECT_FALSE(a.animation);
    EXPECT_EQ(scene_to_json(a), scene_to_json(b));
    EXPECT_NE(scene_to_json(a), scene_to_json(scene_at_frame(s, 18)));
    EXPECT_NO_THROW(validate_scene(a));
    // The authored scene is left alone.
    EXPECT_TRUE(same_bits(s.objects[1].center, Vec3{-1, 0.5f, 0}));
}

TEST(AnimationPose, ReposingInPlaceGivesTheSceneOfThatFrame) {
    // Partial keys on both spheres, a radius track, frames before, between, on and after
    // the keys, in an order that goes back and forth.
    Json j = base_scene();
    j["animation"]["objects"]["moon"] = Json::array({{{"frame", 3}, {"radius", 1}},
                                                     {{"frame", 9}, {"center", {1, 3, -4}}},
                                                     {{"frame", 30}, {"radius", 2}}});
    const Scene s = parse(j);
    Scene posed = scene_at_frame(s, 0);
    for (int f : {5, 6, 47, 0, 30, 29, 3, -2, 60, 9, 17}) {
        repose_at_frame(s, f, posed);
        EXPECT_EQ(scene_to_json(posed), scene_to_json(scene_at_frame(s, f))) << f;
    }
}

TEST(AnimationError, ReposingToAnUnusableFrameGivesTheErrorOfPosingIt) {
    Json j = base_scene();
    j["animation"]["objects"]["moon"] =
        Json::array({{{"frame", 0}, {"radius", 1}}, {{"frame", 40}, {"radius", 3}}});
    Scene s = parse(j);
    s.animation->objects.back().keys.back().radius = -3.0f;  // skips validate_scene
    Scene posed = scene_at_frame(s, 0);
    const auto message = [&](const std::function<void()>& pose) {
        try {
            pose();
        } catch (const SceneError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    const std::string expected = message([&] { (void)scene_at_frame(s, 35); });
    EXPECT_NE(expected.find("at frame 35, as posed by the animation"), std::string::npos)
        << expected;
    EXPECT_NE(expected.find("objects[2].radius"), std::string::npos) << expected;
    EXPECT_EQ(message([&] { repose_at_frame(s, 35, posed); }), expected);
    // The next frame poses every animated sphere again.
    repose_at_frame(s, 5, posed);
    EXPECT_EQ(scene_to_json(posed), scene_to_json(scene_at_frame(s, 5)));

    // A bounding box that overflows float is found too.
    s.animation->objects.back().keys.back().radius = 3e38f;
    const std::string overflow = message([&] { (void)scene_at_frame(s, 40); });
    EXPECT_NE(overflow.find("overflows float"), std::string::npos) << overflow;
    EXPECT_EQ(message([&] { repose_at_frame(s, 40, posed); }), overflow);
}

// ---------------------------------------------------------------------------------------
// Errors

TEST(AnimationError, Frames) {
    Json j = base_scene();
    j["animation"]["frames"] = 0;
    expect_error(j, "animation.frames", {"expected an integer from 1 to 1000000", "found 0"});
    j["animation"]["frames"] = 1000001;
    expect_error(j, "animation.frames", {"1000000"});
    j["animation"]["frames"] = 2.5;
    expect_error(j, "animation.frames", {"expected an integer"});
    j["animation"].erase("frames");
    expect_error(j, "animation.frames", {"missing required key \"frames\""});
}

TEST(AnimationError, Fps) {
    Json j = base_scene();
    j["animation"]["fps"] = 0;
    expect_error(j, "animation.fps", {"expected frames per second > 0", "found 0"});
    j["animation"]["fps"] = -24;
    expect_error(j, "animation.fps", {"found -24"});
    j["animation"]["fps"] = "24";
    expect_error(j, "animation.fps", {"expected frames per second", "the string \"24\""});
}

TEST(AnimationError, KeyFrames) {
    Json j = base_scene();
    j["animation"]["camera"][0]["frame"] = -1;
    expect_error(j, "animation.camera[0].frame", {"expected an integer from 0 to 2147483647"});
    j["animation"]["camera"][0]["frame"] = 0.5;
    expect_error(j, "animation.camera[0].frame", {"expected an integer", "found 0.5"});
    j["animation"]["camera"][0].erase("frame");
    expect_error(j, "animation.camera[0].frame", {"missing required key \"frame\""});

    j = base_scene();
    j["animation"]["camera"][1]["frame"] = 0;
    expect_error(j, "animation.camera[1].frame",
                 {"strictly increasing", "found frame 0 after frame 0 (animation.camera[0])"});
    j = base_scene();
    j["animation"]["objects"]["ball"][0]["frame"] = 50;
    expect_error(j, "animation.objects.ball[1].frame",
                 {"strictly increasing", "found frame 47 after frame 50"});
}

TEST(AnimationError, UnknownAndUnanimatedKeys) {
    Json j = base_scene();
    j["animation"]["frame"] = 3;
    expect_error(j, "animation.frame", {"unknown key \"frame\"", "did you mean \"frames\"?"});
    j = base_scene();
    j["animation"]["camera"][1]["eyes"] = {0, 0, 0};
    expect_error(j, "animation.camera[1].eyes",
                 {"unknown key", "did you mean \"eye\"?",
                  "\"frame\", \"eye\", \"lookat\", \"up\", \"fov\""});
    j = base_scene();
    j["animation"]["camera"][0]["aperture"] = 0.1;
    expect_error(
        j, "animation.camera[0].aperture",
        {"key \"aperture\" cannot be animated", "\"eye\", \"lookat\", \"up\", \"fov\""});
    j = base_scene();
    j["animation"]["objects"]["ball"][0]["material"] = "x";
    expect_error(j, "animation.objects.ball[0].material",
                 {"cannot be animated", "\"center\", \"radius\""});
    j = base_scene();
    j["animation"]["objects"]["ball"][0]["centre"] = {0, 0, 0};
    expect_error(j, "animation.objects.ball[0].centre", {"did you mean \"center\"?"});
}

TEST(AnimationError, KeysThatSetNothing) {
    Json j = base_scene();
    j["animation"]["camera"][0] = {{"frame", 0}};
    expect_error(j, "animation.camera[0]", {"a camera key sets nothing"});
    j = base_scene();
    j["animation"]["objects"]["ball"][0] = {{"frame", 0}};
    expect_error(j, "animation.objects.ball[0]", {"an object key sets nothing"});
}

TEST(AnimationError, ObjectNames) {
    Json j = base_scene();
    j["animation"]["objects"] = {{"bal", Json::array({{{"frame", 0}, {"radius", 1}}})}};
    expect_error(j, "animation.objects.bal",
                 {"unknown object \"bal\"", "did you mean \"ball\"?",
                  "the scene names \"floor\", \"ball\", \"moon\""});
    j.erase("objects");
    expect_error(j, "animation.objects.bal", {"the scene names no objects"});
    j = base_scene();
    j["objects"][2]["name"] = "ball";
    expect_error(j, "objects[2].name", {"unique object name"});
}

TEST(AnimationError, SphereKeysOnAPlane) {
    Json j = base_scene();
    j["animation"]["objects"]["floor"] = Json::array({{{"frame", 0}, {"radius", 2}}});
    expect_error(
        j, "animation.objects.floor[0].radius",
        {"key \"radius\" applies only to spheres, not to a plane (objects[0], \"floor\")"});
    j["animation"]["objects"]["floor"] = Json::array({{{"frame", 0}, {"center", {0, 1, 0}}}});
    expect_error(j, "animation.objects.floor[0].center", {"applies only to spheres"});
}

TEST(AnimationError, Values) {
    Json j = base_scene();
    j["animation"]["objects"]["ball"][1]["radius"] = 0;
    expect_error(j, "animation.objects.ball[1].radius", {"expected a radius > 0, found 0"});
    j["animation"]["objects"]["ball"][1]["radius"] = -1;
    expect_error(j, "animation.objects.ball[1].radius", {"found -1"});
    j = base_scene();
    j["animation"]["objects"]["ball"][1]["center"] = {1, 2};
    expect_error(j, "animation.objects.ball[1].center", {"expected an array of 3 numbers"});
    j = base_scene();
    j["animation"]["camera"][1]["fov"] = 180;
    expect_error(j, "animation.camera[1].fov",
                 {"expected a field of view in (0, 180)", "found 180"});
    j["animation"]["camera"][1]["fov"] = 0;
    expect_error(j, "animation.camera[1].fov", {"found 0"});
    j = base_scene();
    j["camera"]["type"] = "fisheye";
    j["animation"]["camera"][1]["fov"] = 360;
    EXPECT_NO_THROW((void)parse(j));
    j["animation"]["camera"][1]["fov"] = 361;
    expect_error(j, "animation.camera[1].fov", {"(0, 360]"});
    j = base_scene();
    j["camera"] = {{"type", "orthographic"}, {"eye", {0, 1, 5}}, {"lookat", {0, 0, 0}}};
    expect_error(
        j, "animation.camera[1].fov",
        {"applies only to pinhole, thinlens and fisheye cameras, not to an orthographic"});
    j = base_scene();
    j["animation"]["camera"][1]["up"] = {0, 0, 0};
    expect_error(j, "animation.camera[1].up", {"expected a non-zero up vector"});
}

TEST(AnimationError, InterpolatedCameraIsCheckedOnEveryFrame) {
    // up turns from +y to -y: on the frame halfway it is [0, 0, 0].
    Json j = base_scene();
    j["animation"]["camera"] =
        Json::array({{{"frame", 0}, {"up", {0, 1, 0}}}, {{"frame", 10}, {"up", {0, -1, 0}}}});
    expect_error(j, "animation.camera",
                 {"at frame 5 the interpolated camera is unusable", "non-zero up vector"});
    // The eye passes through the look-at point on frame 2.
    j = base_scene();
    j["animation"]["camera"] = Json::array(
        {{{"frame", 0}, {"eye", {0, 0.5f, -2}}}, {{"frame", 4}, {"eye", {0, 0.5f, 2}}}});
    expect_error(j, "animation.camera", {"at frame 2", "eye and lookat coincide"});
    // Looking straight down along up on frame 3.
    j = base_scene();
    j["animation"]["camera"] = Json::array(
        {{{"frame", 0}, {"eye", {-3, 3.5f, 0}}}, {{"frame", 6}, {"eye", {3, 3.5f, 0}}}});
    expect_error(j, "animation.camera", {"at frame 3", "parallel to the view direction"});
    // ... but only frames of the sequence count: the same keys beyond it are fine.
    j["animation"]["frames"] = 3;
    EXPECT_NO_THROW((void)parse(j));
}

TEST(AnimationError, Shapes) {
    Json j = base_scene();
    j["animation"]["camera"] = {{"frame", 0}};
    expect_error(j, "animation.camera", {"expected an array of camera keys"});
    j = base_scene();
    j["animation"]["objects"] = Json::array();
    expect_error(j, "animation.objects", {"expected an object mapping object names"});
    j = base_scene();
    j["animation"]["objects"]["ball"] = {{"frame", 0}};
    expect_error(j, "animation.objects.ball", {"expected an array of object keys"});
    j = base_scene();
    j["animation"] = 48;
    expect_error(j, "animation", {"expected an object"});
}

TEST(AnimationError, HandBuiltAnimationIsValidated) {
    Scene s = parse(base_scene());
    Scene bad = s;
    bad.animation->objects[0].object = 9;
    EXPECT_THROW(validate_scene(bad), SceneError);
    bad = s;
    bad.animation->objects[0].object = 2;  // "moon", but the track says "ball"
    try {
        validate_scene(bad);
        ADD_FAILURE() << "expected a SceneError";
    } catch (const SceneError& e) {
        EXPECT_EQ(e.json_path(), "animation.objects.ball");
        EXPECT_NE(std::string(e.what()).find("is named \"moon\""), std::string::npos)
            << e.what();
    }
    bad = s;
    bad.animation->objects.push_back(bad.animation->objects[0]);
    EXPECT_THROW(validate_scene(bad), SceneError);
    bad = s;
    bad.animation->fps = std::nan("");
    EXPECT_THROW(validate_scene(bad), SceneError);
}

TEST(AnimationError, PosingAnUnvalidatedSceneNamesTheFrame) {
    Scene s = parse(base_scene());
    s.animation->camera[1].eye = s.camera.lookat;  // skips validate_scene
    try {
        (void)scene_at_frame(s, 47);
        ADD_FAILURE() << "expected a SceneError";
    } catch (const SceneError& e) {
        EXPECT_EQ(e.json_path(), "camera");
        EXPECT_NE(std::string(e.what()).find("at frame 47, as posed by the animation"),
                  std::string::npos)
            << e.what();
    }
}

// ---------------------------------------------------------------------------------------
// Writing

void expect_same_animation(const Animation& a, const Animation& b) {
    EXPECT_EQ(a.frames, b.frames);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(a.fps), std::bit_cast<std::uint64_t>(b.fps));
    ASSERT_EQ(a.camera.size(), b.camera.size());
    const auto same_opt = [](const auto& x, const auto& y) {
        return x.has_value() == y.has_value() && (!x || same_bits(*x, *y));
    };
    for (std::size_t i = 0; i < a.camera.size(); ++i) {
        const CameraKey &x = a.camera[i], &y = b.camera[i];
        EXPECT_EQ(x.frame, y.frame) << i;
        EXPECT_TRUE(same_opt(x.eye, y.eye) && same_opt(x.lookat, y.lookat) &&
                    same_opt(x.up, y.up) && same_opt(x.fov, y.fov))
            << "camera key " << i;
    }
    ASSERT_EQ(a.objects.size(), b.objects.size());
    for (std::size_t t = 0; t < a.objects.size(); ++t) {
        EXPECT_EQ(a.objects[t].name, b.objects[t].name);
        EXPECT_EQ(a.objects[t].object, b.objects[t].object);
        ASSERT_EQ(a.objects[t].keys.size(), b.objects[t].keys.size());
        for (std::size_t i = 0; i < a.objects[t].keys.size(); ++i) {
            const ObjectKey &x = a.objects[t].keys[i], &y = b.objects[t].keys[i];
            EXPECT_EQ(x.frame, y.frame);
            EXPECT_TRUE(same_opt(x.center, y.center) && same_opt(x.radius, y.radius))
                << a.objects[t].name << " key " << i;
        }
    }
}

TEST(AnimationWrite, RoundTripIsExact) {
    Json j = base_scene();
    j["animation"]["fps"] = 29.97;
    j["animation"]["camera"][0]["lookat"] = {0.1, 0.2, 0.3};
    j["animation"]["camera"][0]["up"] = {0, 1, 0.1};
    j["animation"]["objects"]["moon"] =
        Json::array({{{"frame", 3}, {"radius", 0.7}},
                     {{"frame", 9}, {"center", {1e-7, 3, -4}}, {"radius", 1.3}}});
    for (const Scene& s : {parse(j), load_scene_file(kBounce)}) {
        const std::string text = scene_to_json(s);
        const Scene back = parse_scene_json(text, "written.json");
        ASSERT_TRUE(back.animation) << text;
        expect_same_animation(*s.animation, *back.animation);
        EXPECT_EQ(scene_to_json(back), text);
        // Every frame poses the same.
        for (int f : {0, 5, 24, 47}) {
            EXPECT_EQ(scene_to_json(scene_at_frame(s, f)),
                      scene_to_json(scene_at_frame(back, f)));
        }
    }
}

TEST(AnimationWrite, WritesOnlyTheKeysProperties) {
    const std::string text = scene_to_json(parse(base_scene()));
    EXPECT_NE(text.find("{\"frame\":0,\"eye\":[0.0,1.0,5.0]}"), std::string::npos) << text;
    EXPECT_NE(text.find("\"frames\": 48"), std::string::npos) << text;
}

TEST(AnimationWrite, EmptyTracksRoundTrip) {
    Json j = base_scene();
    j["animation"]["objects"]["moon"] = Json::array();
    j["animation"]["camera"] = Json::array();
    const Scene s = parse(j);
    const Scene back = parse_scene_json(scene_to_json(s), "written.json");
    expect_same_animation(*s.animation, *back.animation);
}

// ---------------------------------------------------------------------------------------
// Rendering posed frames (the scalar reference, 32 x 24: fast under sanitizers too)

Image render_frame(const Scene& animated, int frame) {
    Scene posed = scene_at_frame(animated, frame);
    posed.image.width = 32;
    posed.image.height = 24;
    validate_scene(posed);
    RenderOptions options;
    options.frame = static_cast<std::uint32_t>(frame);
    options.threads = 1;
    return render_reference(posed, options).image;
}

TEST(AnimationRender, BounceFramesDifferAndFrameZeroIsTheAuthoredPose) {
    const Scene s = load_scene_file(kBounce);
    const Image f0 = render_frame(s, 0);
    const Image f24 = render_frame(s, 24);
    const Image f47 = render_frame(s, 47);
    EXPECT_FALSE(same_pixels(f0, f24));
    EXPECT_FALSE(same_pixels(f24, f47));
    // bounce.json's frame-0 keys repeat the authored eye, fov and ball center, and the
    // ball's first radius key equals its authored radius: frame 0 is the authored scene.
    Scene still = s;
    still.animation.reset();
    still.image.width = 32;
    still.image.height = 24;
    RenderOptions options;
    options.threads = 1;
    EXPECT_TRUE(same_pixels(f0, render_reference(still, options).image));
    // Rendering a frame twice gives the same image.
    EXPECT_TRUE(same_pixels(f24, render_frame(s, 24)));
}

}  // namespace
}  // namespace octray
