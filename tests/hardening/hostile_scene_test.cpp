// Pathological but valid scenes: both renderers must finish, write finite pixels where
// the closed form says so, and agree (max |reference - packet| <= 1e-3, the project's
// threshold; the packet path claims bit-identity, so differing pixels are reported).
// Scenes: no objects, no lights, the camera inside a sphere, a light inside an object,
// coincident spheres, a plane through the eye, radii 1e-6 and 1e6, grazing rays,
// max_depth 0 and 64, mirror inside mirror (ending by depth and by weight).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "render/packet_renderer.h"
#include "render/reference.h"
#include "scene/load.h"
#include "scene_builders.h"

namespace octray {
namespace {

using testing::add_material;
using testing::add_plane;
using testing::add_point_light;
using testing::add_sphere;
using testing::empty_scene;

Material diffuse(Rgb color, float kd = 1.0f) {
    Material m;
    m.color = color;
    m.kd = kd;
    return m;
}

Material mirror(float kr) {
    Material m = diffuse(Rgb(0.0f), 0.0f);
    m.reflect = Rgb(kr);
    return m;
}

Material glass() {
    Material m = diffuse(Rgb(1.0f), 0.0f);
    m.ks = 0.5f;
    m.shininess = 100.0f;
    m.reflect = Rgb(0.1f);
    m.transmit = 0.9f;
    m.ior = 1.5f;
    return m;
}

struct Rendered {
    RenderResult reference;
    RenderResult packet;
};

// Renders with both paths (2 threads, the default tiles), checks finiteness and the
// agreement threshold, and returns both for scene-specific checks.
Rendered render_both(const Scene& scene, const std::string& what) {
    SCOPED_TRACE(what);
    validate_scene(scene);  // every hostile scene here is valid
    RenderOptions options;
    options.threads = 2;
    Rendered r{render_reference(scene, options), render_packet(scene, options)};
    const Image &a = r.reference.image, &b = r.packet.image;
    EXPECT_EQ(a.width(), b.width());
    EXPECT_EQ(a.height(), b.height());
    if (a.pixel_count() != b.pixel_count()) return r;
    double max_abs = 0.0;
    std::size_t differing = 0, non_finite = 0;
    for (std::size_t k = 0; k < a.pixel_count(); ++k) {
        const Rgb pa = rgb_at(a, k), pb = rgb_at(b, k);
        if (!is_finite(pa) || !is_finite(pb)) ++non_finite;
        max_abs = std::max({max_abs, std::fabs(double(pa.r) - pb.r),
                            std::fabs(double(pa.g) - pb.g), std::fabs(double(pa.b) - pb.b)});
        if (!(pa == pb)) ++differing;
    }
    std::printf("  %-34s max |ref - packet| %.3g, %zu of %zu pixels differ, rays %llu\n",
                what.c_str(), max_abs, differing, a.pixel_count(),
                static_cast<unsigned long long>(r.reference.rays.total()));
    EXPECT_EQ(non_finite, 0u) << "NaN or Inf pixels";
    EXPECT_LE(max_abs, 1e-3);
    EXPECT_EQ(r.reference.rays.total(), r.packet.rays.total());
    return r;
}

bool all_pixels(const Image& image, Rgb value) {
    const std::vector<Rgb> pixels = rgb_pixels(image);
    return std::all_of(pixels.begin(), pixels.end(), [&](const Rgb& p) { return p == value; });
}

TEST(HostileScene, NoObjectsShowsOnlyTheBackground) {
    Scene s = empty_scene(40, 30);
    s.background = {BackgroundType::constant, {0.2f, 0.4f, 0.6f}, {}, {}};
    add_point_light(s, {0, 5, 0}, Rgb(1.0f));
    const Rendered r = render_both(s, "no objects");
    EXPECT_TRUE(all_pixels(r.reference.image, {0.2f, 0.4f, 0.6f}));
    EXPECT_EQ(r.reference.rays.total(), 40u * 30u);  // primary rays only
}

TEST(HostileScene, NoLightsLeavesOnlyTheAmbientTerm) {
    Scene s = empty_scene(40, 30);
    s.ambient = Rgb(0.5f);
    s.materials[0].material = diffuse({0.8f, 0.6f, 0.4f}, 0.5f);
    add_sphere(s, {0, 0, 0}, 3.0f);  // fills the view
    const Rendered r = render_both(s, "no lights");
    // ambient * (Cd * kd), the reference's order.
    const Rgb expected = Rgb(0.5f) * (Rgb(0.8f, 0.6f, 0.4f) * 0.5f);
    EXPECT_TRUE(all_pixels(r.reference.image, expected));
    EXPECT_EQ(r.reference.rays.shadow, 0u);
}

TEST(HostileScene, CameraInsideAnOpaqueSphereSeesItsUnlitInside) {
    Scene s = empty_scene(40, 30);
    s.ambient = Rgb(0.1f);
    s.camera.eye = {0, 0, 0};
    s.camera.lookat = {0, 0, -1};
    add_sphere(s, {0, 0, 0}, 2.0f);
    add_point_light(s, {0, 10, 0}, Rgb(1.0f));  // outside: every shadow ray is blocked
    const Rendered r = render_both(s, "camera inside a sphere");
    EXPECT_TRUE(all_pixels(r.reference.image, Rgb(0.1f) * (Rgb(0.8f) * 1.0f)));
    EXPECT_GT(r.reference.rays.shadow, 0u);
}

TEST(HostileScene, LightInsideAClosedSphereLightsNothingOutside) {
    Scene s = empty_scene(40, 30);
    add_sphere(s, {0, 0.5f, 0}, 1.0f);
    add_plane(s, {0, -1, 0}, {0, 1, 0});          // below the sphere, not touching it
    add_point_light(s, {0, 0.5f, 0}, Rgb(1.0f));  // at the sphere's center
    const Rendered r = render_both(s, "light inside an object");
    EXPECT_TRUE(all_pixels(r.reference.image, Rgb(0.0f)));  // no ambient, background black
}

TEST(HostileScene, CoincidentSpheresShowTheFirstListed) {
    Scene s = empty_scene(40, 30);
    s.background = {BackgroundType::constant, Rgb(0.3f), {}, {}};
    const auto red = add_material(s, diffuse({1, 0, 0}));
    const auto blue = add_material(s, diffuse({0, 0, 1}));
    add_sphere(s, {0, 0, 0}, 1.5f, red);
    add_point_light(s, {2, 3, 5}, Rgb(1.0f));
    Scene twice = s;
    twice.objects.push_back(twice.objects.front());
    twice.objects.back().material = blue;
    const Rendered one = render_both(s, "one sphere");
    const Rendered two = render_both(twice, "coincident spheres");
    EXPECT_TRUE(same_pixels(one.reference.image, two.reference.image));
    EXPECT_TRUE(same_pixels(one.packet.image, two.packet.image));
}

TEST(HostileScene, PlaneThroughTheEye) {
    Scene s = empty_scene(40, 30);
    s.background = {BackgroundType::gradient, {}, {1, 1, 1}, {0, 0, 1}};
    s.materials[0].material.checker = Checker{Rgb(0.1f), 0.5f};
    add_plane(s, s.camera.eye, {0, 1, 0});     // horizontal, through the eye
    add_plane(s, s.camera.eye, {1, 0, 0.3f});  // tilted, through the eye
    add_sphere(s, {0, 0, 0}, 1.0f);
    add_point_light(s, {2, 3, 5}, Rgb(1.0f));
    render_both(s, "planes through the eye");
}

TEST(HostileScene, TinyAndHugeRadii) {
    Scene tiny = empty_scene(40, 30);
    tiny.background = {BackgroundType::constant, Rgb(0.25f), {}, {}};
    add_sphere(tiny, {0, 0, 0}, 1e-6f);
    add_point_light(tiny, {2, 3, 5}, Rgb(1.0f));
    const Rendered t = render_both(tiny, "radius 1e-6");
    // Far below a pixel: the center ray may hit it, no other pixel can.
    std::size_t background = 0;
    for (const Rgb& p : rgb_pixels(t.reference.image)) background += p == Rgb(0.25f) ? 1 : 0;
    EXPECT_GE(background, 40u * 30u - 1u);

    Scene huge = empty_scene(40, 30);
    huge.camera.eye = {0, 2, 5};
    add_sphere(huge, {0, -1e6f, 0}, 1e6f);  // a ground the size of a planet
    add_sphere(huge, {0, 1, 0}, 1.0f);
    add_point_light(huge, {2, 30, 5}, Rgb(1.0f));
    render_both(huge, "radius 1e6 ground");
    huge.render.epsilon = 1e-3f;  // ε_s from the 2e6 bounding box would be 346
    render_both(huge, "radius 1e6, epsilon 1e-3");
}

TEST(HostileScene, GrazingRays) {
    Scene s = empty_scene(64, 48);
    s.background = {BackgroundType::gradient, {}, {1, 1, 1}, {0, 0, 1}};
    s.camera.eye = {0, 1e-3f, 5};  // a millimetre above the floor, looking along it
    s.camera.lookat = {0, 1e-3f, 0};
    Material floor = diffuse(Rgb(0.9f));
    floor.checker = Checker{Rgb(0.1f), 0.25f};
    floor.reflect = Rgb(0.5f);
    add_plane(s, {0, 0, 0}, {0, 1, 0}, add_material(s, floor));
    // A sphere whose silhouette the rays of one column graze, and a glass one to bend them.
    add_sphere(s, {0.5f, 1.0f, 0}, 1.0f, add_material(s, mirror(0.9f)));
    add_sphere(s, {-1.5f, 0.5f, 1}, 0.5f, add_material(s, glass()));
    add_point_light(s, {-3, 0.01f, 5}, Rgb(1.0f));  // grazing light too
    render_both(s, "grazing rays");
}

Scene glass_and_mirrors(int max_depth) {
    Scene s = empty_scene(40, 30);
    s.background = {BackgroundType::gradient, {}, {1, 1, 1}, {0.2f, 0.3f, 0.8f}};
    s.render.max_depth = max_depth;
    add_plane(s, {0, -1, 0}, {0, 1, 0}, add_material(s, mirror(0.7f)));
    add_sphere(s, {-1, 0, 0}, 1.0f, add_material(s, mirror(0.95f)));
    add_sphere(s, {1.1f, 0, 0.5f}, 0.8f, add_material(s, glass()));
    add_point_light(s, {3, 5, 4}, Rgb(1.0f));
    return s;
}

TEST(HostileScene, MaxDepthZeroAndSixtyFour) {
    const Rendered zero = render_both(glass_and_mirrors(0), "max_depth 0");
    EXPECT_EQ(zero.reference.rays.reflected, 0u);
    EXPECT_EQ(zero.reference.rays.refracted, 0u);
    const Rendered deep = render_both(glass_and_mirrors(64), "max_depth 64");
    EXPECT_GT(deep.reference.rays.reflected, 0u);
    EXPECT_GT(deep.reference.rays.refracted, 0u);
}

// The camera inside a perfect mirror sphere: every ray bounces until max_depth (64) ends
// it; with kr = 0.5 the weight cut-off (1e-3) ends it after 9 bounces.
TEST(HostileScene, MirrorInsideMirrorEndsByDepthOrByWeight) {
    for (const float kr : {1.0f, 0.5f}) {
        Scene s = empty_scene(16, 12);
        s.render.max_depth = 64;
        s.background = {BackgroundType::constant, Rgb(1.0f), {}, {}};
        s.camera.eye = {0, 0, 0};
        s.camera.lookat = {0, 0, -1};
        s.materials[0].material = mirror(kr);
        add_sphere(s, {0, 0, 0}, 2.0f);
        add_sphere(s, {0.3f, 0.2f, -1.0f}, 0.4f);  // a mirror inside the mirror
        const Rendered r =
            render_both(s, kr == 1.0f ? "mirror in mirror, kr 1" : "mirror in mirror, kr 0.5");
        const std::uint64_t pixels = 16u * 12u;
        if (kr == 1.0f) {
            EXPECT_EQ(r.reference.rays.reflected, pixels * 64u);
            // Cut off at depth 65, each ray sees the background through 64 perfect mirrors.
            EXPECT_TRUE(all_pixels(r.reference.image, Rgb(1.0f)));
        } else {
            EXPECT_EQ(r.reference.rays.reflected, pixels * 9u);  // 0.5^10 < 1e-3
        }
    }
}

// Issue 23: the scene limits on the index of refraction (0.01 ... 100) and on the thin
// lens (radius up to 10 x the focus distance) are where rendering stays finite: scenes at
// the limits render finite pixels on both paths (beyond them NaN or Inf appeared).
TEST(HostileScene, ValuesAtTheRefractionAndLensLimitsRenderFinitely) {
    for (const float ior : {100.0f, 0.01f}) {
        Scene s = glass_and_mirrors(8);
        for (NamedMaterial& m : s.materials)
            if (m.material.transmit > 0.0f) m.material.ior = ior;
        render_both(s, "ior " + std::to_string(ior));
    }
    Scene lens = glass_and_mirrors(5);
    lens.image.spp = 4;
    lens.camera.type = CameraType::thinlens;
    lens.camera.focus_distance = 5.0f;
    lens.camera.aperture = 50.0f;
    render_both(lens, "thinlens aperture 10 x focus distance");
}

}  // namespace
}  // namespace octray
