// The scalar reference against closed forms and the traps of "The Ray Tracing Algorithm"
// lecture notes: plane denominators and negative t, spheres from inside / behind /
// tangent, upside-down images, pixel centers, false shadows, freckles, reflection,
// refraction and total internal reflection, a light inside a closed sphere.

#include "render/reference.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "scene_builders.h"

namespace octray {
namespace {

using testing::add_directional_light;
using testing::add_material;
using testing::add_plane;
using testing::add_point_light;
using testing::add_sphere;
using testing::empty_scene;

void expect_rgb_near(Rgb a, Rgb b, float tol) {
    EXPECT_NEAR(a.r, b.r, tol);
    EXPECT_NEAR(a.g, b.g, tol);
    EXPECT_NEAR(a.b, b.b, tol);
}

Material diffuse(Rgb color, float kd = 1.0f) {
    Material m;
    m.color = color;
    m.kd = kd;
    return m;
}

// ---- Ray-plane -------------------------------------------------------------------------

TEST(ReferencePlane, HitInFrontMissBehindAndParallel) {
    Scene s = empty_scene();
    add_plane(s, {0, 0, 0}, {0, 1, 0});
    const ReferenceTracer tr(s);
    // In front: straight down from y = 2.
    auto hit = tr.intersect({{0, 2, 0}, {0, -1, 0}, 0.0f, kInfinity});
    ASSERT_TRUE(hit);
    EXPECT_FLOAT_EQ(hit->t, 2.0f);
    // Negative t: the plane is behind the ray.
    EXPECT_FALSE(tr.intersect({{0, 2, 0}, {0, 1, 0}, 0.0f, kInfinity}));
    // Tiny denominator: a ray parallel to the plane (|V.N| < 1e-12) misses.
    EXPECT_FALSE(tr.intersect({{0, 2, 0}, {1, 1e-13f, 0}, 0.0f, kInfinity}));
    // Exactly in the plane and parallel: no division by zero, a miss.
    EXPECT_FALSE(tr.intersect({{0, 0, 0}, {1, 0, 0}, 0.0f, kInfinity}));
    // A hit beyond t_max is not live.
    EXPECT_FALSE(tr.intersect({{0, 2, 0}, {0, -1, 0}, 0.0f, 1.5f}));
}

// ---- Ray-sphere ------------------------------------------------------------------------

TEST(ReferenceSphere, FromOutsideInsideBehindAndTangent) {
    Scene s = empty_scene();
    add_sphere(s, {0, 0, 0}, 1.0f);
    const ReferenceTracer tr(s);
    auto outside = tr.intersect({{0, 0, 5}, {0, 0, -1}, 0.0f, kInfinity});
    ASSERT_TRUE(outside);
    EXPECT_FLOAT_EQ(outside->t, 4.0f);  // the nearer root
    EXPECT_EQ(outside->normal, (Vec3{0, 0, 1}));

    // From inside the near root is negative: the far root counts.
    auto inside = tr.intersect({{0, 0, 0.5f}, {0, 0, -1}, 0.0f, kInfinity});
    ASSERT_TRUE(inside);
    EXPECT_FLOAT_EQ(inside->t, 1.5f);
    EXPECT_EQ(inside->normal, (Vec3{0, 0, -1}));  // geometric normal points outwards

    // From behind: both roots negative.
    EXPECT_FALSE(tr.intersect({{0, 0, 5}, {0, 0, 1}, 0.0f, kInfinity}));

    // Tangent: discriminant exactly 0 is a (double) root and hits.
    auto tangent = tr.intersect({{1, 0, -5}, {0, 0, 1}, 0.0f, kInfinity});
    ASSERT_TRUE(tangent);
    EXPECT_FLOAT_EQ(tangent->t, 5.0f);
    // Just outside the tangent: a miss.
    EXPECT_FALSE(tr.intersect({{1.0001f, 0, -5}, {0, 0, 1}, 0.0f, kInfinity}));
}

TEST(ReferenceSphere, UnnormalisedDirectionsGiveTheSamePoint) {
    Scene s = empty_scene();
    add_sphere(s, {0, 0, 0}, 1.0f);
    const ReferenceTracer tr(s);
    auto hit = tr.intersect({{0, 0, 5}, {0, 0, -4}, 0.0f, kInfinity});
    ASSERT_TRUE(hit);
    EXPECT_FLOAT_EQ(hit->t, 1.0f);
    EXPECT_EQ(hit->point, (Vec3{0, 0, 1}));
}

TEST(ReferenceIntersect, TiesGoToTheObjectListedFirst) {
    Scene s = empty_scene();
    add_sphere(s, {0, 0, 0}, 1.0f);
    add_sphere(s, {0, 0, 0}, 1.0f);
    const ReferenceTracer tr(s);
    auto hit = tr.intersect({{0, 0, 5}, {0, 0, -1}, 0.0f, kInfinity});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->object, 0u);

