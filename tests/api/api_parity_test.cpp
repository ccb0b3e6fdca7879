// The API against `octray render` and the batch library it runs: an animation's frames
// written by api::render_frames hold, channel for channel and bit for bit, what the
// command and its frame loop write for the same scene and settings (color, AOVs, a crop's
// data window), and api::render's AOVs are the AOV channels of those files.

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "floor_and_ball.h"
#include "octray/octray.h"
#include "render/batch/frame_loop.h"
#include "render/batch/observer.h"
#include "render/batch/output_paths.h"
#include "render/batch/plan.h"
#include "render/batch/spec.h"
#include "render/image/image_read.h"
#include "render/render_config.h"
#include "tests/tools/run_octray.h"

namespace api = octray::api;
namespace batch = octray::batch;
namespace fs = std::filesystem;

namespace {

// A floor, a moving ball, 3 frames, as a scene file both sides load.
std::string write_scene(const std::string& dir) {
    std::string json = octray::api::testing::floor_and_ball(36, 24, 2).to_json();
    json.insert(json.rfind('}'), R"(, "animation": {"frames": 3, "objects": {"ball": [
        {"frame": 0, "center": [0, 1, 0]}, {"frame": 2, "center": [1, 1.5, -1]}]}})");
    fs::create_directories(dir);
    const std::string path = dir + "/anim.json";
    std::ofstream(path) << json;
    return path;
}

// The files `octray render FILE --aov depth,normal,albedo,id --float [--crop ...]
// -o DIR/anim.####.exr` writes, through the same library calls as tools/cmd_render.cpp.
void render_like_the_cli(const std::string& scene_file, const std::string& output,
                         const std::string& crop) {
    batch::BatchRequest request;
    request.threads = 2;
    request.output = output;
    std::vector<batch::BatchInput> scenes{batch::load_batch_input(scene_file, request)};
    if (!crop.empty())
        scenes[0].crop =
            batch::parse_crop(crop, scenes[0].scene.image.width, scenes[0].scene.image.height);
    batch::BatchSettings settings;
    settings.render.threads = 2;
    settings.render.set_aovs("depth,normal,albedo,id");
    settings.render.resolve_isa();
    settings.exr.float32 = true;
    const std::vector<batch::BatchJob> jobs = batch::plan_jobs(scenes, request);
    batch::prepare_output_directories(jobs);
    batch::BatchObserver quiet;
    const batch::BatchSummary summary =
        batch::run_batch(scenes, jobs, settings, quiet, nullptr);
    ASSERT_EQ(summary.rendered, jobs.size());
}

void expect_same_pixels(const std::string& a, const std::string& b) {
    const octray::Image x = octray::read_image(a), y = octray::read_image(b);
    EXPECT_EQ(x.channel_names(), y.channel_names()) << a;
    EXPECT_EQ(x.data_window, y.data_window) << a;
    EXPECT_TRUE(x.channels == y.channels) << a << " and " << b << " differ";
}

std::vector<float> channel(const octray::Image& image, const char* name) {
    const int c = image.channel_index(name);
    if (c < 0) return {};
    return {image.plane(c), image.plane(c) + image.pixel_count()};
}

}  // namespace

