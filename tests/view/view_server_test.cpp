// `octray view`'s HTTP API with a real client (httplib::Client) against a server started
// in this process on a free port: the token, refused requests, the first picture equal to
// a plain render bit for bit, the camera endpoint, previews, event streams, reconnects.

#include "view/view_server.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "render/image/image_io.h"
#include "render/image/image_read.h"
#include "render/packet_renderer.h"
#include "scene/builtin.h"
#include "scene/load.h"
#include "view/frameless.h"
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

// An image's raw bytes, as /api/image.f32 returns them.
std::string bytes_of(const octray::Image& image) {
    const std::vector<octray::Rgb> pixels = octray::rgb_pixels(image);
    return std::string(reinterpret_cast<const char*>(pixels.data()),
                       pixels.size() * sizeof(octray::Rgb));
}

// The raw bytes of render_packet's image of `scene`: what /api/image.f32 must return.
std::string rendered_bytes(const Scene& scene) {
    return bytes_of(octray::render_packet(scene).image);
}

class ViewServerTest : public ::testing::Test {
  protected:
    virtual octray::view::PixelOrder order() const { return octray::view::PixelOrder::tiled; }

    void SetUp() override {
        ViewSettings settings;
        settings.order = order();
        settings.render.threads = 2;
        // Long enough that a test polling the status sees a preview before it is refined,
        // however loaded the machine.
        settings.settle = std::chrono::milliseconds(3000);
        session_ = std::make_unique<ViewSession>(scene_, settings);
        server_ = std::make_unique<ViewServer>(*session_, ServerOptions{});
        server_->start();
        client_ = std::make_unique<httplib::Client>("127.0.0.1", server_->port());
        client_->set_read_timeout(60, 0);
    }
    void TearDown() override {
        client_.reset();
        server_.reset();
        session_.reset();
    }

    std::string with_token(const std::string& path) const {
        return path + (path.find('?') == std::string::npos ? "?" : "&") +
               "token=" + server_->token();
    }

    json status() {
        const auto result = client_->Get(with_token("/api/status"));
        EXPECT_TRUE(result);
        if (!result || result->status != 200) return json{};
        return json::parse(result->body);
    }

    // Polls the status until `done(frame)` holds (60 s at most); the frame, or null.
    json wait_for_frame(const std::function<bool(const json&)>& done) {
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
        while (std::chrono::steady_clock::now() < deadline) {
            const json s = status();
            if (s.contains("frame") && done(s["frame"])) return s["frame"];
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
        }
        return json{};
    }

    const Scene scene_ = small_whitted();
    std::unique_ptr<ViewSession> session_;
    std::unique_ptr<ViewServer> server_;
    std::unique_ptr<httplib::Client> client_;
};

TEST_F(ViewServerTest, EveryPathWithoutTheTokenIs403) {
    for (const char* path : {"/", "/api/status", "/api/events", "/api/image.png",
                             "/api/image.f32", "/no/such/page", "/../etc/passwd"}) {
        const auto result = client_->Get(path);
        ASSERT_TRUE(result) << path;
        EXPECT_EQ(result->status, 403) << path;
        EXPECT_EQ(result->body.find(server_->token()), std::string::npos);
    }
    const auto post = client_->Post("/api/camera", R"({"eye": [0, 1, 5]})", "application/json");
    ASSERT_TRUE(post);
    EXPECT_EQ(post->status, 403);
    EXPECT_EQ(session_->camera().eye.z, scene_.camera.eye.z);
}

TEST_F(ViewServerTest, AWrongTokenIs403) {
    std::string wrong = server_->token();
    wrong[0] = wrong[0] == 'a' ? 'b' : 'a';
    for (const std::string& token :
         {wrong, server_->token().substr(0, 31), std::string(), server_->token() + "0"}) {
        const auto result = client_->Get("/api/status?token=" + token);
        ASSERT_TRUE(result);
        EXPECT_EQ(result->status, 403) << token;
    }
    const std::string cookie = "octray_token_" + std::to_string(server_->port());
    const auto by_cookie = client_->Get("/api/status", {{"Cookie", cookie + "=" + wrong}});
    ASSERT_TRUE(by_cookie);
    EXPECT_EQ(by_cookie->status, 403);
    // The cookie of another port's viewer does not open this one.
    const auto other_port =
        client_->Get("/api/status", {{"Cookie", "octray_token_1=" + server_->token()}});
    ASSERT_TRUE(other_port);
    EXPECT_EQ(other_port->status, 403);
}

