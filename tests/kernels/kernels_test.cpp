// The packet kernels against the scalar reference's math, under every ISA this CPU runs
// (typed tests; an ISA the CPU lacks is skipped): closest hit and any hit for random
// rays and scenes, partially live packets, rays missing everything, rays starting inside
// spheres, grazing and tangent rays, sphere/plane ties; camera rays for every camera;
// shading never produces NaN, and AVX-512's 16-lane shading is AVX2's 8-lane shading bit for
// bit. Results must equal the reference's bit for bit.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "core/aligned.h"
#include "core/random.h"
#include "kernels/dispatch.h"
#include "render/prepare/bvh_build.h"
#include "render/prepare/scene_view.h"
#include "render/reference.h"
#include "scene/compile.h"
#include "scene/load.h"

namespace octray {
namespace {

using kernels::kPacketWidth;

template <Isa I>
struct IsaTag {
    static constexpr Isa isa = I;
};
using Isas = ::testing::Types<IsaTag<Isa::sse2>, IsaTag<Isa::sse4_1>, IsaTag<Isa::avx2>,
                              IsaTag<Isa::avx512>>;

std::size_t padded(std::size_t n) {
    return (n + kPacketWidth - 1) / kPacketWidth * kPacketWidth;
}

// SoA ray storage sized exactly to whole packets (plus the spare packet compaction
// needs), so that AddressSanitizer catches a kernel writing past a stream.
struct Rays {
    std::size_t n;
    AlignedVector<float> ox, oy, oz, dx, dy, dz, wr, wg, wb, t_max;
    AlignedVector<std::uint32_t> pixel;
    explicit Rays(std::size_t count, std::size_t capacity = 0) : n(count) {
        const std::size_t c = capacity ? capacity : padded(count);
        for (auto* v : {&ox, &oy, &oz, &dx, &dy, &dz, &wr, &wg, &wb, &t_max})
            v->assign(c, 0.0f);
        pixel.assign(c, 0u);
    }
    void set(std::size_t k, const Ray& r) {
        ox[k] = r.origin.x, oy[k] = r.origin.y, oz[k] = r.origin.z;
        dx[k] = r.direction.x, dy[k] = r.direction.y, dz[k] = r.direction.z;
        wr[k] = wg[k] = wb[k] = 1.0f;
        t_max[k] = r.t_max;
    }
    kernels::RayStream stream() {
        return {ox.data(), oy.data(), oz.data(), dx.data(), dy.data(),
                dz.data(), wr.data(), wg.data(), wb.data(), pixel.data()};
    }
    kernels::ShadowStream shadow_stream(AlignedVector<float>& scratch,
                                        AlignedVector<std::uint32_t>& parent) {
        scratch.assign(3 * t_max.size(), 0.0f);
        parent.assign(t_max.size(), 0u);
        float* s = scratch.data();
        return {ox.data(),    oy.data(),    oz.data(), dx.data(),        dy.data(),
                dz.data(),    t_max.data(), s,         s + t_max.size(), s + 2 * t_max.size(),
                parent.data()};
    }
};

// A random scene: spheres of many sizes, some overlapping, and a few planes, in mixed file
// order.
Scene random_scene(std::mt19937& rng, int spheres, int planes) {
    Scene s;
    s.image = {64, 48, 1};
    s.materials.push_back({"m", Material{}});
    std::uniform_real_distribution<float> pos(-3.0f, 3.0f), rad(0.05f, 1.5f), unit(-1.0f, 1.0f);
    std::vector<Object> objects;
    for (int k = 0; k < spheres; ++k) {
        Object o;
        o.type = ObjectType::sphere;
        o.center = {pos(rng), pos(rng), pos(rng)};
        o.radius = rad(rng);
        objects.push_back(o);
    }
    for (int k = 0; k < planes; ++k) {
        Object o;
        o.type = ObjectType::plane;
        o.point = {pos(rng), pos(rng), pos(rng)};
        o.normal = normalize(Vec3{unit(rng), unit(rng), unit(rng)});
        objects.push_back(o);
    }
    std::shuffle(objects.begin(), objects.end(), rng);
    s.objects = objects;
    return s;
}

// A unit vector in a random direction.
Vec3 random_unit_vector(std::mt19937& rng) {
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    for (;;) {
        const Vec3 v{unit(rng), unit(rng), unit(rng)};
        if (length(v) > 0.1f) return normalize(v);
    }
}

// A scene of one material and no objects yet.
Scene one_material_scene() {
    Scene scene;
    scene.materials.push_back({"m", Material{}});
    return scene;
}

// A sphere of `radius` at a random place within 50 radii of the origin, added to `scene`.
Object add_sphere_near_origin(Scene& scene, std::mt19937& rng, float radius) {
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    Object sphere;
    sphere.radius = radius;
    sphere.center = Vec3{unit(rng), unit(rng), unit(rng)} * (radius * 50.0f);
    scene.objects.push_back(sphere);
    return sphere;
}

// `count` spheres of radius 1/2 up to 2e5 from the origin, added to `scene`: far from the
// grazed ones, so that a BVH has inner nodes and leaves to skip.
void add_far_spheres(Scene& scene, std::mt19937& rng, int count) {
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    for (int i = 0; i < count; ++i) {
        Object sphere;
        sphere.radius = 0.5f;
        sphere.center = Vec3{unit(rng), unit(rng), unit(rng)} * 2e5f;
        scene.objects.push_back(sphere);
    }
}

// Spheres of radius 1e-6, 1e-3, 1 and 1e3, each added to `scene` within 50 radii of the
// origin and handed to f, for rays that graze them.
template <class F>
void for_spheres_at_every_scale(Scene& scene, std::mt19937& rng, F&& f) {
    for (const float radius : {1e-6f, 1e-3f, 1.0f, 1e3f})
        f(add_sphere_near_origin(scene, rng, radius));
}

Ray random_ray(std::mt19937& rng, float t_min) {
    std::uniform_real_distribution<float> pos(-4.0f, 4.0f), unit(-1.0f, 1.0f);
    Ray r;
    r.origin = {pos(rng), pos(rng), pos(rng)};
    r.direction = {unit(rng), unit(rng), unit(rng)};
    if (!(length(r.direction) > 1e-3f)) r.direction = {0, 0, 1};
    r.t_min = t_min;
    return r;
}

// A compiled scene and the view the kernels read: brute force, or, with `bvh_min_lanes`,
// through the spheres' BVH, packets with fewer live lanes going on ray by ray (0: packets
// only, 9: single rays only).
struct TestView {
    CompiledScene compiled;
    SphereBvh bvh;
    kernels::SceneView view;

