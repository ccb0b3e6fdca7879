// End-to-end tests of `octray compare`: every exit code, its one-line reason, and the files
// --diff and --heatmap leave behind. Inputs are written with OpenEXR and libpng directly.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "run_octray.h"
#include "tests/image/compare_fixtures.h"

namespace octray {
namespace {

using testing::make_image;
using testing::write_test_exr;

using testing::RunResult;

class CompareCliTest : public testing::ScratchDirTest {
  protected:
    // Runs `octray compare <args...>` in the scratch directory.
    RunResult compare(std::vector<std::string> args, bool capture_stderr = true) {
        args.insert(args.begin(), "compare");
        return testing::run_octray(args, dir_, capture_stderr);
    }

    // The reference: 8x8 RGB, a ramp; and a copy whose pixel (5, 3) is off in G by `delta`.
    void write_pair(float delta) {
        Image a = make_image(8, 8, {"R", "G", "B"});
        for (int c = 0; c < a.channel_count(); ++c)
            for (std::size_t i = 0; i < a.pixel_count(); ++i)
                a.plane(c)[i] = static_cast<float>(i % 64) / 64.0f;
        Image b = a;
        b.at(1, 5, 3) += delta;
        write_test_exr(path("a.exr"), a);
        write_test_exr(path("b.exr"), b);
    }
};

std::string last_line(const std::string& text) {
    std::string trimmed = text;
    while (!trimmed.empty() && trimmed.back() == '\n') trimmed.pop_back();
    return trimmed.substr(trimmed.rfind('\n') + 1);
}

TEST_F(CompareCliTest, IdenticalImagesExit0) {
    write_pair(0.0f);
    const RunResult r = compare({"a.exr", "b.exr"});
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(last_line(r.output), "PASS: images are identical");
}

TEST_F(CompareCliTest, OverTheWarnLimitExits1) {
    write_pair(0.125f);
    const RunResult r = compare({"a.exr", "b.exr", "--fail", "0.5", "--warn", "0.01"});
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_EQ(last_line(r.output),
              "WARN: 1 of 64 pixels (1.562%) differ by more than 0.01; allowed 0%");
    EXPECT_NE(r.output.find("max error 0.125 at (5, 3) G"), std::string::npos) << r.output;
}

TEST_F(CompareCliTest, OverTheFailLimitExits2) {
    write_pair(0.125f);
    const RunResult r = compare({"a.exr", "b.exr"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_EQ(last_line(r.output).rfind("FAIL: 1 of 64 pixels", 0), 0u) << r.output;
}

TEST_F(CompareCliTest, PercentAllowancesAndHardFail) {
    write_pair(0.125f);
    EXPECT_EQ(compare({"a.exr", "b.exr", "--failpercent", "2", "--warnpercent", "2"}).status,
              0);
    const RunResult r = compare(
        {"a.exr", "b.exr", "--failpercent", "2", "--warnpercent", "2", "--hardfail", "0.1"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_EQ(last_line(r.output), "FAIL: error 0.125 at (5, 3) G is over the hard limit 0.1");
}

TEST_F(CompareCliTest, SizeMismatchExits3) {
    write_test_exr(path("a.exr"), make_image(8, 8, {"R", "G", "B"}));
    write_test_exr(path("b.exr"), make_image(8, 7, {"R", "G", "B"}));
    const RunResult r = compare({"a.exr", "b.exr"});
    EXPECT_EQ(r.status, 3) << r.output;
    EXPECT_EQ(r.output,
              "octray: compare: size mismatch: A is 8x8, B is 8x7 (A = a.exr, B = b.exr)\n");
}

TEST_F(CompareCliTest, ChannelMismatchExits3UnlessChannelsAreChosen) {
    write_test_exr(path("rgba.exr"), make_image(4, 4, {"R", "G", "B", "A"}, 0.5f));
    testing::write_test_png(path("rgb.png"), 4, 4, 3, 8,
                            std::vector<std::uint16_t>(4 * 4 * 3, 255));
    const RunResult r = compare({"rgba.exr", "rgb.png"});
    EXPECT_EQ(r.status, 3) << r.output;
    EXPECT_NE(r.output.find("channel mismatch: A has R,G,B,A, B has R,G,B"), std::string::npos)
        << r.output;
    // With the common channels chosen they compare: 0.5 against 1.0 everywhere.
    const RunResult chosen = compare({"rgba.exr", "rgb.png", "--channels", "R,G,B"});
    EXPECT_EQ(chosen.status, 2) << chosen.output;
    EXPECT_NE(chosen.output.find("max error 0.5"), std::string::npos) << chosen.output;
}

TEST_F(CompareCliTest, FileErrorsExit4WithOneLineReasons) {
    write_pair(0.0f);
    RunResult r = compare({"a.exr", "missing.exr"});
    EXPECT_EQ(r.status, 4);
    EXPECT_EQ(r.output, "octray: I/O error: cannot read 'missing.exr': no such file\n");

    testing::write_text_file(path("notes.exr"), "plain text\n");
    r = compare({"notes.exr", "a.exr"});
    EXPECT_EQ(r.status, 4);
    EXPECT_EQ(r.output,
              "octray: I/O error: cannot read 'notes.exr': not an image (neither an OpenEXR "
              "nor a PNG signature)\n");
}

TEST_F(CompareCliTest, TruncatedExrExits4WithAClearMessage) {
    Image big = make_image(64, 64, {"R", "G", "B"}, 0.25f);
    write_test_exr(path("ref.exr"), big);
    write_test_exr(path("cut.exr"), big, Imf::FLOAT, Imf::NO_COMPRESSION);
    testing::truncate_file(path("cut.exr"), testing::fs::file_size(path("cut.exr")) / 2);
    const RunResult r = compare({"ref.exr", "cut.exr"});
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_EQ(r.output.rfind("octray: I/O error: cannot read 'cut.exr': truncated or corrupt "
                             "OpenEXR file",
                             0),
              0u)
        << r.output;
    EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << "not one line: " << r.output;
}

TEST_F(CompareCliTest, NanAndInfAreReportedNotCrashedOn) {
    Image a = make_image(4, 4, {"R", "G", "B"}, 0.5f);
    Image b = a;
    a.at(0, 1, 2) = std::numeric_limits<float>::quiet_NaN();
    b.at(2, 3, 3) = std::numeric_limits<float>::infinity();
    write_test_exr(path("a.exr"), a);
    write_test_exr(path("b.exr"), b);
    const RunResult r = compare({"a.exr", "b.exr", "--heatmap", "h.png", "--diff", "d.exr"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("2 pixels hold NaN or Inf (A: 1 NaN, 0 Inf; B: 0 NaN, 1 Inf "
                            "values); first at (1, 2) R: A = nan, B = 0.5"),
              std::string::npos)
        << r.output;
    EXPECT_NE(last_line(r.output).find("(2 with NaN or Inf)"), std::string::npos) << r.output;
    EXPECT_TRUE(testing::fs::exists(dir_ / "h.png"));
    EXPECT_TRUE(testing::fs::exists(dir_ / "d.exr"));
}

TEST_F(CompareCliTest, DiffAndHeatmapFilesAreWritten) {
    write_pair(0.125f);
    const RunResult r = compare({"a.exr", "b.exr", "--diff", "d.exr", "--heatmap", "h.png"});
    EXPECT_EQ(r.status, 2) << r.output;
    const Image diff = read_image(path("d.exr"));
    EXPECT_EQ(diff.channel_names(), (std::vector<std::string>{"R", "G", "B"}));
    EXPECT_EQ(diff.at(1, 5, 3), 0.125f);
    EXPECT_EQ(diff.at(1, 4, 3), 0.0f);
    const Image heatmap = read_image(path("h.png"));
    EXPECT_EQ(heatmap.file_format, "PNG 8-bit");
    EXPECT_GE(heatmap.width(), 256);
}

TEST_F(CompareCliTest, UnwritableOutputExits4) {
    write_pair(0.125f);
    const RunResult r = compare({"a.exr", "b.exr", "--diff", "no/such/dir/d.exr"});
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_NE(r.output.find("no/such/dir/d.exr"), std::string::npos) << r.output;
}

TEST_F(CompareCliTest, JsonCarriesTheVerdictForEveryOutcome) {
    write_pair(0.125f);
    RunResult r = compare({"a.exr", "b.exr", "--json"}, /*capture_stderr=*/false);
    EXPECT_EQ(r.status, 2);
    nlohmann::json j = nlohmann::json::parse(r.output);
    EXPECT_EQ(j["verdict"], "FAIL");
    EXPECT_EQ(j["overall"]["fail_pixels"], 1);
    EXPECT_EQ(j["overall"]["max_abs_error"], 0.125);
    EXPECT_EQ(j["overall"]["max_at"]["channel"], "G");
    EXPECT_EQ(j["channels"].size(), 3u);

    r = compare({"a.exr", "a.exr", "--json"}, false);
    EXPECT_EQ(r.status, 0);
    j = nlohmann::json::parse(r.output);
    EXPECT_EQ(j["verdict"], "PASS");
    EXPECT_TRUE(j["overall"]["psnr_db"].is_null());

    write_test_exr(path("small.exr"), make_image(2, 2, {"R", "G", "B"}));
    r = compare({"a.exr", "small.exr", "--json"}, false);
    EXPECT_EQ(r.status, 3);
    j = nlohmann::json::parse(r.output);
    EXPECT_EQ(j["verdict"], "MISMATCH");
    EXPECT_EQ(j["exit_code"], 3);

    r = compare({"a.exr", "gone.exr", "--json"}, false);
    EXPECT_EQ(r.status, 4);
    j = nlohmann::json::parse(r.output);
    EXPECT_EQ(j["verdict"], "ERROR");
    EXPECT_EQ(j["reason"], "cannot read 'gone.exr': no such file");
}

TEST_F(CompareCliTest, BadCommandLinesAreRejected) {
    write_pair(0.0f);
    RunResult r = compare({"a.exr", "b.exr", "--failpercent", "200"});
    EXPECT_EQ(r.status, 5) << r.output;
    EXPECT_NE(r.output.find("--failpercent"), std::string::npos) << r.output;
    r = compare({"a.exr"});
    EXPECT_EQ(r.status, 5) << r.output;
    r = compare({"a.exr", "b.exr", "--diff", "x.exr", "--heatmap", "x.exr"});
    EXPECT_EQ(r.status, 5) << r.output;
}

// Issue 23: a NaN threshold would make every comparison pass (nothing is "> NaN"): it is a
// usage error for every threshold option.
TEST_F(CompareCliTest, NanThresholdsAreUsageErrors) {
    write_pair(0.125f);
    for (const char* option :
         {"--fail", "--warn", "--failpercent", "--warnpercent", "--hardfail", "--hardwarn"}) {
        for (const char* value : {"nan", "NaN", "-nan"}) {
            const RunResult r = compare({"a.exr", "b.exr", option, value});
            EXPECT_EQ(r.status, 5) << option << " " << value << "\n" << r.output;
            EXPECT_NE(r.output.find(option), std::string::npos) << r.output;
            EXPECT_NE(r.output.find("--help"), std::string::npos) << r.output;
        }
    }
    const RunResult both = compare({"a.exr", "b.exr", "--fail", "nan", "--warn", "nan"});
    EXPECT_EQ(both.status, 5) << both.output;
    EXPECT_NE(both.output.find("--help"), std::string::npos) << both.output;
}

// Issue 23: inf, the documented default of the hard limits, can be given; thresholds take
// decimal numbers and inf, nothing else.
TEST_F(CompareCliTest, InfinityIsAValidThreshold) {
    write_pair(0.125f);
    RunResult r = compare({"a.exr", "b.exr", "--failpercent", "2", "--warnpercent", "2",
                           "--hardfail", "inf", "--hardwarn", "inf"});
    EXPECT_EQ(r.status, 0) << r.output;
    r = compare({"a.exr", "b.exr", "--fail", "inf", "--warn", "Infinity"});
    EXPECT_EQ(r.status, 0) << r.output;
    for (const char* value : {"-inf", "-1", "0x1p3", "1e999", "", " 1", "1x"}) {
        r = compare({"a.exr", "b.exr", "--hardfail", value});
        EXPECT_EQ(r.status, 5) << "'" << value << "'\n" << r.output;
        EXPECT_NE(r.output.find("--help"), std::string::npos) << value << "\n" << r.output;
    }
}

// Issue 23: equal infinities are equal (as idiff has it): a depth AOV whose background is
// +inf matches itself with --fail 0. Different infinities, or one against a number, fail.
TEST_F(CompareCliTest, EqualInfinitiesAreEqual) {
    constexpr float inf = std::numeric_limits<float>::infinity();
    Image z = make_image(4, 4, {"Z"}, 2.0f);
    z.at(0, 1, 1) = inf;
    z.at(0, 3, 2) = -inf;
    write_test_exr(path("z.exr"), z);
    write_test_exr(path("z2.exr"), z);
    RunResult r = compare({"z.exr", "z2.exr", "--fail", "0", "--diff", "d.exr"});
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(last_line(r.output), "PASS: images are identical");
    const Image diff = read_image(path("d.exr"));
    EXPECT_EQ(diff.at(0, 1, 1), 0.0f);
    EXPECT_EQ(diff.at(0, 3, 2), 0.0f);

    Image w = z;
    w.at(0, 1, 1) = -inf;
    write_test_exr(path("w.exr"), w);
    r = compare({"z.exr", "w.exr", "--fail", "0"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(last_line(r.output).find("(1 with NaN or Inf)"), std::string::npos) << r.output;
    Image f = z;
    f.at(0, 1, 1) = 1e30f;
    write_test_exr(path("f.exr"), f);
    EXPECT_EQ(compare({"z.exr", "f.exr"}).status, 2);
}

// Issue 23: --diff writes float OpenEXR, chosen by the extension like every output; any
// other extension is a usage error naming the formats.
TEST_F(CompareCliTest, DiffOutputMustBeAnExr) {
    write_pair(0.0f);
    for (const char* name : {"d.png", "d.tif", "d"}) {
        const RunResult r = compare({"a.exr", "b.exr", "--diff", name});
        EXPECT_EQ(r.status, 5) << name << "\n" << r.output;
        EXPECT_NE(r.output.find(".exr"), std::string::npos) << r.output;
        EXPECT_NE(r.output.find("--heatmap"), std::string::npos) << r.output;
        EXPECT_NE(r.output.find("--help"), std::string::npos) << r.output;
        EXPECT_FALSE(testing::fs::exists(dir_ / name)) << name;
    }
    const RunResult r = compare({"a.exr", "b.exr", "--diff", "D.EXR"});
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(read_image(path("D.EXR")).channel_names(),
              (std::vector<std::string>{"R", "G", "B"}));
}

TEST_F(CompareCliTest, HelpListsTheExitCodes) {
    const RunResult r = compare({"--help"});
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.output.find("3  the images cannot be compared"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("--hardfail"), std::string::npos);
    EXPECT_NE(r.output.find("5  usage error"), std::string::npos) << r.output;
}

// Issue 26: a usage error is not the FAIL verdict (2): a CI script tells a typo from a
// regression by the status alone, and the message names compare's own help.
TEST_F(CompareCliTest, UsageErrorsExit5NotTheFailStatus) {
    write_pair(0.125f);
    const std::vector<std::vector<std::string>> bad = {
        {"a.exr"},
        {"a.exr", "b.exr", "--no-such-option"},
        {"a.exr", "b.exr", "--failpercent", "200"},
        {"a.exr", "b.exr", "--fail", "nan"},
        {"a.exr", "b.exr", "--diff", "d.png"},
        {"a.exr", "b.exr", "--diff", "x.exr", "--heatmap", "x.exr"},
    };
    for (const auto& args : bad) {
        const RunResult r = compare(args);
        EXPECT_EQ(r.status, 5) << args.back() << "\n" << r.output;
        EXPECT_NE(r.output.find("Run 'octray compare --help' for more information."),
                  std::string::npos)
            << r.output;
    }
    // The same pair with a good command line is a FAIL: 2, a different status.
    EXPECT_EQ(compare({"a.exr", "b.exr"}).status, 2);
}

// Issue 26: a small error next to a large one is black on the linear 0..max scale;
// --scale F (idiff's) and --heatmapscale log make it visible, and the report says which
// scale the picture uses.
TEST_F(CompareCliTest, HeatmapScaleAndFactorAreReported) {
    write_pair(0.125f);
    RunResult r = compare({"a.exr", "b.exr", "--heatmap", "h.png"});
    EXPECT_NE(r.output.find("wrote h.png (error heatmap, linear: 0 to 0.125)"),
              std::string::npos)
        << r.output;
    r = compare({"a.exr", "b.exr", "--heatmap", "h.png", "--scale", "100"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("wrote h.png (error heatmap, linear x100: 0 to 0.01)"),
              std::string::npos)
        << r.output;
    r = compare({"a.exr", "b.exr", "--heatmap", "h.png", "--heatmapscale", "log"});
    EXPECT_NE(r.output.find("wrote h.png (error heatmap, log: 1.25e-07 to 0.125)"),
              std::string::npos)
        << r.output;
    EXPECT_TRUE(testing::fs::exists(dir_ / "h.png"));
}

TEST_F(CompareCliTest, BadHeatmapScalesAreUsageErrors) {
    write_pair(0.125f);
    const std::vector<std::vector<std::string>> bad = {
        {"--heatmap", "h.png", "--scale", "0"},
        {"--heatmap", "h.png", "--scale", "-2"},
        {"--heatmap", "h.png", "--scale", "nan"},
        {"--heatmap", "h.png", "--scale", "inf"},
        {"--heatmap", "h.png", "--scale", "0x10"},
        {"--heatmap", "h.png", "--scale", " 5"},
        {"--heatmap", "h.png", "--scale", "x"},
        {"--heatmap", "h.png", "--heatmapscale", "cubic"},
        {"--scale", "100"},
        {"--heatmapscale", "log"},
    };
    for (std::vector<std::string> args : bad) {
        const std::string option = args[args.size() - 2];
        args.insert(args.begin(), {"a.exr", "b.exr"});
        const RunResult r = compare(args);
        EXPECT_EQ(r.status, 5) << args.back() << "\n" << r.output;
        EXPECT_NE(r.output.find(option), std::string::npos) << r.output;
    }
    EXPECT_FALSE(testing::fs::exists(dir_ / "h.png"));
    const RunResult none = compare({"a.exr", "b.exr", "--scale", "100"});
    EXPECT_NE(none.output.find("no --heatmap FILE.png was given"), std::string::npos)
        << none.output;
}

// Issue 43: the report says when the two files store their values differently: half
// against float (the same image differs by half's rounding) and a display-referred PNG
// against a linear OpenEXR.
TEST_F(CompareCliTest, TheReportNotesFormatsThatDiffer) {
    Image image = make_image(8, 8, {"R", "G", "B"});
    for (int c = 0; c < image.channel_count(); ++c)
        for (std::size_t i = 0; i < image.pixel_count(); ++i)
            image.plane(c)[i] = 0.1f + 0.731f * static_cast<float>(i % 64) / 64.0f;
    write_test_exr(path("half.exr"), image, Imf::HALF);
    write_test_exr(path("float.exr"), image, Imf::FLOAT);
    RunResult r = compare({"half.exr", "float.exr"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("note: A is OpenEXR half, B is OpenEXR float: half keeps 11 "
                            "significant bits"),
              std::string::npos)
        << r.output;
    EXPECT_EQ(last_line(r.output).rfind("FAIL: ", 0), 0u) << "the reason stays last";
    // What the note advises passes half's rounding.
    r = compare(
        {"half.exr", "float.exr", "--failrelative", "0.001", "--warnrelative", "0.001"});
    EXPECT_EQ(r.status, 0) << r.output;
    r = compare({"half.exr", "float.exr", "--json"});
    const nlohmann::json j = nlohmann::json::parse(r.output);
    ASSERT_EQ(j["notes"].size(), 1u) << r.output;

    testing::write_test_png(path("preview.png"), 8, 8, 3, 8,
                            std::vector<std::uint16_t>(8 * 8 * 3, 128));
    r = compare({"preview.png", "float.exr"});
    EXPECT_NE(r.output.find("note: A is PNG 8-bit, B is OpenEXR float: a PNG holds "
                            "display-referred sRGB-encoded values"),
              std::string::npos)
        << r.output;
    // Files of one format: no note.
    r = compare({"float.exr", "float.exr"});
    EXPECT_EQ(r.output.find("note:"), std::string::npos) << r.output;
}

// Issue 43: idiff's --failrelative, --warnrelative and --allowfailures.
TEST_F(CompareCliTest, RelativeThresholdsAndAllowedFailuresAsIdiffs) {
    write_pair(0.125f);  // G of (5, 3): 29/64 against 29/64 + 0.125, relative error 0.24
    EXPECT_EQ(compare({"a.exr", "b.exr", "--fail", "0.5", "--warnrelative", "0.3"}).status, 0);
    RunResult r = compare({"a.exr", "b.exr", "--fail", "0.5", "--warnrelative", "0.2"});
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_EQ(last_line(r.output),
              "WARN: 1 of 64 pixels (1.562%) differ by more than 1e-06 and 0.2 relative; "
              "allowed 0%");
    EXPECT_EQ(compare({"a.exr", "b.exr", "--failrelative", "0.3", "--warn", "0.5"}).status, 0);
    EXPECT_EQ(compare({"a.exr", "b.exr", "--failrelative", "0.2", "--warn", "0.5"}).status, 2);

    // One pixel may fail by any amount, over --hardfail too; it still warns.
    r = compare({"a.exr", "b.exr", "--allowfailures", "1", "--hardfail", "0.01"});
    EXPECT_EQ(r.status, 1) << r.output;
    r = compare({"a.exr", "b.exr", "--allowfailures", "1", "--warnpercent", "2"});
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(last_line(r.output),
              "PASS: max error 0.125; 1 of 64 pixels (1.562%) over 1e-06, within the 0% + 1 "
              "pixel allowed");
    // Two failing pixels are one too many.
    Image b = make_image(8, 8, {"R", "G", "B"});
    for (int c = 0; c < b.channel_count(); ++c)
        for (std::size_t i = 0; i < b.pixel_count(); ++i)
            b.plane(c)[i] = static_cast<float>(i % 64) / 64.0f;
    b.at(0, 1, 1) += 0.5f;
    b.at(0, 2, 2) += 0.5f;
    write_test_exr(path("b2.exr"), b);
    r = compare({"a.exr", "b2.exr", "--allowfailures", "1"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(last_line(r.output).find("allowed 0% + 1 pixel"), std::string::npos) << r.output;
    r = compare({"a.exr", "b2.exr", "--allowfailures", "2", "--json", "--warnpercent", "100"});
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(nlohmann::json::parse(r.output)["options"]["allowfailures"], 2) << r.output;
}

// Issue 43: idiff's -o (the difference image) is named, not "corrected" to -h.
TEST_F(CompareCliTest, IdiffsDashOIsNamedNotCorrected) {
    write_pair(0.0f);
    const RunResult r = compare({"a.exr", "b.exr", "-o", "diff.exr"});
    EXPECT_EQ(r.status, 5) << r.output;
    EXPECT_NE(r.output.find("idiff's -o is --diff FILE.exr here"), std::string::npos)
        << r.output;
    EXPECT_EQ(r.output.find("did you mean \"-h\""), std::string::npos) << r.output;
}

}  // namespace
}  // namespace octray
