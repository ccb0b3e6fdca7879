// Progressive passes (render/batch/progressive.h): the schedule, the mean after each pass, and
// the final image equal to the plain render bit for bit on both paths (spp 1, 4, 5, 16,
// with and without a crop).

#include "render/batch/progressive.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "output_fixtures.h"

namespace octray::batch {
namespace {

using testing::golden_scene;
using testing::Path;
using testing::path_name;
using testing::render_with;
using testing::same_bits;

TEST(Progressive, ScheduleDoublesAndEndsOnSpp) {
    EXPECT_EQ(progressive_schedule(1), (std::vector<int>{1}));
    EXPECT_EQ(progressive_schedule(2), (std::vector<int>{1, 2}));
    EXPECT_EQ(progressive_schedule(4), (std::vector<int>{1, 2, 4}));
    EXPECT_EQ(progressive_schedule(5), (std::vector<int>{1, 2, 4, 5}));
    EXPECT_EQ(progressive_schedule(16), (std::vector<int>{1, 2, 4, 8, 16}));
    EXPECT_EQ(progressive_schedule(17), (std::vector<int>{1, 2, 4, 8, 16, 17}));
    EXPECT_THROW(progressive_schedule(0), std::invalid_argument);
}

TEST(Progressive, FinalImageEqualsThePlainRenderOnBothPaths) {
    for (int spp : {1, 4, 5, 16}) {
        for (const char* name : {"whitted_spp16", "thinlens_spp4", "fisheye"}) {
            const Scene scene = golden_scene(name, 21, 13, spp);
            for (Path path : {Path::reference, Path::packet}) {
                for (bool crop : {false, true}) {
                    SCOPED_TRACE(std::string(name) + " spp " + std::to_string(spp) + " " +
                                 path_name(path) + (crop ? " crop" : ""));
                    RenderOptions options;
                    options.tile_width = 5;
                    options.tile_height = 3;
                    if (crop) options.crop = PixelRect{3, 2, 17, 11};
                    const RenderResult plain = render_with(path, scene, options);
                    std::vector<int> seen;
                    const RenderResult progressive = render_progressive(
                        [&](const RenderOptions& o) { return render_with(path, scene, o); },
                        spp, options,
                        [&](const RenderResult& so_far, int samples) {
                            seen.push_back(samples);
                            EXPECT_EQ(so_far.image.data_window, plain.image.data_window);
                            EXPECT_EQ(so_far.image.width(), plain.image.width());
                            // The mean so far is the sums divided by the samples so far.
                            const Rgb sum = rgb_at(so_far.sample_sums, 1, 1);
                            const Rgb mean = rgb_at(so_far.image, 1, 1);
                            EXPECT_EQ(mean.r, sum.r / static_cast<float>(samples));
                        });
                    EXPECT_EQ(seen, progressive_schedule(spp));
                    EXPECT_TRUE(same_bits(progressive.image, plain.image));
                    EXPECT_EQ(progressive.image.data_window, plain.image.data_window);
                    EXPECT_EQ(progressive.rays.primary, plain.rays.primary);
                    EXPECT_EQ(progressive.rays.total(), plain.rays.total());
                    EXPECT_EQ(progressive.sample_sums.pixel_count(), 0u);
                }
            }
        }
    }
}

TEST(Progressive, PassesAgreeBetweenPaths) {
    // Each pass of the packet path equals the reference's pass, sums included.
    const Scene scene = golden_scene("mirror_reflection", 19, 11, 5);
    RenderOptions first;
    first.samples = SampleRange{0, 2};
    const RenderResult r1 = render_reference(scene, first), p1 = render_packet(scene, first);
    EXPECT_TRUE(same_bits(r1.sample_sums, p1.sample_sums));
    EXPECT_TRUE(same_bits(r1.image, p1.image));
    RenderOptions second;
    second.samples = SampleRange{2, 5};
    second.sample_sums = &r1.sample_sums;
    const RenderResult r2 = render_reference(scene, second);
    second.sample_sums = &p1.sample_sums;
    const RenderResult p2 = render_packet(scene, second);
    EXPECT_TRUE(same_bits(r2.image, p2.image));
    EXPECT_TRUE(same_bits(r2.image, render_reference(scene, {}).image));
}

TEST(Progressive, BadSampleRangesAreRefused) {
    const Scene scene = golden_scene("pinhole_checker", 8, 8, 4);
    const Image sums(8, 8, {"R", "G", "B"}), wrong(4, 8, {"R", "G", "B"});
    for (Path path : {Path::reference, Path::packet}) {
        SCOPED_TRACE(path_name(path));
        RenderOptions o;
        o.samples = SampleRange{0, 5};  // past spp
        EXPECT_THROW(render_with(path, scene, o), std::invalid_argument);
        o.samples = SampleRange{2, 2};  // empty
        EXPECT_THROW(render_with(path, scene, o), std::invalid_argument);
        o.samples = SampleRange{1, 3};  // no previous sums
        EXPECT_THROW(render_with(path, scene, o), std::invalid_argument);
        o.sample_sums = &wrong;
        EXPECT_THROW(render_with(path, scene, o), std::invalid_argument);
        o.sample_sums = &sums;
        EXPECT_NO_THROW(render_with(path, scene, o));
    }
    RenderOptions preset;
    preset.samples = SampleRange{0, 1};
    const PassRenderer reference = [&](const RenderOptions& o) {
        return render_reference(scene, o);
    };
    EXPECT_THROW(render_progressive(reference, 4, preset, {}), std::invalid_argument);
}

}  // namespace
}  // namespace octray::batch