    Scene p = empty_scene();
    add_plane(p, {0, 0, 1}, {0, 0, 1});  // touches the sphere's front at z = 1
    add_sphere(p, {0, 0, 0}, 1.0f);
    auto tie = ReferenceTracer(p).intersect({{0, 0, 5}, {0, 0, -1}, 0.0f, kInfinity});
    ASSERT_TRUE(tie);
    EXPECT_EQ(tie->object, 0u);
}

// ---- Cameras ---------------------------------------------------------------------------

TEST(ReferenceCamera, PixelCentersAndNonSquareImages) {
    Scene s = empty_scene(200, 100);
    s.camera.fov = 90;  // tan(45) = 1: the film spans x in [-1, 1] at unit distance
    const ReferenceTracer tr(s);
    // Pixel (0, 0) samples its center: x = 2 * 0.5 / 200 - 1, y = 1 - 2 * 0.5 / 100.
    const Ray r = *tr.camera_ray(0, 0, 0);
    const float x = -1.0f + 1.0f / 200.0f, y = (1.0f - 1.0f / 100.0f) * 0.5f;  // v = 1/aspect
    const Vec3 expected = normalize(Vec3{x, y, -1});
    EXPECT_NEAR(r.direction.x, expected.x, 1e-6f);
    EXPECT_NEAR(r.direction.y, expected.y, 1e-6f);
    EXPECT_NEAR(r.direction.z, expected.z, 1e-6f);
    EXPECT_EQ(r.origin, s.camera.eye);
    EXPECT_EQ(r.t_min, tr.epsilon());  // primary rays live on (eps, inf)
}

TEST(ReferenceCamera, RowZeroIsTheTopOfTheImage) {
    Scene s = empty_scene(32, 32);
    add_sphere(s, {0, 2, 0}, 1.0f);  // above the view axis
    add_point_light(s, {0, 0, 10}, Rgb(1.0f));
    const Image img = render_reference(s).image;
    EXPECT_GT(rgb_at(img, 16, 6).r, 0.0f);   // near the top: the sphere
    EXPECT_EQ(rgb_at(img, 16, 26).r, 0.0f);  // near the bottom: black background
}

TEST(ReferenceCamera, LeftIsLeft) {
    Scene s = empty_scene(32, 32);
    add_sphere(s, {-2, 0, 0}, 1.0f);
    add_point_light(s, {0, 0, 10}, Rgb(1.0f));
    const Image img = render_reference(s).image;
    EXPECT_GT(rgb_at(img, 6, 16).r, 0.0f);
    EXPECT_EQ(rgb_at(img, 26, 16).r, 0.0f);
}

TEST(ReferenceCamera, OrthographicRaysAreParallelAndSpanTheFilmWidth) {
    Scene s = empty_scene(4, 2);
    s.camera.type = CameraType::orthographic;
    s.camera.width = 8.0f;
    const ReferenceTracer tr(s);
    const Ray a = *tr.camera_ray(0, 0, 0), b = *tr.camera_ray(3, 1, 0);
    EXPECT_EQ(a.direction, (Vec3{0, 0, -1}));
    EXPECT_EQ(b.direction, (Vec3{0, 0, -1}));
    // x = -0.75 -> -3; y = 0.5 -> 0.5 * (8 / 2 / aspect 2) = 1.
    EXPECT_NEAR(a.origin.x, -3.0f, 1e-6f);
    EXPECT_NEAR(a.origin.y, 1.0f, 1e-6f);
    EXPECT_NEAR(b.origin.x, 3.0f, 1e-6f);
    EXPECT_NEAR(b.origin.y, -1.0f, 1e-6f);
}

TEST(ReferenceCamera, ThinLensWithoutApertureIsThePinhole) {
    Scene s = empty_scene(9, 7);
    s.image.spp = 4;
    Scene lens = s;
    lens.camera.type = CameraType::thinlens;
    lens.camera.aperture = 0.0f;
    lens.camera.focus_distance = 3.0f;
    const ReferenceTracer a(s), b(lens);
    for (int j = 0; j < 7; ++j)
        for (int i = 0; i < 9; ++i) {
            const Ray p = *a.camera_ray(i, j, 1), l = *b.camera_ray(i, j, 1);
            EXPECT_NEAR(p.direction.x, l.direction.x, 1e-6f);
            EXPECT_NEAR(p.direction.y, l.direction.y, 1e-6f);
        }
}

TEST(ReferenceCamera, ThinLensRaysMeetOnTheFocalPlane) {
    Scene s = empty_scene(9, 7);
    s.image.spp = 16;
    s.camera.type = CameraType::thinlens;
    s.camera.aperture = 0.5f;
    s.camera.focus_distance = 4.0f;
    Scene pin = s;
    pin.camera.type = CameraType::pinhole;
    const ReferenceTracer tr(s), tp(pin);
    // Each lens sample passes through its pinhole ray's point on the focal plane z = 1
    // and starts on the lens disk; different samples start at different lens points.
    for (std::uint32_t k = 0; k < 16; ++k) {
        const Ray r = *tr.camera_ray(4, 3, k), p = *tp.camera_ray(4, 3, k);
        const Vec3 focus = p.at(4.0f / -p.direction.z);
        const Vec3 q = r.at((1.0f - r.origin.z) / r.direction.z);
        EXPECT_NEAR(q.x, focus.x, 1e-5f);
        EXPECT_NEAR(q.y, focus.y, 1e-5f);
        EXPECT_LE(std::hypot(r.origin.x, r.origin.y), 0.5f);
        EXPECT_EQ(r.origin.z, 5.0f);
    }
    EXPECT_NE(tr.camera_ray(4, 3, 0)->origin, tr.camera_ray(4, 3, 1)->origin);
}

TEST(ReferenceCamera, FisheyeIsBlackOutsideTheImageCircle) {
    Scene s = empty_scene(64, 32);
    s.camera.type = CameraType::fisheye;
    s.camera.fov = 180;
    s.background = {BackgroundType::constant, Rgb(1.0f), {}, {}};
    const ReferenceTracer tr(s);
    EXPECT_FALSE(tr.camera_ray(0, 0, 0));  // corner: r > 1
    const Ray center = *tr.camera_ray(32, 16, 0);
    EXPECT_NEAR(center.direction.z, -1.0f, 1e-3f);
    // Equidistant: the angle from the axis is r * fov / 2, with r the film radius
    // (x = 2 * 47.5 / 64 - 1, y / aspect = (1 - 2 * 16.5 / 32) / 2).
    const Ray right = *tr.camera_ray(47, 16, 0);
    const float r = std::hypot(0.484375f, -0.015625f);
    EXPECT_NEAR(std::acos(-right.direction.z), r * std::numbers::pi_v<float> / 2, 1e-4f);
    EXPECT_GT(right.direction.x, 0.0f);
    const Image img = render_reference(s).image;
    EXPECT_EQ(rgb_at(img, 0, 0), Rgb(0.0f));
    EXPECT_EQ(rgb_at(img, 32, 16), Rgb(1.0f));
}

TEST(ReferenceCamera, UpParallelToTheViewIsRefused) {
    Scene s = empty_scene();
    s.camera.up = {0, 0, 1};
    EXPECT_THROW(ReferenceTracer{s}, std::invalid_argument);
}

// ---- Shading ---------------------------------------------------------------------------

TEST(ReferenceShading, HeadOnDiffuseSphereCenterPixelClosedForm) {
    Scene s = empty_scene(33, 33);
    const Rgb cd{0.8f, 0.4f, 0.2f}, light{0.9f, 0.7f, 0.5f}, ambient{0.1f, 0.2f, 0.3f};
    const float kd = 0.75f;
    s.ambient = ambient;
    s.materials[0].material = diffuse(cd, kd);
    add_sphere(s, {0, 0, 0}, 1.0f);
    add_point_light(s, {0, 0, 10}, light);
    const Image img = render_reference(s).image;
    // ambient.kd.Cd + kd.Cd.(N.L).L with N.L = 1
    const Rgb expected = ambient * (cd * kd) + light * (cd * kd);
    expect_rgb_near(rgb_at(img, 16, 16), expected, 1e-6f);
}

TEST(ReferenceShading, PhongHighlightHeadOnAddsKs) {
    Scene s = empty_scene(33, 33);
    Material m = diffuse(Rgb(0.5f), 1.0f);
    m.ks = 0.25f;
    m.shininess = 50;
    s.materials[0].material = m;
    add_sphere(s, {0, 0, 0}, 1.0f);
    add_point_light(s, {0, 0, 10}, Rgb(1.0f));
    const Rgb c = ReferenceTracer(s).render_pixel(16, 16, 0, *std::make_unique<RayCounts>());
    expect_rgb_near(c, Rgb(0.5f + 0.25f), 1e-6f);  // R.W = 1
}

TEST(ReferenceShading, InverseSquareFalloffAndDirectionalLights) {
    Scene s = empty_scene(33, 33);
    s.materials[0].material = diffuse(Rgb(1.0f));
    add_sphere(s, {0, 0, 0}, 1.0f);
    add_point_light(s, {0, 0, 5}, Rgb(32.0f), true);  // distance 4 from the hit point
    RayCounts counts;
    expect_rgb_near(ReferenceTracer(s).render_pixel(16, 16, 0, counts), Rgb(2.0f), 1e-5f);

    Scene d = empty_scene(33, 33);
    d.materials[0].material = diffuse(Rgb(1.0f));
    add_sphere(d, {0, 0, 0}, 1.0f);
    // Travels along -z and -y at 45 degrees: N.l = cos 45 at the front point.
    add_directional_light(d, {0, -1, -1}, Rgb(1.0f));
    expect_rgb_near(ReferenceTracer(d).render_pixel(16, 16, 0, counts), Rgb(std::sqrt(0.5f)),
                    1e-6f);
}

TEST(ReferenceShading, LightBehindTheSurfaceContributesNothingAndCastsNoShadowRay) {
    Scene s = empty_scene(33, 33);
    add_sphere(s, {0, 0, 0}, 1.0f);
    add_point_light(s, {0, 0, -10}, Rgb(1.0f));
    RayCounts counts;
    EXPECT_EQ(ReferenceTracer(s).render_pixel(16, 16, 0, counts), Rgb(0.0f));
    EXPECT_EQ(counts.shadow, 0u);
}

TEST(ReferenceShadows, ABlockerBeyondTheLightCastsNoFalseShadow) {
    Scene s = empty_scene(33, 33);
    add_plane(s, {0, 0, 0}, {0, 1, 0});
    add_point_light(s, {0, 1, 0}, Rgb(1.0f));
    add_sphere(s, {0, 3, 0}, 0.5f);  // on the line from the floor through the light, beyond it
    RayCounts counts;
    // The floor under the light, seen from the side: N.l = 1, lit (0.8 grey * 1). A shadow
    // ray that ran past the light (t > 1) would hit the sphere and darken it.
    const ReferenceTracer ts(s);
    const Ray side{{2, 2, 0}, normalize(Vec3{-1, -1, 0}), 0.0f, kInfinity};
    expect_rgb_near(ts.trace(side, 0, Rgb(1.0f), counts), Rgb(0.8f), 1e-5f);

    // The same blocker between floor and light does shadow.
    Scene b = s;
    b.objects.back().center = {0.0f, 0.5f, 0.0f};
    b.objects.back().radius = 0.2f;
    b.camera.eye = {3, 5, 0};  // look past the blocker at the floor under it
    b.camera.lookat = {0, 0, 0};
    const ReferenceTracer tb(b);
    const Ray r{b.camera.eye, normalize(Vec3{0, 0, 0} - b.camera.eye), tb.epsilon(), kInfinity};
    EXPECT_EQ(tb.trace(r, 0, Rgb(1.0f), counts), Rgb(0.0f));
}

// Every pixel of a sphere lit from the camera faces the light: none may be in shadow.
int count_freckles(float epsilon_override) {
    Scene s = empty_scene(64, 64);
    if (epsilon_override >= 0.0f) s.render.epsilon = epsilon_override;
    s.camera.eye = {0, 0, 6};
    s.camera.fov = 30.0f;
    add_sphere(s, {0.3f, 0.2f, 0}, 1.0f);
    add_point_light(s, {0, 0, 6}, Rgb(1.0f));
    const Image img = render_reference(s).image;
    const ReferenceTracer tr(s);
    int freckles = 0;
    for (int j = 0; j < 64; ++j)
        for (int i = 0; i < 64; ++i) {
            const Ray r = *tr.camera_ray(i, j, 0);
            if (tr.intersect(r) && rgb_at(img, i, j).r == 0.0f) ++freckles;
        }
    return freckles;
}

TEST(ReferenceShadows, TheOffsetRulePreventsFreckles) {
    EXPECT_EQ(count_freckles(1e-4f), 0);
    EXPECT_EQ(count_freckles(-1.0f), 0);  // < 0: not an override in this helper
    // The trap is real: without the offset, rounding puts hit points inside the sphere.
    EXPECT_GT(count_freckles(0.0f), 0);
}

TEST(ReferenceShadows, ALightInsideAClosedSphereLightsOnlyTheInside) {
    Scene s = empty_scene(33, 33);
    s.camera.eye = {0, 4, 6};
    s.camera.lookat = {0, 0, 0};
    add_plane(s, {0, -2, 0}, {0, 1, 0});
    add_sphere(s, {0, 1, 0}, 1.0f);
    add_point_light(s, {0, 1, 0}, Rgb(1.0f));
    const ReferenceTracer tr(s);
    RayCounts counts;
    // The floor below is in the sphere's shadow: every object casts a full shadow.
    const Ray floor{{0, 5, 0.5f}, {0, -1, -0.1f}, 0.0f, kInfinity};
    EXPECT_EQ(tr.trace(Ray{{3, 0, 0}, {0, -1, 0}, 0.0f, kInfinity}, 0, Rgb(1.0f), counts),
              Rgb(0.0f));
    (void)floor;
    // The inside of the sphere seen from within is lit head-on: 0.8 * N.l = 0.8.
    const Ray inside{{0, 1, 0}, {0, 0, -1}, 0.0f, kInfinity};
    expect_rgb_near(tr.trace(inside, 0, Rgb(1.0f), counts), Rgb(0.8f), 1e-5f);
}

TEST(ReferenceChecker, TangentBasisAndSquares) {
    const TangentBasis up = checker_basis({0, 1, 0});
    EXPECT_EQ(up.t1, (Vec3{1, 0, 0}));
    EXPECT_EQ(up.t2, (Vec3{0, 0, 1}));
    const TangentBasis tilted = checker_basis(normalize(Vec3{0, 1, 1}));
    EXPECT_NEAR(dot(tilted.t1, normalize(Vec3{0, 1, 1})), 0.0f, 1e-6f);
    EXPECT_EQ(tilted.t1, (Vec3{1, 0, 0}));  // |x| smallest

    Scene s = empty_scene();
    Material floor = diffuse(Rgb(1.0f, 0.0f, 0.0f));
    floor.checker = Checker{Rgb(0.0f, 0.0f, 1.0f), 2.0f};
    s.materials[0].material = floor;
    add_plane(s, {0, 0, 0}, {0, 1, 0});
    add_directional_light(s, {0, -1, 0}, Rgb(1.0f));
    const ReferenceTracer tr(s);
    RayCounts counts;
    const auto color_at = [&](float x, float z) {
        return tr.trace({{x, 1, z}, {0, -1, 0}, 0.0f, kInfinity}, 0, Rgb(1.0f), counts);
    };
    EXPECT_EQ(color_at(0.5f, 0.5f), (Rgb{1, 0, 0}));    // floor 0 + 0: even
    EXPECT_EQ(color_at(2.5f, 0.5f), (Rgb{0, 0, 1}));    // 1 + 0: odd
    EXPECT_EQ(color_at(-0.5f, 0.5f), (Rgb{0, 0, 1}));   // -1 + 0: odd
    EXPECT_EQ(color_at(-0.5f, -0.5f), (Rgb{1, 0, 0}));  // -1 + -1: even
}

// ---- Reflection and refraction ----------------------------------------------------------

Scene gradient_mirror_floor(float max_depth_value) {
    Scene s = empty_scene(33, 33);
    s.render.max_depth = static_cast<int>(max_depth_value);
    s.background = {BackgroundType::gradient, {}, Rgb(0.0f), Rgb(1.0f)};
    Material mirror = diffuse(Rgb(0.0f), 0.0f);
    mirror.reflect = Rgb(0.5f);
    s.materials[0].material = mirror;
    add_plane(s, {0, 0, 0}, {0, 1, 0});
    return s;
}

TEST(ReferenceReflection, MirrorDirectionFormula) {
    const Scene s = gradient_mirror_floor(5);
    const ReferenceTracer tr(s);
    RayCounts counts;
    // Down at 45 degrees: R = V - 2(N.V)N goes up at 45 degrees; the gradient there is
    // 0.5 (up.R + 1) = 0.5 (0.7071 + 1).
    const Ray r{{0, 1, 1}, normalize(Vec3{0, -1, -1}), 0.0f, kInfinity};
    const float sky = 0.5f * (std::sqrt(0.5f) + 1.0f);
    expect_rgb_near(tr.trace(r, 0, Rgb(1.0f), counts), Rgb(0.5f * sky), 1e-6f);
    EXPECT_EQ(counts.reflected, 1u);
}

TEST(ReferenceReflection, MaxDepthZeroTracesNoSecondaryRaysButSeesTheBackground) {
    const Scene s = gradient_mirror_floor(0);
    const ReferenceTracer tr(s);
    RayCounts counts;
    const Ray r{{0, 1, 1}, normalize(Vec3{0, -1, -1}), 0.0f, kInfinity};
    const float sky = 0.5f * (std::sqrt(0.5f) + 1.0f);
    expect_rgb_near(tr.trace(r, 0, Rgb(1.0f), counts), Rgb(0.5f * sky), 1e-6f);
    EXPECT_EQ(counts.reflected, 0u);
}

Scene parallel_mirrors(float kr, int max_depth) {
    Scene s = empty_scene();
    s.render.max_depth = max_depth;
    s.background = {BackgroundType::constant, Rgb(1.0f), {}, {}};
    Material mirror = diffuse(Rgb(0.0f), 0.0f);
    mirror.reflect = Rgb(kr);
    s.materials[0].material = mirror;
    add_plane(s, {0, 0, -1}, {0, 0, 1});
    add_plane(s, {0, 0, 1}, {0, 0, -1});
    return s;
}

TEST(ReferenceReflection, MirrorInsideMirrorEndsByDepth) {
    const Scene s = parallel_mirrors(1.0f, 64);
    const ReferenceTracer tr(s);
    RayCounts counts;
    const Rgb c = tr.trace({{0, 0, 0}, {0, 0, -1}, 0.0f, kInfinity}, 0, Rgb(1.0f), counts);
    EXPECT_EQ(counts.reflected, 64u);
    EXPECT_EQ(c, Rgb(1.0f));  // the ray cut off at depth 65 sees the background
}

TEST(ReferenceReflection, MirrorInsideMirrorEndsByWeight) {
    const Scene s = parallel_mirrors(0.05f, 64);
    const ReferenceTracer tr(s);
    RayCounts counts;
    const Rgb c = tr.trace({{0, 0, 0}, {0, 0, -1}, 0.0f, kInfinity}, 0, Rgb(1.0f), counts);
    // Weights 0.05, 0.0025 are traced; 1.25e-4 < 1e-3 is not and sees the background.
    EXPECT_EQ(counts.reflected, 2u);
    expect_rgb_near(c, Rgb(0.05f * 0.05f * 0.05f), 1e-9f);
}

Scene glass_plane() {
    Scene s = empty_scene();
    s.background = {BackgroundType::gradient, {}, Rgb(0.0f), Rgb(1.0f)};
    Material glass = diffuse(Rgb(0.0f), 0.0f);
    glass.transmit = 1.0f;
    glass.ior = 1.5f;
    s.materials[0].material = glass;
    add_plane(s, {0, 0, 0}, {0, 1, 0});
    return s;
}

TEST(ReferenceRefraction, SnellsLawEnteringAndLeaving) {
    const Scene s = glass_plane();
    const ReferenceTracer tr(s);
    RayCounts counts;
    // Entering from above at 45 degrees: sin t = sin 45 / 1.5; it goes on downwards, so it
    // sees the gradient's lower half: 0.5 (1 - cos t).
    const float sin_t = std::sqrt(0.5f) / 1.5f, cos_t = std::sqrt(1.0f - sin_t * sin_t);
    const Ray down{{0, 1, 1}, normalize(Vec3{0, -1, -1}), 0.0f, kInfinity};
    expect_rgb_near(tr.trace(down, 0, Rgb(1.0f), counts), Rgb(0.5f * (1.0f - cos_t)), 1e-5f);
    EXPECT_EQ(counts.refracted, 1u);
    EXPECT_EQ(counts.reflected, 0u);

    // Leaving upwards at a small angle (sin 0.2 * 1.5 < 1): refracts out.
    const float sin_i = 0.2f, sin_o = 1.5f * sin_i, cos_o = std::sqrt(1.0f - sin_o * sin_o);
    const Ray up{{0, -1, 0}, Vec3{0, std::sqrt(1.0f - sin_i * sin_i), sin_i}, 0.0f, kInfinity};
    expect_rgb_near(tr.trace(up, 0, Rgb(1.0f), counts), Rgb(0.5f * (1.0f + cos_o)), 1e-5f);
}

TEST(ReferenceRefraction, TotalInternalReflectionMovesKtToTheMirrorRay) {
    const Scene s = glass_plane();
    const ReferenceTracer tr(s);
    RayCounts counts;
    // Leaving glass at 60 degrees from the normal: 1.5 sin 60 > 1, total internal
    // reflection. The reflected ray heads down at 60 degrees: 0.5 (1 - cos 60) = 0.25.
    const Ray up{{0, -1, 0}, Vec3{0, 0.5f, std::sqrt(0.75f)}, 0.0f, kInfinity};
    expect_rgb_near(tr.trace(up, 0, Rgb(1.0f), counts), Rgb(0.25f), 1e-5f);
    EXPECT_EQ(counts.refracted, 0u);
    EXPECT_EQ(counts.reflected, 1u);
}

TEST(ReferenceRefraction, StraightThroughAGlassSphere) {
    Scene s = empty_scene(33, 33);
    s.background = {BackgroundType::gradient, {}, Rgb(0.0f), Rgb(1.0f)};
    Material glass = diffuse(Rgb(0.0f), 0.0f);
    glass.transmit = 1.0f;
    s.materials[0].material = glass;
    add_sphere(s, {0, 0, 0}, 1.0f);
    RayCounts counts;
    // Normal incidence: no bending; enters and leaves, then sees the horizon (0.5).
    const Rgb c = ReferenceTracer(s).render_pixel(16, 16, 0, counts);
    expect_rgb_near(c, Rgb(0.5f), 1e-5f);
    EXPECT_EQ(counts.refracted, 2u);
}

// ---- Background, sampling, parallelism ---------------------------------------------------

TEST(ReferenceBackground, GradientFollowsTheCameraUpAsGiven) {
    Scene s = empty_scene();
    s.camera.up = {0, 2, 0.5f};  // not orthogonal to the view: used as given, normalised
    s.background = {BackgroundType::gradient, {}, Rgb(0.0f), Rgb(1.0f)};
    const ReferenceTracer tr(s);
    RayCounts counts;
    const Vec3 up = normalize(Vec3{0, 2, 0.5f});
    const Rgb c = tr.trace({{0, 0, 0}, up * 3.0f, 0.0f, kInfinity}, 0, Rgb(1.0f), counts);
    expect_rgb_near(c, Rgb(1.0f), 1e-6f);
    const Rgb d = tr.trace({{0, 0, 0}, -up, 0.0f, kInfinity}, 0, Rgb(1.0f), counts);
    expect_rgb_near(d, Rgb(0.0f), 1e-6f);
}

Scene busy_scene() {
    Scene s = empty_scene(61, 47);
    s.image.spp = 4;
    s.background = {BackgroundType::gradient, {}, Rgb(0.1f), Rgb(0.6f, 0.7f, 1.0f)};
    Material mirror = diffuse(Rgb(0.9f), 0.2f);
    mirror.reflect = Rgb(0.6f);
    Material glass = diffuse(Rgb(1.0f), 0.0f);
    glass.transmit = 0.9f;
    glass.reflect = Rgb(0.1f);
    const auto m1 = add_material(s, mirror), m2 = add_material(s, glass);
    add_plane(s, {0, -1, 0}, {0, 1, 0});
    add_sphere(s, {-1, 0, 0}, 1.0f, m1);
    add_sphere(s, {1.2f, 0, 0.5f}, 0.8f, m2);
    add_point_light(s, {3, 5, 4}, Rgb(1.0f));
    return s;
}

TEST(ReferenceRender, ThreadCountAndTileSizeDoNotChangeASingleBit) {
    const Scene s = busy_scene();
    RenderOptions one;
    one.threads = 1;
    const RenderResult a = render_reference(s, one);
    for (int threads : {2, 3}) {
        for (int tile : {1, 7, 16}) {
            RenderOptions o;
            o.threads = threads;
            o.tile_width = tile;
            o.tile_height = tile + 1;
            const RenderResult b = render_reference(s, o);
            EXPECT_TRUE(same_pixels(a.image, b.image)) << threads << " threads, tile " << tile;
            EXPECT_EQ(a.rays.total(), b.rays.total());
        }
    }
}

TEST(ReferenceRender, CountsRaysByKindAndNeverWritesNaN) {
    const Scene s = busy_scene();
    const RenderResult r = render_reference(s);
    EXPECT_EQ(r.rays.primary, 61u * 47u * 4u);
    EXPECT_GT(r.rays.shadow, 0u);
    EXPECT_GT(r.rays.reflected, 0u);
    EXPECT_GT(r.rays.refracted, 0u);
    for (const Rgb& p : rgb_pixels(r.image)) ASSERT_TRUE(is_finite(p));
}

TEST(ReferenceRender, FrameChangesTheJitterButNotASingleSampleImage) {
    Scene s = busy_scene();
    RenderOptions f0, f1;
    f1.frame = 1;
    EXPECT_FALSE(same_pixels(render_reference(s, f0).image, render_reference(s, f1).image));
    s.image.spp = 1;
    EXPECT_TRUE(same_pixels(render_reference(s, f0).image, render_reference(s, f1).image));
}

}  // namespace
}  // namespace octray
