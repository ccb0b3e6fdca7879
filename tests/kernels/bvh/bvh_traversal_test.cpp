// The sphere BVH's traversal (kernels/stream/hit_kernels.h and the kernels/bvh/ headers it
// includes), under every ISA the CPU runs and with packets, single rays and the switch
// between them: closest hits equal the scalar reference's (brute force) bit for bit and hit
// for hit on random rays over random and degenerate scenes
// (tests/kernels/bvh/bvh_test_scenes.h); any-hit equals the reference's occlusion and agrees
// with closest hit. The builder: tests/render/prepare/bvh_build_test.cpp.

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/aligned.h"
#include "kernels/dispatch.h"
#include "render/prepare/bvh_build.h"
#include "render/prepare/scene_view.h"
#include "render/reference.h"
#include "scene/compile.h"
#include "tests/kernels/bvh/bvh_test_scenes.h"

namespace octray {
namespace {

using kernels::kPacketWidth;
using testing::large_scene;
using testing::NamedScene;
using testing::random_spheres;
using testing::scene_of;
using testing::sphere;
using testing::test_scenes;

std::size_t padded(std::size_t n) {
    return (n + kPacketWidth - 1) / kPacketWidth * kPacketWidth;
}

// ---------------------------------------------------------------------------------------
// Traversal against brute force.

template <Isa I>
struct IsaTag {
    static constexpr Isa isa = I;
};
using Isas = ::testing::Types<IsaTag<Isa::sse2>, IsaTag<Isa::sse4_1>, IsaTag<Isa::avx2>,
                              IsaTag<Isa::avx512>>;

struct RaySoA {
    AlignedVector<float> ox, oy, oz, dx, dy, dz, w, t_max, term;
    AlignedVector<std::uint32_t> pixel;
    std::size_t n = 0;
    explicit RaySoA(const std::vector<Ray>& rays) : n(rays.size()) {
        // Exactly the stream's whole 8-ray packets (kernel_types.h): a kernel that reads
        // past them (a 16-ray traversal packet over a tail of 8 or fewer) fails under ASan.
        const std::size_t c = padded(n);
        for (auto* v : {&ox, &oy, &oz, &dx, &dy, &dz, &w, &t_max}) v->assign(c, 0.0f);
        term.assign(3 * c, 0.0f);
        pixel.assign(c, 0u);
        for (std::size_t i = 0; i < n; ++i) {
            const Ray& r = rays[i];
            ox[i] = r.origin.x, oy[i] = r.origin.y, oz[i] = r.origin.z;
            dx[i] = r.direction.x, dy[i] = r.direction.y, dz[i] = r.direction.z;
            t_max[i] = r.t_max;
        }
    }
    kernels::RayStream stream() {
        return {ox.data(), oy.data(), oz.data(), dx.data(), dy.data(),
                dz.data(), w.data(),  w.data(),  w.data(),  pixel.data()};
    }
    kernels::ShadowStream shadow() {
        const std::size_t c = t_max.size();
        return {ox.data(),       oy.data(),           oz.data(),    dx.data(),
                dy.data(),       dz.data(),           t_max.data(), term.data(),
                term.data() + c, term.data() + 2 * c, pixel.data()};
    }
};

// The box of the scene's sphere centers (a unit box without spheres), and random points in
// it grown by `grow` of its extent on each side.
struct CenterBox {
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};

