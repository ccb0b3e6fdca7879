// `octray view A.exr B.exr`'s HTTP API with a real client: the pictures of A and B are the
// files' pixels as read_image() reads them, the figures are `octray compare --json`'s, the
// heatmap is compare's, the value under the cursor is validated, and unreadable or
// mismatched images fail as compare fails.

#include "view/compare_view.h"

#include <gtest/gtest.h>
#include <httplib.h>
#include <png.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "render/image/image_compare.h"
#include "render/image/image_io.h"
#include "render/image/image_read.h"
#include "view/view_server.h"

namespace {

using nlohmann::json;
using octray::Image;
using octray::view::CompareView;
using octray::view::ServerOptions;
using octray::view::ViewServer;

Image gradient(int width, int height, float offset) {
    Image image(width, height, {"R", "G", "B"});
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            image.at(0, x, y) = 0.01f * static_cast<float>(x) + offset;
            image.at(1, x, y) = 0.02f * static_cast<float>(y);
            image.at(2, x, y) = (x + y) % 3 == 0 ? 0.5f + offset : 0.25f;
        }
    }
    return image;
}

// The width and height of a PNG in memory (0, 0 if it is not one).
std::pair<int, int> png_size(const std::string& bytes) {
    png_image image;
    std::memset(&image, 0, sizeof(image));
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&image, bytes.data(), bytes.size())) return {0, 0};
    const std::pair<int, int> size{static_cast<int>(image.width),
                                   static_cast<int>(image.height)};
    png_image_free(&image);
    return size;
}

class CompareViewTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("octray_compare_view_" + std::to_string(::getpid()));
        std::filesystem::create_directories(dir_);
        a_ = (dir_ / "a.exr").string();
        b_ = (dir_ / "b.exr").string();
        octray::write_exr(a_, gradient(40, 24, 0.0f));
        octray::write_exr(b_, gradient(40, 24, 0.125f));
        view_ = octray::view::load_compare_view(a_, b_);
        server_ = std::make_unique<ViewServer>(view_, ServerOptions{});
        server_->start();
        client_ = std::make_unique<httplib::Client>("127.0.0.1", server_->port());
        client_->set_read_timeout(30, 0);
    }
    void TearDown() override {
        client_.reset();
        server_.reset();
        std::filesystem::remove_all(dir_);
    }

    httplib::Result get(const std::string& path) {
        return client_->Get(path + (path.find('?') == std::string::npos ? "?" : "&") +
                            "token=" + server_->token());
    }

    std::filesystem::path dir_;
    std::string a_, b_;
    CompareView view_;
    std::unique_ptr<ViewServer> server_;
    std::unique_ptr<httplib::Client> client_;
};

TEST_F(CompareViewTest, ThePicturesAreTheFilesPixels) {
    for (const auto& [name, path] : {std::pair{"a", a_}, std::pair{"b", b_}}) {
        const auto result = get(std::string("/api/image.f32?picture=") + name);
        ASSERT_TRUE(result);
        ASSERT_EQ(result->status, 200);
        const Image file = octray::read_image(path);
        ASSERT_EQ(result->body.size(), file.pixel_count() * 3 * sizeof(float));
        std::vector<float> served(file.pixel_count() * 3);
        std::memcpy(served.data(), result->body.data(), result->body.size());
        for (int y = 0; y < file.height(); ++y) {
            for (int x = 0; x < file.width(); ++x) {
                for (int c = 0; c < 3; ++c) {
                    const std::size_t i = (static_cast<std::size_t>(y) * file.width() + x) * 3;
                    ASSERT_EQ(served[i + c], file.at(file.channel_index(c == 0   ? "R"
                                                                        : c == 1 ? "G"
                                                                                 : "B"),
                                                     x, y))
                        << name << " " << x << "," << y << " c" << c;
                }
            }
        }
    }
    // |A - B|: the red channel differs by the offset everywhere.
    const auto diff = get("/api/pixel?picture=diff&x=3&y=4");
    ASSERT_TRUE(diff);
    ASSERT_EQ(diff->status, 200);
    EXPECT_FLOAT_EQ(json::parse(diff->body)["rgb"][0].get<float>(), 0.125f);
    EXPECT_FLOAT_EQ(json::parse(diff->body)["rgb"][1].get<float>(), 0.0f);
}

