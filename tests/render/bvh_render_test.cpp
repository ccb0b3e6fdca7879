// Whole images with the sphere BVH (RenderOptions::accel = bvh) against the scalar
// reference (brute force) and the packet path without it (accel = none): the same bits and
// the same ray counts, on built-in scenes and on a scene of mirror and glass spheres over a
// checkered plane seen through every camera, with several samples per pixel, and with the
// eye inside a sphere. Small images: the reference is brute force.

#include <gtest/gtest.h>

#include <random>
#include <string>

#include "render/accel.h"
#include "render/packet_renderer.h"
#include "render/reference.h"
#include "scene/load.h"
#include "tests/render/scene_builders.h"

namespace octray {
namespace {

Scene sized(Scene s, int width = 64, int height = 48) {
    s.image.width = width;
    s.image.height = height;
    return s;
}

void expect_same_images(const Scene& scene, const std::string& what) {
    SCOPED_TRACE(what);
    RenderOptions with_bvh, without;
    with_bvh.accel = Accel::bvh;
    without.accel = Accel::none;
    const RenderResult ref = render_reference(scene, {});
    const RenderResult bvh = render_packet(scene, with_bvh);
    const RenderResult brute = render_packet(scene, without);
    ASSERT_EQ(ref.image.pixel_count(), bvh.image.pixel_count());
    std::size_t differing = 0;
    for (std::size_t k = 0; k < ref.image.pixel_count(); ++k)
        differing += !(rgb_at(ref.image, k) == rgb_at(bvh.image, k));
    EXPECT_EQ(differing, 0u) << "pixels differing from the reference";
    EXPECT_TRUE(same_pixels(bvh.image, brute.image));
    EXPECT_EQ(bvh.rays.primary, ref.rays.primary);
    EXPECT_EQ(bvh.rays.shadow, ref.rays.shadow);
    EXPECT_EQ(bvh.rays.reflected, ref.rays.reflected);
    EXPECT_EQ(bvh.rays.refracted, ref.rays.refracted);
}

// Mirror, glass and diffuse spheres of mixed sizes (some overlapping) over a checkered
// floor: reflected, refracted and shadow rays all go through the tree.
Scene glass_and_mirrors(CameraType camera) {
    Scene s = testing::empty_scene(64, 48);
    s.camera.type = camera;
    s.camera.eye = {0.0f, 2.0f, 6.0f};
    s.camera.lookat = {0.0f, 0.5f, 0.0f};
    s.camera.fov = camera == CameraType::fisheye ? 180.0f : 55.0f;
    s.camera.width = 7.0f;
    s.camera.aperture = 0.05f;
    s.camera.focus_distance = 5.5f;
    s.background = {
        BackgroundType::gradient, Rgb(0.0f), {0.9f, 0.9f, 1.0f}, {0.2f, 0.4f, 0.8f}};
    s.ambient = Rgb(0.05f);
    Material floor;
    floor.checker = Checker{{0.1f, 0.1f, 0.1f}, 0.5f};
    Material mirror;
    mirror.kd = 0.2f, mirror.ks = 0.5f, mirror.shininess = 40.0f, mirror.reflect = Rgb(0.7f);
    Material glass;
    glass.kd = 0.0f, glass.reflect = Rgb(0.1f), glass.transmit = 0.85f, glass.ior = 1.5f;
    testing::add_plane(s, {0, 0, 0}, {0, 1, 0}, testing::add_material(s, floor));
    const std::uint32_t materials[3] = {testing::add_material(s, mirror),
                                        testing::add_material(s, glass), 0};
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), size(0.05f, 0.5f);
    for (int i = 0; i < 150; ++i) {
        const float r = size(rng);
        testing::add_sphere(s, {3 * u(rng), r + 1.5f * (u(rng) + 1), 3 * u(rng)}, r,
                            materials[i % 3]);
    }
    testing::add_point_light(s, {-4, 6, 5}, Rgb(0.7f));
    testing::add_directional_light(s, {1, -1, -0.5f}, Rgb(0.3f));
    return s;
}

TEST(BvhRender, BuiltinScenesMatchTheReference) {
    for (const char* spec : {"whitted", "random:1", "random:64", "random:300", "sphereflake:2"})
        expect_same_images(sized(load_scene(spec)), spec);
}

TEST(BvhRender, EveryCameraMatchesTheReference) {
    expect_same_images(glass_and_mirrors(CameraType::pinhole), "pinhole");
    expect_same_images(glass_and_mirrors(CameraType::orthographic), "orthographic");
    expect_same_images(glass_and_mirrors(CameraType::fisheye), "fisheye");
    Scene s = sized(glass_and_mirrors(CameraType::thinlens), 32, 24);
    s.image.spp = 4;
    expect_same_images(s, "thinlens spp 4");
}

TEST(BvhRender, EyeInsideASphereMatchesTheReference) {
    Scene s = glass_and_mirrors(CameraType::pinhole);
    testing::add_sphere(s, s.camera.eye, 0.3f, 2);  // a glass sphere around the eye
    s.render.max_depth = 8;
    expect_same_images(s, "eye inside glass");
}

// The --accel names, and where `auto` switches to the BVH (render/accel.h).
TEST(Accel, NamesRoundTrip) {
    for (Accel a : {Accel::automatic, Accel::bvh, Accel::none})
        EXPECT_EQ(parse_accel(accel_name(a)), a);
    EXPECT_FALSE(parse_accel("BVH").has_value());
    EXPECT_FALSE(parse_accel("").has_value());
    EXPECT_FALSE(accel_uses_bvh(Accel::none, 1000000));
    EXPECT_TRUE(accel_uses_bvh(Accel::bvh, 1));
    EXPECT_FALSE(accel_uses_bvh(Accel::bvh, 0));
    EXPECT_FALSE(accel_uses_bvh(Accel::automatic, kBvhAutoMinSpheres - 1));
    EXPECT_TRUE(accel_uses_bvh(Accel::automatic, kBvhAutoMinSpheres));
}

TEST(BvhRender, AutoMatchesOnBothSidesOfTheCrossover) {
    for (std::uint32_t n : {kBvhAutoMinSpheres - 1, kBvhAutoMinSpheres}) {
        const Scene s = sized(load_scene("random:" + std::to_string(n)), 40, 30);
        RenderOptions automatic;
        EXPECT_EQ(automatic.accel, Accel::automatic);
        EXPECT_TRUE(
            same_pixels(render_packet(s, automatic).image, render_reference(s, {}).image))
            << n;
    }
}

}  // namespace
}  // namespace octray