    explicit CenterBox(const CompiledScene& c) {
        for (std::uint32_t i = 0; i < c.spheres.count; ++i) {
            const float p[3] = {c.spheres.cx[i], c.spheres.cy[i], c.spheres.cz[i]};
            for (int a = 0; a < 3; ++a)
                lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
        }
        if (c.spheres.count == 0) lo[0] = lo[1] = lo[2] = -1, hi[0] = hi[1] = hi[2] = 1;
    }
    Vec3 random_point(std::mt19937& rng, float grow) const {
        std::uniform_real_distribution<float> u01(0.0f, 1.0f);
        Vec3 p;
        float* q[3] = {&p.x, &p.y, &p.z};
        for (int a = 0; a < 3; ++a) {
            const float ext = std::max(hi[a] - lo[a], 1e-3f);
            *q[a] = lo[a] - grow * ext + (1 + 2 * grow) * ext * u01(rng);
        }
        return p;
    }
};

// Random rays (random origins and directions, some unnormalised, some axis-aligned), and
// coherent bundles from one point towards the scene (packets that stay together).
std::vector<Ray> test_rays(const CompiledScene& c, std::mt19937& rng, std::size_t count) {
    std::uniform_real_distribution<float> u01(0.0f, 1.0f), unit(-1.0f, 1.0f);
    const CenterBox box(c);
    const auto in_box = [&](float grow) { return box.random_point(rng, grow); };
    std::vector<Ray> rays;
    while (rays.size() < count) {
        const int kind = static_cast<int>(rays.size() / 8 % 6);
        if (kind == 5 && c.spheres.count > 0) {
            // Nearly parallel to a face of the sphere's box, passing just outside the point
            // where the sphere touches it, from 10 to 10^5 radii away: the rays the brute
            // force may report as hits by rounding (l is off by ~u|O'|) while the exact box
            // says miss, which only the traversal's widening keeps. Rare with the robust
            // form: in 2M such rays (a standalone check in double), 3 of ~97 000 reported
            // hits missed the exact box, by at most 0.08 u|O'|; the widening is 96 u D.
            const auto i = static_cast<std::uint32_t>(rng() % c.spheres.count);
            const Vec3 center{c.spheres.cx[i], c.spheres.cy[i], c.spheres.cz[i]};
            const float radius = std::sqrt(c.spheres.r2[i]);
            const float distance = radius * std::pow(10.0f, 1.0f + 4.0f * u01(rng));
            const float u = 0x1.0p-24f, slack = 8.0f * u * distance;
            const auto axis = static_cast<int>(rng() % 3);
            const auto along = static_cast<int>((axis + 1 + rng() % 2) % 3);
            const auto unit_vector = [](int a, float v) {
                return Vec3{a == 0 ? v : 0.0f, a == 1 ? v : 0.0f, a == 2 ? v : 0.0f};
            };
            const float side = (rng() % 2 ? 1.0f : -1.0f) * (radius + slack * u01(rng));
            const Vec3 touch = center + unit_vector(axis, side);
            const Vec3 direction =
                normalize(unit_vector(along, 1.0f) +
                          unit_vector(axis, (u01(rng) - 0.5f) * slack / radius));
            Ray r;
            r.origin = touch - direction * distance;
            r.direction = direction;
            r.t_max = distance * (0.5f + u01(rng));
            rays.push_back(r);
            continue;
        }
        if (kind == 4 && c.spheres.count > 0) {
            // Aimed from afar (1 to 1000 units) at a sphere, missing its center by about
            // its radius or by the brute force's rounding fuzz (~sqrt(u) * distance): the
            // grazing rays whose hits only exact arithmetic decides.
            const auto i = static_cast<std::uint32_t>(rng() % c.spheres.count);
            const Vec3 center{c.spheres.cx[i], c.spheres.cy[i], c.spheres.cz[i]};
            const float radius = std::sqrt(c.spheres.r2[i]);
            const float distance = std::pow(10.0f, 3.0f * u01(rng));
            const Vec3 from = normalize(Vec3{unit(rng), unit(rng), unit(rng)});
            const float fuzz = 1e-3f * distance * u01(rng);
            const float miss = (rng() % 2 ? radius : 0.0f) + (rng() % 2 ? fuzz : 0.0f);
            const Vec3 side = normalize(cross(from, Vec3{0.577f, 0.577f, -0.577f}));
            Ray r;
            r.origin = center + from * distance;
            r.direction = normalize(center + side * (miss * (u01(rng) * 2.0f)) - r.origin);
            r.t_max = distance * (0.5f + u01(rng));
            rays.push_back(r);
            continue;
        }
        if (kind == 3) {
            // A coherent packet: one origin, directions towards a small region.
            const Vec3 origin = in_box(1.0f), target = in_box(0.0f);
            for (int k = 0; k < 8; ++k) {
                Ray r;
                r.origin = origin;
                const Vec3 jitter{0.02f * unit(rng), 0.02f * unit(rng), 0.02f * unit(rng)};
                r.direction =
                    normalize(target + jitter * (box.hi[0] - box.lo[0] + 1e-3f) - origin);
                r.t_max = 0.5f + 2 * u01(rng);
                rays.push_back(r);
            }
            continue;
        }
        Ray r;
        r.origin = in_box(kind == 0 ? 0.2f : 1.0f);
        if (kind == 2 && rays.size() % 3 == 0) {
            const float sign = u01(rng) < 0.5f ? -1.0f : 1.0f;
            const std::size_t axis = rays.size() % 9 / 3;
            r.direction = {axis == 0 ? sign : 0.0f, axis == 1 ? sign : 0.0f,
                           axis == 2 ? sign : 0.0f};
        } else {
            r.direction =
                (kind == 1 ? in_box(0.0f) - r.origin : Vec3{unit(rng), unit(rng), unit(rng)});
            if (!(length(r.direction) > 1e-3f)) r.direction = {0, 1, 0};
            if (kind != 1) r.direction = normalize(r.direction);
        }
        r.t_max = kind == 1 ? u01(rng) * 1.2f : INFINITY;  // shadow-like rays end early
        rays.push_back(r);
    }
    return rays;
}

template <class Tag>
class BvhTraversalTest : public ::testing::Test {
  protected:
    void SetUp() override {
        if (!isa_supported(Tag::isa)) GTEST_SKIP() << isa_name(Tag::isa) << " not on this CPU";
    }