TEST_F(ViewServerTest, ThePageSetsTheTokenCookieWhichThenSuffices) {
    const auto page = client_->Get(with_token("/"));
    ASSERT_TRUE(page);
    ASSERT_EQ(page->status, 200);
    EXPECT_NE(page->body.find("<canvas id=\"view\""), std::string::npos);
    EXPECT_EQ(page->body.find("http://"), std::string::npos) << "the page loads nothing else";
    EXPECT_EQ(page->body.find("https://"), std::string::npos) << "the page loads nothing else";
    const std::string cookie = page->get_header_value("Set-Cookie");
    const std::string name = "octray_token_" + std::to_string(server_->port());
    EXPECT_EQ(cookie.rfind(name + "=" + server_->token() + ";", 0), 0u) << cookie;
    EXPECT_NE(cookie.find("HttpOnly"), std::string::npos);
    EXPECT_NE(cookie.find("SameSite=Strict"), std::string::npos);
    const auto by_cookie =
        client_->Get("/api/status", {{"Cookie", "a=b; " + name + "=" + server_->token()}});
    ASSERT_TRUE(by_cookie);
    EXPECT_EQ(by_cookie->status, 200);
}

TEST_F(ViewServerTest, UnknownPathsWithTheTokenAre404) {
    for (const char* path : {"/index.html", "/api", "/api/scene", "/../whitted.json"}) {
        const auto result = client_->Get(with_token(path));
        ASSERT_TRUE(result) << path;
        EXPECT_EQ(result->status, 404) << path;
    }
}

TEST_F(ViewServerTest, BadCameraRequestsAre400AndChangeNothing) {
    const octray::Camera before = session_->camera();
    for (const std::string& body :
         {std::string("not json"), std::string("[1, 2, 3]"), std::string(R"({"eye": [1, 2]})"),
          std::string(R"({"eye": [1, 2, "3"]})"), std::string(R"({"eye": [1, 2, 1e999]})"),
          std::string(R"({"eye": [1, 2, 1e31]})"), std::string(R"({"fov": -5})"),
          std::string(R"({"fov": 180})"), std::string(R"({"moving": 1})"),
          std::string(R"({"zoom": 2})"),
          std::string(R"({"eye": [0, 0, 0], "lookat": [0, 0, 0]})"),
          std::string(R"({"up": [0, 0, 0]})"),
          // Issue 38: a duplicate key, as a scene file's, is refused.
          std::string(R"({"eye": [0, 1, 5], "eye": [0, 1, 6]})")}) {
        const auto result = client_->Post(with_token("/api/camera"), body, "application/json");
        ASSERT_TRUE(result) << body;
        EXPECT_EQ(result->status, 400) << body << " -> " << result->body;
        EXPECT_FALSE(result->body.empty()) << body;
    }
    EXPECT_EQ(session_->camera().eye.x, before.eye.x);
    EXPECT_EQ(session_->camera().fov, before.fov);
}

TEST_F(ViewServerTest, AnOversizedBodyIs413) {
    const std::string body = R"({"eye": [0, 1, 5], "pad": ")" + std::string(10000, 'x') + "\"}";
    const auto result = client_->Post(with_token("/api/camera"), body, "application/json");
    ASSERT_TRUE(result);
    EXPECT_EQ(result->status, 413);
}

TEST_F(ViewServerTest, ABadExposureIs400) {
    ASSERT_FALSE(wait_for_frame([](const json&) { return true; }).is_null());
    for (const char* exposure : {"abc", "1e9", "nan", "", "2x"}) {
        const auto result =
            client_->Get(with_token(std::string("/api/image.png?exposure=") + exposure));
        ASSERT_TRUE(result) << exposure;
        EXPECT_EQ(result->status, 400) << exposure;
    }
    const auto good = client_->Get(with_token("/api/image.png?exposure=-1.5"));
    ASSERT_TRUE(good);
    EXPECT_EQ(good->status, 200);
    EXPECT_EQ(good->body.substr(1, 3), "PNG");
}

