// Assembling crops (render/batch/assemble.h): parts of a render, written as cropped EXRs with
// AOVs, assemble into exactly the file the uncropped render writes (2x2 and irregular
// splits, half and float); overlaps, gaps and mismatches are refused with the parts and
// pixels named.

#include "render/batch/assemble.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "output_fixtures.h"
#include "render/aov.h"
#include "render/batch/camera_matrices.h"
#include "render/image/image_io.h"
#include "render/image/image_read.h"

namespace octray::batch {
namespace {

constexpr int kWidth = 29, kHeight = 19;

// What `octray render --crop R --aov depth,normal,albedo,id` writes for one crop.
Image render_part(const Scene& scene, std::optional<PixelRect> crop, bool float32) {
    RenderOptions options;
    options.crop = crop;
    const RenderResult result = render_packet(scene, options);
    ExrAttributes attributes;
    attributes.strings.emplace_back("software", "octray test");
    attributes.rationals.emplace_back("framesPerSecond", ExrRational{24, 1});
    add_camera_attributes(attributes, scene, scene.camera);
    Image exr =
        make_exr_image(result.image, ExrWriteOptions{float32, ExrCompression::zip}, attributes);
    append_aov_channels(exr, compute_aovs(scene, options, AovSet{true, true, true, true}),
                        float32 ? PixelFormat::float32 : PixelFormat::half);
    return exr;
}

std::vector<std::string> write_parts(const Scene& scene, const std::vector<PixelRect>& crops,
                                     bool float32, const std::filesystem::path& dir) {
    std::vector<std::string> paths;
    for (std::size_t k = 0; k < crops.size(); ++k) {
        std::string name = "part";
        name += std::to_string(k);
        name += ".exr";
        paths.push_back((dir / name).string());
        write_exr(paths.back(), render_part(scene, crops[k], float32));
    }
    return paths;
}

void expect_same_image(const Image& a, const Image& b) {
    EXPECT_EQ(a.display_window, b.display_window);
    EXPECT_EQ(a.data_window, b.data_window);
    EXPECT_EQ(a.compression, b.compression);
    ASSERT_EQ(a.channels.size(), b.channels.size());
    for (std::size_t k = 0; k < a.channels.size(); ++k) {
        EXPECT_EQ(a.channels[k].name, b.channels[k].name);
        EXPECT_EQ(a.channels[k].format, b.channels[k].format);
        EXPECT_TRUE(a.channels[k].samples == b.channels[k].samples) << a.channels[k].name;
    }
    EXPECT_EQ(a.attributes.strings, b.attributes.strings);
    EXPECT_EQ(a.attributes.matrices, b.attributes.matrices);
    EXPECT_EQ(a.attributes.rationals, b.attributes.rationals);
    EXPECT_EQ(a.attributes.floats, b.attributes.floats);
    EXPECT_EQ(a.attributes.opaque.size(), b.attributes.opaque.size());
}

TEST(Assemble, PartsMakeTheFullRenderBitForBit) {
    const Scene scene = testing::golden_scene("thinlens_spp4", kWidth, kHeight);
    const std::vector<std::vector<PixelRect>> splits{
        // 2 x 2
        {{0, 0, 15, 10}, {15, 0, 29, 10}, {0, 10, 15, 19}, {15, 10, 29, 19}},
        // irregular: a one-pixel part, a single row, uneven columns, given out of order
        {{0, 0, 1, 1},
         {1, 0, 29, 1},
         {20, 1, 29, 19},
         {0, 1, 7, 19},
         {7, 1, 20, 18},
         {7, 18, 20, 19}},
        // one part that is the whole image
        {{0, 0, 29, 19}},
    };
    for (bool float32 : {false, true}) {
        const std::filesystem::path dir = testing::test_dir();
        const std::string whole = (dir / "whole.exr").string();
        write_exr(whole, render_part(scene, std::nullopt, float32));
        const Image expected = read_exr_image(whole);
        for (std::size_t s = 0; s < splits.size(); ++s) {
            SCOPED_TRACE(std::string(float32 ? "float" : "half") + " split " +
                         std::to_string(s));
            const std::vector<std::string> parts = write_parts(scene, splits[s], float32, dir);
            const std::string out = (dir / "assembled.exr").string();
            const AssembleSummary summary = assemble_files(parts, out);
            EXPECT_EQ(summary.parts, splits[s].size());
            EXPECT_EQ(summary.display_window, (PixelRect{0, 0, kWidth, kHeight}));
            EXPECT_EQ(summary.channels.size(), 11u);
            expect_same_image(read_exr_image(out), expected);
        }
    }
}

// The message of the AssembleError that assembling `parts` throws.
std::string assemble_error(const std::vector<Image>& parts) {
    std::vector<std::string> names;
    for (std::size_t k = 0; k < parts.size(); ++k) {
        std::string name = "p";
        name += std::to_string(k);
        names.push_back(name);
    }
    try {
        assemble_parts(parts, names);
    } catch (const AssembleError& e) {
        return e.what();
    }
    return "(no error)";
}

Image blank(PixelRect data, PixelRect display = {0, 0, 8, 6}, bool float32 = false) {
    Image image(data.width(), data.height(), {"R", "G", "B"});
    image.data_window = data;
    image.display_window = PixelRect{0, 0, display.x1, display.y1};
    Image exr = make_exr_image(image, ExrWriteOptions{float32, ExrCompression::zip});
    return exr;
}

TEST(Assemble, OverlapsGapsAndMismatchesAreNamed) {
    const PixelRect left{0, 0, 4, 6}, right{4, 0, 8, 6};
    EXPECT_EQ(assemble_error({blank(left), blank(right)}), "(no error)");

    std::string e = assemble_error({blank(left), blank({3, 2, 8, 6}), blank({4, 0, 8, 2})});
    EXPECT_NE(e.find("parts 'p0' (0, 0)-(4, 6) and 'p1' (3, 2)-(8, 6) overlap in "
                     "(3, 2)-(4, 6)"),
              std::string::npos)
        << e;

    e = assemble_error({blank(left), blank({4, 0, 8, 3}), blank({4, 4, 8, 6})});
    EXPECT_NE(e.find("no part covers pixel (4, 3)"), std::string::npos) << e;
    EXPECT_NE(e.find("leave 4 of the 48 pixels"), std::string::npos) << e;
    EXPECT_NE(e.find("among them (4, 3)-(8, 4)"), std::string::npos) << e;

    e = assemble_error({blank(left)});
    EXPECT_NE(e.find("no part covers pixel (4, 0)"), std::string::npos) << e;
    EXPECT_NE(e.find("(4, 0)-(8, 6)"), std::string::npos) << e;

    e = assemble_error({blank(left), blank({4, 0, 9, 6}, {0, 0, 9, 6})});
    EXPECT_NE(e.find("part 'p1' has the display window (0, 0)-(9, 6), but 'p0' has "
                     "(0, 0)-(8, 6)"),
              std::string::npos)
        << e;

    e = assemble_error({blank(left), blank(right, {0, 0, 8, 6}, true)});
    EXPECT_NE(e.find("part 'p1' has the channels R (float), G (float), B (float)"),
              std::string::npos)
        << e;
    EXPECT_NE(e.find("'p0' has R (half), G (half), B (half)"), std::string::npos) << e;

    Image extra = blank(right);
    extra.channels.push_back(make_channel("id", std::vector<std::uint32_t>(24, 1u)));
    e = assemble_error({blank(left), extra});
    EXPECT_NE(e.find("id (uint)"), std::string::npos) << e;

    Image outside = blank({4, 0, 9, 6}, {0, 0, 8, 6});
    e = assemble_error({blank(left), outside});
    EXPECT_NE(e.find("data window (4, 0)-(9, 6), which is not inside the display window"),
              std::string::npos)
        << e;
}

TEST(Assemble, UnreadablePartsAreIoErrorsAndNothingIsWritten) {
    const std::filesystem::path dir = testing::test_dir();
    const std::string good = (dir / "good.exr").string();
    write_exr(good, blank({0, 0, 4, 6}));
    const std::string out = (dir / "out.exr").string();
    EXPECT_THROW(assemble_files({good, (dir / "missing.exr").string()}, out), IoError);
    EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace octray::batch
