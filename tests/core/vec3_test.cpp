#include "core/vec3.h"

#include <gtest/gtest.h>

#include "core/color.h"
#include "core/ray.h"

namespace octray {
namespace {

TEST(Vec3, DotCrossAndNormalize) {
    const Vec3 x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
    EXPECT_EQ(cross(x, y), z);  // right-handed
    EXPECT_EQ(cross(y, z), x);
    EXPECT_EQ(cross(z, x), y);
    EXPECT_FLOAT_EQ(dot(Vec3{1, 2, 3}, Vec3{4, -5, 6}), 12.0f);
    const Vec3 n = normalize(Vec3{3, 0, 4});
    EXPECT_FLOAT_EQ(n.x, 0.6f);
    EXPECT_FLOAT_EQ(n.z, 0.8f);
    EXPECT_FLOAT_EQ(length(n), 1.0f);
}

TEST(Vec3, ComponentwiseMinMaxAndIndexing) {
    const Vec3 a{1, 5, -2}, b{3, -1, 0};
    EXPECT_EQ(min(a, b), (Vec3{1, -1, -2}));
    EXPECT_EQ(max(a, b), (Vec3{3, 5, 0}));
    EXPECT_EQ(a[0], 1.0f);
    EXPECT_EQ(a[1], 5.0f);
    EXPECT_EQ(a[2], -2.0f);
}

TEST(Ray, PointAtParameterAndOpenLiveInterval) {
    const Ray r{{1, 2, 3}, {0, 0, -2}, 0.5f, 4.0f};
    EXPECT_EQ(r.at(1.5f), (Vec3{1, 2, 0}));
    EXPECT_FALSE(r.live(0.5f));  // open interval: the ends are not live
    EXPECT_TRUE(r.live(0.6f));
    EXPECT_FALSE(r.live(4.0f));
    EXPECT_FALSE(r.live(-1.0f));
}

TEST(Rgb, OperatorsThatMakeSense) {
    const Rgb a{0.5f, 1.0f, 2.0f}, b{2.0f, 0.5f, 0.25f};
    EXPECT_EQ(a * b, (Rgb{1.0f, 0.5f, 0.5f}));  // filtering is component-wise
    EXPECT_EQ(a + b, (Rgb{2.5f, 1.5f, 2.25f}));
    EXPECT_EQ(a * 2.0f, (Rgb{1.0f, 2.0f, 4.0f}));
    EXPECT_EQ(Rgb(0.3f), (Rgb{0.3f, 0.3f, 0.3f}));  // a bare number is grey
    EXPECT_EQ(max_component(b), 2.0f);
    EXPECT_EQ(mix(Rgb(0.0f), Rgb(1.0f), 0.25f), Rgb(0.25f));
    EXPECT_FALSE(is_finite(Rgb{0.0f, kInfinity, 0.0f}));
}

}  // namespace
}  // namespace octray
