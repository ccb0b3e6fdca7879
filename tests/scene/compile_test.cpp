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
    std::uint32_t si = 0, pi = 0;
    for (std::uint32_t k = 0; k < count; ++k) {
        const Object& obj = scene.objects[k];
        const bool plane = obj.type == ObjectType::plane;
        ASSERT_EQ(o.is_plane[k], plane ? 1u : 0u) << k;
        ASSERT_EQ(o.material[k], obj.material) << k;
        ASSERT_EQ(o.checker[k], plane && obj.material != 0 ? 1u : 0u) << k;
        if (plane) {
            ASSERT_EQ(o.cx[k], 0.0f) << k;  // a plane has no center
            ASSERT_EQ(o.cy[k], 0.0f) << k;
            ASSERT_EQ(o.cz[k], 0.0f) << k;
            ASSERT_EQ(o.nx[k], obj.normal.x) << k;
            ASSERT_EQ(o.nz[k], obj.normal.z) << k;
            const TangentBasis tb = checker_basis(obj.normal);
            ASSERT_EQ(o.t1x[k], tb.t1.x) << k;
            ASSERT_EQ(o.t2z[k], tb.t2.z) << k;
            ASSERT_EQ(p.object[pi], k);
            ASSERT_EQ(p.material[pi], obj.material);
            ASSERT_EQ(p.ny[pi], obj.normal.y);
            ASSERT_EQ(p.d[pi], dot(obj.point, obj.normal));
            ++pi;
        } else {
            ASSERT_EQ(o.cx[k], obj.center.x) << k;
            ASSERT_EQ(o.cy[k], obj.center.y) << k;
            ASSERT_EQ(o.cz[k], obj.center.z) << k;
            for (const auto* a :
                 {&o.nx, &o.ny, &o.nz, &o.t1x, &o.t1y, &o.t1z, &o.t2x, &o.t2y, &o.t2z})
                ASSERT_EQ((*a)[k], 0.0f) << k;  // a sphere has no normal or tangents
            ASSERT_EQ(s.object[si], k);
            ASSERT_EQ(s.material[si], obj.material);
            ASSERT_EQ(s.cx[si], obj.center.x);
            ASSERT_EQ(s.cy[si], obj.center.y);
            ASSERT_EQ(s.cz[si], obj.center.z);
            ASSERT_EQ(s.radius[si], obj.radius);
            ASSERT_EQ(s.r2[si], obj.radius * obj.radius);
            ++si;
        }
    }
    ASSERT_EQ(s.count, si);
    ASSERT_EQ(p.count, pi);
    // The padding: geometry that no ray hits, no object, no material, no checker.
    for (std::uint32_t k = count; k < o.padded_count; ++k) {
        EXPECT_EQ(o.is_plane[k], 0u);
        EXPECT_EQ(o.material[k], 0u);
        EXPECT_EQ(o.checker[k], 0u);
        EXPECT_EQ(o.cx[k], 0.0f);
        EXPECT_EQ(o.t2z[k], 0.0f);
    }
    for (std::uint32_t i = s.count; i < s.padded_count; ++i) {
        EXPECT_TRUE(std::isnan(s.cx[i]) && std::isnan(s.r2[i]) && std::isnan(s.radius[i]));
        EXPECT_EQ(s.object[i], std::numeric_limits<std::uint32_t>::max());
        EXPECT_EQ(s.material[i], 0u);
    }
    for (std::uint32_t i = p.count; i < p.padded_count; ++i) {
        EXPECT_TRUE(std::isnan(p.nx[i]) && std::isnan(p.d[i]));
        EXPECT_EQ(p.object[i], std::numeric_limits<std::uint32_t>::max());
    }
}

TEST(CompileScene, EveryEntryOfEveryArrayIsWritten) {
    expect_every_entry(1);
    expect_every_entry(21);
    expect_every_entry(40001);  // three blocks of the parallel fill, the last one short
}

}  // namespace
}  // namespace octray
