// compile_scene's flat arrays (scene/compile.h): every entry of every geometry array is
// written, each as the header documents it, however the objects fall into the parallel
// fill's blocks. The arrays are sized without being written, so an entry the fill missed
// holds whatever the allocator left there (under AddressSanitizer, 0xbe bytes for small
// arrays): these tests read every one.

#include "scene/compile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "tests/render/scene_builders.h"

namespace octray {
namespace {

// `count` objects, a plane every seventh (one with a checker material), the rest spheres.
Scene mixed_scene(std::uint32_t count) {
    Scene s = testing::empty_scene();
    Material checkered;
    checkered.checker = Checker{Rgb(0.1f), 2.0f};
    const std::uint32_t checker = testing::add_material(s, checkered);
    for (std::uint32_t k = 0; k < count; ++k) {
        const float f = static_cast<float>(k);
        if (k % 7 == 3)
            testing::add_plane(s, {0, -1 - f, 0}, {0.1f * (k % 5), 1, 0.2f},
                               k % 2 ? checker : 0);
        else
            testing::add_sphere(s, {f, -f, 0.5f * f}, 0.25f + 0.001f * f, k % 3 ? 0 : checker);
    }
    return s;
}

void expect_every_entry(std::uint32_t count) {
    SCOPED_TRACE(std::to_string(count) + " objects");
    const Scene scene = mixed_scene(count);
    const CompiledScene c = compile_scene(scene);
    const CompiledObjects& o = c.objects;
    const CompiledSpheres& s = c.spheres;
    const CompiledPlanes& p = c.planes;
    ASSERT_EQ(o.count, count);
    // The tangent columns exist in a scene with a checkered plane (the fourth object on),
    // and only there: shading reads them only for a lane that hit one.
    const bool checker_planes = count > 3;
    for (const auto* a : {&o.t1x, &o.t1y, &o.t1z, &o.t2x, &o.t2y, &o.t2z})
        ASSERT_EQ(a->size(), checker_planes ? o.padded_count : 0u);
    std::uint32_t si = 0, pi = 0;
    for (std::uint32_t k = 0; k < count; ++k) {
        const Object& obj = scene.objects[k];
        const bool plane = obj.type == ObjectType::plane;
        ASSERT_EQ(o.is_plane(k), plane) << k;
        ASSERT_EQ(o.material(k), obj.material) << k;
        ASSERT_EQ(o.checker(k), plane && obj.material != 0) << k;
        if (plane) {
            ASSERT_EQ(o.center(k), (Vec3{0, 0, 0})) << k;  // a plane has no center
            ASSERT_EQ(o.normal(k), obj.normal) << k;
            if (checker_planes) {
                const TangentBasis tb = checker_basis(obj.normal);
                ASSERT_EQ(o.t1x[k], tb.t1.x) << k;
                ASSERT_EQ(o.t1y[k], tb.t1.y) << k;
                ASSERT_EQ(o.t1z[k], tb.t1.z) << k;
                ASSERT_EQ(o.t2x[k], tb.t2.x) << k;
                ASSERT_EQ(o.t2y[k], tb.t2.y) << k;
                ASSERT_EQ(o.t2z[k], tb.t2.z) << k;
            }
            ASSERT_EQ(p.object[pi], k);
            ASSERT_EQ(p.ny[pi], obj.normal.y);
            ASSERT_EQ(p.d[pi], dot(obj.point, obj.normal));
            ++pi;
        } else {
            ASSERT_EQ(o.center(k), obj.center) << k;
            ASSERT_EQ(o.normal(k), (Vec3{0, 0, 0})) << k;  // a sphere has no normal
            if (checker_planes) {
                for (const auto* a : {&o.t1x, &o.t1y, &o.t1z, &o.t2x, &o.t2y, &o.t2z})
                    ASSERT_EQ((*a)[k], 0.0f) << k;  // nor tangents
            }
            ASSERT_EQ(s.object[si], k);
            ASSERT_EQ(s.cx[si], obj.center.x);
            ASSERT_EQ(s.cy[si], obj.center.y);
            ASSERT_EQ(s.cz[si], obj.center.z);
            ASSERT_EQ(s.r2[si], obj.radius * obj.radius);
            ++si;
        }
    }
    ASSERT_EQ(s.count, si);
    ASSERT_EQ(p.count, pi);
    // The epsilon, from the spheres' box the fill's blocks measured: the whole scene's.
    EXPECT_EQ(c.epsilon, self_intersection_epsilon(scene));
    Scene fixed = scene;
    fixed.render.epsilon = 0.125f;
    EXPECT_EQ(compile_scene(fixed).epsilon, 0.125f);
    // The padding: geometry that no ray hits, no object, no material, no checker.
    ASSERT_EQ(o.record.size(), std::size_t{o.padded_count} * kObjectRecordFloats);
    for (std::uint32_t k = count; k < o.padded_count; ++k) {
        for (std::uint32_t f = 0; f < kObjectRecordFloats; ++f)
            EXPECT_EQ(o.record_of(k)[f], 0.0f);  // a sphere at the origin, material 0
        if (checker_planes) {
            EXPECT_EQ(o.t2z[k], 0.0f);
        }
    }
    for (std::uint32_t i = s.count; i < s.padded_count; ++i) {
        EXPECT_TRUE(std::isnan(s.cx[i]) && std::isnan(s.r2[i]));
        EXPECT_EQ(s.object[i], std::numeric_limits<std::uint32_t>::max());
    }
    for (std::uint32_t i = p.count; i < p.padded_count; ++i) {
        EXPECT_TRUE(std::isnan(p.nx[i]) && std::isnan(p.d[i]));
        EXPECT_EQ(p.object[i], std::numeric_limits<std::uint32_t>::max());
    }
}

TEST(CompileScene, EveryEntryOfEveryArrayIsWritten) {
    expect_every_entry(1);
    expect_every_entry(3);
    expect_every_entry(4);  // the first plane, checkered
    expect_every_entry(21);
    expect_every_entry(40001);  // three blocks of the parallel fill, the last one short
}

// Planes without a checker, and spheres with one (a checker colours planes only), need no
// tangent basis.
TEST(CompileScene, NoTangentColumnsWithoutACheckeredPlane) {
    Scene s = testing::empty_scene();
    Material checkered;
    checkered.checker = Checker{Rgb(0.1f), 2.0f};
    const std::uint32_t checker = testing::add_material(s, checkered);
    testing::add_plane(s, {0, -1, 0}, {0, 1, 0}, 0);
    testing::add_sphere(s, {0, 0, -3}, 1.0f, checker);
    const CompiledScene c = compile_scene(s);
    EXPECT_FALSE(c.objects.checker(0));
    for (const auto* a : {&c.objects.t1x, &c.objects.t1y, &c.objects.t1z, &c.objects.t2x,
                          &c.objects.t2y, &c.objects.t2z})
        EXPECT_TRUE(a->empty());
    s.objects[0].material = checker;
    const CompiledScene with = compile_scene(s);
    EXPECT_TRUE(with.objects.checker(0));
    ASSERT_EQ(with.objects.t1x.size(), with.objects.padded_count);
    EXPECT_EQ(with.objects.t2y[0], checker_basis(s.objects[0].normal).t2.y);
}

}  // namespace
}  // namespace octray