    // closest_hit and any_hit with the BVH (with this packet/single-ray switch) against the
    // reference, ray by ray; and any-hit against closest hit.
    void check(const NamedScene& ns, std::uint32_t packet_min_lanes, std::size_t ray_count) {
        SCOPED_TRACE(ns.name + ", packet_min_lanes " + std::to_string(packet_min_lanes));
        const CompiledScene c = compile_scene(ns.scene);
        const SphereBvh bvh = build_sphere_bvh(c.spheres);
        kernels::SceneView view = make_scene_view(c, bvh, packet_min_lanes);
        // Shadow rays regrouped whatever the scene's size (the default keeps the order
        // given below kBvhShadowSortMinSpheres; the loop after any_hit checks that path).
        view.bvh_shadow_sort_min_spheres = 0;
        // The traversal even in small trees (one sphere), which otherwise test every sphere.
        view.bvh_brute_force_max_spheres = 0;
        ASSERT_NE(view.bvh_nodes, nullptr);
        const kernels::KernelTable& k = kernel_table(Tag::isa);
        const ReferenceTracer ref(ns.scene);
        std::mt19937 rng(99 + packet_min_lanes);
        const std::vector<Ray> rays = test_rays(c, rng, ray_count);
        // Odd counts leave dead lanes in the last packet: 1197, 597 and 397 rays end with
        // 13, 5 and 13 rays past the last multiple of 16 (AVX-512's traversal packets).
        const auto n = static_cast<std::uint32_t>(rays.size() - 3);
        RaySoA soa(rays);
        int mismatches = 0;
        // Secondary rays (t_min 0) by the same rule as the others, and ray by ray as in
        // large BVHs (SceneView::bvh_secondary_min_lanes).
        for (const auto& [t_min, secondary] :
             {std::pair{0.0f, packet_min_lanes}, std::pair{0.0f, kPacketWidth + 1},
              std::pair{1e-3f, packet_min_lanes}}) {
            SCOPED_TRACE("secondary rays' min lanes " + std::to_string(secondary));
            kernels::SceneView v = view;
            v.bvh_secondary_min_lanes = secondary;
            AlignedVector<float> t(padded(n), -7.0f), t0(padded(n), -7.0f);
            AlignedVector<std::int32_t> id(padded(n), -7);
            k.closest_hit(v, soa.stream(), n, t_min, {t.data(), id.data()});
            for (std::uint32_t i = 0; i < n && mismatches < 10; ++i) {
                Ray r = rays[i];
                r.t_min = t_min;
                r.t_max = INFINITY;
                const std::optional<SurfaceHit> hit = ref.intersect(r);
                const std::int32_t want_id = hit ? static_cast<std::int32_t>(hit->object) : -1;
                const float want_t = hit ? hit->t : INFINITY;
                if (id[i] != want_id || !(t[i] == want_t)) {
                    ++mismatches;
                    ADD_FAILURE()
                        << "closest hit, ray " << i << " t_min " << t_min << ": got " << id[i]
                        << " at " << t[i] << ", reference " << want_id << " at " << want_t;
                }
            }
        }
        AlignedVector<std::uint32_t> occluded(padded(n) + kPacketWidth, 7u);
        k.any_hit(view, soa.shadow(), n, occluded.data());
        // In the order given (a short stream, or a small scene) as regrouped.
        for (const std::uint32_t few : {21u, n}) {
            kernels::SceneView in_order = view;
            in_order.bvh_shadow_sort_min_spheres = few == n ? ~0u : 0u;
            AlignedVector<std::uint32_t> got(padded(n) + kPacketWidth, 7u);
            k.any_hit(in_order, soa.shadow(), few, got.data());
            for (std::uint32_t i = 0; i < few; ++i)
                EXPECT_EQ(got[i], occluded[i]) << "ray " << i << " of " << few << " in order";
        }
        AlignedVector<float> t(padded(n), -7.0f);
        AlignedVector<std::int32_t> id(padded(n), -7);
        k.closest_hit(view, soa.stream(), n, 0.0f, {t.data(), id.data()});
        for (std::uint32_t i = 0; i < n && mismatches < 10; ++i) {
            Ray r = rays[i];
            r.t_min = 0.0f;
            const bool want = ref.occluded(r);
            if (occluded[i] != (want ? 1u : 0u)) {
                ++mismatches;
                ADD_FAILURE() << "any hit, ray " << i << ": got " << occluded[i]
                              << ", reference " << want;
            }
            // Occluded on (0, t_max) exactly when the closest hit on (0, inf) is nearer.
            EXPECT_EQ(occluded[i], t[i] < rays[i].t_max ? 1u : 0u) << "ray " << i;
        }
    }
};
TYPED_TEST_SUITE(BvhTraversalTest, Isas);

// Streams whose groups of 256 rays share their origin: the beams of closest_hit
// (kernels/bvh/bvh_beam.h). Each group is a grid of 16 x 16 directions about a random axis,
// from 1e-4 to 1 radian wide, from an origin in or around the scene; in every other group
// the grid's first row grazes a sphere's silhouette (to within a few ulps, from 10 to 10^6
// radii away), so that the sphere lies on the edge of the beam's pyramid and of its first
// packet's. A last group of 37 rays leaves a partial beam.
std::vector<Ray> beam_test_rays(const CompiledScene& c, std::mt19937& rng, int groups,
                                bool wide) {
    std::uniform_real_distribution<float> u01(0.0f, 1.0f), unit(-1.0f, 1.0f);
    const CenterBox box(c);
    const auto in_box = [&](float grow) { return box.random_point(rng, grow); };
    std::vector<Ray> rays;
    for (int g = 0; g <= groups; ++g) {
        Vec3 origin = in_box(wide ? 0.0f : 1.5f), axis = normalize(in_box(0.0f) - origin);
        // Radians across the grid; wide groups from inside the scene hold many spheres.
        float width = wide ? 0.5f + u01(rng) : std::pow(10.0f, -4.0f + 4.0f * u01(rng));
        Vec3 right = normalize(cross(axis, Vec3{0.36f, 0.8f, -0.48f}));
        Vec3 up = cross(right, axis);
        const bool graze = g % 2 == 1;
        if (graze) {
            // The ray along the axis passes sphere i at r + miss from its center, offset
            // along the normal of one of the beam's planes (the plane of slopes through
            // the axis that holds the coordinate axis b): the sphere lies just outside or
            // inside the face of the pyramid. |miss| goes up to 64 u D, beyond the exact
            // test's rounding (10 u |O'|), whose hits the beam must keep. The first row
            // lies in that plane (column 8 on the axis); the others step away from the
            // sphere, and the grid is narrow (down to rays equal in float), so that the
            // pyramid's face is the grazing plane.
            const auto i = static_cast<std::uint32_t>(rng() % c.spheres.count);
            const Vec3 center{c.spheres.cx[i], c.spheres.cy[i], c.spheres.cz[i]};
            const float r = std::sqrt(c.spheres.r2[i]);
            const float distance = r * std::pow(10.0f, 1.0f + 5.0f * u01(rng));
            axis = normalize(Vec3{unit(rng), unit(rng), unit(rng)});
            const float comp[3] = {std::fabs(axis.x), std::fabs(axis.y), std::fabs(axis.z)};
            const int m = comp[0] >= comp[1] && comp[0] >= comp[2] ? 0
                          : comp[1] >= comp[2]                     ? 1
                                                                   : 2;
            const int b = (m + 1 + static_cast<int>(rng() % 2)) % 3;
            const Vec3 e_b{b == 0 ? 1.0f : 0.0f, b == 1 ? 1.0f : 0.0f, b == 2 ? 1.0f : 0.0f};
            const Vec3 side = normalize(cross(axis, e_b)) * (rng() % 2 ? 1.0f : -1.0f);
            const float miss =
                unit(rng) * 64.0f * 0x1.0p-24f * distance * std::pow(10.0f, -2.0f * u01(rng));
            origin = center - axis * distance - side * (r + miss);
            right = normalize(cross(axis, side));
            up = side * -1.0f;
            width = std::pow(10.0f, -9.0f + 5.0f * u01(rng));
        }
        const int count = g == groups ? 37 : 256;
        for (int k = 0; k < count; ++k) {
            const float x = (static_cast<float>(k % 16) - 8.0f) / 15.0f * width;
            const float y =
                (static_cast<float>(k / 16) - (graze ? 0.0f : 7.5f)) / 15.0f * width;
            Ray r;
            r.origin = origin;
            r.direction = axis + right * x + up * y;
            r.t_max = INFINITY;
            rays.push_back(r);
        }
    }
    return rays;
}

template <class Tag>
class BeamTraversalTest : public BvhTraversalTest<Tag> {
  protected:
    // closest_hit on beams against the reference, ray by ray, bit for bit.
    void check_beams(const NamedScene& ns, int groups, bool wide = false) {
        SCOPED_TRACE(ns.name);
        const CompiledScene c = compile_scene(ns.scene);
        const SphereBvh bvh = build_sphere_bvh(c.spheres);
        kernels::SceneView view = make_scene_view(c, bvh, 3);
        view.bvh_brute_force_max_spheres = 0;  // beams and the traversal in small trees too
        ASSERT_NE(view.bvh_nodes, nullptr);
        const kernels::KernelTable& k = kernel_table(Tag::isa);
        const ReferenceTracer ref(ns.scene);
        std::mt19937 rng(4242);
        const std::vector<Ray> rays = beam_test_rays(c, rng, groups, wide);
        const auto n = static_cast<std::uint32_t>(rays.size());
        RaySoA soa(rays);
        int mismatches = 0;
        for (const float t_min : {1e-3f, 0.0f}) {
            AlignedVector<float> t(padded(n), -7.0f);
            AlignedVector<std::int32_t> id(padded(n), -7);
            k.closest_hit(view, soa.stream(), n, t_min, {t.data(), id.data()});
            for (std::uint32_t i = 0; i < n && mismatches < 10; ++i) {
                Ray r = rays[i];
                r.t_min = t_min;
                const std::optional<SurfaceHit> hit = ref.intersect(r);
                const std::int32_t want_id = hit ? static_cast<std::int32_t>(hit->object) : -1;
                const float want_t = hit ? hit->t : INFINITY;
                if (id[i] != want_id || !(t[i] == want_t)) {
                    ++mismatches;
                    ADD_FAILURE() << "closest hit, ray " << i << " (group " << i / 256
                                  << ") t_min " << t_min << ": got " << id[i] << " at " << t[i]
                                  << ", reference " << want_id << " at " << want_t;
                }
            }
        }
    }

