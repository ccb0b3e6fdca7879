// The one description of a render (render/render_config.h): names parsed or refused with
// the setting they belong to, ranges checked, a crop checked against the image, and what
// the renderers and the EXR's octray.path take from it (the memory estimate's part:
// tests/batch/memory_limits_test.cpp).

#include "render/render_config.h"

#include <gtest/gtest.h>

#include <string>

#include "kernels/dispatch.h"
#include "render/frame_renderer.h"
#include "scene/builtin.h"

namespace octray {
namespace {

// The setting a ConfigError names, or "" when `f` throws none.
template <typename F>
std::string failing_setting(F&& f) {
    try {
        f();
    } catch (const ConfigError& e) {
        EXPECT_EQ(std::string(e.what()), e.setting() + ": " + e.detail());
        return e.setting();
    }
    return "";
}

TEST(RenderConfig, NamesParseIntoTheirSettings) {
    RenderConfig c;
    c.set_path("scalar");
    c.set_isa("sse4.1");
    c.set_accel("none");
    c.set_tile("8x32");
    c.set_aovs("id,depth");
    EXPECT_EQ(c.path, RenderPath::scalar);
    EXPECT_EQ(c.isa, Isa::sse4_1);
    EXPECT_EQ(c.accel, Accel::none);
    EXPECT_EQ(c.tile, (TileSize{8, 32}));
    EXPECT_EQ(c.aovs, (AovSet{.depth = true, .id = true}));
}

TEST(RenderConfig, BadNamesNameTheirSetting) {
    RenderConfig c;
    EXPECT_EQ(failing_setting([&] { c.set_path("vector"); }), "path");
    EXPECT_EQ(failing_setting([&] { c.set_isa("avx3"); }), "isa");
    EXPECT_EQ(failing_setting([&] { c.set_accel("kd"); }), "accel");
    EXPECT_EQ(failing_setting([&] { c.set_tile("16"); }), "tile");
    EXPECT_EQ(failing_setting([&] { c.set_tile("0x16"); }), "tile");
    EXPECT_EQ(failing_setting([&] { c.set_aovs("depth,fog"); }), "aovs");
    // A failed parse leaves the setting as it was.
    EXPECT_EQ(c.path, RenderPath::simd);
    EXPECT_EQ(c.tile, TileSize{});
    EXPECT_FALSE(c.aovs.any());
}

TEST(RenderConfig, RangesAreChecked) {
    RenderConfig c;
    EXPECT_EQ(failing_setting([&] { c.check(); }), "");
    c.threads = kMaxRenderThreads + 1;
    EXPECT_EQ(failing_setting([&] { c.check(); }), "threads");
    c.threads = -1;
    EXPECT_EQ(failing_setting([&] { c.check(); }), "threads");
    c.threads = kMaxRenderThreads;
    c.tile = {kMaxTileSide + 1, 4};
    EXPECT_EQ(failing_setting([&] { c.check(); }), "tile");
    c.tile = {4, 0};
    EXPECT_EQ(failing_setting([&] { c.check(); }), "tile");
}

TEST(RenderConfig, ACropMustLieInsideTheImage) {
    RenderConfig c;
    EXPECT_EQ(failing_setting([&] { c.check_crop(64, 48); }), "");  // no crop
    c.crop = PixelRect{0, 0, 64, 48};
    EXPECT_EQ(failing_setting([&] { c.check_crop(64, 48); }), "");
    for (const PixelRect r : {PixelRect{0, 0, 65, 48}, PixelRect{-1, 0, 8, 8},
                              PixelRect{4, 4, 4, 8}, PixelRect{0, 9, 8, 8}}) {
        c.crop = r;
        EXPECT_EQ(failing_setting([&] { c.check_crop(64, 48); }), "crop");
    }
}

TEST(RenderConfig, OverridesReplaceOnlyWhatTheySet) {
    Scene scene = make_builtin_scene("whitted");
    const Scene before = scene;
    SceneOverrides o;
    EXPECT_FALSE(o.any());
    apply_overrides(scene, o);
    EXPECT_EQ(scene.image.width, before.image.width);
    o.height = 20;
    o.seed = 7;
    EXPECT_TRUE(o.any());
    apply_overrides(scene, o);
    EXPECT_EQ(scene.image.width, before.image.width);
    EXPECT_EQ(scene.image.height, 20);
    EXPECT_EQ(scene.image.spp, before.image.spp);
    EXPECT_EQ(scene.render.seed, 7u);
}

TEST(RenderConfig, WhatTheRenderersTake) {
    RenderConfig c;
    c.threads = 3;
    c.tile = {8, 4};
    c.accel = Accel::bvh;
    c.crop = PixelRect{1, 2, 3, 4};
    const RenderOptions o = c.render_options();
    EXPECT_EQ(o.threads, 3);
    EXPECT_EQ(o.tile_width, 8);
    EXPECT_EQ(o.tile_height, 4);
    EXPECT_EQ(o.accel, Accel::bvh);
    EXPECT_EQ(o.crop, c.crop);
}

TEST(RenderConfig, TheIsaResolvesAndLabelsThePath) {
    RenderConfig c;
    EXPECT_EQ(c.resolve_isa(), resolve_isa(Isa::automatic));
    EXPECT_EQ(c.path_label(), std::string("simd (") + isa_name(c.isa) + ")");
    c.path = RenderPath::scalar;
    c.isa = Isa::automatic;
    EXPECT_EQ(c.resolve_isa(), Isa::automatic);  // the scalar path runs no kernels
    EXPECT_EQ(c.path_label(), "scalar");
    c.path = RenderPath::simd;
    for (Isa isa : {Isa::sse2, Isa::sse4_1, Isa::avx2, Isa::avx512}) {
        c.isa = isa;
        EXPECT_EQ(failing_setting([&] { c.resolve_isa(); }), isa_supported(isa) ? "" : "isa");
    }
}

// The options it gives render the image of the renderers' own options.
TEST(RenderConfig, ItsRenderOptionsRenderTheCropOfTheWholeImage) {
    Scene scene = make_builtin_scene("whitted");
    scene.image = {32, 24, 1};
    RenderConfig c;
    c.threads = 2;
    c.resolve_isa();
    FrameRenderer whole(scene, c.path, c.isa, c.accel, c.threads);
    whole.prepare(0);
    const Image full = whole.render(c.render_options()).image;
    c.crop = PixelRect{3, 5, 20, 17};
    c.check_crop(32, 24);
    const Image part = whole.render(c.render_options()).image;
    ASSERT_EQ(part.width(), 17);
    ASSERT_EQ(part.height(), 12);
    for (int y = 0; y < 12; ++y)
        for (int x = 0; x < 17; ++x) {
            EXPECT_EQ(rgb_at(part, x, y).r, rgb_at(full, x + 3, y + 5).r);
            EXPECT_EQ(rgb_at(part, x, y).b, rgb_at(full, x + 3, y + 5).b);
        }
}

}  // namespace
}  // namespace octray
