// POST /api/save of `octray view` (view/view_save.h) through a real client: what it
// writes equals what `octray render` writes of the same scene and spp.

#include <gtest/gtest.h>
#include <httplib.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "kernels/dispatch.h"
#include "render/image/image_io.h"
#include "render/image/image_read.h"
#include "render/packet_renderer.h"
#include "scene/builtin.h"
#include "scene/load.h"
#include "view/view_server.h"
#include "view/view_session.h"
#include "view_fixtures.h"

namespace {

using nlohmann::json;
using octray::Scene;
using octray::view::ServerOptions;
using octray::view::ViewServer;
using octray::view::ViewSession;
using octray::view::ViewSettings;
using octray::view::testing::small_whitted;

// A new empty directory for one test (this process's, under the temporary directory).
std::filesystem::path empty_directory(const std::string& prefix) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / (prefix + std::to_string(getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

// POST /api/save writes the refined picture as `octray render` writes the same scene and
// spp (same pixels, same header attributes), in the save directory only, refusing names
// with a path and files that exist unless asked; a moved camera writes its scene beside.
TEST(ViewSave, WritesWhatRenderWrites) {
    namespace fs = std::filesystem;
    const fs::path dir = empty_directory("octray_view_save_");
    const Scene scene = small_whitted();
    ViewSettings settings;
    settings.render.threads = 2;
    ViewSession session(scene, settings);
    ServerOptions options;
    octray::view::SaveSettings save;
    save.spec = "whitted";
    save.sha256 = "0123";
    save.directory = dir.string();
    options.save = save;
    ViewServer server(session, options);
    server.start();
    httplib::Client client("127.0.0.1", server.port());
    client.set_read_timeout(60, 0);
    const std::string url = "/api/save?token=" + server.token();
    const auto post = [&](const std::string& body) {
        auto result = client.Post(url, body, "application/json");
        EXPECT_TRUE(result);
        return result;
    };
    // 409 while the picture refines: retried until it is refined.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    const auto save_refined = [&](const std::string& body) {
        for (;;) {
            auto result = client.Post(url, body, "application/json");
            if (!result || result->status != 409 || std::chrono::steady_clock::now() > deadline)
                return result;
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
    };
    auto saved = save_refined(R"({"name": "view.exr"})");
    ASSERT_TRUE(saved);
    ASSERT_EQ(saved->status, 200) << saved->body;
    const json answer = json::parse(saved->body);
    EXPECT_EQ(answer["command"],
              "octray render whitted --width 64 --height 36 --spp 4 --max-depth " +
                  std::to_string(scene.render.max_depth) + " -o view.exr");
    EXPECT_EQ(answer["camera_moved"], false);

    // The pixels `octray render` writes: render_packet through the same EXR writer.
    const fs::path expected_path = dir / "expected.exr";
    const octray::RenderResult result = octray::render_packet(scene);
    octray::write_exr(expected_path.string(), octray::make_exr_image(result.image, {}, {}));
    const octray::Image got = octray::read_image((dir / "view.exr").string());
    const octray::Image expected = octray::read_image(expected_path.string());
    EXPECT_EQ(got.file_format, expected.file_format);
    EXPECT_EQ(got.channel_names(), expected.channel_names());
    EXPECT_EQ(got.channels, expected.channels);
    const octray::ExrAttributes attributes =
        octray::read_exr_attributes((dir / "view.exr").string());
    const auto find_string = [&](const std::string& name) {
        for (const auto& [key, value] : attributes.strings)
            if (key == name) return value;
        return std::string("(absent)");
    };
    const auto find_int = [&](const std::string& name) {
        for (const auto& [key, value] : attributes.ints)
            if (key == name) return value;
        return -1;
    };
    EXPECT_EQ(find_string("octray.scene"), "whitted");
    EXPECT_EQ(find_string("octray.sceneSha256"), "0123");
    // The picture's own path, named as `octray render` names it.
    EXPECT_EQ(find_string("octray.path"),
              std::string("simd (") +
                  octray::isa_name(octray::resolve_isa(octray::Isa::automatic)) + ")");
    EXPECT_EQ(find_int("samplesPerPixel"), 4);
    EXPECT_EQ(find_int("octray.maxDepth"), scene.render.max_depth);

    // Existing files, bad names, bad bodies.
    EXPECT_EQ(post(R"({"name": "view.exr"})")->status, 409);
    EXPECT_EQ(post(R"({"name": "view.exr", "overwrite": true})")->status, 200);
    for (const char* body :
         {R"({"name": "../view.exr"})", R"({"name": "sub/view.exr"})",
          R"({"name": "/tmp/v.exr"})", R"({"name": "..exr"})", R"({"name": ".hidden.exr"})",
          R"({"name": "-o.exr"})", R"({"name": "view.png"})", R"({"name": "a b.exr"})",
          R"({"name": ""})", R"({"name": 3})", R"({"name": "v.exr", "overwrite": 1})",
          R"({"name": "v.exr", "x": 1})", "not json"}) {
        const auto result = post(body);
        EXPECT_EQ(result->status, 400) << body << " -> " << result->body;
    }
    EXPECT_FALSE(fs::exists(dir / "v.exr"));

    // A moved camera: its scene is written beside the picture and named in the command.
    octray::Camera moved = scene.camera;
    moved.eye.x += 1.0f;
    session.set_camera(moved, false);
    // Until the moved camera's picture is refined, the old one would be saved: wait for it.
    while (session.latest()->camera_version < 2 || session.latest()->spp < 4)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    saved = save_refined(R"({"name": "moved.exr"})");
    ASSERT_TRUE(saved);
    ASSERT_EQ(saved->status, 200) << saved->body;
    const json moved_answer = json::parse(saved->body);
    EXPECT_EQ(moved_answer["camera_moved"], true);
    EXPECT_EQ(moved_answer["scene_file"], "moved.json");
    EXPECT_EQ(moved_answer["command"].get<std::string>().rfind("octray render moved.json ", 0),
              0u);
    const Scene reloaded = octray::load_scene((dir / "moved.json").string());
    EXPECT_EQ(reloaded.camera.eye.x, moved.eye.x);
    const octray::RenderResult again = octray::render_packet(reloaded);
    octray::write_exr(expected_path.string(), octray::make_exr_image(again.image, {}, {}));
    EXPECT_EQ(octray::read_image((dir / "moved.exr").string()).channels,
              octray::read_image(expected_path.string()).channels);
    server.stop();
    fs::remove_all(dir);
}

// Issue 38: with a moved camera, save writes NAME.json beside NAME.exr. When that JSON is
// the scene being viewed, "overwrite" replaced it (an animated scene lost its animation),
// and a 409 named only the EXR. The viewed scene is never overwritten, and the 409 names
// every file that exists.
TEST(ViewSave, NeverOverwritesTheViewedSceneAndNamesEveryExistingFile) {
    namespace fs = std::filesystem;
    const fs::path dir = empty_directory("octray_view_save_source_");
    const Scene scene = small_whitted();
    const std::string source_text = octray::scene_to_json(scene);
    {
        std::ofstream(dir / "shot.json") << source_text;
        std::ofstream(dir / "other.exr") << "x";
        std::ofstream(dir / "other.json") << "y";
    }
    ViewSettings settings;
    settings.render.threads = 2;
    ViewSession session(scene, settings);
    ServerOptions options;
    octray::view::SaveSettings save;
    save.spec = (dir / "shot.json").string();
    save.directory = dir.string();
    options.save = save;
    ViewServer server(session, options);
    server.start();
    httplib::Client client("127.0.0.1", server.port());
    client.set_read_timeout(60, 0);
    const std::string url = "/api/save?token=" + server.token();

    octray::Camera moved = scene.camera;
    moved.eye.x += 1.0f;
    session.set_camera(moved, false);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while ((!session.latest() || session.latest()->camera_version < 2 ||
            session.latest()->spp < 4) &&
           std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "no refined picture";

    auto result = client.Post(url, R"({"name": "other.exr"})", "application/json");
    ASSERT_TRUE(result);
    EXPECT_EQ(result->status, 409) << result->body;
    EXPECT_NE(result->body.find("other.exr and other.json exist"), std::string::npos)
        << result->body;

    result = client.Post(url, R"({"name": "shot.exr", "overwrite": true})", "application/json");
    ASSERT_TRUE(result);
    EXPECT_EQ(result->status, 409) << result->body;
    EXPECT_NE(result->body.find("shot.json is the scene being viewed"), std::string::npos)
        << result->body;
    std::ifstream in(dir / "shot.json");
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), source_text);
    EXPECT_FALSE(fs::exists(dir / "shot.exr"));
    server.stop();
    fs::remove_all(dir);
}

}  // namespace
