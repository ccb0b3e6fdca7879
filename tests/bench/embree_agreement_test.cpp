// octray and Embree (user-geometry spheres with the robust form, and its built-in sphere
// primitive; 16- and 8-wide packets and single rays) trace the same primary rays of each
// default scene and must agree: on
// hit or miss for >= 99.99% of the rays, and on t within 1e-4 relative on every ray both
// hit. (Until octray took the robust ray-sphere form, its textbook quadratic lost digits
// on small or grazed spheres far from the ray origin, and up to 1% of the rays had to be
// excused where Embree had the double-precision root.) A disagreement means an unfair or
// broken comparison (wrong scene conversion, wrong object ids, wrong intervals) or a
// precision loss on one side; the message names the double-precision root to tell which.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "bench/embree_baseline.h"
#include "bench/embree_frames.h"
#include "bench/ray_sets.h"
#include "kernels/dispatch.h"
#include "render/prepare/scene_view.h"
#include "render/reference.h"
#include "scene/compile.h"
#include "scene/load.h"

namespace octray::bench {
namespace {

#if OCTRAY_HAVE_EMBREE
constexpr int kWidth = 320, kHeight = 180;
#endif

class EmbreeAgreement : public ::testing::TestWithParam<const char*> {};

TEST_P(EmbreeAgreement, PrimaryRaysAgreeWithOctray) {
#if !OCTRAY_HAVE_EMBREE
    GTEST_SKIP() << "Embree 3 was not found by CMake (or OCTRAY_WITH_EMBREE is OFF): "
                    "there is no baseline to compare with";
#else
    const std::string spec = GetParam();
    const Scene scene = load_scene(spec + ",width=320,height=180");
    const CompiledScene compiled = compile_scene(scene);
    const ReferenceTracer tracer(scene);
    const RaySet rays = make_primary_rays(tracer, kWidth, kHeight,
                                          pixel_order(kWidth, kHeight, PixelOrder::tiled));
    ASSERT_EQ(rays.count, static_cast<std::uint32_t>(kWidth * kHeight));

    HitSet octray;
    octray.resize(static_cast<std::uint32_t>(rays.ox.size()));
    const kernels::KernelTable& table = kernel_table(resolve_isa(Isa::automatic));
    table.closest_hit(make_scene_view(compiled), rays.ray_stream(0), rays.count, rays.t_min,
                      octray.stream(0));

    for (EmbreeGeometry geometry : {EmbreeGeometry::user, EmbreeGeometry::sphere_point})
        for (EmbreeMode mode :
             {EmbreeMode::packet16, EmbreeMode::packet8, EmbreeMode::single}) {
            const EmbreeScene embree(scene, compiled, 1, geometry);
            SCOPED_TRACE(std::string(embree_geometry_name(geometry)) + " " +
                         embree_mode_name(mode));
            HitSet e;
            e.resize(static_cast<std::uint32_t>(rays.ox.size()));
            embree.intersect(mode, rays, 0, rays.count, e, true);

            std::uint32_t hit_mismatch = 0, both = 0, t_mismatch = 0, octray_hits = 0;
            for (std::uint32_t i = 0; i < rays.count; ++i) {
                octray_hits += octray.hit(i) ? 1 : 0;
                if (octray.hit(i) != e.hit(i)) {
                    ++hit_mismatch;
                    continue;
                }
                if (!octray.hit(i)) continue;
                ++both;
                const double rel =
                    std::fabs(static_cast<double>(octray.t[i]) - e.t[i]) / octray.t[i];
                if (rel <= 1e-4) continue;
                ++t_mismatch;
                const double truth = exact_root(
                    scene.objects[static_cast<std::size_t>(e.object[i])], rays.ray(i));
                ADD_FAILURE() << "ray " << i << ": octray t " << octray.t[i] << " (object "
                              << octray.object[i] << "), Embree t " << e.t[i] << " (object "
                              << e.object[i] << "), double-precision root " << truth;
            }
            // The scenes are not trivially empty: most default views hit something.
            EXPECT_GT(octray_hits, rays.count / 10);
            EXPECT_LE(hit_mismatch, rays.count / 10000)
                << hit_mismatch << " of " << rays.count << " rays disagree on hit or miss";
            EXPECT_EQ(t_mismatch, 0u) << t_mismatch << " of " << both
                                      << " both-hit rays differ in t by more than 1e-4";
        }
#endif
}

// Whole frames with Embree answering the hit queries (bench/embree_frames.h): the image
// is the reference's but where Embree's roots round differently, and both trace the same
// primary rays. Several EmbreeFrames may exist at once (the bench times their frames in
// rounds): each renders its own scene, here while another of a different scene exists.
TEST_P(EmbreeAgreement, WholeFramesMatchTheReference) {
#if !OCTRAY_HAVE_EMBREE
    GTEST_SKIP() << "Embree 3 was not found by CMake (or OCTRAY_WITH_EMBREE is OFF)";
#else
    const Scene scene = load_scene(std::string(GetParam()) + ",width=96,height=64");
    const CompiledScene compiled = compile_scene(scene);
    const EmbreeScene embree(scene, compiled, 1, EmbreeGeometry::user);
    const RenderResult ref = render_reference(scene, {});
    const Scene other = load_scene("random:3,width=96,height=64");
    const CompiledScene other_compiled = compile_scene(other);
    const EmbreeScene other_embree(other, other_compiled, 1, EmbreeGeometry::user);
    const RenderResult other_ref = render_reference(other, {});
    // Embree's frame against the reference's: the same primary rays, finite pixels, and a
    // mean squared error of at most 1e-5.
    const auto expect_agrees = [](const RenderResult& e, const RenderResult& r) {
        ASSERT_EQ(e.image.pixel_count(), r.image.pixel_count());
        EXPECT_EQ(e.rays.primary, r.rays.primary);
        double squared = 0.0;
        for (std::size_t k = 0; k < r.image.pixel_count(); ++k) {
            const Rgb a = rgb_at(r.image, k), b = rgb_at(e.image, k);
            ASSERT_TRUE(is_finite(b)) << "pixel " << k;
            squared += (double(a.r) - b.r) * (double(a.r) - b.r) +
                       (double(a.g) - b.g) * (double(a.g) - b.g) +
                       (double(a.b) - b.b) * (double(a.b) - b.b);
        }
        const double mse = squared / (3.0 * static_cast<double>(r.image.pixel_count()));
        EXPECT_LE(mse, 1e-5) << "PSNR (peak 1) " << 10.0 * std::log10(1.0 / mse) << " dB";
    };
    for (EmbreeMode mode : {EmbreeMode::packet16, EmbreeMode::packet8}) {
        SCOPED_TRACE(embree_mode_name(mode));
        const EmbreeFrames other_frames(other_embree, mode, Isa::automatic);
        const EmbreeFrames frames(embree, mode, Isa::automatic);
        expect_agrees(frames.render(compiled, {}), ref);
        expect_agrees(other_frames.render(other_compiled, {}), other_ref);
    }
#endif
}

// Issue 42: the still rows charge Embree a BVH build per frame at LOW or MEDIUM quality
// (EmbreeScene::rebuild). A rebuild must really build (the spheres' bounds are asked for
// again) and leave a scene that traces as the first build did, at every quality.
TEST_P(EmbreeAgreement, RebuildBuildsAgainAndTracesTheSame) {
#if !OCTRAY_HAVE_EMBREE
    GTEST_SKIP() << "Embree 3 was not found by CMake (or OCTRAY_WITH_EMBREE is OFF)";
#else
    const Scene scene = load_scene(std::string(GetParam()) + ",width=64,height=48");
    const CompiledScene compiled = compile_scene(scene);
    const ReferenceTracer tracer(scene);
    const RaySet rays =
        make_primary_rays(tracer, 64, 48, pixel_order(64, 48, PixelOrder::tiled));
    for (EmbreeBuildQuality quality :
         {EmbreeBuildQuality::low, EmbreeBuildQuality::medium, EmbreeBuildQuality::high}) {
        SCOPED_TRACE(embree_build_quality_name(quality));
        EmbreeScene embree(scene, compiled, 1, EmbreeGeometry::user, quality);
        EXPECT_EQ(embree.build_quality(), quality);
        EXPECT_EQ(embree.sphere_builds(), 1u);
        HitSet before, after;
        before.resize(static_cast<std::uint32_t>(rays.ox.size()));
        after.resize(static_cast<std::uint32_t>(rays.ox.size()));
        embree.intersect(EmbreeMode::packet16, rays, 0, rays.count, before, true);
        EXPECT_GE(embree.rebuild(), 0.0);
        EXPECT_GE(embree.rebuild(), 0.0);
        EXPECT_EQ(embree.sphere_builds(), 3u);
        embree.intersect(EmbreeMode::packet16, rays, 0, rays.count, after, true);
        for (std::uint32_t i = 0; i < rays.count; ++i) {
            ASSERT_EQ(before.object[i], after.object[i]) << "ray " << i;
            if (before.hit(i)) {
                ASSERT_EQ(before.t[i], after.t[i]) << "ray " << i;
            }
        }
    }
#endif
}

INSTANTIATE_TEST_SUITE_P(DefaultScenes, EmbreeAgreement,
                         ::testing::Values("whitted", "random:16", "random:1024",
                                           "sphereflake:4"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                             std::string name = info.param;
                             for (char& c : name)
                                 if (c == ':') c = '_';
                             return name;
                         });

}  // namespace
}  // namespace octray::bench
