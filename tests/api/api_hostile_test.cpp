// Every public function of include/octray/octray.h under hostile arguments (issue 38): each
// call returns or throws api::Error, never crashes, hangs or throws anything else. A
// deterministic sweep over the edges of each argument (0, negative, INT_MAX, NaN, infinities,
// huge and tiny floats, enum values outside the enums, empty and odd strings and images),
// plus a seeded random mix of them; the sanitizer build (asan preset) runs it too.

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "error_kind.h"
#include "octray/octray.h"

namespace api = octray::api;
using octray::api::testing::kind_of;

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

const std::vector<float> kFloats = {0.0f,  -0.0f, 1.0f,   -1.0f,   0.5f, 1e-45f, 1e-30f,
                                    1e20f, 1e30f, -1e30f, 3.4e38f, kNaN, kInf,   -kInf};
const std::vector<int> kInts = {INT_MIN,       -1,     0, 1, 2, 3, 16, 65, 4097, 1 << 20,
                                (1 << 20) + 1, INT_MAX};

std::string temp_path(const std::string& name) {
    std::filesystem::create_directories(OCTRAY_TEST_TMPDIR);
    return std::string(OCTRAY_TEST_TMPDIR) + "/api_hostile_" + name;
}

// Runs f; true when it returned, false when it threw api::Error; fails the test on any
// other exception.
bool returns_or_api_error(const std::string& what, const std::function<void()>& f) {
    try {
        f();
        return true;
    } catch (const api::Error&) {
        return false;
    } catch (const std::exception& e) {
        ADD_FAILURE() << what << ": threw " << e.what() << " instead of api::Error";
    } catch (...) {
        ADD_FAILURE() << what << ": threw a non-std exception";
    }
    return false;
}

