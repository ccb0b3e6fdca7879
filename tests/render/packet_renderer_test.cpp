// The packet renderer against the scalar reference, image by image: every built-in scene
// and feature scenes for each camera, checker, refraction with TIR, directional light,
// falloff, gradient background and spp 4 / 16. Thresholds of the issue: max |a - b| <=
// 1e-3 and at least 99.9% of pixels within 1e-4, and beyond them bit-identity: the packet
// path performs the reference's IEEE operations in the reference's order, resolving each
// tile's ray tree last generation first (render/README.md, "The packet path").
// Also: equal ray counts, no NaN, every ISA gives the same bits, and any thread count or
// tile size gives the same bits.

#include "render/packet_renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "kernels/dispatch.h"
#include "render/batch/memory_estimate.h"
#include "render/reference.h"
#include "scene/load.h"
#include "scene_builders.h"

namespace octray {
namespace {

using testing::add_directional_light;
using testing::add_material;
using testing::add_plane;
using testing::add_point_light;
using testing::add_sphere;
using testing::empty_scene;

struct Agreement {
    double max_abs = 0.0;
    std::size_t over_1e4 = 0;   // pixels with any channel off by more than 1e-4
    std::size_t differing = 0;  // pixels not bit-identical
    std::size_t pixels = 0;
    bool finite = true;
};

Agreement agreement(const Image& a, const Image& b) {
    Agreement g;
    g.pixels = a.pixel_count();
    for (std::size_t k = 0; k < a.pixel_count(); ++k) {
        const Rgb pa = rgb_at(a, k), pb = rgb_at(b, k);
        g.finite = g.finite && is_finite(pa) && is_finite(pb);
        const double e =
            std::max({std::fabs(double(pa.r) - pb.r), std::fabs(double(pa.g) - pb.g),
                      std::fabs(double(pa.b) - pb.b)});
        g.max_abs = std::max(g.max_abs, e);
        if (e > 1e-4) ++g.over_1e4;
        if (!(pa == pb)) ++g.differing;
    }
    return g;
}

// A scene at test size: small, so the suite stays fast under sanitizers on 2 cores.
Scene sized(Scene s, int width = 96, int height = 64) {
    s.image.width = width;
    s.image.height = height;
    return s;
}

void expect_agrees_with_reference(const Scene& scene, const std::string& what) {
    SCOPED_TRACE(what);
    const RenderResult ref = render_reference(scene, {});
    const RenderResult simd = render_packet(scene, {});
    ASSERT_EQ(ref.image.width(), simd.image.width());
    ASSERT_EQ(ref.image.height(), simd.image.height());
    const Agreement g = agreement(ref.image, simd.image);
    // For the record (render/README.md quotes these): how far apart, and how many pixels
    // differ at all.
    std::printf("  %-28s max |diff| %.3g, %zu of %zu pixels not bit-identical, %zu over 1e-4\n",
                what.c_str(), g.max_abs, g.differing, g.pixels, g.over_1e4);
    EXPECT_TRUE(g.finite) << "NaN or Inf in an image";
    EXPECT_LE(g.max_abs, 1e-3);
    EXPECT_GE(1.0 - double(g.over_1e4) / double(g.pixels), 0.999);
    // Same rays, kind by kind.
    EXPECT_EQ(ref.rays.primary, simd.rays.primary);
    EXPECT_EQ(ref.rays.shadow, simd.rays.shadow);
    EXPECT_EQ(ref.rays.reflected, simd.rays.reflected);
    EXPECT_EQ(ref.rays.refracted, simd.rays.refracted);
    // Stronger than the thresholds: the packet path performs the reference's operations
    // in the reference's order (render/README.md), so the images are the same bits.
    EXPECT_EQ(g.differing, 0u) << "max abs " << g.max_abs;
}

Material diffuse(Rgb color, float kd = 1.0f) {
    Material m;
    m.color = color;
    m.kd = kd;
    return m;
}

// Spheres of every kind over a checkered floor, two kinds of light, a gradient sky.
Scene feature_scene(CameraType camera) {
    Scene s = empty_scene(96, 64);
    s.camera.type = camera;
    s.camera.eye = {0.0f, 1.5f, 5.0f};
    s.camera.lookat = {0.0f, 0.6f, 0.0f};
    s.camera.fov = camera == CameraType::fisheye ? 200.0f : 55.0f;
    s.camera.width = 6.0f;
    s.camera.aperture = 0.08f;
    s.camera.focus_distance = 4.5f;
    s.background = {
        BackgroundType::gradient, Rgb(0.0f), {0.9f, 0.9f, 1.0f}, {0.2f, 0.4f, 0.8f}};
    s.ambient = Rgb(0.05f);

    Material floor = diffuse({0.9f, 0.9f, 0.9f}, 0.9f);
    floor.checker = Checker{{0.1f, 0.1f, 0.1f}, 0.7f};
    Material mirror = diffuse(Rgb(0.9f), 0.1f);
    mirror.ks = 0.5f;
    mirror.shininess = 64.0f;
    mirror.reflect = {0.8f, 0.7f, 0.6f};
    Material glass = diffuse(Rgb(1.0f), 0.0f);
    glass.ks = 0.5f;
    glass.shininess = 128.0f;
    glass.reflect = Rgb(0.1f);
    glass.transmit = 0.9f;
    glass.ior = 1.5f;
    Material shiny = diffuse({0.2f, 0.5f, 0.9f}, 0.8f);
    shiny.ks = 0.4f;
    shiny.shininess = 20.0f;

    add_plane(s, {0, 0, 0}, {0, 1, 0}, add_material(s, floor));
    add_sphere(s, {-1.2f, 0.8f, -0.5f}, 0.8f, add_material(s, mirror));
    add_sphere(s, {0.5f, 0.7f, 0.6f}, 0.7f, add_material(s, glass));
    add_sphere(s, {1.8f, 0.5f, -0.8f}, 0.5f, add_material(s, shiny));
    add_plane(s, {0, 0, -4}, {0, 0.2f, 1}, add_material(s, diffuse({0.6f, 0.8f, 0.6f})));
    add_point_light(s, {-4, 6, 5}, Rgb(0.7f));
    add_directional_light(s, {1, -1, -0.5f}, Rgb(0.3f));
    return s;
}

TEST(PacketRenderer, BuiltinScenesAgreeWithReference) {
    for (const char* spec : {"whitted", "random:64", "random:1", "sphereflake:1"})
        expect_agrees_with_reference(sized(load_scene(spec)), spec);
}

TEST(PacketRenderer, EveryCameraAgreesWithReference) {
    expect_agrees_with_reference(feature_scene(CameraType::pinhole), "pinhole");
    expect_agrees_with_reference(feature_scene(CameraType::orthographic), "orthographic");
    expect_agrees_with_reference(feature_scene(CameraType::thinlens), "thinlens");
    expect_agrees_with_reference(feature_scene(CameraType::fisheye), "fisheye");
}

TEST(PacketRenderer, SamplesPerPixelAgreeWithReference) {
    for (int spp : {4, 16}) {
        Scene s = sized(feature_scene(CameraType::thinlens), 48, 32);
        s.image.spp = spp;
        expect_agrees_with_reference(s, "thinlens spp " + std::to_string(spp));
        s.camera.type = CameraType::pinhole;
        s.image.spp = spp + 1;  // not a square: uniform jitter
        expect_agrees_with_reference(s, "pinhole spp " + std::to_string(spp + 1));
    }
}

// Diffuse and Phong only (no secondary rays): the paths must agree to the bit.
TEST(PacketRenderer, DirectLightingIsBitIdentical) {
    Scene s = empty_scene(80, 60);
    s.ambient = Rgb(0.1f);
    Material floor = diffuse({0.8f, 0.7f, 0.6f});
    floor.checker = Checker{{0.2f, 0.3f, 0.4f}, 0.5f};
    add_plane(s, {0, -1, 0}, {0, 1, 0.1f}, add_material(s, floor));
    Material phong = diffuse({0.3f, 0.6f, 0.9f}, 0.7f);
    phong.ks = 0.6f;
    phong.shininess = 50.0f;
    add_sphere(s, {0, 0, 0}, 1.0f, add_material(s, phong));
    add_sphere(s, {1.5f, 0.5f, -1}, 0.6f);
    add_point_light(s, {3, 4, 5}, {20.0f, 18.0f, 15.0f}, /*inverse_square=*/true);
    add_point_light(s, {-3, 2, 2}, Rgb(0.4f));
    add_directional_light(s, {-1, -2, -1}, Rgb(0.25f));
    const RenderResult ref = render_reference(s, {});
    const RenderResult simd = render_packet(s, {});
    EXPECT_EQ(ref.rays.reflected + ref.rays.refracted, 0u);
    EXPECT_TRUE(same_pixels(ref.image, simd.image));
    EXPECT_EQ(ref.rays.shadow, simd.rays.shadow);
}

// Refraction with total internal reflection: a glass sphere of high index seen from
// inside-out paths, and max_depth 0 (primary rays only, every secondary ray cut off).
TEST(PacketRenderer, RefractionTirAndDepthCutoffsAgree) {
    Scene s = feature_scene(CameraType::pinhole);
    s.materials[2].material.ior = 2.4f;  // the glass: TIR inside the sphere
    s.render.max_depth = 8;
    expect_agrees_with_reference(s, "ior 2.4, depth 8");
    s.render.max_depth = 0;
    expect_agrees_with_reference(s, "depth 0");
    s.render.max_depth = 1;
    expect_agrees_with_reference(s, "depth 1");
}

// Rays starting inside a sphere (the eye in the glass ball), and a constant background.
TEST(PacketRenderer, EyeInsideSphereAgrees) {
    Scene s = feature_scene(CameraType::pinhole);
    s.camera.eye = {0.5f, 0.7f, 0.6f};  // the glass sphere's center
    s.camera.lookat = {0.0f, 0.6f, -3.0f};
    s.background = {BackgroundType::constant, {0.3f, 0.2f, 0.1f}, {}, {}};
    expect_agrees_with_reference(s, "eye inside the glass sphere");
}

TEST(PacketRenderer, SceneWithoutObjectsOrLights) {
    Scene s = empty_scene(20, 10);
    s.background = {BackgroundType::gradient, Rgb(0.0f), {1, 0, 0}, {0, 0, 1}};
    expect_agrees_with_reference(s, "empty");
    add_sphere(s, {0, 0, 0}, 1.0f);
    expect_agrees_with_reference(s, "no lights");
}

// Every ISA this CPU runs performs the same IEEE operations: the same bits.
TEST(PacketRenderer, EveryIsaGivesTheSameImage) {
    const Scene s = sized(load_scene("whitted"), 64, 48);
    const RenderResult first = render_packet(s, {}, supported_isas().front());
    for (Isa isa : supported_isas()) {
        SCOPED_TRACE(isa_name(isa));
        const RenderResult r = render_packet(s, {}, isa);
        EXPECT_TRUE(same_pixels(r.image, first.image));
        EXPECT_EQ(r.rays.total(), first.rays.total());
    }
}

TEST(PacketRenderer, BitIdenticalForAnyThreadCountAndTileSize) {
    Scene s = feature_scene(CameraType::pinhole);
    s.image.spp = 4;
    RenderOptions base;
    base.threads = 1;
    const RenderResult one = render_packet(s, base);
    for (int threads : {1, 2})
        for (auto [tw, th] :
             {std::pair{16, 16}, {5, 3}, {96, 1}, {1, 1}, {7, 64}, {200, 200}}) {
            RenderOptions o;
            o.threads = threads;
            o.tile_width = tw;
            o.tile_height = th;
            SCOPED_TRACE(std::to_string(threads) + " threads, tile " + std::to_string(tw) +
                         "x" + std::to_string(th));
            const RenderResult r = render_packet(s, o);
            EXPECT_TRUE(same_pixels(r.image, one.image));
            EXPECT_EQ(r.rays.total(), one.rays.total());
        }
}

// Chunks of a generation (RenderOptions::ray_chunk) change no pixel and no ray count:
// each ray is traced alone and each pixel adds its samples in order.
TEST(PacketRenderer, RayChunksChangeNoPixel) {
    for (CameraType camera : {CameraType::pinhole, CameraType::thinlens}) {
        Scene s = feature_scene(camera);
        s.image.spp = 4;
        s.render.max_depth = 6;
        const RenderResult whole = render_packet(s, {});
        for (std::uint32_t chunk : {1u, 16u, 40u, 100u, 4096u}) {
            SCOPED_TRACE("ray_chunk " + std::to_string(chunk));
            RenderOptions o;
            o.ray_chunk = chunk;
            const RenderResult r = render_packet(s, o);
            EXPECT_TRUE(same_pixels(r.image, whole.image));
            EXPECT_EQ(r.rays.shadow, whole.rays.shadow);
            EXPECT_EQ(r.rays.reflected, whole.rays.reflected);
            EXPECT_EQ(r.rays.refracted, whole.rays.refracted);
        }
    }
}

// The worst case for a breadth-first tile: every bounce spawns a mirror and a refracted
// ray that the weight cut-off never stops (reflect = transmit = 1), depth 8, the eye
// inside nested glass shells. A generation then has up to 2^8 times the tile's samples;
// in chunks, a thread's scratch stays within render/batch/memory_estimate.h's per-thread
// estimate (which assumes one chunk per generation), and the image is still the reference's.
TEST(PacketRenderer, MirrorAndGlassEverywhereStaysWithinBoundedMemory) {
    Scene s = empty_scene(16, 16);
    s.image.spp = 8;
    s.render.max_depth = 8;
    s.camera.eye = {0.0f, 0.0f, 0.0f};
    s.camera.lookat = {0.0f, 0.0f, -1.0f};
    s.camera.fov = 90.0f;
    s.ambient = Rgb(0.1f);
    Material glass = diffuse(Rgb(1.0f), 0.2f);
    glass.reflect = Rgb(1.0f);
    glass.transmit = 1.0f;
    glass.ior = 1.1f;
    const std::uint32_t m = add_material(s, glass);
    for (int k = 1; k <= 6; ++k) add_sphere(s, {0, 0, 0}, float(k), m);
    add_sphere(s, {0.3f, 0.2f, -0.5f}, 0.2f, m);
    add_point_light(s, {0.5f, 0.5f, 0.5f}, Rgb(1.0f));

    // A fresh thread with threads = 1 renders every tile itself, with a scratch of its own.
    RenderResult chunked, reference;
    std::thread([&] {
        RenderOptions o;
        o.threads = 1;
        chunked = render_packet(s, o);
    }).join();
    reference = render_reference(s, {});
    const std::uint64_t samples = 16 * 16 * 8;
    const std::uint64_t secondary = chunked.rays.reflected + chunked.rays.refracted;
    std::printf("  %llu secondary rays for %llu samples, scratch %llu bytes\n",
                static_cast<unsigned long long>(secondary),
                static_cast<unsigned long long>(samples),
                static_cast<unsigned long long>(chunked.scratch_bytes));
    // Breadth first, the deepest generations alone would hold many chunks of rays.
    EXPECT_GT(secondary, 16 * std::uint64_t{kDefaultRayChunk});
    EXPECT_TRUE(same_pixels(chunked.image, reference.image));
    EXPECT_EQ(chunked.rays.reflected, reference.rays.reflected);
    EXPECT_EQ(chunked.rays.refracted, reference.rays.refracted);

    batch::RenderMemoryParams params;
    params.threads = 1;
    const batch::RenderMemoryEstimate estimate = batch::estimate_render_memory(s, params);
    EXPECT_GT(chunked.scratch_bytes, 0u);
    EXPECT_LE(chunked.scratch_bytes, estimate.per_thread);
    // ... and the estimate itself is bounded: a chunk per generation, far below the
    // secondary rays' 56 bytes each.
    EXPECT_LT(estimate.per_thread, secondary * 56 / 4);
}

TEST(PacketRenderer, ForcingAnIsaTheCpuLacksThrows) {
    for (Isa isa : compiled_isas()) {
        if (!isa_supported(isa)) {
            EXPECT_THROW(render_packet(empty_scene(4, 4), {}, isa), std::runtime_error);
        }
    }
    EXPECT_NO_THROW(render_packet(empty_scene(4, 4), {}, Isa::sse2));
}

}  // namespace
}  // namespace octray
