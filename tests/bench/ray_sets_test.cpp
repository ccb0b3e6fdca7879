// bench/ray_sets.h: pixel orders, ray set generation, and the validation that decides
// whether a bench row's speed means anything.

#include "bench/ray_sets.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>
#include <set>

#include "scene/load.h"

namespace octray::bench {
namespace {

// ---- Pixel orders ----------------------------------------------------------------------

struct FrameCase {
    int width, height;
    TileSize tile;
};

class PixelOrderTest : public ::testing::TestWithParam<FrameCase> {};

TEST_P(PixelOrderTest, EveryOrderVisitsEveryPixelExactlyOnce) {
    const FrameCase c = GetParam();
    const std::size_t n = static_cast<std::size_t>(c.width) * c.height;
    for (PixelOrder order : {PixelOrder::rowmajor, PixelOrder::tiled, PixelOrder::morton}) {
        SCOPED_TRACE(pixel_order_name(order));
        const std::vector<std::uint32_t> visit = pixel_order(c.width, c.height, order, c.tile);
        ASSERT_EQ(visit.size(), n);
        std::vector<int> seen(n, 0);
        for (std::uint32_t p : visit) {
            ASSERT_LT(p, n);
            ++seen[p];
        }
        EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int s) { return s == 1; }));
    }
}

INSTANTIATE_TEST_SUITE_P(Frames, PixelOrderTest,
                         ::testing::Values(FrameCase{1, 1, {16, 16}}, FrameCase{7, 5, {16, 16}},
                                           FrameCase{64, 36, {16, 16}},
                                           FrameCase{33, 17, {5, 3}},
                                           FrameCase{320, 180, {100, 100}},
                                           FrameCase{3, 70, {1, 1}}));

TEST(PixelOrder, RowMajorIsScanlines) {
    const std::vector<std::uint32_t> visit = pixel_order(5, 3, PixelOrder::rowmajor);
    std::vector<std::uint32_t> expected(15);
    std::iota(expected.begin(), expected.end(), 0u);
    EXPECT_EQ(visit, expected);
}

TEST(PixelOrder, TiledFinishesATileBeforeTheNext) {
    // 6 x 4 frame, 4 x 2 tiles: the first tile is columns 0-3 of rows 0-1; the second tile
    // (columns 4-5, rows 0-1) is clipped by the frame.
    const std::vector<std::uint32_t> visit = pixel_order(6, 4, PixelOrder::tiled, {4, 2});
    const std::vector<std::uint32_t> first_two_tiles{0, 1, 2, 3, 6, 7, 8, 9, 4, 5, 10, 11};
    EXPECT_EQ(std::vector<std::uint32_t>(visit.begin(), visit.begin() + 12), first_two_tiles);
}

TEST(PixelOrder, MortonPacketsAreFourByTwoBlocks) {
    // On a 16 x 16 frame each run of 8 codes is a 4 x 2 block of pixels.
    const std::vector<std::uint32_t> visit = pixel_order(16, 16, PixelOrder::morton);
    for (std::size_t base = 0; base < visit.size(); base += 8) {
        std::uint32_t x0 = 99, y0 = 99, x1 = 0, y1 = 0;
        for (std::size_t k = base; k < base + 8; ++k) {
            x0 = std::min(x0, visit[k] % 16), x1 = std::max(x1, visit[k] % 16);
            y0 = std::min(y0, visit[k] / 16), y1 = std::max(y1, visit[k] / 16);
        }
        EXPECT_EQ(x1 - x0, 3u);
        EXPECT_EQ(y1 - y0, 1u);
    }
}

TEST(PixelOrder, ParsesItsNamesAndTileSizes) {
    EXPECT_EQ(parse_pixel_order("morton"), PixelOrder::morton);
    EXPECT_EQ(parse_pixel_order("zorder"), std::nullopt);
    const auto tile = parse_tile_size("32x8");
    ASSERT_TRUE(tile);
    EXPECT_EQ(tile->width, 32);
    EXPECT_EQ(tile->height, 8);
    EXPECT_FALSE(parse_tile_size("32"));
    EXPECT_FALSE(parse_tile_size("0x8"));
    EXPECT_FALSE(parse_tile_size("8x8x"));
}

// ---- Ray sets --------------------------------------------------------------------------

struct Fixture {
    Scene scene = load_scene("whitted,width=64,height=36");
    ReferenceTracer tracer{scene};
    RaySet primary = make_primary_rays(tracer, 64, 36, pixel_order(64, 36, PixelOrder::morton));
};

// The oracle's hits of every ray of a set, as a HitSet.
HitSet oracle_as_hits(const RaySet& rays, const OracleHits& oracle) {
    HitSet hits;
    hits.resize(static_cast<std::uint32_t>(rays.ox.size()));
    for (std::size_t k = 0; k < oracle.index.size(); ++k) {
        hits.t[oracle.index[k]] = oracle.t[k];
        hits.object[oracle.index[k]] = oracle.object[k];
    }
    return hits;
}