TEST_F(CompareViewTest, TheFiguresAreCompareJson) {
    const std::string expected = octray::format_compare_json(
        octray::compare_images(octray::read_image(a_), octray::read_image(b_)),
        octray::CompareOptions{}, a_, b_);
    const auto figures = get("/api/compare");
    ASSERT_TRUE(figures);
    ASSERT_EQ(figures->status, 200);
    EXPECT_EQ(figures->body, expected);
    const auto status = get("/api/status");
    ASSERT_TRUE(status);
    const json s = json::parse(status->body);
    EXPECT_EQ(s["mode"], "compare");
    EXPECT_EQ(s["compare"], json::parse(expected));
    EXPECT_EQ(s["compare"]["verdict"], "FAIL");
    EXPECT_EQ(s["full_width"], 40);
    EXPECT_EQ(s["full_height"], 24);
}

TEST_F(CompareViewTest, TheHeatmapIsComparesAndTheOthersArePngs) {
    const octray::ErrorHeatmap expected = octray::render_error_heatmap(
        octray::read_image(a_), octray::read_image(b_), view_.result);
    const auto heatmap = get("/api/image.png?picture=heatmap");
    ASSERT_TRUE(heatmap);
    ASSERT_EQ(heatmap->status, 200);
    EXPECT_EQ(heatmap->body, octray::encode_png(expected.image));
    for (const char* name : {"a", "b", "diff"}) {
        const auto png = get(std::string("/api/image.png?exposure=1&picture=") + name);
        ASSERT_TRUE(png);
        ASSERT_EQ(png->status, 200) << name;
        EXPECT_EQ(png_size(png->body), (std::pair{40, 24})) << name;
    }
}

TEST_F(CompareViewTest, BadRequestsAre400AndTheTokenIsNeeded) {
    for (const char* path :
         {"/api/image.png?picture=c", "/api/image.f32?picture=heatmap", "/api/pixel?x=40&y=0",
          "/api/pixel?x=0&y=24", "/api/pixel?x=-1&y=0", "/api/pixel?x=1", "/api/pixel?x=a&y=1",
          "/api/pixel?x=1.5&y=1", "/api/pixel?x=99999999999999999999&y=1",
          "/api/image.png?exposure=nan"}) {
        const auto result = get(path);
        ASSERT_TRUE(result) << path;
        EXPECT_EQ(result->status, 400) << path << " -> " << result->body;
    }
    // Issue 38: the message said "expected a, b, diff or heatmap, found heatmap".
    const auto heatmap_f32 = get("/api/image.f32?picture=heatmap");
    ASSERT_TRUE(heatmap_f32);
    EXPECT_EQ(heatmap_f32->body,
              "picture: the heatmap is a PNG picture only (/api/image.png?picture=heatmap); "
              "here expected a, b or diff\n");
    for (const char* path : {"/api/status", "/api/compare", "/api/image.f32"}) {
        const auto result = client_->Get(path);
        ASSERT_TRUE(result);
        EXPECT_EQ(result->status, 403) << path;
    }
    // Nothing but the two images: no camera, no file endpoint.
    for (const char* path : {"/api/events", "/api/file?path=a.exr", "/a.exr"}) {
        const auto result = get(path);
        ASSERT_TRUE(result);
        EXPECT_EQ(result->status, 404) << path;
    }
    const auto camera =
        client_->Post("/api/camera?token=" + server_->token(), "{}", "application/json");
    ASSERT_TRUE(camera);
    EXPECT_EQ(camera->status, 404);
}

