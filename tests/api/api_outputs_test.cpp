// What the API renders besides a whole image: crops (each pixel the same pixel of the whole
// image), AOVs (the same on both paths, a crop's the window of the whole image's) and an
// animation's frames written to files; bad input as an api::Error of the right kind.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "error_kind.h"
#include "floor_and_ball.h"
#include "octray/octray.h"

namespace api = octray::api;
namespace fs = std::filesystem;
using octray::api::testing::kind_of;

namespace {

// The floor and the ball against a sky: every AOV has hits and misses.
api::Scene small_scene() {
    api::Scene scene = octray::api::testing::floor_and_ball(40, 30, 2);
    scene.set_background({1.0f, 1.0f, 1.0f}, {0.4f, 0.6f, 1.0f});
    return scene;
}

// small_scene() with its ball moving over 4 frames.
api::Scene animated_scene() {
    std::string json = small_scene().to_json();
    json.insert(json.rfind('}'), R"(, "animation": {"frames": 4, "objects": {"ball": [
        {"frame": 0, "center": [0, 1, 0]}, {"frame": 3, "center": [1, 1.5, -1]}]}})");
    return api::Scene::from_json(json, "anim.json");
}

// Rows y0..y1-1, columns x0..x1-1 of a per-pixel vector of `n` values a pixel.
template <typename T>
std::vector<T> window(const std::vector<T>& v, int width, int n, const api::Crop& c) {
    std::vector<T> out;
    for (int y = c.y0; y < c.y1; ++y)
        for (int x = c.x0; x < c.x1; ++x)
            for (int k = 0; k < n; ++k)
                out.push_back(v[static_cast<std::size_t>(n) * (y * width + x) + k]);
    return out;
}

const api::AovSelection kAllAovs{.depth = true, .normal = true, .albedo = true, .id = true};

std::string temp_dir(const std::string& name) {
    const std::string dir = std::string(OCTRAY_TEST_TMPDIR) + "/api_outputs_" + name;
    fs::remove_all(dir);
    return dir;
}

}  // namespace

TEST(ApiCrop, EachPixelIsThatPixelOfTheWholeImage) {
    const api::Scene scene = small_scene();
    const api::Crop crop{5, 3, 29, 20};
    for (api::Path path : {api::Path::simd, api::Path::scalar}) {
        const api::RenderResult whole = api::render(scene, {.path = path, .threads = 2});
        EXPECT_EQ(whole.window.x1, 40);
        EXPECT_EQ(whole.window.y1, 30);
        api::RenderOptions options{.path = path, .threads = 2};
        options.crop = crop;
        const api::RenderResult part = api::render(scene, options);
        EXPECT_EQ(part.image.width, 24);
        EXPECT_EQ(part.image.height, 17);
        EXPECT_EQ(part.window.x0, 5);
        EXPECT_EQ(part.window.y0, 3);
        EXPECT_EQ(part.window.x1, 29);
        EXPECT_EQ(part.window.y1, 20);
        EXPECT_EQ(part.full_width, 40);
        EXPECT_EQ(part.full_height, 30);
        EXPECT_EQ(part.image.rgb, window(whole.image.rgb, 40, 3, crop));
        EXPECT_LT(part.rays.primary, whole.rays.primary);
    }
}

TEST(ApiCrop, OutsideTheImageOrEmptyIsAnInvalidArgument) {
    const api::Scene scene = small_scene();
    for (const api::Crop crop : {api::Crop{0, 0, 41, 30}, api::Crop{-1, 0, 10, 10},
                                 api::Crop{5, 5, 5, 9}, api::Crop{0, 20, 10, 10}}) {
        api::RenderOptions options{.threads = 1};
        options.crop = crop;
        EXPECT_EQ(kind_of([&] { api::render(scene, options); }),
                  api::ErrorKind::invalid_argument);
        EXPECT_EQ(kind_of([&] { api::Renderer(scene, options); }),
                  api::ErrorKind::invalid_argument);
    }
    // The crop is checked against the image after the options' size.
    api::RenderOptions options{.threads = 1, .width = 80};
    options.crop = api::Crop{50, 0, 80, 30};
    EXPECT_EQ(api::render(scene, options).image.width, 30);
}