// A small valid scene to break one piece at a time.
api::Scene small_scene() {
    api::Scene scene;
    scene.set_image(8, 6, 1);
    const auto m = scene.add_material({.reflect = {0.5f, 0.5f, 0.5f}, .transmit = 0.3f});
    scene.add_sphere({0.0f, 0.0f, 0.0f}, 1.0f, m);
    scene.add_plane({0.0f, -1.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, m);
    scene.add_point_light({2.0f, 3.0f, 4.0f}, {1.0f, 1.0f, 1.0f});
    return scene;
}

api::Vec3 v3(float x, float y, float z) { return {x, y, z}; }

// The cases the issue names: each was a crash or a wrong verdict.
TEST(ApiHostile, TheReportedCrashesAreErrors) {
    const api::Image empty{0, 0, {}};
    EXPECT_EQ(kind_of([&] { api::compare(empty, empty); }), api::ErrorKind::invalid_argument);
    EXPECT_EQ(kind_of([&] { api::render(small_scene(), {.threads = INT_MAX}); }),
              api::ErrorKind::invalid_argument);
    EXPECT_EQ(kind_of([&] { api::render(small_scene(), {.threads = 4097}); }),
              api::ErrorKind::invalid_argument);

    // A NaN threshold compared false with every error, and so passed images that differ.
    const api::Image a{1, 1, {0.0f, 0.0f, 0.0f}};
    const api::Image b{1, 1, {1.0f, 1.0f, 1.0f}};
    for (double nan : {std::nan(""), -1.0}) {
        EXPECT_EQ(kind_of([&] { api::compare(a, b, {.fail_threshold = nan}); }),
                  api::ErrorKind::invalid_argument);
        EXPECT_EQ(kind_of([&] { api::compare(a, b, {.warn_threshold = nan}); }),
                  api::ErrorKind::invalid_argument);
        EXPECT_EQ(kind_of([&] { api::compare(a, b, {.fail_percent = nan}); }),
                  api::ErrorKind::invalid_argument);
        EXPECT_EQ(kind_of([&] { api::compare(a, b, {.warn_percent = nan}); }),
                  api::ErrorKind::invalid_argument);
    }
    EXPECT_EQ(kind_of([&] { api::compare(a, b, {.fail_percent = 101.0}); }),
              api::ErrorKind::invalid_argument);
    EXPECT_EQ(api::compare(a, b).verdict, api::Verdict::fail);
}

// One limit for spp wherever it is set: the API's option, the scene's image and a built-in.
TEST(ApiHostile, SppHasTheOneLimitEverywhere) {
    EXPECT_EQ(kind_of([&] { api::render(small_scene(), {.spp = (1 << 20) + 1}); }),
              api::ErrorKind::scene);
    api::Scene s = small_scene();
    s.set_image(8, 6, (1 << 20) + 1);
    EXPECT_EQ(kind_of([&] { s.validate(); }), api::ErrorKind::scene);
    s.set_image(8, 6, 1 << 20);
    EXPECT_NO_THROW(s.validate());
    EXPECT_EQ(kind_of([] { api::Scene::load("whitted,spp=1048577"); }), api::ErrorKind::scene);
    EXPECT_EQ(api::Scene::load("whitted,spp=1048576").spp(), 1 << 20);
    EXPECT_EQ(
        kind_of([] {
            api::Scene::from_json(R"({"image": {"width": 4, "height": 4, "spp": 1048577}})");
        }),
        api::ErrorKind::scene);
    EXPECT_EQ(kind_of([&] { api::render(small_scene(), {.width = -1}); }),
              api::ErrorKind::invalid_argument);
}

// The scene setters take anything; validate(), to_json() and render() then either work or
// throw api::Error. Renders stay tiny (the image size is never fuzzed upwards).
TEST(ApiHostile, SceneSettersThenValidateJsonAndRender) {
    const auto exercise = [](const std::string& what, const api::Scene& scene) {
        const bool valid = returns_or_api_error(what + " validate", [&] { scene.validate(); });
        std::string json;
        const bool written =
            returns_or_api_error(what + " to_json", [&] { json = scene.to_json(); });
        EXPECT_EQ(valid, written) << what;
        if (written) {
            returns_or_api_error(what + " from_json", [&] { api::Scene::from_json(json); });
        }
        if (valid && scene.width() * static_cast<long>(scene.height()) <= 64 &&
            scene.spp() <= 4) {
            returns_or_api_error(what + " render simd", [&] { api::render(scene); });
            returns_or_api_error(what + " render scalar",
                                 [&] { api::render(scene, {.path = api::Path::scalar}); });
        }
    };
    for (float f : kFloats) {
        const std::string at = " " + std::to_string(f);
        for (int type = -1; type <= 4; ++type) {
            api::Scene s = small_scene();
            s.set_camera({.type = static_cast<api::CameraType>(type),
                          .eye = v3(f, 0.0f, 5.0f),
                          .fov = f,
                          .width = f,
                          .aperture = f,
                          .focus_distance = f});
            exercise("camera type " + std::to_string(type) + at, s);
        }
        api::Scene s = small_scene();
        s.set_camera(
            {.eye = v3(0.0f, 0.0f, f), .lookat = v3(f, f, f), .up = v3(f, 1.0f, 0.0f)});
        exercise("camera eye/lookat/up" + at, s);
        s = small_scene();
        s.add_sphere(v3(f, f, f), f, 0);
        exercise("sphere" + at, s);
        s = small_scene();
        s.add_plane(v3(f, 0.0f, 0.0f), v3(f, f, 0.0f), 0);
        exercise("plane" + at, s);
        s = small_scene();
        s.add_material({.color = {f, f, f},
                        .kd = f,
                        .ks = f,
                        .shininess = f,
                        .reflect = {f, f, f},
                        .transmit = f,
                        .ior = f,
                        .checker = true,
                        .checker_color = {f, f, f},
                        .checker_size = f});
        s.add_sphere(v3(0.0f, 2.0f, 0.0f), 0.5f, 1);
        exercise("material" + at, s);
        s = small_scene();
        s.add_point_light(v3(f, f, f), {f, f, f}, true);
        s.add_directional_light(v3(f, f, f), {f, f, f});
        s.set_background({f, f, f}, {f, f, f}).set_ambient({f, f, f});
        exercise("lights and background" + at, s);
    }
    for (int n : kInts) {
        const std::string at = " " + std::to_string(n);
        api::Scene s = small_scene();
        s.set_image(n, 1, 1);
        exercise("width" + at, s);
        s.set_image(1, n, 1);
        exercise("height" + at, s);
        s.set_image(1, 1, n);
        exercise("spp" + at, s);
        s = small_scene();
        s.set_max_depth(n);
        exercise("max depth" + at, s);
        s = small_scene();
        s.add_sphere(v3(0.0f, 0.0f, 0.0f), 1.0f, static_cast<std::uint32_t>(n));
        s.add_plane(v3(0.0f, 0.0f, 0.0f), v3(0.0f, 1.0f, 0.0f), static_cast<std::uint32_t>(n));
        exercise("material index" + at, s);
    }
    api::Scene s = small_scene();
    s.set_seed(~std::uint64_t{0});
    s.add_material({}, "m");
    s.add_material({}, "m");  // a duplicate name
    s.add_sphere(v3(0.0f, 0.0f, 0.0f), 1.0f, 0, "ball");
    s.add_sphere(v3(0.0f, 0.0f, 0.0f), 1.0f, 0, "ball");
    exercise("duplicate names", s);
}

// render()'s options, each at its edges, on a tiny valid scene.
TEST(ApiHostile, RenderOptionsAtTheirEdges) {
    const api::Scene scene = small_scene();
    const std::vector<int> small = {INT_MIN, -1, 0, 1, 2, 4096, INT_MAX};
    for (int n : small) {
        const std::string at = " " + std::to_string(n);
        if (n <= 2)
            returns_or_api_error("threads" + at, [&] { api::render(scene, {.threads = n}); });
        returns_or_api_error("tile width" + at, [&] { api::render(scene, {.tile_width = n}); });
        returns_or_api_error("tile height" + at,
                             [&] { api::render(scene, {.tile_height = n}); });
        returns_or_api_error("frame" + at, [&] { api::render(scene, {.frame = n}); });
        returns_or_api_error("Renderer frame" + at, [&] { api::Renderer(scene).render(n); });
        if (n <= 2)
            returns_or_api_error("Renderer threads" + at,
                                 [&] { api::Renderer(scene, {.threads = n}).render(0); });
        returns_or_api_error("Renderer tiles" + at, [&] {
            api::Renderer(scene, {.tile_width = n, .tile_height = n}).render(1);
        });
        if (n <= 16)
            returns_or_api_error("size" + at,
                                 [&] { api::render(scene, {.width = n, .height = n}); });
        if (n <= 4) returns_or_api_error("spp" + at, [&] { api::render(scene, {.spp = n}); });
    }
    for (int v : {-1, 0, 1, 2, 3, 4, 5, 99}) {
        const std::string at = " " + std::to_string(v);
        returns_or_api_error("isa" + at,
                             [&] { api::render(scene, {.isa = static_cast<api::Isa>(v)}); });
        returns_or_api_error("path" + at,
                             [&] { api::render(scene, {.path = static_cast<api::Path>(v)}); });
        EXPECT_NE(api::isa_name(static_cast<api::Isa>(v)), nullptr);
    }
    EXPECT_FALSE(api::supported_isas().empty());
}

// Crops at the edges of int, AOV names, and frames to files with odd frame lists,
// patterns and crops: each an api::Error or a render, never a crash.
TEST(ApiHostile, CropsAovsAndFramesToFiles) {
    const api::Scene scene = small_scene();
    const std::vector<int> edges = {INT_MIN, -1, 0, 1, 5, 6, 8, 9, INT_MAX};
    int rendered = 0;
    for (int a : edges)
        for (int b : edges) {
            api::RenderOptions options{.threads = 1};
            options.crop = api::Crop{a, a, b, b};
            options.aovs.id = true;
            const std::string at = " crop " + std::to_string(a) + "," + std::to_string(b);
            if (returns_or_api_error(at, [&] { api::render(scene, options); })) ++rendered;
            returns_or_api_error("Renderer" + at,
                                 [&] { api::Renderer(scene, options).render(0); });
        }
    EXPECT_GT(rendered, 0);
    for (const char* list : {"", ",", "depth,,id", "id,id", "\xff", "depth,normal,albedo,id,"})
        returns_or_api_error(std::string("aovs ") + list, [&] { api::parse_aovs(list); });
    for (const char* name : {"", "AVX2", "sse4_1", "auto ", "\n"})
        returns_or_api_error(std::string("isa ") + name, [&] { api::parse_isa(name); });

    const std::string dir = temp_path("frames");
    std::filesystem::remove_all(dir);
    for (const char* frames : {"-1", "0-", "99999999999", "5-1", "0-3:0", "a", "0,0", ""}) {
        for (const char* output : {"/x.####.exr", "/x.exr", "/x.####.jpg", "/{bad}.####.exr",
                                   "/x.####.png", "/", "/.exr"}) {
            api::FrameFilesOptions files;
            files.output = dir + output;
            files.frames = frames;
            returns_or_api_error(std::string("render_frames ") + frames + " " + output,
                                 [&] { api::render_frames(scene, {.threads = 1}, files); });
        }
    }
    api::FrameFilesOptions files;
    files.output = dir + "/same.####.exr";
    files.png = files.output;  // one file twice
    returns_or_api_error("png = output",
                         [&] { api::render_frames(scene, {.threads = 1}, files); });
}

// Images, files and comparisons: odd shapes and paths.
TEST(ApiHostile, ImagesFilesAndComparisons) {
    const std::vector<api::Image> images = {
        {0, 0, {}},
        {-1, 1, {}},
        {1, -1, {}},
        {INT_MAX, INT_MAX, {}},
        {1, 1, {}},
        {1, 1, {0.0f, 0.0f}},
        {1, 1, {kNaN, kInf, -kInf}},
        {2, 1, {0.0f, 0.0f, 0.0f, 1e30f, -1e30f, 1e-45f}},
        {1, 2, std::vector<float>(6, 65504.0f)},
    };
    for (std::size_t i = 0; i < images.size(); ++i) {
        const std::string at = " image " + std::to_string(i);
        const std::string file = temp_path(std::to_string(i) + ".exr");
        const bool written =
            returns_or_api_error("write_exr" + at, [&] { api::write_exr(file, images[i]); });
        returns_or_api_error("write_exr float" + at,
                             [&] { api::write_exr(file, images[i], {.float32 = true}); });
        if (written) {
            returns_or_api_error("read_image" + at, [&] { api::read_image(file); });
            returns_or_api_error("compare_files" + at, [&] { api::compare_files(file, file); });
        }
        for (std::size_t j = 0; j < images.size(); ++j)
            returns_or_api_error("compare" + at + " with " + std::to_string(j),
                                 [&] { api::compare(images[i], images[j]); });
    }
    for (const std::string& path :
         {std::string(), std::string("/"), std::string("/dev/null"), temp_path("missing.exr"),
          std::string(4096, 'x'), temp_path("nul") + std::string("\0b", 2)}) {
        returns_or_api_error("read_image '" + path + "'", [&] { api::read_image(path); });
        // (Never a write to /dev/null: a build without the device check would replace it.)
        if (path != "/dev/null")
            returns_or_api_error("write_exr '" + path + "'",
                                 [&] { api::write_exr(path, images[7]); });
        returns_or_api_error("compare_files '" + path + "'",
                             [&] { api::compare_files(path, path); });
        returns_or_api_error("load '" + path + "'", [&] { api::Scene::load(path); });
    }
}

// A FIFO (or a device) as the output is refused, not replaced by a regular file.
TEST(ApiHostile, WriteExrLeavesAFifoAlone) {
    const std::string fifo = temp_path("fifo.exr");
    std::remove(fifo.c_str());
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0666), 0);
    EXPECT_EQ(kind_of([&] {
                  api::write_exr(fifo, {1, 1, {0.0f, 0.0f, 0.0f}});
              }),
              api::ErrorKind::io);
    struct stat info {};
    ASSERT_EQ(::lstat(fifo.c_str(), &info), 0);
    EXPECT_TRUE(S_ISFIFO(info.st_mode));
    std::remove(fifo.c_str());
}