TEST(RaySets, PrimaryRaysAreTheReferenceCameraRaysInPixelOrder) {
    Fixture f;
    ASSERT_EQ(f.primary.count, 64u * 36u);
    EXPECT_EQ(f.primary.t_min, f.tracer.epsilon());
    EXPECT_EQ(f.primary.ox.size() % kernels::kPacketWidth, 0u);
    EXPECT_GT(f.primary.ox.size(), f.primary.count);  // a spare packet
    const std::vector<std::uint32_t> order = pixel_order(64, 36, PixelOrder::morton);
    for (std::uint32_t k : {0u, 1u, 100u, 2303u}) {
        const Ray want = *f.tracer.camera_ray(static_cast<int>(order[k] % 64),
                                              static_cast<int>(order[k] / 64), 0);
        const Ray got = f.primary.ray(k);
        EXPECT_EQ(got.origin, want.origin);
        EXPECT_EQ(got.direction, want.direction);
        EXPECT_EQ(got.t_max, kInfinity);
    }
}

TEST(RaySets, ShadowAndMirrorRaysFollowTheRenderingModel) {
    Fixture f;
    const HitSet hits = oracle_as_hits(f.primary, oracle_hits(f.tracer, f.primary, 0));
    const RaySet shadow = make_shadow_rays(f.scene, f.primary, hits);
    const RaySet mirror = make_secondary_rays(f.scene, f.primary, hits);
    std::uint32_t primary_hits = 0;
    for (std::uint32_t i = 0; i < f.primary.count; ++i) primary_hits += hits.hit(i) ? 1 : 0;
    ASSERT_GT(primary_hits, 0u);
    EXPECT_EQ(mirror.count, primary_hits);
    // At most one shadow ray per light and hit; point lights end at t = 1.
    EXPECT_GT(shadow.count, 0u);
    EXPECT_LE(shadow.count, primary_hits * f.scene.lights.size());
    for (std::uint32_t i = 0; i < shadow.count; ++i) ASSERT_EQ(shadow.t_max[i], 1.0f);
    EXPECT_EQ(shadow.t_min, 0.0f);
    EXPECT_EQ(mirror.t_min, 0.0f);
    // The first primary hit: its mirror ray is R = V - 2(N.V)N from P + eps N_facing.
    std::uint32_t first = 0;
    while (!hits.hit(first)) ++first;
    const Ray ray = f.primary.ray(first);
    const SurfaceHit h = *f.tracer.intersect(ray);
    const Vec3 n = dot(h.normal, ray.direction) > 0.0f ? -h.normal : h.normal;
    const Ray m = mirror.ray(0);
    EXPECT_EQ(m.origin, h.point + n * f.tracer.epsilon());
    EXPECT_EQ(m.direction, ray.direction - h.normal * (2.0f * dot(h.normal, ray.direction)));
}

// ---- Validation ------------------------------------------------------------------------

TEST(Validation, TheOraclesOwnHitsAreValid) {
    Fixture f;
    const OracleHits oracle = oracle_hits(f.tracer, f.primary, 0);
    const HitSet hits = oracle_as_hits(f.primary, oracle);
    const Validation exact = validate_hits(hits, oracle, kExactRule);
    EXPECT_TRUE(exact.valid) << exact.summary();
    EXPECT_EQ(exact.checked, f.primary.count);
    EXPECT_TRUE(validate_hits(hits, oracle, kToleranceRule).valid);
}

TEST(Validation, DeliberatelyWrongHitSetsAreFlaggedInvalid) {
    Fixture f;
    const OracleHits oracle = oracle_hits(f.tracer, f.primary, 0);
    const HitSet good = oracle_as_hits(f.primary, oracle);
    std::uint32_t hit = 0;
    while (!good.hit(hit)) ++hit;

    HitSet t_off_by_one_ulp = good;
    t_off_by_one_ulp.t[hit] = std::nextafter(good.t[hit], kInfinity);
    const Validation v1 = validate_hits(t_off_by_one_ulp, oracle, kExactRule);
    EXPECT_FALSE(v1.valid);
    EXPECT_EQ(v1.t_mismatches, 1u);

    HitSet wrong_object = good;
    wrong_object.object[hit] = good.object[hit] + 1;
    const Validation v2 = validate_hits(wrong_object, oracle, kExactRule);
    EXPECT_FALSE(v2.valid);
    EXPECT_EQ(v2.object_mismatches, 1u);

    HitSet lost_hit = good;
    lost_hit.object[hit] = kernels::kNoHit;
    lost_hit.t[hit] = kInfinity;
    const Validation v3 = validate_hits(lost_hit, oracle, kExactRule);
    EXPECT_FALSE(v3.valid);
    EXPECT_EQ(v3.hit_mismatches, 1u);

    // The tolerance rule forgives one flipped ray in 2304, not 1% of them, nor t 1% off.
    EXPECT_TRUE(
        validate_hits(lost_hit, oracle, ValidationRule{false, 1e-4, 0.999, 0.99}).valid);
    HitSet many_lost = good;
    for (std::uint32_t i = 0; i < f.primary.count; i += 50)
        many_lost.object[i] = kernels::kNoHit;
    EXPECT_FALSE(validate_hits(many_lost, oracle, kToleranceRule).valid);
    HitSet t_scaled = good;
    for (std::uint32_t i = 0; i < f.primary.count; ++i) t_scaled.t[i] *= 1.01f;
    const Validation v4 = validate_hits(t_scaled, oracle, kToleranceRule);
    EXPECT_FALSE(v4.valid);
    EXPECT_NEAR(v4.max_t_rel_error, 0.01, 1e-6);
}