// A request line that is not HTTP gets 400 from the server, which keeps serving.
TEST_F(ViewServerTest, AMalformedRequestIs400) {
    const int fd = socket(AF_INET, SOCK_STREAM, 0);
    ASSERT_GE(fd, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<std::uint16_t>(server_->port()));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
    const std::string garbage = "\x01\x02 GARBAGE\r\n\r\n";
    ASSERT_EQ(write(fd, garbage.data(), garbage.size()), static_cast<ssize_t>(garbage.size()));
    char reply[256] = {};
    const ssize_t n = read(fd, reply, sizeof reply - 1);
    close(fd);
    ASSERT_GT(n, 0);
    EXPECT_EQ(std::string(reply).rfind("HTTP/1.1 400", 0), 0u) << reply;
    EXPECT_EQ(status().is_null(), false);
}

// The first picture, once its last pass (spp = the scene's) is in, is render_packet's image
// of the same scene bit for bit: progressive passes sum samples in the same order
// (render/progressive.h).
TEST_F(ViewServerTest, TheFirstPictureEqualsAPlainRenderBitForBit) {
    const json frame = wait_for_frame([&](const json& f) { return f["spp"] == 4; });
    ASSERT_FALSE(frame.is_null());
    EXPECT_EQ(frame["camera_version"], 1);
    EXPECT_EQ(frame["preview"], false);
    EXPECT_EQ(frame["width"], 64);
    EXPECT_EQ(frame["height"], 36);
    const auto image = client_->Get(with_token("/api/image.f32"));
    ASSERT_TRUE(image);
    ASSERT_EQ(image->status, 200);
    EXPECT_EQ(image->get_header_value("X-Octray-Spp"), "4");
    EXPECT_EQ(image->get_header_value("X-Octray-Width"), "64");
    EXPECT_EQ(image->get_header_value("X-Octray-Height"), "36");
    ASSERT_EQ(image->body.size(), 64u * 36u * 3u * sizeof(float));
    EXPECT_TRUE(image->body == rendered_bytes(scene_)) << "the picture differs from render";
}

TEST_F(ViewServerTest, ACameraSetThroughTheApiIsRenderedExactly) {
    const auto result =
        client_->Post(with_token("/api/camera"), R"({"eye": [1.5, 2.5, 6.0], "moving": false})",
                      "application/json");
    ASSERT_TRUE(result);
    ASSERT_EQ(result->status, 200) << result->body;
    const int version = json::parse(result->body)["camera_version"];
    EXPECT_GE(version, 2);
    const json frame = wait_for_frame(
        [&](const json& f) { return f["camera_version"] == version && f["spp"] == 4; });
    ASSERT_FALSE(frame.is_null());
    EXPECT_EQ(frame["camera"]["eye"], json::array({1.5, 2.5, 6.0}));
    const auto image = client_->Get(with_token("/api/image.f32"));
    ASSERT_TRUE(image);
    ASSERT_EQ(image->get_header_value("X-Octray-Camera-Version"), std::to_string(version));
    Scene moved = scene_;
    moved.camera.eye = octray::Vec3{1.5f, 2.5f, 6.0f};
    EXPECT_TRUE(image->body == rendered_bytes(moved));
    EXPECT_FALSE(image->body == rendered_bytes(scene_));
}

// While the camera moves the picture is a 1-spp preview at a quarter of the size; once it
// has settled, the full picture follows.
TEST_F(ViewServerTest, AMovingCameraGetsAPreviewThenTheRefinedPicture) {
    ASSERT_FALSE(wait_for_frame([](const json& f) { return f["spp"] == 4; }).is_null());
    const auto result =
        client_->Post(with_token("/api/camera"), R"({"eye": [0.5, 2.0, 7.0], "moving": true})",
                      "application/json");
    ASSERT_TRUE(result);
    ASSERT_EQ(result->status, 200);
    const int version = json::parse(result->body)["camera_version"];
    const json preview = wait_for_frame(
        [&](const json& f) { return f["camera_version"] == version && f["preview"] == true; });
    ASSERT_FALSE(preview.is_null());
    EXPECT_EQ(preview["width"], 16);
    EXPECT_EQ(preview["height"], 9);
    EXPECT_EQ(preview["spp"], 1);
    const json refined = wait_for_frame([&](const json& f) {
        return f["camera_version"] == version && f["preview"] == false && f["spp"] == 4;
    });
    ASSERT_FALSE(refined.is_null());
    EXPECT_EQ(refined["width"], 64);
}