// Scene specs and JSON: a seeded random mix of fragments of valid ones.
TEST(ApiHostile, SpecsAndJsonFromFragments) {
    const std::vector<std::string> specs = {"whitted",
                                            "random:",
                                            "random:0",
                                            "random:-1",
                                            "random:99999999999999999999",
                                            "random:4,seed=",
                                            "sphereflake:",
                                            "sphereflake:99",
                                            "whitted,width=0",
                                            "whitted,spp=2147483647",
                                            "whitted,width=65536,height=65536",
                                            "whitted,,",
                                            "nope:1",
                                            "random:4,max_depth=65",
                                            "whitted,seed=18446744073709551616"};
    for (const std::string& spec : specs)
        returns_or_api_error("load " + spec, [&] { api::Scene::load(spec); });
    const std::vector<std::string> pieces = {
        "{",
        "}",
        "[",
        "]",
        ",",
        ":",
        "\"image\"",
        "\"camera\"",
        "\"objects\"",
        "\"spp\"",
        "1e999",
        "-0",
        "0x10",
        "+1",
        "\"\\u0000\"",
        "null",
        "true",
        "2147483648",
        "1",
        "{\"type\": \"sphere\", \"center\": [0,0,0], \"radius\": 1}",
        "\"materials\"",
        "\xff"};
    std::mt19937 random(38);
    for (int round = 0; round < 2000; ++round) {
        std::string json;
        const int n = 1 + static_cast<int>(random() % 24);
        for (int k = 0; k < n; ++k) json += pieces[random() % pieces.size()];
        returns_or_api_error("from_json " + json, [&] {
            const api::Scene s = api::Scene::from_json(json);
            s.to_json();
        });
    }
}

