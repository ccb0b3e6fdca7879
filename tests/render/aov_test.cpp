// AOVs (render/aov.h): the list parser, the values on a scene whose answers are known (a
// sphere straight ahead, a plane seen from behind, a checker, a miss), crops, and the EXR
// channels with their pixel types.

#include "render/aov.h"

#include <gtest/gtest.h>
#include <half.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>

#include "output_fixtures.h"
#include "render/image/image_io.h"
#include "render/image/image_read.h"
#include "render/packet_renderer.h"
#include "scene/builtin.h"
#include "scene_builders.h"
#include "tests/image/inflated_file.h"

namespace octray {
namespace {

// Pixel k of an AOV image (render/aov.h), read by channel name.
float aov_depth(const Image& aovs, std::size_t k) {
    return aovs.find_channel("Z")->floats()[k];
}
Vec3 aov_normal(const Image& aovs, std::size_t k) {
    return {aovs.find_channel("N.X")->floats()[k], aovs.find_channel("N.Y")->floats()[k],
            aovs.find_channel("N.Z")->floats()[k]};
}
Rgb aov_albedo(const Image& aovs, std::size_t k) {
    return {aovs.find_channel("albedo.R")->floats()[k],
            aovs.find_channel("albedo.G")->floats()[k],
            aovs.find_channel("albedo.B")->floats()[k]};
}
std::uint32_t aov_id(const Image& aovs, std::size_t k) {
    return aovs.find_channel("id")->uint_value(k);
}

TEST(Aov, ParsesListsAndNamesMistakes) {
    EXPECT_EQ(parse_aov_list("depth"), (AovSet{true, false, false, false}));
    EXPECT_EQ(parse_aov_list("id,albedo"), (AovSet{false, false, true, true}));
    EXPECT_EQ(parse_aov_list("depth,normal,albedo,id"), (AovSet{true, true, true, true}));
    std::string error;
    EXPECT_FALSE(parse_aov_list("depth,colour", &error));
    EXPECT_NE(error.find("unknown AOV 'colour'"), std::string::npos) << error;
    EXPECT_NE(error.find("depth, normal, albedo, id"), std::string::npos) << error;
    EXPECT_FALSE(parse_aov_list("depth,,id", &error));
    EXPECT_NE(error.find("empty item"), std::string::npos) << error;
    EXPECT_FALSE(parse_aov_list("", &error));
    EXPECT_FALSE(parse_aov_list("id,id", &error));
    EXPECT_NE(error.find("'id' is listed twice"), std::string::npos) << error;
    EXPECT_FALSE(parse_aov_list("Depth"));
}

// The eye at (0, 0, 5) looking at the origin, 33x33 pixels, 60 degrees: pixel (16, 16)
// looks straight down -Z. A red unit sphere at the origin (object 0), behind it a plane at
// z = -3 whose normal points away from the eye (object 1), with a checker.
Scene known_scene(int spp = 1) {
    Scene s = testing::empty_scene(33, 33);
    s.image.spp = spp;
    Material red;
    red.color = {0.8f, 0.1f, 0.1f};
    Material floor;
    floor.color = {0.2f, 0.3f, 0.4f};
    floor.checker = Checker{{0.9f, 0.8f, 0.7f}, 0.5f};
    testing::add_sphere(s, {0, 0, 0}, 1.0f, testing::add_material(s, red));
    testing::add_plane(s, {0, 0, -3}, {0, 0, -1}, testing::add_material(s, floor));
    return s;
}

TEST(Aov, KnownValuesOfASphereAPlaneAndAMiss) {
    Scene scene = known_scene();
    const Image a = compute_aovs(scene, {}, AovSet{true, true, true, true});
    ASSERT_EQ(a.data_window, (PixelRect{0, 0, 33, 33}));
    const auto at = [&](int x, int y) { return static_cast<std::size_t>(y) * 33 + x; };
    // Straight ahead: the sphere's front at distance 4, normal -view = +Z, Cd, id 1.
    EXPECT_EQ(aov_depth(a, at(16, 16)), 4.0f);
    EXPECT_EQ(aov_normal(a, at(16, 16)), (Vec3{0, 0, 1}));
    EXPECT_EQ(aov_albedo(a, at(16, 16)), (Rgb{0.8f, 0.1f, 0.1f}));
    EXPECT_EQ(aov_id(a, at(16, 16)), 1u);
    // A corner sees the plane from behind: the normal is flipped towards the eye, the
    // depth is the distance along the ray (8 / cos of the angle off axis), id 2.
    const std::size_t c = at(0, 0);
    EXPECT_EQ(aov_id(a, c), 2u);
    EXPECT_EQ(aov_normal(a, c), (Vec3{0, 0, 1}));
    ReferenceTracer tracer(scene);
    const Ray ray = *tracer.camera_ray(0, 0, 0);
    EXPECT_NEAR(aov_depth(a, c), 8.0f / -ray.direction.z, 1e-5f);
    // The checker's two colors both occur on the plane, and nothing else.
    std::set<std::tuple<float, float, float>> plane_colors;
    for (std::size_t k = 0; k < a.pixel_count(); ++k)
        if (aov_id(a, k) == 2u)
            plane_colors.insert({aov_albedo(a, k).r, aov_albedo(a, k).g, aov_albedo(a, k).b});
    EXPECT_EQ(plane_colors, (std::set<std::tuple<float, float, float>>{{0.2f, 0.3f, 0.4f},
                                                                       {0.9f, 0.8f, 0.7f}}));

    // Without the plane the corner misses: Z = +inf, N = 0, albedo = 0, id = 0.
    scene.objects.pop_back();
    const Image m = compute_aovs(scene, {}, AovSet{true, true, true, true});
    EXPECT_TRUE(std::isinf(aov_depth(m, c)) && aov_depth(m, c) > 0.0f);
    EXPECT_EQ(aov_normal(m, c), (Vec3{0, 0, 0}));
    EXPECT_EQ(aov_albedo(m, c), (Rgb{0, 0, 0}));
    EXPECT_EQ(aov_id(m, c), 0u);
    EXPECT_EQ(aov_id(m, at(16, 16)), 1u);
}

TEST(Aov, OnlyTheAskedAovsAndCropsAreTheFullImagesPixels) {
    const Scene scene = testing::golden_scene("thinlens_spp4", 23, 17);
    const Image full = compute_aovs(scene, {}, AovSet{true, true, true, true});
    RenderOptions options;
    options.crop = PixelRect{4, 3, 15, 9};
    options.threads = 1;
    const Image part = compute_aovs(scene, options, AovSet{true, false, false, true});
    EXPECT_EQ(part.data_window, *options.crop);
    EXPECT_EQ(part.channel_names(), (std::vector<std::string>{"Z", "id"}));
    ASSERT_EQ(part.pixel_count(), 11u * 6u);
    for (int y = 3; y < 9; ++y)
        for (int x = 4; x < 15; ++x) {
            const std::size_t k = static_cast<std::size_t>(y - 3) * 11 + (x - 4);
            const std::size_t f = static_cast<std::size_t>(y) * 23 + x;
            EXPECT_EQ(aov_depth(part, k), aov_depth(full, f));
            EXPECT_EQ(aov_id(part, k), aov_id(full, f));
        }
    options.crop = PixelRect{0, 0, 24, 1};
    EXPECT_THROW(compute_aovs(scene, options, AovSet{true}), std::invalid_argument);
}

// The packet path's first hits (trace_first_hits) give the scalar AOVs bit for bit: with
// and without the kernels' BVH, at 4 spp (sample 0 is jittered), through a thin lens and a
// fisheye (pixels outside its circle have no ray), with a crop and a frame counter.
TEST(Aov, FromThePacketPathsFirstHitsTheSameBits) {
    AovSet all;
    all.depth = all.normal = all.albedo = all.id = true;
    // Channels compare by name, format and bytes: the same bits.
    const auto same = [](const Image& a, const Image& b) {
        return a.data_window == b.data_window && a.channels == b.channels;
    };
    for (const char* spec : {"whitted", "random:300", "sphereflake:2"})
        for (const CameraType camera :
             {CameraType::pinhole, CameraType::thinlens, CameraType::fisheye})
            for (const Accel accel : {Accel::bvh, Accel::none}) {
                Scene scene =
                    make_builtin_scene(std::string(spec) + ",width=40,height=24,spp=4");
                scene.camera.type = camera;
                scene.camera.fov = camera == CameraType::fisheye ? 200.0f : 50.0f;
                scene.camera.aperture = 0.1f;
                scene.camera.focus_distance = 8.0f;
                RenderOptions options;
                options.accel = accel;
                options.frame = 3;
                options.crop = PixelRect{3, 2, 37, 21};
                const PreparedScene prepared(scene, accel);
                const Image scalar = compute_aovs(scene, options, all);
                const FirstHits hits = trace_first_hits(prepared, options);
                const Image packet = compute_aovs(scene, options, all, hits);
                // A miss (or no ray) is object -1 at t = +inf; a hit is in front.
                std::size_t misses = 0;
                for (std::size_t k = 0; k < hits.t.size(); ++k) {
                    if (hits.object[k] < 0) {
                        ++misses;
                        EXPECT_EQ(hits.t[k], std::numeric_limits<float>::infinity()) << k;
                    } else {
                        EXPECT_GT(hits.t[k], 0.0f) << k;
                    }
                }
                if (camera == CameraType::fisheye) {
                    EXPECT_GT(misses, 0u);
                }
                EXPECT_TRUE(same(scalar, packet))
                    << spec << ", camera " << static_cast<int>(camera) << ", accel "
                    << accel_name(accel);
                if (camera == CameraType::fisheye) {
                    // The crop's corner pixel (3, 2) lies outside the image circle: no ray,
                    // a miss's values, written though nothing was traced.
                    for (const Image* a : {&scalar, &packet}) {
                        EXPECT_TRUE(std::isinf(aov_depth(*a, 0)) && aov_depth(*a, 0) > 0.0f);
                        EXPECT_EQ(aov_normal(*a, 0), (Vec3{0, 0, 0}));
                        EXPECT_EQ(aov_albedo(*a, 0), (Rgb{0, 0, 0}));
                        EXPECT_EQ(aov_id(*a, 0), 0u);
                    }
                }
            }
    // Hits of another rectangle are refused.
    const Scene scene = make_builtin_scene("whitted,width=8,height=8");
    RenderOptions crop;
    crop.crop = PixelRect{0, 0, 4, 4};
    EXPECT_THROW(compute_aovs(scene, crop, all, trace_first_hits(PreparedScene(scene), {})),
                 std::invalid_argument);
}

// trace_first_hits sizes its arrays without filling them: every tile writes its pixels'
// misses first. A fisheye's corners have no camera ray, so only that write gives them
// object -1 and t = +inf (a first allocation this large is fresh, zeroed memory).
TEST(Aov, FirstHitsOfPixelsWithoutARayAreMisses) {
    Scene scene = make_builtin_scene("whitted,width=256,height=256");
    scene.camera.type = CameraType::fisheye;
    scene.camera.fov = 180.0f;
    const FirstHits hits = trace_first_hits(PreparedScene(scene), {});
    ASSERT_EQ(hits.t.size(), 256u * 256u);
    for (const std::size_t corner : {std::size_t{0}, std::size_t{255}, std::size_t{255 * 256},
                                     std::size_t{256 * 256 - 1}}) {
        EXPECT_EQ(hits.object[corner], -1) << corner;
        EXPECT_EQ(hits.t[corner], std::numeric_limits<float>::infinity()) << corner;
    }
    EXPECT_GE(hits.object[128 * 256 + 128], 0);  // the centre sees the scene
}

TEST(Aov, ChannelsInTheExrHaveTheirPixelTypes) {
    const Scene scene = known_scene();
    const std::filesystem::path dir = testing::test_dir();
    for (bool float32 : {false, true}) {
        SCOPED_TRACE(float32 ? "float" : "half");
        RenderOptions options;
        options.crop = PixelRect{10, 12, 20, 21};
        const RenderResult result = render_reference(scene, options);
        const Image aovs = compute_aovs(scene, options, AovSet{true, true, true, true});
        Image exr = make_exr_image(result.image, ExrWriteOptions{float32, ExrCompression::zip});
        const PixelFormat color = float32 ? PixelFormat::float32 : PixelFormat::half;
        append_aov_channels(exr, aovs, color);
        const std::string path = (dir / "aovs.exr").string();
        write_exr(path, exr);

        const Image back = read_exr_image(path);
        EXPECT_EQ(back.data_window, *options.crop);
        EXPECT_EQ(back.display_window, (PixelRect{0, 0, 33, 33}));
        ASSERT_EQ(back.channels.size(), 11u);
        const auto type_of = [&](const char* name) {
            const ImageChannel* c = back.find_channel(name);
            EXPECT_NE(c, nullptr) << name;
            return c != nullptr ? c->format : PixelFormat::uint32;
        };
        EXPECT_EQ(type_of("R"), color);
        EXPECT_EQ(type_of("N.X"), color);
        EXPECT_EQ(type_of("albedo.G"), color);
        EXPECT_EQ(type_of("Z"), PixelFormat::float32);
        EXPECT_EQ(type_of("id"), PixelFormat::uint32);
        // Pixel (16, 16) of the full image is (6, 4) of the crop.
        const std::size_t k = 4 * 10 + 6;
        EXPECT_EQ(back.find_channel("Z")->value(k), 4.0f);
        EXPECT_EQ(back.find_channel("id")->uint_value(k), 1u);
        EXPECT_EQ(back.find_channel("N.Z")->value(k), 1.0f);
        EXPECT_EQ(back.find_channel("albedo.R")->value(k), float32 ? 0.8f : float(half(0.8f)));
        for (std::size_t p = 0; p < exr.data_window.pixel_count(); ++p)
            EXPECT_EQ(back.find_channel("Z")->value(p), aov_depth(aovs, p));
    }
    const RenderResult whole = render_reference(scene, {});
    Image wrong = make_exr_image(whole.image, ExrWriteOptions{});
    RenderOptions crop;
    crop.crop = PixelRect{0, 0, 5, 5};
    EXPECT_THROW(
        append_aov_channels(wrong, compute_aovs(scene, crop, AovSet{true}), PixelFormat::half),
        std::invalid_argument);
}

// The frame loop writes a frame's EXR from its planes and its AOVs as they are (ExrSources:
// each line converted as its chunk is packed): the file of the image make_exr_image and
// append_aov_channels make, byte for byte, in every compression, half and float, over a
// crop; the sources refuse AOVs of another window as append_aov_channels does.
TEST(Aov, AnExrWrittenFromItsSourcesIsTheFileOfItsImage) {
    const Scene scene = known_scene();
    const std::filesystem::path dir = testing::test_dir();
    RenderOptions options;
    options.crop = PixelRect{3, 5, 30, 26};
    const RenderResult result = render_reference(scene, options);
    const Image aovs = compute_aovs(scene, options, AovSet{true, true, true, true});
    ExrAttributes attributes;
    attributes.strings.emplace_back("octray.test", "sources");
    for (const bool float32 : {false, true})
        for (const ExrCompression c :
             {ExrCompression::none, ExrCompression::rle, ExrCompression::zips,
              ExrCompression::zip, ExrCompression::piz, ExrCompression::pxr24,
              ExrCompression::b44, ExrCompression::dwaa}) {
            SCOPED_TRACE(std::string(to_string(c)) + (float32 ? " float" : " half"));
            const ExrWriteOptions exr{float32, c};
            const PixelFormat color = float32 ? PixelFormat::float32 : PixelFormat::half;
            Image image = make_exr_image(result.image, exr, attributes);
            append_aov_channels(image, aovs, color);
            write_exr((dir / "image.exr").string(), image);
            ExrSources sources = exr_sources(result.image, exr, attributes);
            append_aov_sources(sources, aovs, color);
            write_exr((dir / "sources.exr").string(), sources);
            EXPECT_GT(std::filesystem::file_size(dir / "sources.exr"), 1000u);
            // Byte for byte but for the compressed data, which must inflate to the same
            // bytes (tests/image/inflated_file.h says why).
            EXPECT_EQ(test::exr_inflated(dir / "sources.exr"),
                      test::exr_inflated(dir / "image.exr"));
        }
    const RenderResult whole = render_reference(scene, {});
    ExrSources wrong = exr_sources(whole.image, ExrWriteOptions{});
    EXPECT_THROW(append_aov_sources(wrong, aovs, PixelFormat::half), std::invalid_argument);
    // A source whose samples are not the data window's: an IoError naming the file.
    ExrSources short_one = exr_sources(result.image, ExrWriteOptions{});
    short_one.data_window.x1 += 1;
    EXPECT_THROW(write_exr((dir / "short.exr").string(), short_one), IoError);
    EXPECT_FALSE(std::filesystem::exists(dir / "short.exr"));
}

}  // namespace
}  // namespace octray
