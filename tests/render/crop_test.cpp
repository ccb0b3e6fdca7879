// Crops (RenderOptions::crop) on both render paths: a crop's pixels are the same pixels of
// the full render, bit for bit, for odd, one-pixel, edge and unaligned rectangles and any
// tile size; ray counts cover only the crop; bad crops are refused.

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "output_fixtures.h"

namespace octray {
namespace {

using testing::golden_scene;
using testing::Path;
using testing::path_name;
using testing::render_with;
using testing::same_bits;
using testing::sub_image;

const std::vector<PixelRect> kCrops{
    {0, 0, 37, 23},    // the whole image
    {0, 0, 1, 1},      // one pixel, top left
    {36, 22, 37, 23},  // one pixel, bottom right
    {5, 3, 18, 14},    // odd, inside, not on tile or block boundaries
    {0, 7, 37, 8},     // one full row
    {17, 0, 18, 23},   // one full column
    {3, 1, 36, 22},    // almost everything
    {16, 16, 32, 23},  // on a 16x16 tile boundary
};

TEST(Crop, PixelsEqualTheFullRenderOnBothPaths) {
    for (const char* name : {"whitted_spp16", "thinlens_spp4", "fisheye", "pinhole_checker"}) {
        const Scene scene = golden_scene(name, 37, 23, name[0] == 'w' ? 3 : 0);
        for (Path path : {Path::reference, Path::packet}) {
            const RenderResult full = render_with(path, scene, {});
            EXPECT_EQ(full.image.data_window, (PixelRect{0, 0, 37, 23}));
            EXPECT_EQ(full.image.display_window.width(), 37);
            EXPECT_EQ(full.image.display_window.height(), 23);
            for (const PixelRect& crop : kCrops)
                for (const auto& [tw, th] : std::vector<std::pair<int, int>>{
                         {16, 16}, {1, 1}, {3, 5}, {8, 2}, {64, 64}}) {
                    SCOPED_TRACE(std::string(name) + " " + path_name(path) + " crop " +
                                 to_string(crop) + " tile " + std::to_string(tw) + "x" +
                                 std::to_string(th));
                    RenderOptions options;
                    options.crop = crop;
                    options.tile_width = tw;
                    options.tile_height = th;
                    const RenderResult part = render_with(path, scene, options);
                    EXPECT_EQ(part.image.data_window, crop);
                    EXPECT_EQ(part.image.display_window.width(), 37);
                    EXPECT_EQ(part.image.display_window.height(), 23);
                    ASSERT_EQ(part.image.width(), crop.width());
                    ASSERT_EQ(part.image.height(), crop.height());
                    EXPECT_TRUE(same_bits(part.image, sub_image(full.image, crop)));
                    EXPECT_TRUE(part.sample_sums.pixel_count() == 0);
                }
        }
    }
}

TEST(Crop, RayCountsCoverOnlyTheCropAndAgreeBetweenPaths) {
    const Scene scene = golden_scene("mirror_reflection", 40, 30, 2);
    const PixelRect left{0, 0, 20, 30}, right{20, 0, 40, 30};
    for (Path path : {Path::reference, Path::packet}) {
        SCOPED_TRACE(path_name(path));
        const RenderResult full = render_with(path, scene, {});
        RenderOptions a, b;
        a.crop = left;
        b.crop = right;
        const RenderResult ra = render_with(path, scene, a), rb = render_with(path, scene, b);
        EXPECT_EQ(ra.rays.primary, 20u * 30u * 2u);
        EXPECT_EQ(ra.rays.primary + rb.rays.primary, full.rays.primary);
        EXPECT_EQ(ra.rays.shadow + rb.rays.shadow, full.rays.shadow);
        EXPECT_EQ(ra.rays.reflected + rb.rays.reflected, full.rays.reflected);
        EXPECT_EQ(ra.rays.refracted + rb.rays.refracted, full.rays.refracted);
    }
    RenderOptions o;
    o.crop = PixelRect{3, 4, 17, 9};
    const RenderResult r = render_reference(scene, o), p = render_packet(scene, o);
    EXPECT_EQ(r.rays.total(), p.rays.total());
    EXPECT_EQ(r.rays.shadow, p.rays.shadow);
}

TEST(Crop, BadCropsAreRefusedByBothPaths) {
    const Scene scene = golden_scene("pinhole_checker", 16, 8);
    for (const PixelRect& bad : std::vector<PixelRect>{{0, 0, 0, 8},
                                                       {4, 4, 2, 6},
                                                       {-1, 0, 4, 4},
                                                       {0, 0, 17, 8},
                                                       {0, 0, 16, 9},
                                                       {16, 0, 17, 1}}) {
        RenderOptions options;
        options.crop = bad;
        for (Path path : {Path::reference, Path::packet}) {
            SCOPED_TRACE(std::string(path_name(path)) + " " + to_string(bad));
            try {
                render_with(path, scene, options);
                ADD_FAILURE() << "no exception";
            } catch (const std::invalid_argument& e) {
                EXPECT_NE(std::string(e.what()).find(to_string(bad)), std::string::npos)
                    << e.what();
                EXPECT_NE(std::string(e.what()).find("16x8"), std::string::npos) << e.what();
            }
        }
    }
}

}  // namespace
}  // namespace octray