// A render over its memory limit is refused before it starts, with the estimate, as
// `octray render --max-memory` refuses it: by api::render, a Renderer and render_frames
// (which then writes nothing). 0, the default, is this machine's memory.
TEST(ApiHostile, ARenderOverItsMemoryLimitIsRefusedBeforeItStarts) {
    const api::Scene scene = api::Scene::load("whitted");
    api::RenderOptions options;
    options.width = 64;
    options.height = 48;
    options.threads = 1;
    options.max_memory = 1024;  // less than any frame
    try {
        (void)api::render(scene, options);
        ADD_FAILURE() << "a render over its memory limit ran";
    } catch (const api::Error& e) {
        EXPECT_EQ(e.kind(), api::ErrorKind::scene);
        const std::string message = e.what();
        EXPECT_NE(message.find("64 x 48 image"), std::string::npos) << message;
        EXPECT_NE(message.find("memory limit"), std::string::npos) << message;
    }
    EXPECT_EQ(kind_of([&] { api::Renderer renderer(scene, options); }), api::ErrorKind::scene);
    api::FrameFilesOptions files;
    files.output = temp_path("memory") + "/f.exr";
    std::filesystem::remove_all(temp_path("memory"));
    EXPECT_EQ(kind_of([&] { (void)api::render_frames(scene, options, files); }),
              api::ErrorKind::scene);
    EXPECT_FALSE(std::filesystem::exists(files.output));
    options.max_memory = 0;
    EXPECT_EQ(api::render(scene, options).image.width, 64);
}

}  // namespace
