// Files that lie, end to end: an EXR whose header declares FLOAT channels over HALF data
// (which OpenEXR 3.1 reads as garbage) is a file error, exit 4 naming the file, wherever
// octray reads an EXR: `compare`, `assemble`, and `render --skip-existing` resuming over
// it. The files are patched copies of what OpenEXR or octray itself wrote
// (tests/image/lying_exr.h).

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "run_octray.h"
#include "tests/image/compare_fixtures.h"
#include "tests/image/lying_exr.h"

namespace octray {
namespace {

using testing::run_octray;
using testing::RunResult;

class LyingExrCliTest : public testing::ScratchDirTest {};

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

TEST_F(LyingExrCliTest, CompareExits4NamingTheFileForEveryCodec) {
    for (const auto& codec : testing::all_exr_codecs()) {
        SCOPED_TRACE(codec.name);
        testing::write_smooth_exr(path("honest.exr"), codec.compression, Imf::HALF, false);
        testing::write_lying_exr(path("lie.exr"), codec.compression, true, false);
        const RunResult r = run_octray({"compare", "honest.exr", "lie.exr"}, dir_);
        EXPECT_EQ(r.status, 4) << r.output;
        // (An uncompressed one is found short by its size before its chunks are read.)
        EXPECT_TRUE(contains(r.output, "octray: I/O error: cannot read 'lie.exr': "))
            << r.output;
        EXPECT_TRUE(contains(r.output, "corrupt OpenEXR file")) << r.output;
        EXPECT_FALSE(contains(r.output, "FAIL")) << r.output;
    }
}

TEST_F(LyingExrCliTest, AssembleExits4NamingTheFileAndWritesNothing) {
    testing::write_smooth_exr(path("part.exr"), Imf::ZIP_COMPRESSION, Imf::HALF, false);
    testing::declare_channels_as(path("part.exr"), Imf::HALF, Imf::FLOAT);
    const RunResult r = run_octray({"assemble", "part.exr", "-o", "out.exr"}, dir_);
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, "cannot read '")) << r.output;
    EXPECT_TRUE(contains(r.output, "part.exr': corrupt OpenEXR file")) << r.output;
    EXPECT_FALSE(testing::fs::exists(path("out.exr")));
}

// A resumed batch never takes a lying file for a finished frame, nor renders over it.
TEST_F(LyingExrCliTest, ResumeOverALyingFrameExits4AndLeavesItAlone) {
    const std::vector<std::string> render{
        "render", "whitted", "--width",     "16",       "--height", "8",          "--spp",
        "1",      "-o",      "out/r.#.exr", "--frames", "0-1",      "--progress", "none"};
    RunResult r = run_octray(render, dir_);
    ASSERT_EQ(r.status, 0) << r.output;
    testing::declare_channels_as(path("out/r.0.exr"), Imf::HALF, Imf::FLOAT);
    const std::vector<char> lying = testing::read_bytes(path("out/r.0.exr"));

    std::vector<std::string> resume = render;
    resume.push_back("--skip-existing");
    r = run_octray(resume, dir_);
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, "cannot read 'out/r.0.exr': corrupt OpenEXR file"))
        << r.output;
    EXPECT_TRUE(contains(r.output, "remove it to render the frame again")) << r.output;
    EXPECT_EQ(testing::read_bytes(path("out/r.0.exr")), lying);

    std::vector<std::string> claims = render;
    claims.push_back("--placeholders");
    r = run_octray(claims, dir_);
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_EQ(testing::read_bytes(path("out/r.0.exr")), lying);
}

}  // namespace
}  // namespace octray
