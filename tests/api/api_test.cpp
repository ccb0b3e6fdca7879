// The public API: scenes built in code, loaded and round-tripped through JSON; both paths
// and every supported ISA give the same image; options; EXR written and read back;
// comparison verdicts; every failure an api::Error of the right kind.

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "error_kind.h"
#include "octray/octray.h"

namespace api = octray::api;
using octray::api::testing::kind_of;

namespace {

api::Scene small_scene() {
    api::Scene scene;
    scene.set_image(48, 32, 4)
        .set_camera({.eye = {0.0f, 1.5f, 6.0f}, .lookat = {0.0f, 0.8f, 0.0f}, .fov = 45.0f})
        .set_background({1.0f, 1.0f, 1.0f}, {0.4f, 0.6f, 1.0f})
        .set_ambient({0.05f, 0.05f, 0.05f});
    const auto floor = scene.add_material(
        {.color = {0.9f, 0.9f, 0.9f}, .checker = true, .checker_color = {0.1f, 0.1f, 0.1f}},
        "floor");
    const auto glass = scene.add_material({.color = {1.0f, 1.0f, 1.0f},
                                           .kd = 0.0f,
                                           .ks = 0.5f,
                                           .shininess = 128.0f,
                                           .reflect = {0.1f, 0.1f, 0.1f},
                                           .transmit = 0.9f});
    scene.add_plane({0.0f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f}, floor);
    scene.add_sphere({0.0f, 1.0f, 0.0f}, 1.0f, glass, "ball");
    scene.add_point_light({5.0f, 8.0f, 5.0f}, {1.0f, 1.0f, 1.0f});
    scene.add_directional_light({-1.0f, -1.0f, -0.5f}, {0.3f, 0.3f, 0.3f});
    return scene;
}

std::string temp_path(const std::string& name) {
    std::filesystem::create_directories(OCTRAY_TEST_TMPDIR);
    return std::string(OCTRAY_TEST_TMPDIR) + "/api_" + name;
}

}  // namespace

TEST(Api, BuiltSceneRendersAndCountsRays) {
    const api::Scene scene = small_scene();
    EXPECT_NO_THROW(scene.validate());
    EXPECT_EQ(scene.object_count(), 2u);
    EXPECT_EQ(scene.light_count(), 2u);
    const api::RenderResult r = api::render(scene, {.threads = 2});
    EXPECT_EQ(r.image.width, 48);
    EXPECT_EQ(r.image.height, 32);
    EXPECT_EQ(r.image.rgb.size(), 3u * 48 * 32);
    EXPECT_EQ(r.rays.primary, 48u * 32 * 4);
    EXPECT_GT(r.rays.shadow, 0u);
    EXPECT_GT(r.rays.refracted, 0u);
    EXPECT_EQ(r.rays.total(),
              r.rays.primary + r.rays.shadow + r.rays.reflected + r.rays.refracted);
    EXPECT_EQ(r.path.rfind("simd (", 0), 0u) << r.path;
}

TEST(Api, PathsIsasAndThreadsGiveTheSameImage) {
    const api::Scene scene = small_scene();
    const api::RenderResult scalar = api::render(scene, {.path = api::Path::scalar});
    EXPECT_EQ(scalar.path, "scalar");
    for (api::Isa isa : api::supported_isas()) {
        for (int threads : {1, 2}) {
            const api::RenderResult simd =
                api::render(scene, {.isa = isa, .threads = threads, .tile_width = 8});
            EXPECT_EQ(simd.image.rgb, scalar.image.rgb) << api::isa_name(isa);
            EXPECT_EQ(simd.rays.total(), scalar.rays.total());
        }
    }
}

TEST(Api, JsonRoundTripRendersTheSameImage) {
    const api::Scene scene = small_scene();
    const api::Scene back = api::Scene::from_json(scene.to_json());
    EXPECT_EQ(back.to_json(), scene.to_json());
    EXPECT_EQ(api::render(back).image.rgb, api::render(scene).image.rgb);
}

TEST(Api, OptionsOverrideTheScene) {
    const api::Scene scene = api::Scene::load("random:8");
    EXPECT_EQ(scene.width(), 1920);
    const api::RenderResult r = api::render(scene, {.spp = 2, .width = 40, .height = 30});
    EXPECT_EQ(r.image.width, 40);
    EXPECT_EQ(r.image.height, 30);
    EXPECT_EQ(r.rays.primary, 40u * 30 * 2);
}