TEST(ApiAovs, BothPathsGiveTheSameAovsWithHitsAndMisses) {
    const api::Scene scene = small_scene();
    api::RenderOptions options{.threads = 2};
    options.aovs = kAllAovs;
    const api::RenderResult simd = api::render(scene, options);
    options.path = api::Path::scalar;
    const api::RenderResult scalar = api::render(scene, options);
    const std::size_t pixels = 40 * 30;
    ASSERT_EQ(simd.aovs.depth.size(), pixels);
    ASSERT_EQ(simd.aovs.normal.size(), 3 * pixels);
    ASSERT_EQ(simd.aovs.albedo.size(), 3 * pixels);
    ASSERT_EQ(simd.aovs.id.size(), pixels);
    EXPECT_EQ(simd.aovs.depth, scalar.aovs.depth);
    EXPECT_EQ(simd.aovs.normal, scalar.aovs.normal);
    EXPECT_EQ(simd.aovs.albedo, scalar.aovs.albedo);
    EXPECT_EQ(simd.aovs.id, scalar.aovs.id);
    // Background, floor (object 1) and ball (object 2): a miss has +inf depth and id 0.
    int seen[3] = {0, 0, 0};
    for (std::size_t k = 0; k < pixels; ++k) {
        const std::uint32_t id = simd.aovs.id[k];
        ASSERT_LE(id, 2u);
        ++seen[id];
        EXPECT_EQ(std::isinf(simd.aovs.depth[k]), id == 0) << "pixel " << k;
        if (id == 2) {
            EXPECT_EQ(simd.aovs.albedo[3 * k], 0.8f);
        }
    }
    EXPECT_GT(seen[0], 0);
    EXPECT_GT(seen[1], 0);
    EXPECT_GT(seen[2], 0);
    // The image is the one rendered without AOVs.
    EXPECT_EQ(simd.image.rgb, api::render(scene, {.threads = 2}).image.rgb);
    EXPECT_TRUE(api::render(scene, {.threads = 2}).aovs.depth.empty());
}

TEST(ApiAovs, OnlyTheSelectedAndACropsAreTheWindowOfTheWholeImages) {
    const api::Scene scene = small_scene();
    api::RenderOptions options{.threads = 2};
    options.aovs = kAllAovs;
    const api::RenderResult whole = api::render(scene, options);
    const api::Crop crop{7, 2, 33, 25};
    options.crop = crop;
    options.aovs = api::parse_aovs("id,depth");
    const api::RenderResult part = api::render(scene, options);
    EXPECT_EQ(part.aovs.depth, window(whole.aovs.depth, 40, 1, crop));
    EXPECT_EQ(part.aovs.id, window(whole.aovs.id, 40, 1, crop));
    EXPECT_TRUE(part.aovs.normal.empty());
    EXPECT_TRUE(part.aovs.albedo.empty());
}

TEST(ApiAovs, ARendererGivesEachFramesAovsAsRenderedAlone) {
    const api::Scene scene = animated_scene();
    api::RenderOptions options{.threads = 2};
    options.aovs = kAllAovs;
    api::Renderer renderer(scene, options);
    for (int frame : {3, 0, 2}) {
        api::RenderOptions alone = options;
        alone.frame = frame;
        const api::RenderResult a = renderer.render(frame), b = api::render(scene, alone);
        EXPECT_EQ(a.aovs.depth, b.aovs.depth) << frame;
        EXPECT_EQ(a.aovs.normal, b.aovs.normal) << frame;
        EXPECT_EQ(a.aovs.id, b.aovs.id) << frame;
    }
    EXPECT_NE(renderer.render(0).aovs.depth, renderer.render(3).aovs.depth);
}