// Issue 44: a camera that moves faster than a preview renders still gets previews on the
// screen. Each move abandoned the preview in flight, so while a drag's moves came every
// few milliseconds no picture was published at all; now a moving camera lets the preview
// in flight finish, and the latest camera is rendered next.
TEST(ViewSessionPreviews, MovesFasterThanAPreviewRendersStillPublishPreviews) {
    Scene scene = small_whitted();
    scene.image.width = 640;  // a preview of some milliseconds: longer than a move
    scene.image.height = 360;
    ViewSettings settings;
    settings.render.threads = 1;
    settings.preview_divisor = 1;
    ViewSession session(scene, settings);
    ASSERT_TRUE(session.wait_newer(0, std::chrono::seconds(60)));
    octray::Camera camera = scene.camera;
    const std::uint64_t first = session.set_camera(camera, true);
    std::uint64_t previews_seen = 0, last_generation = 0;
    for (int i = 0; i < 2000 && previews_seen < 3; ++i) {
        camera.eye.x += 0.001f;
        session.set_camera(camera, true);
        const auto frame = session.latest();
        if (frame && frame->preview && frame->camera_version > first &&
            frame->generation != last_generation) {
            last_generation = frame->generation;
            ++previews_seen;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    EXPECT_GE(previews_seen, 3u) << "previews were abandoned while the camera kept moving";
}

// The viewer prepares the scene once (compile + BVH) and re-aims and re-sizes it for each
// picture: a preview (a quarter of the size, 1 spp) and the refined picture after it are
// each, bit for bit, the scene rendered afresh at that size with that camera.
TEST(ViewSessionPreviews, APreviewAndTheRefinedPictureAreThoseOfAFreshRender) {
    Scene scene = octray::load_scene("random:64,width=64,height=36,spp=2");
    ViewSettings settings;
    settings.render.threads = 2;
    settings.settle = std::chrono::milliseconds(300);
    ViewSession session(scene, settings);
    auto frame = session.wait_newer(0, std::chrono::seconds(60));
    ASSERT_TRUE(frame);
    octray::Camera camera = scene.camera;
    camera.eye = {0.7f, 0.4f, 3.5f};
    const std::uint64_t version = session.set_camera(camera, true);
    std::shared_ptr<const octray::view::ViewFrame> preview, refined;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!refined && std::chrono::steady_clock::now() < deadline) {
        frame = session.wait_newer(frame->generation, std::chrono::seconds(1));
        if (!frame || frame->camera_version != version) continue;
        if (frame->preview) preview = frame;
        if (!frame->preview && frame->spp == 2) refined = frame;
    }
    ASSERT_TRUE(preview) << "no preview of the moved camera";
    ASSERT_TRUE(refined) << "no refined picture of the moved camera";
    Scene moved = scene;
    moved.camera = camera;
    EXPECT_EQ(bytes_of(refined->image), rendered_bytes(moved));
    moved.image.width = 16;
    moved.image.height = 9;
    moved.image.spp = 1;
    EXPECT_EQ(bytes_of(preview->image), rendered_bytes(moved));
}

// Reads one event stream until `enough` says so; the events' JSON payloads.
std::vector<json> read_events(httplib::Client& client, const std::string& path,
                              const std::function<bool(const std::vector<json>&)>& enough) {
    std::vector<json> events;
    std::string buffer;
    client.Get(path, [&](const char* data, std::size_t size) {
        buffer.append(data, size);
        for (std::size_t end; (end = buffer.find("\n\n")) != std::string::npos;) {
            const std::string message = buffer.substr(0, end);
            buffer.erase(0, end + 2);
            const std::size_t data_at = message.find("data: ");
            if (message.rfind("event: frame", 0) == 0 && data_at != std::string::npos)
                events.push_back(json::parse(message.substr(data_at + 6)));
        }
        return !enough(events);
    });
    return events;
}

// A stream announces the current picture at once, then newer ones in order, ending on the
// last pass of a new camera. A reader that is slower than the passes skips some (the
// stream holds only the latest picture, never a queue), so the passes seen are an
// increasing part of 1, 2, 4.
TEST_F(ViewServerTest, TheEventStreamAnnouncesANewCamerasPassesInOrder) {
    ASSERT_FALSE(wait_for_frame([](const json& f) { return f["spp"] == 4; }).is_null());
    std::thread mover([&] {
        httplib::Client other("127.0.0.1", server_->port());
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        other.Post(with_token("/api/camera"), R"({"eye": [-1.0, 2.0, 7.0]})",
                   "application/json");
    });
    const std::vector<json> events =
        read_events(*client_, with_token("/api/events"), [](const std::vector<json>& e) {
            return !e.empty() && e.back()["camera_version"] == 2 && e.back()["spp"] == 4;
        });
    mover.join();
    ASSERT_GE(events.size(), 2u);
    EXPECT_EQ(events.front()["camera_version"], 1);
    EXPECT_EQ(events.front()["spp"], 4);
    std::vector<int> passes;
    for (std::size_t i = 1; i < events.size(); ++i) {
        EXPECT_GT(events[i]["generation"], events[i - 1]["generation"]);
        if (events[i]["camera_version"] == 2) passes.push_back(events[i]["spp"]);
    }
    ASSERT_FALSE(passes.empty());
    EXPECT_EQ(passes.back(), 4);
    for (std::size_t i = 0; i < passes.size(); ++i) {
        EXPECT_TRUE(passes[i] == 1 || passes[i] == 2 || passes[i] == 4) << passes[i];
        if (i > 0) {
            EXPECT_GT(passes[i], passes[i - 1]);
        }
    }
}

// A hundred clients that open the event stream and go away, and a hundred that fetch a
// picture, one after the other: the server still answers, and its event streams end.
TEST_F(ViewServerTest, AHundredReconnectsLeaveTheServerRunning) {
    ASSERT_FALSE(wait_for_frame([](const json& f) { return f["spp"] == 4; }).is_null());
    for (int i = 0; i < 100; ++i) {
        httplib::Client client("127.0.0.1", server_->port());
        client.set_read_timeout(60, 0);
        const auto events = read_events(client, with_token("/api/events"),
                                        [](const std::vector<json>& e) { return !e.empty(); });
        ASSERT_EQ(events.size(), 1u) << "reconnect " << i;
        const auto image = client.Get(with_token("/api/image.png"));
        ASSERT_TRUE(image) << "reconnect " << i;
        ASSERT_EQ(image->status, 200);
    }
    const json s = status();
    ASSERT_TRUE(s.contains("frame"));
    EXPECT_EQ(s["frame"]["spp"], 4);
}

// One message of /api/pictures: the JSON header (null for a heartbeat) and the picture.
struct PictureMessage {
    json header;
    std::string picture;
};

// Reads /api/pictures until `enough` says so; the messages other than heartbeats.
std::vector<PictureMessage> read_pictures(
    httplib::Client& client, const std::string& path,
    const std::function<bool(const std::vector<PictureMessage>&)>& enough) {
    std::vector<PictureMessage> messages;
    std::string buffer;
    const auto u32 = [&](std::size_t at) {
        std::uint32_t v = 0;
        for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(buffer[at + i]);
        return std::size_t{v};
    };
    client.Get(path, [&](const char* data, std::size_t size) {
        buffer.append(data, size);
        while (buffer.size() >= 12) {
            EXPECT_EQ(buffer.substr(0, 4), "OCTP");
            const std::size_t header = u32(4), picture = u32(8);
            if (buffer.size() < 12 + header + picture) break;
            if (header > 0)
                messages.push_back({json::parse(buffer.substr(12, header)),
                                    buffer.substr(12 + header, picture)});
            buffer.erase(0, 12 + header + picture);
        }
        return !enough(messages);
    });
    return messages;
}

// Issue 44: the pictures themselves come over one long-lived stream, no request each. Its
// first message is the current picture; the refined picture is the very PNG that
// /api/image.png serves (lossless), a preview of a moving camera a JPEG; each carries the
// frame's JSON as the event stream does.
TEST_F(ViewServerTest, ThePictureStreamSendsTheLatestPictureRefinedAsPngPreviewsAsJpeg) {
    ASSERT_FALSE(wait_for_frame([](const json& f) { return f["spp"] == 4; }).is_null());
    const auto png = client_->Get(with_token("/api/image.png?exposure=1"));
    ASSERT_TRUE(png);
    httplib::Client stream_client("127.0.0.1", server_->port());
    stream_client.set_read_timeout(60, 0);
    std::thread mover([&] {
        httplib::Client other("127.0.0.1", server_->port());
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        other.Post(with_token("/api/camera"), R"({"eye": [-1.0, 2.0, 7.0], "moving": true})",
                   "application/json");
    });
    const auto messages = read_pictures(stream_client, with_token("/api/pictures?exposure=1"),
                                        [](const std::vector<PictureMessage>& m) {
                                            return !m.empty() &&
                                                   m.back().header["camera_version"] == 2 &&
                                                   m.back().header["preview"] == true;
                                        });
    mover.join();
    ASSERT_GE(messages.size(), 2u);
    const PictureMessage& first = messages.front();
    EXPECT_EQ(first.header["event"], "frame");
    EXPECT_EQ(first.header["camera_version"], 1);
    EXPECT_EQ(first.header["spp"], 4);
    EXPECT_EQ(first.header["format"], "png");
    EXPECT_TRUE(first.picture == png->body) << "the refined picture differs from image.png's";
    const PictureMessage& preview = messages.back();
    EXPECT_EQ(preview.header["format"], "jpeg");
    EXPECT_EQ(preview.header["width"], 16);
    ASSERT_GE(preview.picture.size(), 4u);
    EXPECT_EQ(static_cast<unsigned char>(preview.picture[0]), 0xff);  // JPEG's SOI marker
    EXPECT_EQ(static_cast<unsigned char>(preview.picture[1]), 0xd8);
}

// (Many event streams, slow clients and the cap on connections: view_load_test.cpp.)

TEST_F(ViewServerTest, StopEndsAnOpenEventStream) {
    ASSERT_FALSE(wait_for_frame([](const json&) { return true; }).is_null());
    std::thread stopper([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        server_->stop();
    });
    // Without stop() this would read forever (the test would time out).
    read_events(*client_, with_token("/api/events"),
                [](const std::vector<json>&) { return false; });
    stopper.join();
    server_->wait();
    SUCCEED();
}

TEST(FramelessBlocks, CoverThePictureOnceInAFixedShuffledOrder) {
    const auto blocks = octray::view::frameless_blocks(21, 10, 8);
    ASSERT_EQ(blocks.size(), 6u);  // 3 x 2, the last column 5 wide and the last row 2 high
    std::vector<int> hits(21 * 10, 0);
    for (const octray::PixelRect& r : blocks)
        for (int y = r.y0; y < r.y1; ++y)
            for (int x = r.x0; x < r.x1; ++x) ++hits[static_cast<std::size_t>(y * 21 + x)];
    EXPECT_EQ(std::count(hits.begin(), hits.end(), 1), 210);
    EXPECT_EQ(octray::view::frameless_blocks(21, 10, 8), blocks) << "the order is fixed";
    const auto many = octray::view::frameless_blocks(64, 64, 8);
    auto row_major = many;
    std::sort(row_major.begin(), row_major.end(), [](const auto& a, const auto& b) {
        return a.y0 != b.y0 ? a.y0 < b.y0 : a.x0 < b.x0;
    });
    EXPECT_NE(many, row_major) << "the order is shuffled";
    EXPECT_THROW(octray::view::frameless_blocks(0, 10, 8), std::invalid_argument);
}

class FramelessViewTest : public ViewServerTest {
  protected:
    octray::view::PixelOrder order() const override {
        return octray::view::PixelOrder::frameless;
    }
};

// Single pixels (--frameless-block 1): 64 x 36 blocks of one pixel, in batches; once every
// pixel of the camera has landed, the picture is the tiled order's bit for bit.
TEST(FramelessSinglePixels, ConvergeToTheTiledPictureBitForBit) {
    const Scene scene = octray::load_scene("random:64,width=64,height=36,spp=2");
    ViewSettings settings;
    settings.order = octray::view::PixelOrder::frameless;
    settings.frameless_block = 1;
    settings.render.threads = 2;
    ViewSession session(scene, settings);
    std::shared_ptr<const octray::view::ViewFrame> frame;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < deadline) {
        frame = session.wait_newer(frame ? frame->generation : 0, std::chrono::seconds(1));
        if (frame && frame->coverage == 1.0) break;
    }
    ASSERT_TRUE(frame && frame->coverage == 1.0);
    EXPECT_EQ(bytes_of(frame->image), rendered_bytes(scene));
}

