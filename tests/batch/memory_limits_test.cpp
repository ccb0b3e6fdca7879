// render/batch/memory_estimate.h: the render memory estimate, the limit check behind
// --max-memory, the size parser, and what the estimate takes from a RenderConfig.

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>

#include "render/batch/memory_estimate.h"
#include "scene/builtin.h"
#include "scene/scene_error.h"

namespace octray::batch {
namespace {

constexpr std::uint64_t kGiB = std::uint64_t{1} << 30;
constexpr std::uint64_t kMiB = std::uint64_t{1} << 20;

Scene image_scene(int width, int height, int spp = 1) {
    Scene s = make_builtin_scene("whitted");
    s.image = {width, height, spp};
    return s;
}

TEST(RenderMemory, FramebufferAndHalfOutputScaleWithPixels) {
    RenderMemoryParams reference_path;
    reference_path.packet_path = false;
    reference_path.threads = 1;
    const RenderMemoryEstimate e =
        estimate_render_memory(image_scene(1000, 500), reference_path);
    EXPECT_EQ(e.framebuffer, 1000u * 500u * 12u);
    // The EXR image's half channels, and OpenEXR's block of 16 lines (zip) three times.
    EXPECT_EQ(e.output, 1000u * 500u * 6u + 16u * 1000u * 6u * 3u);
    EXPECT_EQ(e.per_thread, 0u);
    EXPECT_EQ(e.total, e.framebuffer + e.output + e.scene + e.fixed);

    // --float: the EXR image holds float copies of the channels (the framebuffer is not
    // handed to OpenEXR), twice the half ones.
    reference_path.float32_output = true;
    EXPECT_EQ(estimate_render_memory(image_scene(1000, 500), reference_path).output,
              2 * e.output);
}

// Issue 23: whitted at 4096 x 2160 with --float --aov depth,normal,albedo,id peaked at
// 778 MB where 101.7 MiB was estimated. Every buffer is counted: the image (12 bytes a
// pixel), the AOVs (32) and their float EXR copies (44).
TEST(RenderMemory, AovsFloatOutputAndProgressivePassesAreCounted) {
    RenderMemoryParams p;
    p.threads = 1;
    const Scene s = image_scene(4096, 2160);
    const std::uint64_t pixels = 4096u * 2160u;
    const RenderMemoryEstimate plain = estimate_render_memory(s, p);
    p.float32_output = true;
    p.aov_depth = p.aov_normal = p.aov_albedo = p.aov_id = true;
    const RenderMemoryEstimate all = estimate_render_memory(s, p);
    EXPECT_EQ(all.aovs, pixels * 32u);
    EXPECT_GE(all.output, pixels * 44u);
    EXPECT_GT(all.total, std::uint64_t{778} * 1000 * 1000);
    EXPECT_NE(all.describe().find("AOVs"), std::string::npos) << all.describe();
    p.progressive = true;
    EXPECT_EQ(estimate_render_memory(s, p).framebuffer, all.framebuffer + 3 * pixels * 12u);
    EXPECT_LT(plain.total, all.total);
}

// Write behind (batch::BatchSettings::write_behind): the frame being written keeps its
// image and its files' buffers while the next frame renders, so both count twice.
TEST(RenderMemory, AFrameWrittenBehindCountsItsImageAndFilesTwice) {
    RenderMemoryParams p;
    p.threads = 1;
    p.png_preview = true;
    const Scene s = image_scene(1920, 1080);
    const RenderMemoryEstimate one = estimate_render_memory(s, p);
    p.write_behind = true;
    const RenderMemoryEstimate behind = estimate_render_memory(s, p);
    EXPECT_EQ(behind.framebuffer, one.framebuffer + 1920u * 1080u * 12u);
    EXPECT_EQ(behind.output, 2 * one.output);
    EXPECT_EQ(behind.total - one.total, 1920u * 1080u * 12u + one.output);
}

// A scene file is estimated from its size before it is parsed.
TEST(MemoryLimit, ASceneFileTooLargeToParseIsRefusedFromItsSize) {
    const std::uint64_t bytes = std::uint64_t{350} << 20;     // 5 M spheres as JSON
    EXPECT_GT(estimate_load_memory(bytes).total, 6 * bytes);  // measured: 6.2 bytes a byte
    try {
        check_load_memory_limit("big.json", bytes, 1024);
        FAIL() << "a 350 MiB scene file parses in 1 KiB?";
    } catch (const SceneError& err) {
        const std::string what = err.what();
        EXPECT_EQ(err.file(), "big.json");
        EXPECT_NE(what.find("367001600-byte scene file"), std::string::npos) << what;
        EXPECT_NE(what.find("1024 bytes"), std::string::npos) << what;
    }
    EXPECT_NO_THROW(check_load_memory_limit("small.json", 1000, 1 * kGiB));
}

TEST(RenderMemory, PacketScratchGrowsWithSppLightsDepthAndThreads) {
    RenderMemoryParams p;
    p.threads = 2;
    p.tile_width = p.tile_height = 16;  // the counts below are 16 x 16 tiles' (not the default)
    const Scene base = image_scene(640, 480, 1);
    const RenderMemoryEstimate e1 = estimate_render_memory(base, p);
    EXPECT_GT(e1.per_thread, 0u);
    EXPECT_EQ(e1.threads, 2u);
    EXPECT_EQ(e1.total, e1.framebuffer + e1.output + e1.scene + e1.fixed + 2 * e1.per_thread);

    // More samples per pixel fill a tile's chunk of rays (16 x 16 x 16 = 4096, a whole
    // chunk); beyond it, the tile traces more chunks, not bigger ones.
    const RenderMemoryEstimate e16 = estimate_render_memory(image_scene(640, 480, 16), p);
    EXPECT_GT(e16.per_thread, e1.per_thread + (4096u - 256u) * 100u);
    EXPECT_EQ(estimate_render_memory(image_scene(640, 480, 1000000), p).per_thread,
              e16.per_thread);

    Scene lights = base;
    lights.lights.resize(100, lights.lights.front());
    EXPECT_GT(estimate_render_memory(lights, p).per_thread, e1.per_thread + 256u * 90u * 48u);

    // A generation more, a chunk more (not twice the rays: the chunks bound them).
    Scene deep = base;
    deep.render.max_depth = 64;
    const std::uint64_t deep_bytes = estimate_render_memory(deep, p).per_thread;
    EXPECT_GT(deep_bytes, e1.per_thread + 59u * 4096u * 100u);
    EXPECT_LT(deep_bytes, std::uint64_t{64} << 20);

    p.threads = 8;
    EXPECT_EQ(estimate_render_memory(base, p).total, e1.total + 6 * e1.per_thread);
}

TEST(RenderMemory, TilesNeverExceedTheImage) {
    RenderMemoryParams p;
    p.threads = 1;
    p.tile_width = 1 << 20;
    p.tile_height = 1 << 20;
    const RenderMemoryEstimate small = estimate_render_memory(image_scene(4, 4), p);
    EXPECT_LT(small.per_thread, kMiB);
}

TEST(RenderMemory, SaturatesInsteadOfOverflowing) {
    // 2^31 - 1 threads, each with a 46340 x 46340 tile's accumulators: far beyond 2^64.
    RenderMemoryParams p;
    p.threads = std::numeric_limits<int>::max();
    p.tile_width = 46340;
    p.tile_height = 46340;
    Scene s = image_scene(46340, 46340, std::numeric_limits<int>::max());
    s.render.max_depth = 64;
    const RenderMemoryEstimate e = estimate_render_memory(s, p);
    EXPECT_EQ(e.total, std::numeric_limits<std::uint64_t>::max());
    EXPECT_NE(e.describe().find("more than 16 EiB"), std::string::npos) << e.describe();
}

TEST(MemoryLimit, RefusesUpFrontWithTheEstimateInTheMessage) {
    Scene s = image_scene(20000, 20000);
    s.source = "big.json";
    RenderMemoryParams p;
    p.threads = 2;
    const RenderMemoryEstimate e = estimate_render_memory(s, p);
    ASSERT_GT(e.total, 4 * kGiB);  // 400 M pixels: 4.5 GiB of framebuffer alone
    try {
        check_memory_limit(s, kGiB, p);
        FAIL() << "a 20000 x 20000 render fits in 1 GiB?";
    } catch (const SceneError& err) {
        const std::string what = err.what();
        EXPECT_EQ(err.file(), "big.json");
        EXPECT_EQ(err.json_path(), "image");
        EXPECT_NE(what.find("20000 x 20000"), std::string::npos) << what;
        EXPECT_NE(what.find(e.describe()), std::string::npos) << what;
        EXPECT_NE(what.find("framebuffer 4.5 GiB"), std::string::npos) << what;
        EXPECT_NE(what.find("1073741824 bytes"), std::string::npos) << what;
    }
    EXPECT_NO_THROW(check_memory_limit(s, e.total, p));  // the limit is inclusive
    EXPECT_THROW(check_memory_limit(s, e.total - 1, p), SceneError);
}

// `octray render`'s check: a limit that holds two frames keeps the frame written behind
// the next; one that holds a single frame writes them one after another; one below that
// refuses the render with check_memory_limit's message. Every bound is inclusive.
TEST(MemoryLimit, WriteBehindIsKeptOnlyWhereBothFramesFit) {
    Scene s = image_scene(1920, 1080);
    s.source = "anim.json";
    RenderMemoryParams p;
    p.threads = 2;
    p.png_preview = true;
    const RenderMemoryEstimate one = estimate_render_memory(s, p);
    p.write_behind = true;
    const RenderMemoryEstimate two = estimate_render_memory(s, p);
    ASSERT_GT(two.total, one.total);

    for (const std::uint64_t limit : {two.total, two.total + kGiB}) {
        RenderMemoryParams fit = p;
        EXPECT_EQ(fit_memory_limit(s, limit, fit).total, two.total) << limit;
        EXPECT_TRUE(fit.write_behind) << limit;
    }
    for (const std::uint64_t limit : {two.total - 1, one.total}) {
        RenderMemoryParams fit = p;
        EXPECT_EQ(fit_memory_limit(s, limit, fit).total, one.total) << limit;
        EXPECT_FALSE(fit.write_behind) << limit;
    }
    RenderMemoryParams fit = p;
    try {
        fit_memory_limit(s, one.total - 1, fit);
        FAIL() << "one frame fits in less than its estimate?";
    } catch (const SceneError& err) {
        EXPECT_EQ(err.file(), "anim.json");
        EXPECT_NE(std::string(err.what()).find(one.describe()), std::string::npos)
            << err.what();
    }
    // Without write behind asked for, the limit only decides whether the render fits.
    RenderMemoryParams alone = p;
    alone.write_behind = false;
    EXPECT_EQ(fit_memory_limit(s, one.total, alone).total, one.total);
    EXPECT_FALSE(alone.write_behind);
}

TEST(MemoryLimit, HugeSppIsBoundedByTheTileChunks) {
    // A small image with (default, 32 x 32) tiles of 10^6 samples each: the packet path
    // traces them a chunk at a time (render/README.md, "Bounded memory"), so its scratch is
    // that of any tile with a full chunk, and the render fits where the framebuffer does.
    Scene s = image_scene(64, 64, 1000000);
    RenderMemoryParams p;
    p.threads = 1;
    EXPECT_LT(estimate_render_memory(s, p).per_thread, 8 * kMiB);
    EXPECT_NO_THROW(check_memory_limit(s, kGiB, p));
    p.packet_path = false;  // the reference renderer keeps one sample at a time
    EXPECT_NO_THROW(check_memory_limit(s, kGiB, p));
}

TEST(RenderMemory, TheReferencePathCountsItsOwnBvhUnlessAccelNone) {
    // render/reference_bvh.h: about 76 bytes per sphere while it is built; --accel none
    // tests every object and builds nothing.
    const Scene s = make_builtin_scene("random:100000");
    RenderMemoryParams with_tree, without;
    with_tree.packet_path = without.packet_path = false;
    with_tree.threads = without.threads = 1;
    without.accel = Accel::none;
    const std::uint64_t tree =
        estimate_render_memory(s, with_tree).scene - estimate_render_memory(s, without).scene;
    EXPECT_GE(tree, 100000u * 40u);
    EXPECT_LE(tree, 100000u * 100u);
}

TEST(MemorySize, ParsesBinaryUnits) {
    EXPECT_EQ(parse_memory_size("1048576"), std::uint64_t{1048576});
    EXPECT_EQ(parse_memory_size("512K"), 512u * 1024u);
    EXPECT_EQ(parse_memory_size("512KiB"), 512u * 1024u);
    EXPECT_EQ(parse_memory_size("512kb"), 512u * 1024u);
    EXPECT_EQ(parse_memory_size("300M"), 300 * kMiB);
    EXPECT_EQ(parse_memory_size("4G"), 4 * kGiB);
    EXPECT_EQ(parse_memory_size("4GiB"), 4 * kGiB);
    EXPECT_EQ(parse_memory_size("2T"), 2 * 1024 * kGiB);
    EXPECT_EQ(parse_memory_size("7B"), std::uint64_t{7});
    EXPECT_EQ(parse_memory_size("16777215T"), std::uint64_t{16777215} << 40);
}

TEST(MemorySize, RefusesEverythingElse) {
    for (const char* bad : {"", "G", "0", "0G", "-1G", "1.5G", "4 G", "4X", "4GG", "4Bi", "4iB",
                            "16777216T", "18446744073709551616", " 4G"}) {
        EXPECT_FALSE(parse_memory_size(bad).has_value()) << bad;
    }
}

TEST(MemoryParams, WhatTheEstimateTakesFromARenderConfig) {
    RenderConfig c;
    c.threads = 3;
    c.tile = {8, 4};
    c.accel = Accel::bvh;
    c.aovs.normal = true;
    const RenderMemoryParams m = memory_params(c);
    EXPECT_EQ(m.threads, 3);
    EXPECT_EQ(m.tile_width, 8);
    EXPECT_EQ(m.tile_height, 4);
    EXPECT_TRUE(m.packet_path);
    EXPECT_EQ(m.accel, Accel::bvh);
    EXPECT_TRUE(m.aov_normal);
    EXPECT_FALSE(m.aov_depth || m.aov_albedo || m.aov_id);
    c.path = RenderPath::scalar;
    EXPECT_FALSE(memory_params(c).packet_path);
}

}  // namespace
}  // namespace octray::batch