TEST(ApiAovs, NamesParseOrFailNamingTheItem) {
    const api::AovSelection s = api::parse_aovs("normal,albedo");
    EXPECT_FALSE(s.depth);
    EXPECT_TRUE(s.normal);
    EXPECT_TRUE(s.albedo);
    EXPECT_FALSE(s.id);
    EXPECT_TRUE(s.any());
    EXPECT_FALSE(api::AovSelection{}.any());
    for (const char* bad : {"depht", "", "depth,", "depth,depth", "Depth"}) {
        try {
            (void)api::parse_aovs(bad);
            ADD_FAILURE() << "\"" << bad << "\" parsed";
        } catch (const api::Error& e) {
            EXPECT_EQ(e.kind(), api::ErrorKind::invalid_argument);
            EXPECT_NE(std::string(e.what()).find("aovs: "), std::string::npos) << e.what();
        }
    }
    try {
        (void)api::parse_aovs("depth,fog");
        ADD_FAILURE() << "fog parsed";
    } catch (const api::Error& e) {
        EXPECT_NE(std::string(e.what()).find("unknown AOV 'fog'"), std::string::npos)
            << e.what();
    }
}

TEST(ApiIsa, NamesParseBackAndOthersFail) {
    for (api::Isa isa : {api::Isa::automatic, api::Isa::sse2, api::Isa::sse4_1, api::Isa::avx2,
                         api::Isa::avx512})
        EXPECT_EQ(api::parse_isa(api::isa_name(isa)), isa);
    EXPECT_EQ(kind_of([] { api::parse_isa("avx3"); }), api::ErrorKind::invalid_argument);
}

// ---- Frames to files ---------------------------------------------------------------------

TEST(ApiFrames, EachFileHoldsTheFrameRenderedAlone) {
    const api::Scene scene = animated_scene();
    const std::string dir = temp_dir("frames");
    api::RenderOptions options{.threads = 2};
    std::vector<api::Progress> calls;
    const std::thread::id caller = std::this_thread::get_id();
    bool other_thread = false;
    options.progress_interval_ms = 1;
    options.progress = [&](const api::Progress& p) {
        calls.push_back(p);
        other_thread |= std::this_thread::get_id() != caller;
        return true;
    };
    api::FrameFilesOptions files;
    files.output = dir + "/out/anim.####.exr";  // out/ is created
    files.png = dir + "/out/anim.####.png";
    files.exr.float32 = true;  // the file's floats are the render's bits
    const api::FrameFilesResult r = api::render_frames(scene, options, files);
    EXPECT_EQ(r.rendered, 4);
    EXPECT_EQ(r.skipped, 0);
    EXPECT_EQ(r.failed, 0);
    EXPECT_FALSE(r.cancelled);
    ASSERT_EQ(r.frames.size(), 4u);
    for (int f = 0; f < 4; ++f) {
        const api::FrameFile& file = r.frames[static_cast<std::size_t>(f)];
        EXPECT_EQ(file.frame, f);
        EXPECT_EQ(file.status, api::FrameStatus::rendered);
        EXPECT_EQ(file.output, dir + "/out/anim.000" + std::to_string(f) + ".exr");
        EXPECT_EQ(file.png, dir + "/out/anim.000" + std::to_string(f) + ".png");
        EXPECT_TRUE(fs::is_regular_file(file.png));
        EXPECT_GT(file.rays, 0u);
        api::RenderOptions alone{.threads = 2};
        alone.frame = f;
        EXPECT_EQ(api::read_image(file.output).rgb, api::render(scene, alone).image.rgb)
            << file.output;
    }
    // Progress over the whole run, on the caller's thread, never backwards, ending whole.
    ASSERT_GE(calls.size(), 2u);
    EXPECT_FALSE(other_thread);
    for (std::size_t i = 0; i < calls.size(); ++i) {
        EXPECT_EQ(calls[i].pixels_total, 4u * 40 * 30);
        if (i > 0) {
            EXPECT_GE(calls[i].pixels_done, calls[i - 1].pixels_done);
        }
    }
    EXPECT_EQ(calls.front().pixels_done, 0u);
    EXPECT_EQ(calls.back().pixels_done, 4u * 40 * 30);

    // Again with skip_existing: nothing to render; a frame list picks frames.
    files.skip_existing = true;
    const api::FrameFilesResult again = api::render_frames(scene, {.threads = 2}, files);
    EXPECT_EQ(again.skipped, 4);
    EXPECT_EQ(again.rendered, 0);
    files.skip_existing = false;
    files.frames = "1-3:2";
    files.png.clear();
    const api::FrameFilesResult some = api::render_frames(scene, {.threads = 2}, files);
    ASSERT_EQ(some.frames.size(), 2u);
    EXPECT_EQ(some.frames[0].frame, 1);
    EXPECT_EQ(some.frames[1].frame, 3);
}