TEST(ApiParity, FramesWrittenByTheApiEqualTheClisFiles) {
    const std::string dir = std::string(OCTRAY_TEST_TMPDIR) + "/api_parity";
    fs::remove_all(dir);
    const std::string scene_file = write_scene(dir);
    for (const std::string crop : {"", "4,3,30,20"}) {
        const std::string cli = dir + "/cli" + (crop.empty() ? "" : "_crop") + "/anim.####.exr";
        const std::string via_api =
            dir + "/api" + (crop.empty() ? "" : "_crop") + "/anim.####.exr";
        render_like_the_cli(scene_file, cli, crop);

        api::RenderOptions options{.threads = 2};
        options.aovs = api::parse_aovs("depth,normal,albedo,id");
        if (!crop.empty()) options.crop = api::Crop{4, 3, 30, 20};
        api::FrameFilesOptions files;
        files.output = via_api;
        files.exr.float32 = true;
        const api::Scene scene = api::Scene::load(scene_file);
        const api::FrameFilesResult r = api::render_frames(scene, options, files);
        ASSERT_EQ(r.rendered, 3);
        for (int f = 0; f < 3; ++f) {
            const std::string name = "/anim.000" + std::to_string(f) + ".exr";
            const std::string cli_file = fs::path(cli).parent_path().string() + name;
            const std::string api_file = fs::path(via_api).parent_path().string() + name;
            expect_same_pixels(cli_file, api_file);

            // api::render's image and AOVs are the file's channels.
            options.frame = f;
            const api::RenderResult rendered = api::render(scene, options);
            const octray::Image file = octray::read_image(api_file);
            const std::size_t n = file.pixel_count();
            ASSERT_EQ(rendered.aovs.depth.size(), n);
            EXPECT_EQ(channel(file, "Z"), rendered.aovs.depth);
            std::vector<float> id(rendered.aovs.id.begin(), rendered.aovs.id.end());
            EXPECT_EQ(channel(file, "id"), id);
            std::vector<float> nx, albedo_g;
            for (std::size_t k = 0; k < n; ++k) {
                nx.push_back(rendered.aovs.normal[3 * k]);
                albedo_g.push_back(rendered.aovs.albedo[3 * k + 1]);
            }
            EXPECT_EQ(channel(file, "N.X"), nx);
            EXPECT_EQ(channel(file, "albedo.G"), albedo_g);
            EXPECT_EQ(file.data_window.x0, rendered.window.x0);
            EXPECT_EQ(file.data_window.y0, rendered.window.y0);
        }
    }
}

// The one description of a render: the API's names are parsed by RenderConfig, with its
// messages, so `--aov`, `--isa` and the API take and refuse the same names.
TEST(ApiParity, TheApisNamesAreTheConfigsOwn) {
    for (const char* list : {"depth,mist", "", "id,id", "normal,"}) {
        octray::RenderConfig config;
        std::string config_error;
        try {
            config.set_aovs(list);
        } catch (const octray::ConfigError& e) {
            config_error = e.what();
        }
        ASSERT_FALSE(config_error.empty()) << list;
        try {
            (void)api::parse_aovs(list);
            ADD_FAILURE() << "\"" << list << "\" parsed";
        } catch (const api::Error& e) {
            EXPECT_EQ(e.what(), config_error);
        }
    }
    octray::RenderConfig config;
    config.set_aovs("albedo,id");
    const api::AovSelection s = api::parse_aovs("albedo,id");
    EXPECT_EQ(s.depth, config.aovs.depth);
    EXPECT_EQ(s.normal, config.aovs.normal);
    EXPECT_EQ(s.albedo, config.aovs.albedo);
    EXPECT_EQ(s.id, config.aovs.id);
    config.set_isa("sse4.1");
    EXPECT_EQ(config.isa, octray::Isa::sse4_1);
    EXPECT_EQ(api::parse_isa("sse4.1"), api::Isa::sse4_1);
}

// The files of the octray executable itself, as a user runs it.
TEST(ApiParity, FramesWrittenByTheApiEqualTheCommandsFiles) {
    const std::string dir = std::string(OCTRAY_TEST_TMPDIR) + "/api_parity_exe";
    fs::remove_all(dir);
    const std::string scene_file = write_scene(dir);
    const octray::testing::RunResult run = octray::testing::run_octray(
        {"render", scene_file, "--aov", "depth,normal,albedo,id", "--float", "--crop",
         "4,3,30,20", "--threads", "2", "--progress", "none", "-q", "-o",
         dir + "/cli/anim.####.exr"},
        dir);
    ASSERT_EQ(run.status, 0) << run.output;

    api::RenderOptions options{.threads = 2};
    options.aovs = api::parse_aovs("depth,normal,albedo,id");
    options.crop = api::Crop{4, 3, 30, 20};
    api::FrameFilesOptions files;
    files.output = dir + "/api/anim.####.exr";
    files.exr.float32 = true;
    ASSERT_EQ(api::render_frames(api::Scene::load(scene_file), options, files).rendered, 3);
    for (int f = 0; f < 3; ++f) {
        const std::string name = "/anim.000" + std::to_string(f) + ".exr";
        expect_same_pixels(dir + "/cli" + name, dir + "/api" + name);
    }
}
