// Rendering a list of blocks into a picture (render_packet_blocks with a PreparedScene,
// render_reference_blocks): every pixel equals the same pixel of a whole render bit for
// bit, with and without the spheres' BVH, at spp > 1 and a frame counter other than 0,
// after the prepared scene's camera has been moved, and on the scalar path; blocks outside
// the picture and options a block render does not take are refused.

#include <gtest/gtest.h>

#include <algorithm>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/pixel_rect.h"
#include "render/packet_renderer.h"
#include "render/reference.h"
#include "scene/builtin.h"
#include "scene/scene.h"

namespace octray {
namespace {

// Blocks of `side` covering a width x height picture, in an order that is not row-major
// (every other row of blocks backwards), so that a renderer that ignored the blocks'
// places would not pass by luck.
std::vector<PixelRect> blocks_of(int width, int height, int side) {
    std::vector<PixelRect> blocks;
    for (int y = 0, row = 0; y < height; y += side, ++row) {
        std::vector<PixelRect> line;
        for (int x = 0; x < width; x += side)
            line.push_back({x, y, std::min(x + side, width), std::min(y + side, height)});
        if (row % 2 == 1) std::reverse(line.begin(), line.end());
        blocks.insert(blocks.end(), line.begin(), line.end());
    }
    return blocks;
}

bool same_bits(const Image& a, const Image& b) {
    if (a.width() != b.width() || a.height() != b.height()) return false;
    for (std::size_t k = 0; k < a.pixel_count(); ++k)
        if (!(rgb_at(a, k) == rgb_at(b, k))) return false;
    return true;
}

Scene test_scene(const char* spec, int spp) {
    Scene scene = make_builtin_scene(spec);
    scene.image.width = 45;  // not a multiple of the blocks: partial blocks at the edges
    scene.image.height = 27;
    scene.image.spp = spp;
    return scene;
}

TEST(BlockRender, PacketBlocksEqualAWholeRenderBitForBit) {
    // random:64 is above the BVH threshold (kBvhAutoMinSpheres), whitted below it; whitted
    // with Accel::bvh takes the BVH too.
    struct Case {
        const char* spec;
        Accel accel;
        int spp;
        std::uint32_t frame;
    };
    for (const Case c :
         {Case{"whitted", Accel::automatic, 1, 0}, Case{"whitted", Accel::bvh, 4, 7},
          Case{"random:64", Accel::automatic, 2, 3}}) {
        const Scene scene = test_scene(c.spec, c.spp);
        RenderOptions options;
        options.frame = c.frame;
        options.accel = c.accel;
        const Image whole = render_packet(scene, options).image;
        const PreparedScene prepared(scene, c.accel);
        EXPECT_EQ(prepared.bvh() != nullptr, c.accel == Accel::bvh || c.spec[0] == 'r')
            << c.spec;
        Image picture(scene.image.width, scene.image.height, {"R", "G", "B"});
        const std::vector<PixelRect> blocks =
            blocks_of(scene.image.width, scene.image.height, 8);
        RenderOptions block_options;
        block_options.frame = c.frame;
        block_options.threads = 2;
        // In two calls, as the viewer renders a batch at a time.
        const std::size_t half = blocks.size() / 2;
        const RenderResult first = render_packet_blocks(prepared, std::span(blocks).first(half),
                                                        picture, block_options);
        EXPECT_FALSE(same_bits(picture, whole)) << c.spec << ": half the blocks are missing";
        const RenderResult second = render_packet_blocks(
            prepared, std::span(blocks).subspan(half), picture, block_options);
        EXPECT_TRUE(same_bits(picture, whole)) << c.spec;
        const RenderResult counted = render_packet(scene, options);
        EXPECT_EQ(first.rays.total() + second.rays.total(), counted.rays.total()) << c.spec;
    }
}

// A new camera re-aims the compiled scene and keeps its BVH: the blocks are then the moved
// camera's render.
TEST(BlockRender, APreparedSceneTakesANewCamera) {
    Scene scene = test_scene("random:64", 1);
    PreparedScene prepared(scene);
    ASSERT_NE(prepared.bvh(), nullptr);
    const SphereBvh* bvh = prepared.bvh();
    scene.camera.eye = scene.camera.eye + Vec3{1.5f, 0.5f, -0.5f};
    scene.camera.up = Vec3{0.1f, 1.0f, 0.0f};
    prepared.set_camera(scene.camera);
    EXPECT_EQ(prepared.bvh(), bvh);
    Image picture(scene.image.width, scene.image.height, {"R", "G", "B"});
    render_packet_blocks(prepared, blocks_of(scene.image.width, scene.image.height, 5),
                         picture);
    EXPECT_TRUE(same_bits(picture, render_packet(scene).image));
}

// A whole frame of a prepared scene (render_packet(PreparedScene)), camera after camera,
// with and without its BVH, with a gradient sky (which follows the camera's up), at spp 4
// and a frame counter other than 0: the render of the scene posed with that camera.
TEST(BlockRender, WholeFramesOfAPreparedSceneEqualRendersOfThePosedScene) {
    for (const Accel accel : {Accel::bvh, Accel::none}) {
        Scene scene = test_scene("random:64", 4);
        scene.background = {
            BackgroundType::gradient, Rgb(0.0f), {0.9f, 0.8f, 0.7f}, {0.1f, 0.3f, 0.9f}};
        PreparedScene prepared(scene, accel);
        EXPECT_EQ(prepared.bvh() != nullptr, accel == Accel::bvh);
        RenderOptions options;
        options.frame = 7;
        options.accel = accel;
        for (int k = 0; k < 3; ++k) {
            scene.camera.eye = scene.camera.eye + Vec3{1.5f, 0.5f, -0.5f};
            scene.camera.up = Vec3{0.2f * float(k), 1.0f, 0.0f};
            prepared.set_camera(scene.camera);
            const RenderResult frame = render_packet(prepared, options);
            EXPECT_EQ(frame.compile_seconds, 0.0);
            EXPECT_EQ(frame.bvh_seconds, 0.0);
            EXPECT_TRUE(same_bits(frame.image, render_packet(scene, options).image))
                << "camera " << k << ", accel " << accel_name(accel);
        }
    }
}

TEST(BlockRender, ReferenceBlocksEqualAWholeReferenceRender) {
    const Scene scene = test_scene("whitted", 2);
    RenderOptions options;
    options.frame = 5;
    Image picture(scene.image.width, scene.image.height, {"R", "G", "B"});
    const RenderResult result = render_reference_blocks(
        scene, blocks_of(scene.image.width, scene.image.height, 8), picture, options);
    EXPECT_TRUE(same_bits(picture, render_reference(scene, options).image));
    EXPECT_EQ(result.rays.total(), render_reference(scene, options).rays.total());
}

TEST(BlockRender, BadBlocksAndOptionsAreRefused) {
    const Scene scene = test_scene("whitted", 1);
    const PreparedScene prepared(scene);
    Image picture(scene.image.width, scene.image.height, {"R", "G", "B"});
    const auto both_refuse = [&](const std::vector<PixelRect>& blocks, Image& target,
                                 const RenderOptions& options) {
        EXPECT_THROW(render_packet_blocks(prepared, blocks, target, options),
                     std::invalid_argument);
        EXPECT_THROW(render_reference_blocks(scene, blocks, target, options),
                     std::invalid_argument);
    };
    for (const PixelRect bad :
         {PixelRect{40, 0, 46, 8}, PixelRect{0, -1, 8, 8}, PixelRect{3, 3, 3, 8}}) {
        both_refuse({PixelRect{0, 0, 8, 8}, bad}, picture, {});
    }
    try {
        render_packet_blocks(prepared, std::vector<PixelRect>{{40, 0, 46, 8}}, picture);
        ADD_FAILURE() << "a block outside the picture was rendered";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()).rfind("block (40, 0)-(46, 8) is not inside the image "
                                              "(the image is 45x27",
                                              0),
                  0u)
            << e.what();
    }
    Image small(8, 8, {"R", "G", "B"});
    both_refuse({PixelRect{0, 0, 8, 8}}, small, {});
    RenderOptions crop;
    crop.crop = PixelRect{0, 0, 8, 8};
    both_refuse({PixelRect{0, 0, 8, 8}}, picture, crop);
    RenderOptions samples;
    samples.samples = SampleRange{0, 1};
    both_refuse({PixelRect{0, 0, 8, 8}}, picture, samples);
}

}  // namespace
}  // namespace octray