// Blocks land a batch at a time; once every block of a still camera has been rendered,
// the picture is the tiled order's (render_packet's) bit for bit, for the first camera and
// for a camera set later, whose sweep starts over a picture of the old one.
TEST_F(FramelessViewTest, ConvergesToTheTiledPictureBitForBit) {
    // 40 blocks of 8x8 in batches of 16: pictures of coverage 0.4, 0.8, then 1.
    const json first = wait_for_frame(
        [](const json& f) { return f["camera_version"] == 1 && f["coverage"] == 1.0; });
    ASSERT_FALSE(first.is_null());
    const auto image = client_->Get(with_token("/api/image.f32"));
    ASSERT_TRUE(image);
    EXPECT_TRUE(image->body == rendered_bytes(scene_));

    const auto result = client_->Post(with_token("/api/camera"), R"({"eye": [1.5, 2.5, 6.0]})",
                                      "application/json");
    ASSERT_TRUE(result);
    ASSERT_EQ(result->status, 200);
    const int version = json::parse(result->body)["camera_version"];
    const json moved = wait_for_frame(
        [&](const json& f) { return f["camera_version"] == version && f["coverage"] == 1.0; });
    ASSERT_FALSE(moved.is_null());
    const auto after = client_->Get(with_token("/api/image.f32"));
    ASSERT_TRUE(after);
    ASSERT_EQ(after->get_header_value("X-Octray-Camera-Version"), std::to_string(version));
    Scene scene = scene_;
    scene.camera.eye = octray::Vec3{1.5f, 2.5f, 6.0f};
    EXPECT_TRUE(after->body == rendered_bytes(scene));
}

}  // namespace