    TestView(const Scene& scene, std::optional<std::uint32_t> bvh_min_lanes)
        : compiled(compile_scene(scene)),
          bvh(bvh_min_lanes ? build_sphere_bvh(compiled.spheres) : SphereBvh{}),
          view(bvh_min_lanes ? make_scene_view(compiled, bvh, *bvh_min_lanes, *bvh_min_lanes)
                             : make_scene_view(compiled)) {}
};

template <class Tag>
class KernelTest : public ::testing::Test {
  protected:
    void SetUp() override {
        if (!isa_supported(Tag::isa)) GTEST_SKIP() << isa_name(Tag::isa) << " not on this CPU";
    }
    const kernels::KernelTable& k() const { return kernel_table(Tag::isa); }

    // Closest hits of `rays` (all with the same t_min) against the reference's intersect(),
    // brute force or through the BVH (TestView).
    void expect_closest_hits_match(const Scene& scene, const std::vector<Ray>& rays,
                                   float t_min,
                                   std::optional<std::uint32_t> bvh_min_lanes = {}) {
        const TestView tv(scene, bvh_min_lanes);
        const kernels::SceneView& view = tv.view;
        const ReferenceTracer ref(scene);
        Rays stream(rays.size());
        for (std::size_t i = 0; i < rays.size(); ++i) stream.set(i, rays[i]);
        AlignedVector<float> t(padded(rays.size()), -7.0f);
        AlignedVector<std::int32_t> object(padded(rays.size()), -7);
        k().closest_hit(view, stream.stream(), static_cast<std::uint32_t>(rays.size()), t_min,
                        {t.data(), object.data()});
        for (std::size_t i = 0; i < rays.size(); ++i) {
            Ray r = rays[i];
            r.t_min = t_min;
            const std::optional<SurfaceHit> hit = ref.intersect(r);
            SCOPED_TRACE("ray " + std::to_string(i));
            if (!hit) {
                EXPECT_EQ(object[i], kernels::kNoHit);
                EXPECT_EQ(t[i], kInfinity);
            } else {
                EXPECT_EQ(object[i], static_cast<std::int32_t>(hit->object));
                EXPECT_EQ(t[i], hit->t);  // the same bits, not merely close
            }
        }
    }