// AOVs (an image written with --aov): the page can show each layer of A, B and |A - B|:
// N.X, N.Y, N.Z as colour, a single channel ("id") as gray; the value under the cursor
// reads the layer; an unknown layer is 400 naming the known ones.
TEST(CompareViewLayers, EachAovLayerIsAPicture) {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("octray_compare_layers_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const auto with_aovs = [](float offset) {
        Image image(8, 4, {"R", "G", "B", "N.X", "N.Y", "N.Z", "id"});
        for (int c = 0; c < image.channel_count(); ++c)
            for (int y = 0; y < 4; ++y)
                for (int x = 0; x < 8; ++x)
                    image.at(c, x, y) = 0.125f * static_cast<float>(c) +
                                        0.0625f * static_cast<float>(x + 8 * y) / 32.0f +
                                        (c == 4 ? offset : 0.0f);
        return image;
    };
    const std::string a = (dir / "a.exr").string(), b = (dir / "b.exr").string();
    octray::write_exr(a, with_aovs(0.0f));
    octray::write_exr(b, with_aovs(0.25f));
    const CompareView view = octray::view::load_compare_view(a, b);
    EXPECT_EQ(view.layers, (std::vector<std::string>{"", "N", "id"}));
    ViewServer server(view, ServerOptions{});
    server.start();
    httplib::Client client("127.0.0.1", server.port());
    client.set_read_timeout(30, 0);
    const auto get = [&](const std::string& path) {
        return client.Get(path + "&token=" + server.token());
    };
    const auto status = get("/api/status?x=0");
    ASSERT_TRUE(status);
    EXPECT_EQ(json::parse(status->body)["layers"], json::array({"", "N", "id"}));

    const Image file = octray::read_image(a);
    const auto normal = get("/api/image.f32?picture=a&layer=N");
    ASSERT_TRUE(normal);
    ASSERT_EQ(normal->status, 200);
    std::vector<float> served(file.pixel_count() * 3);
    ASSERT_EQ(normal->body.size(), served.size() * sizeof(float));
    std::memcpy(served.data(), normal->body.data(), normal->body.size());
    const int nx = file.channel_index("N.X"), id = file.channel_index("id");
    for (int c = 0; c < 3; ++c) EXPECT_EQ(served[c], file.at(nx + c, 0, 0)) << c;
    EXPECT_EQ(served[3 * 13 + 1], file.at(nx + 1, 5, 1));

    const auto gray = get("/api/pixel?picture=b&layer=id&x=3&y=2");
    ASSERT_TRUE(gray);
    ASSERT_EQ(gray->status, 200);
    const json rgb = json::parse(gray->body)["rgb"];
    EXPECT_EQ(rgb[0].get<float>(), file.at(id, 3, 2));
    EXPECT_EQ(rgb[1], rgb[0]);
    EXPECT_EQ(rgb[2], rgb[0]);

    const auto diff = get("/api/pixel?picture=diff&layer=N&x=1&y=1");
    ASSERT_TRUE(diff);
    ASSERT_EQ(diff->status, 200);
    EXPECT_EQ(json::parse(diff->body)["rgb"], json::array({0.0f, 0.25f, 0.0f}));

    const auto unknown = get("/api/image.png?picture=a&layer=albedo");
    ASSERT_TRUE(unknown);
    EXPECT_EQ(unknown->status, 400);
    EXPECT_NE(unknown->body.find("expected one of \"\", \"N\", \"id\""), std::string::npos)
        << unknown->body;
    server.stop();
    server.wait();
    std::filesystem::remove_all(dir);
}

TEST(CompareViewLoad, FailsAsCompareFails) {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("octray_compare_view_load_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string a = (dir / "a.exr").string(), small = (dir / "small.exr").string();
    octray::write_exr(a, gradient(8, 8, 0.0f));
    octray::write_exr(small, gradient(8, 4, 0.0f));
    EXPECT_THROW(octray::view::load_compare_view(a, small), octray::ImageMismatch);
    EXPECT_THROW(octray::view::load_compare_view(a, (dir / "missing.exr").string()),
                 octray::IoError);
    std::filesystem::remove_all(dir);
}

}  // namespace
