// End-to-end tests of `octray assemble`: parts written as `render --crop` writes them
// (cropped data windows, AOVs, camera attributes), stitched by the executable into the
// full render bit for bit; every exit code with its message.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "render/aov.h"
#include "render/batch/assemble.h"
#include "render/batch/camera_matrices.h"
#include "render/image/image_io.h"
#include "render/image/image_read.h"
#include "render/packet_renderer.h"
#include "run_octray.h"
#include "scene/load.h"

namespace octray {
namespace {

namespace fs = std::filesystem;
using testing::RunResult;

class AssembleCliTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::path(OCTRAY_TEST_TMPDIR) / "assemble_cli" / info->name();
        fs::remove_all(dir_);
        fs::create_directories(dir_);
        scene_ = load_scene("whitted");
        scene_.image.width = 24;
        scene_.image.height = 14;
        scene_.image.spp = 2;
        validate_scene(scene_);
    }

    std::string path(const std::string& name) const { return (dir_ / name).string(); }

    // What `octray render --crop` writes for one crop (nullopt: the whole image).
    void write_part(const std::string& name, std::optional<PixelRect> crop,
                    bool float32 = false) const {
        RenderOptions options;
        options.crop = crop;
        ExrAttributes attributes;
        batch::add_camera_attributes(attributes, scene_, scene_.camera);
        attributes.ints.emplace_back("octray:frame", 3);
        const RenderResult result = render_packet(scene_, options);
        Image exr = make_exr_image(result.image, ExrWriteOptions{float32, ExrCompression::zip},
                                   attributes);
        append_aov_channels(exr, compute_aovs(scene_, options, AovSet{true, true, false, true}),
                            float32 ? PixelFormat::float32 : PixelFormat::half);
        write_exr(path(name), exr);
    }

    RunResult assemble(std::vector<std::string> args) const {
        args.insert(args.begin(), "assemble");
        return testing::run_octray(args, dir_);
    }

    fs::path dir_;
    Scene scene_;
};

TEST_F(AssembleCliTest, QuartersMakeTheFullRender) {
    write_part("full.exr", std::nullopt);
    write_part("a.exr", PixelRect{0, 0, 10, 7});
    write_part("b.exr", PixelRect{10, 0, 24, 7});
    write_part("c.exr", PixelRect{0, 7, 10, 14});
    write_part("d.exr", PixelRect{10, 7, 24, 14});
    const RunResult r = assemble({"d.exr", "b.exr", "a.exr", "c.exr", "-o", "out.exr"});
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("wrote out.exr (24x14, 4 parts; "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("Z (float)"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("id (uint)"), std::string::npos) << r.output;

    const Image out = read_exr_image(path("out.exr"));
    const Image full = read_exr_image(path("full.exr"));
    EXPECT_EQ(out.data_window, (PixelRect{0, 0, 24, 14}));
    EXPECT_EQ(out.display_window, full.display_window);
    ASSERT_EQ(out.channels.size(), full.channels.size());
    for (std::size_t k = 0; k < out.channels.size(); ++k) {
        EXPECT_EQ(out.channels[k].name, full.channels[k].name);
        EXPECT_EQ(out.channels[k].format, full.channels[k].format);
        EXPECT_TRUE(out.channels[k].samples == full.channels[k].samples)
            << out.channels[k].name;
    }
    EXPECT_EQ(out.attributes.matrices, full.attributes.matrices);
    EXPECT_EQ(out.attributes.ints, full.attributes.ints);
    // Nothing but the parts and the result in the directory: no temporary left.
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_)) ++files;
    EXPECT_EQ(files, 6u);
}

