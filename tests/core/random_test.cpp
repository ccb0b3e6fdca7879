#include "core/random.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

namespace octray {
namespace {

TEST(Random, IsAPureFunctionOfItsCounter) {
    EXPECT_EQ(sample_uniform(3, 10, 20, 5, 1, 42), sample_uniform(3, 10, 20, 5, 1, 42));
    // Every field of the counter changes the value.
    const float base = sample_uniform(0, 1, 2, 3, 0, 7);
    EXPECT_NE(base, sample_uniform(1, 1, 2, 3, 0, 7));
    EXPECT_NE(base, sample_uniform(0, 2, 2, 3, 0, 7));
    EXPECT_NE(base, sample_uniform(0, 1, 3, 3, 0, 7));
    EXPECT_NE(base, sample_uniform(0, 1, 2, 4, 0, 7));
    EXPECT_NE(base, sample_uniform(0, 1, 2, 3, 1, 7));
    EXPECT_NE(base, sample_uniform(0, 1, 2, 3, 0, 8));
    // i and j are not interchangeable (a symmetric hash would give the same value).
    EXPECT_NE(sample_uniform(0, 1, 2, 0, 0, 0), sample_uniform(0, 2, 1, 0, 0, 0));
}

TEST(Random, UniformInUnitIntervalWithPlausibleMoments) {
    double sum = 0.0, sum2 = 0.0;
    const int n = 100000;
    for (int k = 0; k < n; ++k) {
        const float u = sample_uniform(0, static_cast<std::uint32_t>(k % 317),
                                       static_cast<std::uint32_t>(k / 317), 0, 0, 0);
        ASSERT_GE(u, 0.0f);
        ASSERT_LT(u, 1.0f);
        sum += u;
        sum2 += static_cast<double>(u) * u;
    }
    const double mean = sum / n, var = sum2 / n - mean * mean;
    EXPECT_NEAR(mean, 0.5, 0.01);
    EXPECT_NEAR(var, 1.0 / 12.0, 0.01);
}

TEST(Random, OneSamplePerPixelUsesThePixelCenter) {
    const PixelOffset o = pixel_sample_offset(0, 5, 6, 0, 1, 99);
    EXPECT_EQ(o.ox, 0.5f);
    EXPECT_EQ(o.oy, 0.5f);
}

TEST(Random, SquareSppIsStratifiedOneSamplePerStratum) {
    for (std::uint32_t spp : {4u, 16u}) {
        const auto n = static_cast<std::uint32_t>(std::lround(std::sqrt(spp)));
        std::set<std::pair<int, int>> strata;
        for (std::uint32_t s = 0; s < spp; ++s) {
            const PixelOffset o = pixel_sample_offset(0, 3, 4, s, spp, 1);
            ASSERT_GE(o.ox, 0.0f);
            ASSERT_LT(o.ox, 1.0f);
            strata.insert({static_cast<int>(o.ox * static_cast<float>(n)),
                           static_cast<int>(o.oy * static_cast<float>(n))});
        }
        EXPECT_EQ(strata.size(), spp) << "spp " << spp;
    }
}

TEST(Random, NonSquareSppJittersUniformly) {
    const PixelOffset a = pixel_sample_offset(0, 3, 4, 0, 3, 1);
    const PixelOffset b = pixel_sample_offset(0, 3, 4, 1, 3, 1);
    EXPECT_NE(a.ox, b.ox);
    EXPECT_EQ(a.ox, sample_uniform(0, 3, 4, 0, kDimPixelX, 1));
    EXPECT_EQ(a.oy, sample_uniform(0, 3, 4, 0, kDimPixelY, 1));
}

}  // namespace
}  // namespace octray