    void expect_any_hits_match(const Scene& scene, const std::vector<Ray>& rays,
                               std::optional<std::uint32_t> bvh_min_lanes = {}) {
        const TestView tv(scene, bvh_min_lanes);
        const kernels::SceneView& view = tv.view;
        const ReferenceTracer ref(scene);
        Rays stream(rays.size());
        for (std::size_t i = 0; i < rays.size(); ++i) stream.set(i, rays[i]);
        AlignedVector<float> scratch;
        AlignedVector<std::uint32_t> parent;
        AlignedVector<std::uint32_t> occluded(padded(rays.size()), 7u);
        k().any_hit(view, stream.shadow_stream(scratch, parent),
                    static_cast<std::uint32_t>(rays.size()), occluded.data());
        for (std::size_t i = 0; i < rays.size(); ++i) {
            Ray r = rays[i];
            r.t_min = 0.0f;
            EXPECT_EQ(occluded[i], ref.occluded(r) ? 1u : 0u) << "ray " << i;
        }
    }
};
TYPED_TEST_SUITE(KernelTest, Isas);

TYPED_TEST(KernelTest, ClosestHitMatchesReferenceOnRandomScenes) {
    std::mt19937 rng(12345);
    for (int trial = 0; trial < 20; ++trial) {
        const Scene scene = random_scene(rng, 1 + trial * 3, trial % 4);
        // Partially live packets: counts that are not whole packets.
        const std::size_t count = 1 + static_cast<std::size_t>(trial) * 11;
        std::vector<Ray> rays;
        for (std::size_t i = 0; i < count; ++i) rays.push_back(random_ray(rng, 0.0f));
        this->expect_closest_hits_match(scene, rays, trial % 2 ? 0.0f : 1e-3f);
    }
}

TYPED_TEST(KernelTest, RaysMissingEverythingAndEmptyScenes) {
    Scene scene;
    scene.materials.push_back({"m", Material{}});
    std::vector<Ray> rays;
    for (int i = 0; i < 11; ++i) rays.push_back({{0, 0, 0}, {1, float(i), 0}, 0.0f, kInfinity});
    this->expect_closest_hits_match(scene, rays, 0.0f);  // no objects at all
    Object sphere;
    sphere.center = {0, 0, -10};
    scene.objects.push_back(sphere);
    Object plane;
    plane.type = ObjectType::plane;
    plane.point = {0, -5, 0};
    plane.normal = {0, 1, 0};
    scene.objects.push_back(plane);
    // Away from the sphere, parallel to the plane (|V.N| = 0) or leaving it.
    this->expect_closest_hits_match(scene, rays, 0.0f);
    this->expect_any_hits_match(scene, rays);
}

TYPED_TEST(KernelTest, RaysStartingInsideSpheres) {
    std::mt19937 rng(7);
    Scene scene = random_scene(rng, 12, 1);
    std::vector<Ray> rays;
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f), frac(0.0f, 0.9f);
    for (const Object& o : scene.objects) {
        if (o.type != ObjectType::sphere) continue;
        for (int i = 0; i < 3; ++i) {
            const Vec3 dir = normalize(Vec3{unit(rng), unit(rng), unit(rng)});
            rays.push_back({o.center + dir * (o.radius * frac(rng)),
                            {unit(rng), unit(rng), unit(rng)},
                            0.0f,
                            kInfinity});
        }
    }
    this->expect_closest_hits_match(scene, rays, 0.0f);
    this->expect_any_hits_match(scene, rays);
}

TYPED_TEST(KernelTest, GrazingAndTangentRays) {
    Scene scene;
    scene.materials.push_back({"m", Material{}});
    Object sphere;
    sphere.center = {0, 0, 0};
    sphere.radius = 1.0f;
    scene.objects.push_back(sphere);
    std::vector<Ray> rays;
    // Exactly tangent (disc = 0: a double root counts), and just inside / outside it.
    for (float y : {1.0f, std::nextafter(1.0f, 0.0f), std::nextafter(1.0f, 2.0f), 0.9999f,
                    1.0001f, -1.0f, 0.5f})
        rays.push_back({{-5, y, 0}, {1, 0, 0}, 0.0f, kInfinity});
    // Nearly parallel to a plane: |V.N| just above and below 1e-12.
    Object plane;
    plane.type = ObjectType::plane;
    plane.point = {0, -2, 0};
    plane.normal = {0, 1, 0};
    scene.objects.push_back(plane);
    for (float dy : {-1e-11f, -1e-12f, -9e-13f, -1e-13f, 0.0f})
        rays.push_back({{0, -1, 0}, {1, dy, 0}, 0.0f, kInfinity});
    this->expect_closest_hits_match(scene, rays, 0.0f);
    this->expect_any_hits_match(scene, rays);
}

// Rays passing a sphere's surface by a hair, at every scale: radii from 1e-6 to 1e3, rays
// from beside the sphere to 1e4 radii away, direction lengths from 1e-3 to 1e3, passing
// the center at r (1 + delta) for delta from -2^-8 to 2^-6 (tangent within a few ulps
// included). The BVH's leaves reject most spheres with a division-free test before the
// exact one (kernels/geometry/sphere_test.h, sphere_may_hit); it must never reject a sphere the
// exact test hits (without its |O'|^2 term, rays from 1e6 radii away fail here). Checked
// for brute force and for the BVH's packet and single-ray leaves, against the reference
// bit for bit.
TYPED_TEST(KernelTest, NearMissesAtEveryScale) {
    std::mt19937 rng(2026);
    const auto random_unit = [&] { return random_unit_vector(rng); };
    Scene scene = one_material_scene();
    std::vector<Ray> rays;
    for_spheres_at_every_scale(scene, rng, [&](const Object& sphere) {
        const float radius = sphere.radius;
        for (const float delta :
             {-0x1.0p-8f, -0x1.0p-16f, -0x1.0p-22f, 0.0f, 0x1.0p-22f, 0x1.0p-18f, 0x1.0p-14f,
              0x1.0p-10f, 0x1.0p-8f, 0x1.0p-7f, 0x1.0p-6f, 0x1.0p-5f, 0x1.0p-4f})
            for (const float away : {0.0f, 3.0f, 1e4f, 3e5f, 1e6f, 1e6f, 1e6f, 1e6f})
                for (const float speed : {1e-3f, 1.0f, 1e3f}) {
                    const Vec3 u = random_unit();
                    const Vec3 side = normalize(cross(u, random_unit()));
                    const Vec3 origin =
                        sphere.center + side * (radius * (1.0f + delta)) - u * (radius * away);
                    rays.push_back({origin, u * speed, 0.0f, kInfinity});
                }
    });
    // Spheres elsewhere, so the BVH has inner nodes and leaves to skip.
    add_far_spheres(scene, rng, 60);
    this->expect_closest_hits_match(scene, rays, 0.0f);
    this->expect_any_hits_match(scene, rays);
    for (const std::uint32_t lanes : {0u, 9u}) {
        SCOPED_TRACE("BVH, packets of fewer than " + std::to_string(lanes) +
                     " lanes ray by ray");
        this->expect_closest_hits_match(scene, rays, 0.0f, lanes);
        this->expect_any_hits_match(scene, rays, lanes);
    }
}

// Shadow rays are segments [O, O + t_max V]; brute force skips spheres whose widened box
// misses the box of a packet's segments (kernels/stream/brute_force.h, SegmentBox). Segments
// that graze a sphere at every scale (as above), ending short of it, at its closest point
// to within an ulp or two, or past it, each one sixteen times in a row so that a packet's
// box is one segment's (flat along the axes for axis-aligned rays), among enough spheres
// for the cull to run: the occlusion bit for bit the reference's.
TYPED_TEST(KernelTest, ShadowSegmentsGrazingSpheresAtEveryScale) {
    std::mt19937 rng(2027);
    const auto random_unit = [&] { return random_unit_vector(rng); };
    Scene scene = one_material_scene();
    std::vector<Ray> rays;
    for_spheres_at_every_scale(scene, rng, [&](const Object& sphere) {
        const float radius = sphere.radius;
        for (const float delta : {-0x1.0p-8f, -0x1.0p-22f, 0.0f, 0x1.0p-22f, 0x1.0p-12f})
            for (const float away : {0.0f, 3.0f, 1e4f, 1e6f})
                for (const bool axis_aligned : {false, true}) {
                    const Vec3 u = axis_aligned ? Vec3{0, 0, 1} : random_unit();
                    const Vec3 side =
                        axis_aligned ? Vec3{1, 0, 0} : normalize(cross(u, random_unit()));
                    const Vec3 origin =
                        sphere.center + side * (radius * (1.0f + delta)) - u * (radius * away);
                    const Vec3 v = u * 2.0f;
                    // Where the line passes the center.
                    const float t_ca = dot(sphere.center - origin, v) / dot(v, v);
                    for (const float end :
                         {0.5f, 1.0f - 0x1.0p-20f, 1.0f, 1.0f + 0x1.0p-20f, 2.0f})
                        for (int copy = 0; copy < 16; ++copy)
                            rays.push_back(
                                {origin, v, 0.0f, t_ca * end + radius * (end - 1.0f)});
                }
    });
    add_far_spheres(scene, rng, 20);
    ASSERT_GE(scene.objects.size(), kShadowCullMinSpheres);
    this->expect_any_hits_match(scene, rays);
}

// A sphere and a plane hit at exactly the same t: the one listed first in the file wins,
// whichever kind it is.
TYPED_TEST(KernelTest, TiesGoToTheObjectListedFirst) {
    Object sphere;
    sphere.center = {0, 0, 0};
    sphere.radius = 1.0f;
    Object plane;
    plane.type = ObjectType::plane;
    plane.point = {0, 0, 1};
    plane.normal = {0, 0, 1};
    const std::vector<Ray> rays(9, Ray{{0, 0, 5}, {0, 0, -1}, 0.0f, kInfinity});  // t = 4
    for (bool plane_first : {true, false}) {
        Scene scene;
        scene.materials.push_back({"m", Material{}});
        scene.objects = plane_first ? std::vector<Object>{plane, sphere, plane}
                                    : std::vector<Object>{sphere, plane, sphere};
        this->expect_closest_hits_match(scene, rays, 0.0f);
        const CompiledScene c = compile_scene(scene);
        Rays stream(rays.size());
        for (std::size_t i = 0; i < rays.size(); ++i) stream.set(i, rays[i]);
        AlignedVector<float> t(padded(rays.size()));
        AlignedVector<std::int32_t> object(padded(rays.size()));
        this->k().closest_hit(make_scene_view(c), stream.stream(), 9, 0.0f,
                              {t.data(), object.data()});
        EXPECT_EQ(t[0], 4.0f);
        EXPECT_EQ(object[0], 0);
    }
}

TYPED_TEST(KernelTest, AnyHitMatchesReferenceWithShortSegments) {
    std::mt19937 rng(99);
    for (int trial = 0; trial < 10; ++trial) {
        const Scene scene = random_scene(rng, 2 + trial * 5, trial % 3);
        std::vector<Ray> rays;
        std::uniform_real_distribution<float> tmax(0.1f, 3.0f);
        for (int i = 0; i < 5 + trial * 9; ++i) {
            Ray r = random_ray(rng, 0.0f);
            r.t_max = i % 3 == 0 ? kInfinity : (i % 3 == 1 ? 1.0f : tmax(rng));
            rays.push_back(r);
        }
        this->expect_any_hits_match(scene, rays);
    }
}

// Primary rays for every camera against ReferenceTracer::camera_ray, bit for bit; the
// fisheye drops samples outside its circle and keeps the others in order.
TYPED_TEST(KernelTest, CameraRaysMatchReference) {
    for (CameraType type : {CameraType::pinhole, CameraType::orthographic, CameraType::thinlens,
                            CameraType::fisheye}) {
        Scene scene = load_scene("whitted,width=37,height=23,spp=3");
        scene.camera.type = type;
        scene.camera.fov = type == CameraType::fisheye ? 220.0f : 60.0f;
        scene.camera.aperture = 0.2f;
        scene.camera.focus_distance = 5.0f;
        scene.camera.width = 4.0f;
        const CompiledScene compiled = compile_scene(scene);
        const ReferenceTracer ref(scene);
        const int w = scene.image.width, h = scene.image.height, spp = scene.image.spp;
        const std::size_t n = static_cast<std::size_t>(w) * h * spp;
        AlignedVector<float> x(padded(n)), y(padded(n)), lu(padded(n)), lv(padded(n));
        AlignedVector<std::uint32_t> pixel(padded(n));
        std::vector<std::optional<Ray>> expected;
        std::size_t k = 0;
        for (int j = 0; j < h; ++j)
            for (int i = 0; i < w; ++i)
                for (int s = 0; s < spp; ++s, ++k) {
                    const auto us = static_cast<std::uint32_t>(s);
                    const PixelOffset o = pixel_sample_offset(0, i, j, us, spp, 0);
                    x[k] = film_x(i, o.ox, w);
                    y[k] = film_y(j, o.oy, h);
                    lu[k] = sample_uniform(0, i, j, us, kDimLensU, 0);
                    lv[k] = sample_uniform(0, i, j, us, kDimLensV, 0);
                    pixel[k] = static_cast<std::uint32_t>(k);
                    expected.push_back(ref.camera_ray(i, j, us, 0));
                }
        Rays out(n);
        const std::uint32_t written = this->k().camera_rays(
            make_scene_view(compiled), {x.data(), y.data(), lu.data(), lv.data(), pixel.data()},
            static_cast<std::uint32_t>(n), out.stream());
        std::size_t next = 0;
        for (std::size_t s = 0; s < n; ++s) {
            if (!expected[s]) continue;  // fisheye: outside the circle
            ASSERT_LT(next, written);
            SCOPED_TRACE("camera " + std::to_string(int(type)) + ", sample " +
                         std::to_string(s));
            EXPECT_EQ(out.pixel[next], s);
            const Ray& r = *expected[s];
            EXPECT_EQ(out.ox[next], r.origin.x);
            EXPECT_EQ(out.oy[next], r.origin.y);
            EXPECT_EQ(out.oz[next], r.origin.z);
            EXPECT_EQ(out.dx[next], r.direction.x);
            EXPECT_EQ(out.dy[next], r.direction.y);
            EXPECT_EQ(out.dz[next], r.direction.z);
            ++next;
        }
        EXPECT_EQ(next, written);
        if (type == CameraType::fisheye) {
            EXPECT_LT(written, n);
        }
    }
}

// Shading random hits and misses of a scene with every material feature: every color,
// shadow ray and secondary ray is finite, counts stay within the capacities.
TYPED_TEST(KernelTest, ShadingNeverProducesNaN) {
    Scene scene = load_scene("whitted,width=16,height=16");
    const CompiledScene compiled = compile_scene(scene);
    const kernels::SceneView view = make_scene_view(compiled);
    std::mt19937 rng(3);
    const std::size_t n = 203;
    Rays rays(n);
    for (std::size_t i = 0; i < n; ++i) {
        Ray r = random_ray(rng, 0.0f);
        r.origin = r.origin * 0.5f + Vec3{0, 1, 0};
        rays.set(i, r);
    }
    AlignedVector<float> t(padded(n));
    AlignedVector<std::int32_t> object(padded(n));
    this->k().closest_hit(view, rays.stream(), n, 0.0f, {t.data(), object.data()});
    const std::size_t cap = padded(n) + kPacketWidth;
    std::vector<AlignedVector<float>> color(9, AlignedVector<float>(cap, 0.0f));
    const std::size_t shadow_cap = padded(n * compiled.lights.count) + kPacketWidth;
    Rays shadows(0, shadow_cap), next(0, padded(2 * n) + kPacketWidth);
    AlignedVector<float> term;
    AlignedVector<std::uint32_t> parent;
    const kernels::ShadowStream sh = shadows.shadow_stream(term, parent);
    AlignedVector<std::uint32_t> link(next.ox.size());
    AlignedVector<float> factor(3 * next.ox.size());
    const kernels::ShadeCounts c = this->k().shade(
        view, {rays.stream(), {t.data(), object.data()}, static_cast<std::uint32_t>(n), 0},
        {{color[0].data(), color[1].data(), color[2].data(), color[3].data(), color[4].data(),
          color[5].data(), color[6].data(), color[7].data(), color[8].data()},
         sh,
         next.stream(),
         {link.data(), factor.data(), factor.data() + next.ox.size(),
          factor.data() + 2 * next.ox.size()}});
    EXPECT_LE(c.shadow, n * compiled.lights.count);
    EXPECT_EQ(c.next, c.reflected + c.refracted);
    EXPECT_LE(c.next, 2 * n);
    EXPECT_GT(c.shadow, 0u);
    EXPECT_GT(c.next, 0u);
    for (std::size_t i = 0; i < n; ++i)
        for (const auto& column : color) EXPECT_TRUE(std::isfinite(column[i])) << i;
    for (std::size_t i = 0; i < c.shadow; ++i) {
        EXPECT_LT(sh.parent[i], n);
        EXPECT_TRUE(std::isfinite(sh.term_r[i]) && std::isfinite(sh.dx[i]) &&
                    std::isfinite(sh.ox[i]));
    }
    for (std::size_t i = 0; i < c.next; ++i) {
        EXPECT_LT(link[i] >> 1, n);
        EXPECT_TRUE(std::isfinite(next.dx[i]) && std::isfinite(next.ox[i]) &&
                    std::isfinite(next.wr[i]));
    }
}

// AVX-512 shades 16 rays per register, then its last 8-ray packet 8 wide (shading.h):
// for every count from 1 to 40 (both paths, and every tail), its colors, shadow rays and
// children are AVX2's, bit for bit and in the same order, and nothing is written past a
// stream's capacity (whole packets plus the spare one: ASan checks it).
TEST(ShadeWidths, SixteenLanesShadeAsEight) {
    if (!isa_supported(Isa::avx512) || !isa_supported(Isa::avx2))
        GTEST_SKIP() << "this CPU lacks AVX-512 or AVX2: no two widths to compare";
    const Scene scene = load_scene("whitted,width=16,height=16");
    const CompiledScene compiled = compile_scene(scene);
    const kernels::SceneView view = make_scene_view(compiled);
    const std::uint32_t lights = static_cast<std::uint32_t>(compiled.lights.count);
    struct Shaded {
        kernels::ShadeCounts counts{};
        std::vector<AlignedVector<float>> color;
        Rays shadows, next;
        AlignedVector<float> term;
        AlignedVector<std::uint32_t> parent, link;
        AlignedVector<float> factor;
        Shaded(std::size_t n, std::uint32_t lights)
            : color(9, AlignedVector<float>(padded(n) + kPacketWidth, -1.0f)),
              shadows(0, padded(n * lights) + kPacketWidth),
              next(0, padded(2 * n) + kPacketWidth),
              link(next.ox.size(), 0u),
              factor(3 * next.ox.size(), 0.0f) {}
    };
    for (std::size_t n = 1; n <= 40; ++n) {
        SCOPED_TRACE("count " + std::to_string(n));
        std::mt19937 rng(static_cast<unsigned>(n));
        Rays rays(n);
        for (std::size_t i = 0; i < n; ++i) {
            Ray r = random_ray(rng, 0.0f);
            r.origin = r.origin * 0.5f + Vec3{0, 1, 0};
            rays.set(i, r);
            rays.wr[i] = 0.9f, rays.wg[i] = 0.5f, rays.wb[i] = 0.2f;
        }
        AlignedVector<float> t(padded(n));
        AlignedVector<std::int32_t> object(padded(n));
        kernel_table(Isa::avx2).closest_hit(view, rays.stream(), static_cast<std::uint32_t>(n),
                                            0.0f, {t.data(), object.data()});
        const auto shade = [&](Isa isa) {
            auto out = std::make_unique<Shaded>(n, lights);
            Shaded& o = *out;
            const kernels::ShadowStream sh = o.shadows.shadow_stream(o.term, o.parent);
            const std::size_t cap = o.next.ox.size();
            o.counts = kernel_table(isa).shade(
                view,
                {rays.stream(), {t.data(), object.data()}, static_cast<std::uint32_t>(n), 0},
                {{o.color[0].data(), o.color[1].data(), o.color[2].data(), o.color[3].data(),
                  o.color[4].data(), o.color[5].data(), o.color[6].data(), o.color[7].data(),
                  o.color[8].data()},
                 sh,
                 o.next.stream(),
                 {o.link.data(), o.factor.data(), o.factor.data() + cap,
                  o.factor.data() + 2 * cap}});
            return out;
        };
        const auto narrow = shade(Isa::avx2), wide = shade(Isa::avx512);
        ASSERT_EQ(wide->counts.shadow, narrow->counts.shadow);
        ASSERT_EQ(wide->counts.next, narrow->counts.next);
        EXPECT_EQ(wide->counts.reflected, narrow->counts.reflected);
        EXPECT_EQ(wide->counts.refracted, narrow->counts.refracted);
        for (std::size_t c = 0; c < 9; ++c)
            for (std::size_t i = 0; i < n; ++i)
                EXPECT_EQ(wide->color[c][i], narrow->color[c][i])
                    << "color " << c << ", ray " << i;
        // The streams' order differs (16 rays' shadow rays light by light, then the next 16,
        // against 8 at a time), never the order of one parent's rays: each stream sorted
        // stably by parent slot must be the same.
        const auto shadow_rays = [](const Shaded& o, std::uint32_t count) {
            std::vector<std::array<float, 6>> v;
            for (std::uint32_t i = 0; i < count; ++i)
                v.push_back({static_cast<float>(o.parent[i]), o.shadows.ox[i], o.shadows.dz[i],
                             o.shadows.t_max[i], o.term[i],
                             o.term[o.shadows.t_max.size() + i]});
            std::stable_sort(v.begin(), v.end(),
                             [](const auto& a, const auto& b) { return a[0] < b[0]; });
            return v;
        };
        const auto children = [](const Shaded& o, std::uint32_t count) {
            std::vector<std::array<float, 5>> v;
            for (std::uint32_t i = 0; i < count; ++i)
                v.push_back({static_cast<float>(o.link[i]), o.next.dx[i], o.next.oy[i],
                             o.next.wb[i], o.factor[i]});
            std::stable_sort(v.begin(), v.end(),
                             [](const auto& a, const auto& b) { return a[0] < b[0]; });
            return v;
        };
        EXPECT_EQ(shadow_rays(*wide, wide->counts.shadow),
                  shadow_rays(*narrow, narrow->counts.shadow));
        EXPECT_EQ(children(*wide, wide->counts.next), children(*narrow, narrow->counts.next));
    }
}

TEST(KernelDispatch, ParsesAndResolvesIsas) {
    EXPECT_EQ(parse_isa("avx512"), Isa::avx512);
    EXPECT_EQ(parse_isa("avx2"), Isa::avx2);
    EXPECT_EQ(parse_isa("sse4.1"), Isa::sse4_1);
    EXPECT_EQ(parse_isa("sse2"), Isa::sse2);
    EXPECT_EQ(parse_isa("auto"), Isa::automatic);
    EXPECT_FALSE(parse_isa("AVX2"));
    EXPECT_FALSE(parse_isa("neon"));
    const Isa best = resolve_isa(Isa::automatic);
    EXPECT_NE(best, Isa::automatic);
    EXPECT_EQ(best, supported_isas().back());
    EXPECT_EQ(kernel_table(best).isa, best);
    for (Isa isa : compiled_isas()) EXPECT_STREQ(kernel_table(isa).name, isa_name(isa));
    EXPECT_EQ(kernel_table(Isa::avx512).lanes_per_register, 8u);
    EXPECT_EQ(kernel_table(Isa::avx512).traversal_width, 16u);
    for (Isa isa : {Isa::sse2, Isa::sse4_1, Isa::avx2})
        EXPECT_EQ(kernel_table(isa).traversal_width, 8u) << isa_name(isa);
    EXPECT_EQ(kernel_table(Isa::avx2).lanes_per_register, 8u);
    EXPECT_EQ(kernel_table(Isa::sse2).lanes_per_register, 4u);
}

TEST(CompileScene, SoaArraysArePaddedAlignedAndNeverHit) {
    std::mt19937 rng(1);
    const Scene scene = random_scene(rng, 13, 3);
    const CompiledScene c = compile_scene(scene);
    EXPECT_EQ(c.spheres.count, 13u);
    EXPECT_EQ(c.planes.count, 3u);
    EXPECT_EQ(c.spheres.padded_count, 16u);
    EXPECT_EQ(c.planes.padded_count, 8u);
    EXPECT_EQ(c.spheres.cx.size(), 16u);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(c.spheres.cx.data()) % 64, 0u);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(c.planes.d.data()) % 64, 0u);
    for (std::uint32_t k = c.spheres.count; k < c.spheres.padded_count; ++k)
        EXPECT_TRUE(std::isnan(c.spheres.cx[k]) && std::isnan(c.spheres.r2[k]));
    for (std::uint32_t k = c.planes.count; k < c.planes.padded_count; ++k)
        EXPECT_TRUE(std::isnan(c.planes.nx[k]) && std::isnan(c.planes.d[k]));
    // File order within each kind, and the file index kept for ties.
    std::uint32_t s = 0, p = 0;
    for (std::uint32_t k = 0; k < scene.objects.size(); ++k) {
        const Object& o = scene.objects[k];
        if (o.type == ObjectType::sphere) {
            EXPECT_EQ(c.spheres.object[s], k);
            EXPECT_EQ(c.spheres.r2[s], o.radius * o.radius);
            ++s;
        } else {
            EXPECT_EQ(c.planes.object[p], k);
            EXPECT_EQ(c.planes.d[p], dot(o.point, o.normal));
            ++p;
        }
    }
    EXPECT_GE(c.compile_seconds, 0.0);
}

// The highlight shortcut: below pow_zero_below powf gives exactly 0, just above it not.
TEST(CompileScene, PowZeroThresholdIsExact) {
    Scene scene;
    for (float n : {1.0f, 32.0f, 200.0f, 1000.0f}) {
        Material m;
        m.shininess = n;
        scene.materials.push_back({"", m});
    }
    const CompiledScene c = compile_scene(scene);
    for (std::uint32_t k = 0; k < 4; ++k) {
        const float n = c.materials.shininess[k], x = c.materials.pow_zero_below[k];
        ASSERT_GE(x, 0.0f);
        EXPECT_EQ(std::pow(x, n), 0.0f);
        EXPECT_GT(std::pow(std::nextafter(x, 2.0f), n), 0.0f);
    }
}

}  // namespace
}  // namespace octray