namespace {

// The value under the cursor is the float pixel of the latest picture; outside it, 400.
TEST_F(ViewServerTest, ThePixelEndpointReadsTheLatestPicture) {
    ASSERT_FALSE(
        wait_for_frame([&](const json& f) { return f["spp"] == scene_.image.spp; }).is_null());
    const auto bytes = client_->Get(with_token("/api/image.f32"));
    ASSERT_TRUE(bytes);
    ASSERT_EQ(bytes->status, 200);
    const int x = 17, y = 9;
    float expected[3];
    std::memcpy(expected,
                bytes->body.data() +
                    (static_cast<std::size_t>(y) * scene_.image.width + x) * 3 * sizeof(float),
                sizeof(expected));
    const auto pixel = client_->Get(with_token("/api/pixel?x=17&y=9"));
    ASSERT_TRUE(pixel);
    ASSERT_EQ(pixel->status, 200);
    const json answer = json::parse(pixel->body);
    EXPECT_EQ(answer["width"], scene_.image.width);
    EXPECT_EQ(answer["height"], scene_.image.height);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(answer["rgb"][c].get<float>(), expected[c]) << c;
    // Decimal digits only, as the command line's integers (issue 38: "+1" and " 1" passed).
    for (const char* query :
         {"x=64&y=0", "x=0&y=36", "x=-1&y=0", "x=0", "y=0", "x=1e1&y=0", "x=&y=0", "x=0x1&y=0",
          "x=%2B1&y=0", "x=%201&y=0", "x=1%20&y=0"}) {
        const auto bad = client_->Get(with_token(std::string("/api/pixel?") + query));
        ASSERT_TRUE(bad) << query;
        EXPECT_EQ(bad->status, 400) << query << " -> " << bad->body;
    }
}

// Issue 44: a page that shows a preview (16x9 here) while the refined picture (64x36) is in
// asks with the size it shows: the answer is the pixel at the same place of the latest
// picture, not a 400 (as during every drag before).
TEST_F(ViewServerTest, ThePixelEndpointMapsThePlaceInTheShownPictureToTheLatest) {
    ASSERT_FALSE(
        wait_for_frame([&](const json& f) { return f["spp"] == scene_.image.spp; }).is_null());
    const auto scaled = client_->Get(with_token("/api/pixel?x=15&y=8&width=16&height=9"));
    ASSERT_TRUE(scaled);
    ASSERT_EQ(scaled->status, 200) << scaled->body;
    const json answer = json::parse(scaled->body);
    EXPECT_EQ(answer["x"], 62);  // the centre of (15, 8) of 16x9: (15.5 * 4, 8.5 * 4)
    EXPECT_EQ(answer["y"], 34);
    const auto direct = client_->Get(with_token("/api/pixel?x=62&y=34"));
    ASSERT_TRUE(direct);
    EXPECT_EQ(json::parse(direct->body)["rgb"], answer["rgb"]);
    for (const char* query :
         {"x=16&y=0&width=16&height=9", "x=0&y=0&width=16", "x=0&y=0&width=0&height=9"}) {
        const auto bad = client_->Get(with_token(std::string("/api/pixel?") + query));
        ASSERT_TRUE(bad) << query;
        EXPECT_EQ(bad->status, 400) << query << " -> " << bad->body;
    }
}

}  // namespace