TEST(ApiFrames, ACropIsTheWindowAndAStillIsOneFile) {
    const api::Scene scene = small_scene();
    const std::string dir = temp_dir("still");
    api::RenderOptions options{.threads = 2};
    options.crop = api::Crop{4, 4, 20, 12};
    api::FrameFilesOptions files;
    files.output = dir + "/part.exr";
    files.exr.float32 = true;
    const api::FrameFilesResult r = api::render_frames(scene, options, files);
    ASSERT_EQ(r.frames.size(), 1u);
    EXPECT_EQ(r.frames[0].frame, 0);
    // The EXR's data window is the crop; reading it gives the crop's pixels.
    const api::Image part = api::read_image(files.output);
    EXPECT_EQ(part.width, 16);
    EXPECT_EQ(part.height, 8);
    EXPECT_EQ(part.rgb, api::render(scene, options).image.rgb);
    // An 8-bit PNG output alone.
    files.output = dir + "/still.PNG";
    files.exr.float32 = false;
    EXPECT_EQ(api::render_frames(scene, {.threads = 2}, files).rendered, 1);
    EXPECT_EQ(api::read_image(files.output).width, 40);
}

TEST(ApiFrames, CancellingStopsTheRunWithoutAnError) {
    const api::Scene scene = animated_scene();
    const std::string dir = temp_dir("cancel");
    api::RenderOptions options{.threads = 2};
    options.progress = [](const api::Progress&) { return false; };
    api::FrameFilesOptions files;
    files.output = dir + "/anim.####.exr";
    const api::FrameFilesResult r = api::render_frames(scene, options, files);
    EXPECT_TRUE(r.cancelled);
    EXPECT_EQ(r.rendered, 0);
    EXPECT_FALSE(fs::exists(dir + "/anim.0000.exr"));
}

TEST(ApiFrames, BadRequestsAreErrorsOfTheirKind) {
    const api::Scene scene = animated_scene();
    const std::string dir = temp_dir("bad");
    const auto run = [&](const api::FrameFilesOptions& files,
                         const api::RenderOptions& options = {.threads = 1}) {
        return kind_of([&] { api::render_frames(scene, options, files); });
    };
    const auto with = [&](std::string output, std::string frames) {
        api::FrameFilesOptions f;
        f.output = std::move(output);
        f.frames = std::move(frames);
        return f;
    };
    EXPECT_EQ(run(with(dir + "/a.####.exr", "-1")), api::ErrorKind::invalid_argument);
    EXPECT_EQ(run(with(dir + "/a.####.exr", "3-1")), api::ErrorKind::invalid_argument);
    EXPECT_EQ(run(with(dir + "/a.exr", "0-3")), api::ErrorKind::invalid_argument);  // one file
    EXPECT_EQ(run(with(dir + "/a.####.tif", "")), api::ErrorKind::invalid_argument);
    api::FrameFilesOptions png = with(dir + "/a.####.png", "");
    api::RenderOptions aovs{.threads = 1};
    aovs.aovs.depth = true;  // a PNG holds R, G, B only
    EXPECT_EQ(run(png, aovs), api::ErrorKind::invalid_argument);
    api::RenderOptions crop{.threads = 1};
    crop.crop = api::Crop{0, 0, 400, 10};
    EXPECT_EQ(run(with(dir + "/a.####.exr", ""), crop), api::ErrorKind::invalid_argument);
    // An output directory that cannot be made: a file is in its way.
    fs::create_directories(dir);
    {
        std::FILE* f = std::fopen((dir + "/file").c_str(), "w");
        std::fclose(f);
    }
    EXPECT_EQ(run(with(dir + "/file/a.####.exr", "")), api::ErrorKind::io);
    EXPECT_FALSE(fs::exists(dir + "/a.0000.exr"));
}