TEST(Api, ExrWrittenReadsBackAndCompares) {
    const api::RenderResult r = api::render(small_scene());
    const std::string f32 = temp_path("float.exr"), f16 = temp_path("half.exr");
    api::write_exr(f32, r.image, {.float32 = true});
    api::write_exr(f16, r.image);
    const api::Image back = api::read_image(f32);
    EXPECT_EQ(back.rgb, r.image.rgb);

    const api::CompareResult same = api::compare(r.image, back);
    EXPECT_EQ(same.verdict, api::Verdict::pass);
    EXPECT_EQ(same.max_abs_error, 0.0);
    // Half rounds: over the 1e-6 default, within 1e-2.
    EXPECT_EQ(api::compare_files(f32, f16).verdict, api::Verdict::fail);
    const api::CompareResult loose =
        api::compare_files(f32, f16, {.fail_threshold = 1e-2, .warn_threshold = 1e-2});
    EXPECT_EQ(loose.verdict, api::Verdict::pass) << loose.reason;
    EXPECT_GT(loose.max_abs_error, 0.0);
}

TEST(Api, FailuresAreErrorsOfTheRightKind) {
    EXPECT_EQ(kind_of([] { api::Scene::load(temp_path("missing.json")); }),
              api::ErrorKind::scene);
    EXPECT_EQ(kind_of([] { api::Scene::from_json("{\"camera\": {}}"); }),
              api::ErrorKind::scene);
    api::Scene bad = small_scene();
    bad.add_sphere({0.0f, 0.0f, 0.0f}, -1.0f, 0);
    EXPECT_EQ(kind_of([&] { bad.validate(); }), api::ErrorKind::scene);
    EXPECT_EQ(kind_of([&] { api::render(bad); }), api::ErrorKind::scene);
    EXPECT_EQ(kind_of([] { api::read_image(temp_path("missing.exr")); }), api::ErrorKind::io);
    EXPECT_EQ(kind_of([] {
                  api::write_exr(temp_path("no/such/dir/x.exr"),
                                 api::render(small_scene()).image);
              }),
              api::ErrorKind::io);
    const api::Image a{2, 2, std::vector<float>(12, 0.0f)};
    const api::Image b{3, 2, std::vector<float>(18, 0.0f)};
    EXPECT_EQ(kind_of([&] { api::compare(a, b); }), api::ErrorKind::invalid_argument);
    EXPECT_EQ(kind_of([] { api::render(small_scene(), {.threads = -1}); }),
              api::ErrorKind::invalid_argument);
    EXPECT_STREQ(api::version(), "0.1.0");
}

// Issue 43: a long render through the API reports its progress on the caller's thread and
// can be cancelled from the callback; a cancelled render returns no image.
TEST(Api, ProgressCallbackReportsAndCancels) {
    const api::Scene scene = small_scene();
    std::vector<api::Progress> calls;
    const std::thread::id caller = std::this_thread::get_id();
    bool other_thread = false;
    api::RenderOptions options{.threads = 2};
    options.progress_interval_ms = 1;
    options.progress = [&](const api::Progress& p) {
        calls.push_back(p);
        other_thread |= std::this_thread::get_id() != caller;
        return true;
    };
    const api::RenderResult r = api::render(scene, options);
    ASSERT_GE(calls.size(), 2u);
    EXPECT_FALSE(other_thread) << "the callback ran on another thread";
    EXPECT_EQ(calls.front().pixels_done, 0u);
    EXPECT_EQ(calls.back().pixels_done, 48u * 32);
    EXPECT_EQ(calls.back().fraction(), 1.0);
    for (std::size_t i = 0; i < calls.size(); ++i) {
        EXPECT_EQ(calls[i].pixels_total, 48u * 32);
        if (i > 0) {
            EXPECT_GE(calls[i].pixels_done, calls[i - 1].pixels_done);
        }
    }
    // The same image as a render without the callback.
    EXPECT_EQ(r.image.rgb, api::render(scene, {.threads = 2}).image.rgb);
    // The scalar path reports as well.
    calls.clear();
    options.path = api::Path::scalar;
    EXPECT_EQ(api::render(scene, options).image.rgb, r.image.rgb);
    ASSERT_GE(calls.size(), 2u);
    EXPECT_EQ(calls.back().pixels_done, 48u * 32);
    options.path = api::Path::simd;

    // Cancelled: an Error of kind cancelled, no image.
    int asked = 0;
    options.progress = [&](const api::Progress&) { return ++asked < 1; };
    try {
        (void)api::render(scene, options);
        ADD_FAILURE() << "a cancelled render returned";
    } catch (const api::Error& e) {
        EXPECT_EQ(e.kind(), api::ErrorKind::cancelled) << e.what();
    }
    EXPECT_EQ(asked, 1);
    // An exception from the callback stops the render and reaches the caller.
    options.progress = [](const api::Progress& p) -> bool {
        if (p.pixels_done > 0 || p.pixels_total == 0) return true;
        throw std::runtime_error("from the callback");
    };
    try {
        (void)api::render(scene, options);
        ADD_FAILURE() << "the callback's exception was lost";
    } catch (const api::Error& e) {
        ADD_FAILURE() << "the callback's exception became an api::Error: " << e.what();
    } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "from the callback");
    }
}

