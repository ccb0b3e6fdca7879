// The page's path, ISA and frame switches (view/view_switches.h): the parsing and
// its refusals on their own (an ISA the CPU lacks, with a CPU that lacks one made up), then
// through a real client against a session: the scalar path and a forced ISA render the
// picture `octray render --path/--isa` makes, and an animated scene's frame is rendered,
// shown (tiled and frameless) and saved as `octray render --frames N` renders it.

#include "view/view_switches.h"

#include <gtest/gtest.h>
#include <httplib.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "kernels/dispatch.h"
#include "render/image/image_io.h"
#include "render/image/image_read.h"
#include "render/packet_renderer.h"
#include "render/reference.h"
#include "scene/animation.h"
#include "scene/load.h"
#include "view/http_error.h"
#include "view/view_server.h"
#include "view/view_session.h"
#include "view_fixtures.h"

namespace {

using nlohmann::json;
using octray::Isa;
using octray::RenderPath;
using octray::Scene;
using octray::view::BadRequest;
using octray::view::parse_switches;
using octray::view::RenderSwitches;
using octray::view::SwitchLimits;

// The status and message parse_switches refuses `body` with ("" if it accepts it).
std::pair<int, std::string> refusal(const std::string& body, const SwitchLimits& limits) {
    try {
        parse_switches(body, RenderSwitches{}, limits);
    } catch (const BadRequest& e) {
        return {e.status, e.what()};
    }
    return {0, ""};
}

TEST(ViewSwitches, PathAndIsaAreParsedAndChecked) {
    const SwitchLimits limits{{Isa::sse2, Isa::sse4_1}};
    const RenderSwitches s =
        parse_switches(R"({"path": "scalar", "isa": "sse4.1", "spp": 3})", {}, limits);
    EXPECT_EQ(s.render.path, RenderPath::scalar);
    EXPECT_EQ(s.render.isa, Isa::sse4_1);
    EXPECT_EQ(s.spp, 3);
    EXPECT_EQ(parse_switches(R"({"isa": "auto"})", s, limits).render.isa, Isa::automatic);
    EXPECT_EQ(parse_switches("{}", s, limits).render.path, RenderPath::scalar)
        << "an absent key keeps its value";

    // A CPU without AVX2 (made up here: the limits say what the CPU runs).
    const auto [status, message] = refusal(R"({"isa": "avx2"})", limits);
    EXPECT_EQ(status, 400);
    EXPECT_EQ(message, "settings.isa: this CPU cannot run avx2 (it runs auto, sse2, sse4.1)");
    EXPECT_EQ(refusal(R"({"isa": "avx512"})", limits).second,
              "settings.isa: this CPU cannot run avx512 (it runs auto, sse2, sse4.1)");
    EXPECT_EQ(refusal(R"({"isa": "neon"})", limits).second,
              "settings.isa: expected one of auto, sse2, sse4.1, found \"neon\"");
    EXPECT_EQ(refusal(R"({"path": "gpu"})", limits).second,
              "settings.path: expected simd or scalar, not \"gpu\"");
    for (const char* body :
         {R"({"isa": 2})", R"({"path": null})", R"({"isa": "AVX2"})", R"({"fps": 3})"})
        EXPECT_EQ(refusal(body, limits).first, 400) << body;
}

// The switches carry the render's one description (RenderConfig): what they do not name
// stays as the session's render has it.
TEST(ViewSwitches, TheRestOfTheRenderDescriptionIsKept) {
    const SwitchLimits limits{{Isa::sse2}, 1};
    RenderSwitches current;
    current.render.accel = octray::Accel::none;
    current.render.tile = octray::TileSize{8, 4};
    current.render.threads = 3;
    const RenderSwitches s = parse_switches(R"({"path": "scalar"})", current, limits);
    EXPECT_EQ(s.render.path, RenderPath::scalar);
    EXPECT_EQ(s.render.accel, octray::Accel::none);
    EXPECT_EQ(s.render.tile.width, 8);
    EXPECT_EQ(s.render.tile.height, 4);
    EXPECT_EQ(s.render.threads, 3);
    EXPECT_EQ(parse_switches(R"({"threads": 1})", s, limits).render.threads, 1);
}

// Issue 38: one JSON rule everywhere. A duplicate key (which nlohmann would let the last
// one win) and anything else a scene file refuses is refused, with the path and position.
TEST(ViewSwitches, TheScenesJsonRulesApply) {
    const SwitchLimits limits{{Isa::sse2}, 1};
    const auto [status, message] = refusal(R"({"spp": 2, "spp": 4096})", limits);
    EXPECT_EQ(status, 400);
    EXPECT_NE(message.find("duplicate key \"spp\""), std::string::npos) << message;
    for (const char* body : {R"({"spp": +1})", R"({"spp": 0x10})", R"({"spp": "1"})",
                             R"({"spp": " 1"})", R"({"spp": 1e0})"})
        EXPECT_EQ(refusal(body, limits).first, 400) << body;
    EXPECT_EQ(refusal(std::string("{\"spp\": 1}\0", 11), limits).first, 400);
}

TEST(ViewSwitches, TheFrameIsParsedAndChecked) {
    const SwitchLimits limits{{Isa::sse2}, 48};
    const RenderSwitches s = parse_switches(R"({"frame": 47})", {}, limits);
    EXPECT_EQ(s.frame, 47);
    EXPECT_EQ(parse_switches(R"({"spp": 2})", s, limits).frame, 47)
        << "an absent key keeps its value";
    EXPECT_EQ(parse_switches(R"({"frame": 0})", {}, SwitchLimits{{Isa::sse2}, 1}).frame, 0);
    EXPECT_EQ(refusal(R"({"frame": 48})", limits).second,
              "settings.frame: expected an integer in [0, 47]");
    EXPECT_EQ(refusal(R"({"frame": 2})", SwitchLimits{{Isa::sse2}, 1}).second,
              "settings.frame: the scene is not animated (frame 0 only)");
    for (const char* body :
         {R"({"frame": -1})", R"({"frame": 1.5})", R"({"frame": "3"})", R"({"frame": null})"})
        EXPECT_EQ(refusal(body, limits).first, 400) << body;
}

// The status's choices are this CPU's: "auto" and every ISA it runs, nothing it lacks.
TEST(ViewSwitches, TheChoicesAreTheIsasThisCpuRuns) {
    const std::vector<std::string> choices =
        octray::view::isa_choices(SwitchLimits{octray::supported_isas()});
    ASSERT_FALSE(choices.empty());
    EXPECT_EQ(choices.front(), "auto");
    for (const Isa isa : octray::compiled_isas()) {
        const bool listed =
            std::find(choices.begin(), choices.end(), octray::isa_name(isa)) != choices.end();
        EXPECT_EQ(listed, octray::isa_supported(isa)) << octray::isa_name(isa);
    }
}

// small_whitted animated over 5 frames: the camera moves, and so does the glass sphere.
Scene animated_whitted() {
    Scene scene = octray::view::testing::small_whitted();
    octray::Animation animation;
    animation.frames = 5;
    animation.fps = 10.0;
    animation.camera.push_back({0, scene.camera.eye, {}, {}, {}});
    animation.camera.push_back(
        {4, scene.camera.eye + octray::Vec3{1.0f, 0.5f, 0.0f}, {}, {}, {}});
    std::uint32_t sphere = 0;
    while (scene.objects[sphere].type != octray::ObjectType::sphere) ++sphere;
    scene.objects[sphere].name = "ball";
    const octray::Vec3 c = scene.objects[sphere].center;
    animation.objects.push_back(
        {"ball", sphere, {{0, c, {}}, {4, c + octray::Vec3{0.6f, 0.4f, 0.0f}, {}}}});
    scene.animation = animation;
    octray::validate_scene(scene);
    return scene;
}

std::string bytes_of(const octray::Image& image) {
    const std::vector<octray::Rgb> pixels = octray::rgb_pixels(image);
    return std::string(reinterpret_cast<const char*>(pixels.data()),
                       pixels.size() * sizeof(octray::Rgb));
}

class SwitchesTest : public ::testing::Test {
  protected:
    void start(const Scene& scene, octray::view::PixelOrder order, const std::string& dir) {
        octray::view::ViewSettings settings;
        settings.render.threads = 2;
        settings.order = order;
        session_ = std::make_unique<octray::view::ViewSession>(scene, settings);
        octray::view::ServerOptions options;
        octray::view::SaveSettings save;
        save.spec = "anim.json";
        save.sha256 = "0123";
        save.directory = dir;
        options.save = save;
        server_ = std::make_unique<octray::view::ViewServer>(*session_, options);
        server_->start();
        client_ = std::make_unique<httplib::Client>("127.0.0.1", server_->port());
        client_->set_read_timeout(60, 0);
    }
    void TearDown() override {
        client_.reset();
        server_.reset();
        session_.reset();
    }
    std::string url(const std::string& path) const {
        return path + "?token=" + server_->token();
    }
    json status() {
        const auto result = client_->Get(url("/api/status"));
        EXPECT_TRUE(result && result->status == 200);
        return result && result->status == 200 ? json::parse(result->body) : json{};
    }
    httplib::Result post(const std::string& path, const std::string& body) {
        return client_->Post(url(path), body, "application/json");
    }
    // POSTs `settings` (expecting 200) and waits (60 s at most) for the refined picture
    // (all spp, every block) made with them: of the camera version the answer gives.
    // Its JSON and bytes (null and empty if none came).
    std::pair<json, std::string> switch_to(const std::string& settings) {
        const auto result = post("/api/settings", settings);
        EXPECT_TRUE(result && result->status == 200)
            << settings << " -> " << (result ? result->body : "no answer");
        if (!result || result->status != 200) return {json{}, std::string()};
        const json version = json::parse(result->body)["camera_version"];
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
        while (std::chrono::steady_clock::now() < deadline) {
            const json s = status();
            if (s.contains("frame")) {
                const json& f = s["frame"];
                if (f["camera_version"] == version && f["spp"] == f["target_spp"] &&
                    f["coverage"] == 1.0 && !f["preview"].get<bool>()) {
                    // A refined picture stays until the next switch: this is its image.
                    const auto image = client_->Get(url("/api/image.f32"));
                    if (image && image->status == 200 &&
                        image->get_header_value("X-Octray-Generation") ==
                            std::to_string(f["generation"].get<std::uint64_t>()))
                        return {f, image->body};
                }
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        return {json{}, std::string()};
    }

    std::unique_ptr<octray::view::ViewSession> session_;
    std::unique_ptr<octray::view::ViewServer> server_;
    std::unique_ptr<httplib::Client> client_;
};

// The scalar path is the reference renderer and a forced ISA that ISA's kernels; each
// picture says which made it, and equals what that path renders. ISAs this CPU lacks are
// refused with 400 and change nothing.
TEST_F(SwitchesTest, PathAndIsaSwitchesRenderWithThem) {
    const Scene scene = octray::view::testing::small_whitted();
    start(scene, octray::view::PixelOrder::tiled, ".");
    const json first = status();
    EXPECT_EQ(first["settings"]["path"], "simd");
    EXPECT_EQ(first["settings"]["isa"], "auto");
    EXPECT_EQ(first["isas"], json(octray::view::isa_choices({octray::supported_isas()})));
    EXPECT_TRUE(first["animation"].is_null());
    EXPECT_EQ(first["settings"]["frame"], 0);

    // The simd and scalar paths give the same bits: the picture's path tells them apart.
    const std::string want = bytes_of(octray::render_reference(scene).image);
    const auto [scalar, scalar_bytes] = switch_to(R"({"path": "scalar"})");
    EXPECT_EQ(status()["settings"]["path"], "scalar");
    EXPECT_EQ(scalar["path"], "scalar");
    EXPECT_TRUE(scalar_bytes == want);

    for (const Isa isa : octray::compiled_isas()) {
        const std::string name = octray::isa_name(isa);
        const std::string body = R"({"path": "simd", "isa": ")" + name + "\"}";
        if (!octray::isa_supported(isa)) {
            const auto result = post("/api/settings", body);
            ASSERT_TRUE(result);
            EXPECT_EQ(result->status, 400) << name;
            EXPECT_NE(result->body.find("this CPU cannot run " + name), std::string::npos);
            EXPECT_EQ(status()["settings"]["path"], "scalar") << "nothing changed";
            continue;
        }
        const auto [forced, forced_bytes] = switch_to(body);
        EXPECT_EQ(forced["path"], "simd (" + name + ")");
        EXPECT_TRUE(forced_bytes == bytes_of(octray::render_packet(scene, {}, isa).image))
            << name;
        ASSERT_EQ(post("/api/settings", R"({"path": "scalar", "isa": "auto"})")->status, 200);
    }
    for (const char* body : {R"({"isa": "neon"})", R"({"path": "gpu"})", R"({"isa": 1})"}) {
        const auto result = post("/api/settings", body);
        ASSERT_TRUE(result);
        EXPECT_EQ(result->status, 400) << body;
    }
}

// An animated scene: the status gives the frame range; a frame switch renders that frame
// as `octray render --frames N` does (the frame's pose and its sample hash), in both
// orders, and save writes it with --frames N in the command.
TEST_F(SwitchesTest, TheFrameSwitchRendersAndSavesThatFrame) {
    namespace fs = std::filesystem;
    const fs::path dir =
        fs::temp_directory_path() / ("octray_view_frame_" + std::to_string(getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const Scene scene = animated_whitted();
    start(scene, octray::view::PixelOrder::tiled, dir.string());
    const json s = status();
    EXPECT_EQ(s["animation"], (json{{"frames", 5}, {"fps", 10.0}}));
    EXPECT_EQ(s["settings"]["frame"], 0);

    octray::RenderOptions at3;
    at3.frame = 3;
    const Scene posed = octray::scene_at_frame(scene, 3);
    const std::string want = bytes_of(octray::render_packet(posed, at3).image);
    EXPECT_FALSE(want == bytes_of(octray::render_packet(posed).image))
        << "the sample hash of frame 3 must differ from frame 0's";
    const auto [shown, shown_bytes] = switch_to(R"({"frame": 3})");
    EXPECT_TRUE(shown_bytes == want);
    EXPECT_EQ(shown["animation_frame"], 3);
    EXPECT_EQ(shown["camera"]["eye"][0], posed.camera.eye.x) << "the frame's camera";

    // Saved: the same pixels, and the command line that renders them names the frame.
    // (The refined picture is in: saving needs no retry.)
    const auto result = post("/api/save", R"({"name": "f3.exr"})");
    ASSERT_TRUE(result);
    ASSERT_EQ(result->status, 200) << result->body;
    const json answer = json::parse(result->body);
    EXPECT_EQ(answer["camera_moved"], false);
    EXPECT_NE(answer["command"].get<std::string>().find(" --frames 3 -o f3.exr"),
              std::string::npos)
        << answer["command"];
    const octray::RenderResult expected = octray::render_packet(posed, at3);
    octray::write_exr((dir / "expected.exr").string(),
                      octray::make_exr_image(expected.image, {}, {}));
    EXPECT_EQ(octray::read_image((dir / "f3.exr").string()).channels,
              octray::read_image((dir / "expected.exr").string()).channels);

    // Frameless converges to the same frame; a frame out of range changes nothing.
    const auto [frameless, frameless_bytes] = switch_to(R"({"order": "frameless"})");
    EXPECT_EQ(status()["settings"]["frame"], 3);
    EXPECT_EQ(frameless["animation_frame"], 3);
    EXPECT_TRUE(frameless_bytes == want);
    for (const char* body : {R"({"frame": 5})", R"({"frame": -1})", R"({"frame": "2"})"}) {
        const auto refused = post("/api/settings", body);
        ASSERT_TRUE(refused);
        EXPECT_EQ(refused->status, 400) << body;
    }
    EXPECT_EQ(status()["settings"]["frame"], 3);
    server_->stop();
    fs::remove_all(dir);
}

}  // namespace