    // any_hit on shadow beams against the reference: the same groups turned around, each
    // ray a segment from a point beyond the scene (or inside it) back to the group's
    // origin, as shadow rays towards a point light (V = L - P, t_max = 1), in every other
    // group from points moved off by up to 1e-3 of the segment (as P + eps N is).
    void check_shadow_beams(const NamedScene& ns, int groups, bool wide = false) {
        SCOPED_TRACE(ns.name + ", shadow beams");
        const CompiledScene c = compile_scene(ns.scene);
        const SphereBvh bvh = build_sphere_bvh(c.spheres);
        kernels::SceneView view = make_scene_view(c, bvh, 3);
        view.bvh_shadow_sort_min_spheres = ~0u;  // in the order given: the beams' path
        view.bvh_brute_force_max_spheres = 0;    // in small trees too
        const kernels::KernelTable& k = kernel_table(Tag::isa);
        const ReferenceTracer ref(ns.scene);
        std::mt19937 rng(4243);
        std::uniform_real_distribution<float> u01(0.0f, 1.0f), unit(-1.0f, 1.0f);
        std::vector<Ray> rays = beam_test_rays(c, rng, groups, wide);
        for (std::size_t g = 0; g < rays.size(); g += 256) {
            const float reach = std::pow(10.0f, (wide ? 0.0f : -1.0f) + 3.0f * u01(rng));
            const bool moved = g / 256 % 2 == 1;
            for (std::size_t i = g; i < std::min(rays.size(), g + 256); ++i) {
                Ray& r = rays[i];
                const Vec3 light = r.origin;
                Vec3 from = light + r.direction * reach;
                if (moved)
                    from = from + Vec3{unit(rng), unit(rng), unit(rng)} * (1e-4f * reach);
                r.origin = from;
                r.direction = light - from;
                r.t_max = 1.0f;
            }
        }
        const auto n = static_cast<std::uint32_t>(rays.size());
        RaySoA soa(rays);
        AlignedVector<std::uint32_t> occluded(padded(n) + kPacketWidth, 7u);
        k.any_hit(view, soa.shadow(), n, occluded.data());
        int mismatches = 0;
        for (std::uint32_t i = 0; i < n && mismatches < 10; ++i) {
            const bool want = ref.occluded(rays[i]);
            if (occluded[i] != (want ? 1u : 0u)) {
                ++mismatches;
                ADD_FAILURE() << "any hit, ray " << i << " (group " << i / 256 << "): got "
                              << occluded[i] << ", reference " << want;
            }
        }
    }
};
TYPED_TEST_SUITE(BeamTraversalTest, Isas);

TYPED_TEST(BeamTraversalTest, GroupsFromOneOrigin) {
    for (const NamedScene& ns : test_scenes()) this->check_beams(ns, 16);
}

TYPED_TEST(BeamTraversalTest, ShadowGroupsTowardsOnePoint) {
    for (const NamedScene& ns : test_scenes()) this->check_shadow_beams(ns, 16);
}

// More spheres in a beam than it gathers (kBeamMaxSpheres): its packets finish in the BVH
// where their hits lie beyond the spheres gathered.
TYPED_TEST(BeamTraversalTest, CrowdedBeams) {
    std::mt19937 rng(77);
    const NamedScene crowded{"4000 small spheres",
                             scene_of(random_spheres(rng, 4000, 2.0f, 0.01f, 0.04f))};
    this->check_beams(crowded, 16, true);
    this->check_shadow_beams(crowded, 16, true);
    this->check_beams(large_scene(), 8);
    this->check_shadow_beams(large_scene(), 8);
}

TYPED_TEST(BvhTraversalTest, PacketsSwitchingToSingleRays) {
    for (const NamedScene& ns : test_scenes()) this->check(ns, 3, 1200);
}

TYPED_TEST(BvhTraversalTest, PacketsOnly) {
    for (const NamedScene& ns : test_scenes()) this->check(ns, 0, 600);
}

TYPED_TEST(BvhTraversalTest, SingleRaysOnly) {
    for (const NamedScene& ns : test_scenes()) this->check(ns, 9, 600);
}

TYPED_TEST(BvhTraversalTest, LargeTree) {
    const NamedScene ns = large_scene();
    for (std::uint32_t lanes : {0u, 2u, 9u}) this->check(ns, lanes, 400);
}

}  // namespace
}  // namespace octray