namespace {

// small_scene()'s ball and camera animated over 5 frames: the ball moves and grows, the
// camera moves (JSON: the API builds no animation in code).
api::Scene animated_scene(bool camera_only) {
    std::string json = small_scene().to_json();
    const std::string objects = camera_only ? "" : R"(, "objects": {"ball": [
        {"frame": 0, "center": [0, 1, 0]}, {"frame": 4, "center": [1, 1.5, -1], "radius": 1.4}]})";
    json.insert(json.rfind('}'), R"(, "animation": {"frames": 5, "camera": [
        {"frame": 0, "eye": [0, 1.5, 6]}, {"frame": 4, "eye": [3, 2.5, 5]}])" +
                                     objects + "}");
    return api::Scene::from_json(json, "animated.json");
}

}  // namespace

// Renderer (prepare once, render many): every frame, in any order, is bit for bit the frame
// api::render gives alone, on both paths, for moving spheres, a moving camera and a still.
TEST(Api, ARendererGivesEachFrameAsRenderedAlone) {
    const api::Scene scenes[] = {animated_scene(false), animated_scene(true), small_scene()};
    for (const api::Scene& scene : scenes) {
        for (api::Path path : {api::Path::simd, api::Path::scalar}) {
            const api::RenderOptions options{.path = path, .threads = 2, .spp = 1};
            api::Renderer renderer(scene, options);
            EXPECT_EQ(renderer.frame_count(),
                      scene.to_json().find("animation") != std::string::npos ? 5 : 1);
            for (int frame : {0, 3, 1, 4, 2, 7, 0}) {
                api::RenderOptions alone = options;
                alone.frame = frame;
                EXPECT_EQ(renderer.render(frame).image.rgb, api::render(scene, alone).image.rgb)
                    << "frame " << frame << (path == api::Path::scalar ? " scalar" : " simd");
            }
        }
    }
    // The moving ball really moves: frames differ.
    api::Renderer renderer(animated_scene(false), {.threads = 2, .spp = 1});
    EXPECT_NE(renderer.render(0).image.rgb, renderer.render(4).image.rgb);
}

TEST(Api, ARendererRefusesWhatRenderRefuses) {
    const api::Scene scene = small_scene();
    EXPECT_EQ(kind_of([&] { api::Renderer(scene, {.threads = -1}); }),
              api::ErrorKind::invalid_argument);
    EXPECT_EQ(kind_of([&] { api::Renderer(scene, {.tile_width = 0}); }),
              api::ErrorKind::invalid_argument);
    EXPECT_EQ(kind_of([&] { api::Renderer(scene, {.spp = (1 << 20) + 1}); }),
              api::ErrorKind::scene);
    api::Renderer renderer(scene, {.threads = 1});
    EXPECT_EQ(kind_of([&] { renderer.render(-1); }), api::ErrorKind::invalid_argument);
    api::Renderer moved = std::move(renderer);
    EXPECT_EQ(moved.render(0).image.width, 48);
    EXPECT_EQ(kind_of([&] { renderer.render(0); }),
              api::ErrorKind::invalid_argument);  // NOLINT
}