TEST_F(AssembleCliTest, OverlapExits2NamingBothParts) {
    write_part("left.exr", PixelRect{0, 0, 13, 14});
    write_part("right.exr", PixelRect{12, 0, 24, 14});
    const RunResult r = assemble({"left.exr", "right.exr", "-o", "out.exr"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("parts 'left.exr' (0, 0)-(13, 14) and 'right.exr' (12, 0)-(24, 14) "
                            "overlap in (12, 0)-(13, 14)"),
              std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(path("out.exr")));
}

TEST_F(AssembleCliTest, GapExits2NamingAPixel) {
    write_part("top.exr", PixelRect{0, 0, 24, 5});
    write_part("bottom.exr", PixelRect{0, 6, 24, 14});
    const RunResult r = assemble({"top.exr", "bottom.exr", "-o", "out.exr"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("no part covers pixel (0, 5)"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("among them (0, 5)-(24, 6)"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(path("out.exr")));
}

TEST_F(AssembleCliTest, MismatchedPartsExit2) {
    write_part("half.exr", PixelRect{0, 0, 12, 14});
    write_part("float.exr", PixelRect{12, 0, 24, 14}, true);
    RunResult r = assemble({"half.exr", "float.exr", "-o", "out.exr"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("part 'float.exr' has the channels"), std::string::npos)
        << r.output;

    scene_.image.width = 30;
    write_part("wide.exr", PixelRect{12, 0, 30, 14});
    r = assemble({"half.exr", "wide.exr", "-o", "out.exr"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("part 'wide.exr' has the display window (0, 0)-(30, 14), but "
                            "'half.exr' has (0, 0)-(24, 14)"),
              std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(path("out.exr")));
}

TEST_F(AssembleCliTest, UnreadablePartsAndUnwritableOutputExit4) {
    write_part("a.exr", PixelRect{0, 0, 24, 14});
    RunResult r = assemble({"a.exr", "missing.exr", "-o", "out.exr"});
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_NE(r.output.find("cannot read 'missing.exr': no such file"), std::string::npos)
        << r.output;

    std::ofstream(path("text.exr")) << "not an image\n";
    r = assemble({"text.exr", "-o", "out.exr"});
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_NE(r.output.find("not an OpenEXR file"), std::string::npos) << r.output;

    r = assemble({"a.exr", "-o", "no/such/dir/out.exr"});
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_NE(r.output.find("cannot write no/such/dir/out.exr"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(path("out.exr")));

    // One part that is the whole image is a valid (if trivial) assembly.
    r = assemble({"a.exr", "-o", "out.exr"});
    EXPECT_EQ(r.status, 0) << r.output;
}

TEST_F(AssembleCliTest, UsageErrorsAndHelp) {
    RunResult r = assemble({"-o", "out.exr"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("parts"), std::string::npos) << r.output;
    r = assemble({"a.exr"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--output"), std::string::npos) << r.output;
    r = assemble({"--help"});
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("octray assemble q0.exr q1.exr q2.exr q3.exr -o full.exr"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("Exit codes"), std::string::npos) << r.output;
}

// Issue 23: the extension of -o decides the format: .exr as before, .png the 8-bit sRGB
// preview of the assembled R, G, B; anything else is a usage error naming both.
TEST_F(AssembleCliTest, OutputFormatFollowsTheExtension) {
    write_part("a.exr", PixelRect{0, 0, 10, 14});
    write_part("b.exr", PixelRect{10, 0, 24, 14});
    for (const char* name : {"out.jpg", "out", "out.exr.part"}) {
        const RunResult r = assemble({"a.exr", "b.exr", "-o", name});
        EXPECT_EQ(r.status, 2) << name << "\n" << r.output;
        EXPECT_NE(r.output.find(".exr"), std::string::npos) << r.output;
        EXPECT_NE(r.output.find(".png"), std::string::npos) << r.output;
        EXPECT_FALSE(fs::exists(dir_ / name)) << name;
    }
    RunResult r = assemble({"a.exr", "b.exr", "-o", "OUT.EXR"});
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(read_exr_image(path("OUT.EXR")).data_window, (PixelRect{0, 0, 24, 14}));
    r = assemble({"a.exr", "b.exr", "-o", "out.png"});
    ASSERT_EQ(r.status, 0) << r.output;
    const Image png = read_image(path("out.png"));
    EXPECT_EQ(png.file_format, "PNG 8-bit");
    EXPECT_EQ(png.width(), 24);
    EXPECT_EQ(png.height(), 14);
}

}  // namespace
}  // namespace octray