TEST(Validation, OracleSubsetIsAnEvenStride) {
    Fixture f;
    const OracleHits oracle = oracle_hits(f.tracer, f.primary, 100);
    ASSERT_EQ(oracle.index.size(), 100u);
    EXPECT_EQ(oracle.index.front(), 0u);
    EXPECT_TRUE(std::is_sorted(oracle.index.begin(), oracle.index.end()));
    EXPECT_EQ(std::set<std::uint32_t>(oracle.index.begin(), oracle.index.end()).size(), 100u);
    EXPECT_EQ(oracle.index.back(), 99u * f.primary.count / 100u);  // k * n / 100 for k = 99
}

// ---- The double-precision oracle (Embree's judge) --------------------------------------

TEST(DoubleOracle, AgreesWithTheFloatOracleOnAnOrdinaryScene) {
    Fixture f;
    const OracleHits oracle = oracle_hits(f.tracer, f.primary, 0);
    const OracleHits truth = oracle_hits_double(f.scene, f.primary, oracle);
    EXPECT_EQ(truth.index, oracle.index);
    const Validation v =
        validate_hits(oracle_as_hits(f.primary, oracle), truth, kToleranceRule);
    EXPECT_TRUE(v.valid) << v.summary();
    EXPECT_EQ(v.hit_mismatches, 0u);
    EXPECT_EQ(v.object_mismatches, 0u);
    EXPECT_GT(v.both_hit, f.primary.count / 2);

    // Shadow rays: the same occlusion answers.
    const RaySet shadow =
        make_shadow_rays(f.scene, f.primary, oracle_as_hits(f.primary, oracle));
    const OracleHits occluded = oracle_hits(f.tracer, shadow, 0);
    const OracleHits occluded_truth = oracle_hits_double(f.scene, shadow, occluded);
    ASSERT_GT(shadow.count, 0u);
    EXPECT_EQ(occluded_truth.object, occluded.object);
    EXPECT_NE(std::count(occluded.object.begin(), occluded.object.end(), kOccluded), 0);
}

// A tiny sphere 1000 units away: the double oracle has t to ~1e-12, and the float oracle
// (the reference's robust sphere test) to the float's own step at 1000. The textbook float
// quadratic the model used before was off in the fourth digit here (more than 1e-3 off; it is
// what made Embree's accurate rows look invalid).
TEST(DoubleOracle, HasTheAccurateRootOnATinyDistantSphere) {
    Scene scene = load_scene("random:1,width=8,height=8");
    scene.objects[0].center = Vec3(0.0f, 0.0f, -1000.0f);
    scene.objects[0].radius = 0.01f;
    const ReferenceTracer tracer(scene);
    RaySet rays;
    rays.kind = RayKind::primary;
    rays.resize(1);
    rays.ox[0] = 0.0f, rays.oy[0] = 0.005f, rays.oz[0] = 0.0f;
    rays.dx[0] = 0.0f, rays.dy[0] = 0.0f, rays.dz[0] = -1.0f;
    rays.t_max[0] = kInfinity;
    const OracleHits oracle = oracle_hits(tracer, rays, 0);
    const OracleHits truth = oracle_hits_double(scene, rays, oracle);
    ASSERT_EQ(truth.object[0], 0);
    // Entry at z = -1000 + sqrt(r^2 - y^2), from the origin along -z.
    const double r = 0.01f, y = 0.005f;
    const double exact = 1000.0 - std::sqrt(r * r - y * y);
    EXPECT_NEAR(truth.t[0], exact, 1e-4);  // float storage of t: 6e-5 at 1000
    ASSERT_EQ(oracle.object[0], 0);
    EXPECT_NEAR(oracle.t[0], exact, 1.5e-4) << "the float oracle lost digits";
}

}  // namespace
}  // namespace octray::bench