namespace {

// The page's switches: spp, max depth, order (and threads) re-render the current camera,
// and the refined picture is then `octray render`'s of the scene with those values.
TEST_F(ViewServerTest, SwitchesReRenderWithTheNewValues) {
    ASSERT_FALSE(
        wait_for_frame([&](const json& f) { return f["spp"] == scene_.image.spp; }).is_null());
    for (const std::string& body :
         {std::string(R"({"spp": 0})"), std::string(R"({"spp": 1.5})"),
          std::string(R"({"max_depth": 0})"), std::string(R"({"max_depth": 65})"),
          std::string(R"({"threads": -1})"), std::string(R"({"order": "spiral"})"),
          std::string(R"({"order": 1})"), std::string(R"({"depth": 2})"), std::string("[]"),
          std::string("nope")}) {
        const auto result =
            client_->Post(with_token("/api/settings"), body, "application/json");
        ASSERT_TRUE(result) << body;
        EXPECT_EQ(result->status, 400) << body << " -> " << result->body;
    }
    EXPECT_EQ(status()["settings"]["spp"], scene_.image.spp);
    for (const char* order : {"rows", "frameless", "tiled"}) {
        const std::string body =
            std::string(R"({"spp": 2, "max_depth": 2, "threads": 1, "order": ")") + order +
            "\"}";
        const auto result =
            client_->Post(with_token("/api/settings"), body, "application/json");
        ASSERT_TRUE(result);
        ASSERT_EQ(result->status, 200) << result->body;
        const json s = status();
        EXPECT_EQ(s["settings"]["order"], order);
        EXPECT_EQ(s["settings"]["spp"], 2);
        EXPECT_EQ(s["settings"]["max_depth"], 2);
        EXPECT_EQ(s["settings"]["threads"], 1);
        ASSERT_FALSE(wait_for_frame([](const json& f) {
                         return f["target_spp"] == 2 && f["spp"] == 2 && f["coverage"] == 1.0 &&
                                !f["preview"].get<bool>();
                     }).is_null());
        Scene expected = scene_;
        expected.image.spp = 2;
        expected.render.max_depth = 2;
        // Wait until the picture is of the switched scene (the old one had target 4).
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
        std::string got;
        const std::string want = rendered_bytes(expected);
        while (std::chrono::steady_clock::now() < deadline) {
            const auto bytes = client_->Get(with_token("/api/image.f32"));
            ASSERT_TRUE(bytes);
            got = bytes->body;
            if (got == want) break;
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        EXPECT_TRUE(got == want) << order << ": the refined picture is not render's";
    }
}

}  // namespace
