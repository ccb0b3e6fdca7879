// End-to-end tests of `octray render` and `octray verify` for one frame: the image and its
// attributes and preview, scenes from files and built-ins, overrides, output formats and
// directories, and the errors a bad scene or output gives (the fixture: cli_fixture.h;
// sequences and farms: batch_cli_test.cpp).

#include <gtest/gtest.h>

#include "cli_fixture.h"
#include "render/image/image_read.h"
#include "tests/image/inflated_file.h"

namespace octray::testing {
namespace {

TEST_F(CliTest, RendersSmallBuiltinWithAttributesAndPreview) {
    const std::string spec = "random:8,width=32,height=24";
    const RunResult r =
        octray({"render", spec, "--path", "scalar", "-o", "r.exr", "--png", "r.png"});
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "Mrays/s")) << r.output;
    EXPECT_TRUE(contains(r.output, "r.exr")) << r.output;
    EXPECT_TRUE(contains(r.output, "r.png")) << r.output;
    // Nothing else: no temporaries left next to the outputs.
    EXPECT_EQ(entries(), (std::vector<std::string>{"r.exr", "r.png"}));

    Imf::InputFile file(path("r.exr").c_str());
    const Imf::Header& h = file.header();
    const Imath::Box2i window = h.dataWindow();
    EXPECT_EQ(window.max.x - window.min.x + 1, 32);
    EXPECT_EQ(window.max.y - window.min.y + 1, 24);
    EXPECT_EQ(h.channels().findChannel("R")->type, Imf::HALF);  // the default
    EXPECT_EQ(h.compression(), Imf::ZIP_COMPRESSION);

    const auto* software = h.findTypedAttribute<Imf::StringAttribute>("software");
    ASSERT_NE(software, nullptr);
    EXPECT_EQ(software->value(), "octray 0.1.0");
    const auto* date = h.findTypedAttribute<Imf::StringAttribute>("capDate");
    ASSERT_NE(date, nullptr);
    EXPECT_TRUE(is_exr_date(date->value())) << date->value();
    EXPECT_NE(h.findTypedAttribute<Imf::FloatAttribute>("utcOffset"), nullptr);
    const auto* scene = h.findTypedAttribute<Imf::StringAttribute>("octray.scene");
    ASSERT_NE(scene, nullptr);
    EXPECT_EQ(scene->value(), spec);
    const auto* spp = h.findTypedAttribute<Imf::IntAttribute>("samplesPerPixel");
    ASSERT_NE(spp, nullptr);
    EXPECT_EQ(spp->value(), 1);
    const auto* seconds = h.findTypedAttribute<Imf::DoubleAttribute>("renderTimeSeconds");
    ASSERT_NE(seconds, nullptr);
    EXPECT_GE(seconds->value(), 0.0);

    // One primary ray per pixel sample of the pinhole camera; the kinds add up to the total.
    double sum = 0.0;
    for (const char* kind : {"primary", "shadow", "reflected", "refracted"}) {
        const auto* count =
            h.findTypedAttribute<Imf::DoubleAttribute>(std::string("octray.rays.") + kind);
        ASSERT_NE(count, nullptr) << kind;
        EXPECT_GE(count->value(), 0.0);
        sum += count->value();
    }
    EXPECT_EQ(h.findTypedAttribute<Imf::DoubleAttribute>("octray.rays.primary")->value(),
              32.0 * 24.0);
    const auto* total = h.findTypedAttribute<Imf::DoubleAttribute>("octray.rays.total");
    ASSERT_NE(total, nullptr);
    EXPECT_EQ(total->value(), sum);

    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    ASSERT_NE(png_image_begin_read_from_file(&png, path("r.png").c_str()), 0) << png.message;
    EXPECT_EQ(png.width, 32u);
    EXPECT_EQ(png.height, 24u);
    png_image_free(&png);

    EXPECT_TRUE(any_nonzero(read_exr_pixels(path("r.exr"))));
}

TEST_F(CliTest, SceneWrittenAsJsonRendersBitIdentically) {
    // spp=4 puts the seeded jitter into play as well.
    const std::string spec = "random:8,width=40,height=30,spp=4";
    const RunResult written = octray({"scene", spec, "-o", "x.json"});
    ASSERT_EQ(written.status, 0) << written.output;
    ASSERT_TRUE(fs::exists(dir_ / "x.json"));

    const RunResult from_json = octray({"render", "x.json", "--float", "-o", "json.exr"});
    ASSERT_EQ(from_json.status, 0) << from_json.output;
    const RunResult from_spec = octray({"render", spec, "--float", "-o", "spec.exr"});
    ASSERT_EQ(from_spec.status, 0) << from_spec.output;

    const ExrPixels a = read_exr_pixels(path("json.exr"));
    const ExrPixels b = read_exr_pixels(path("spec.exr"));
    EXPECT_EQ(a.width, 40);
    EXPECT_EQ(a.height, 30);
    EXPECT_TRUE(any_nonzero(a));
    EXPECT_TRUE(same_bits(a, b));
}

TEST_F(CliTest, SceneWithoutOutputPrintsJsonToStdout) {
    const RunResult r = octray({"scene", "random:2"}, /*capture_stderr=*/false);
    ASSERT_EQ(r.status, 0);
    ASSERT_FALSE(r.output.empty());
    EXPECT_EQ(r.output.front(), '{') << r.output;
    EXPECT_TRUE(contains(r.output, "\"objects\"")) << r.output;
    EXPECT_TRUE(entries().empty());
}

TEST_F(CliTest, ImageDoesNotDependOnThreadsOrTiles) {
    const std::string spec = "random:16,width=37,height=23,spp=2";
    ASSERT_EQ(octray({"render", spec, "--float", "--threads", "1", "-o", "a.exr"}).status, 0);
    ASSERT_EQ(
        octray({"render", spec, "--float", "--threads", "2", "--tile", "7x5", "-o", "b.exr"})
            .status,
        0);
    EXPECT_TRUE(same_bits(read_exr_pixels(path("a.exr")), read_exr_pixels(path("b.exr"))));
}

TEST_F(CliTest, OverridesReachTheScene) {
    const RunResult r = octray({"render", "random:4,width=8,height=8", "--width", "20",
                                "--height", "10", "--spp", "4", "--max-depth", "0", "-o",
                                "o.exr", "--compression", "piz", "--float"});
    ASSERT_EQ(r.status, 0) << r.output;
    Imf::InputFile file(path("o.exr").c_str());
    const Imath::Box2i window = file.header().dataWindow();
    EXPECT_EQ(window.max.x - window.min.x + 1, 20);
    EXPECT_EQ(window.max.y - window.min.y + 1, 10);
    EXPECT_EQ(file.header().compression(), Imf::PIZ_COMPRESSION);
    EXPECT_EQ(file.header().channels().findChannel("G")->type, Imf::FLOAT);
    EXPECT_EQ(file.header().findTypedAttribute<Imf::IntAttribute>("samplesPerPixel")->value(),
              4);
    EXPECT_EQ(file.header().findTypedAttribute<Imf::IntAttribute>("octray.maxDepth")->value(),
              0);
    EXPECT_EQ(
        file.header().findTypedAttribute<Imf::DoubleAttribute>("octray.rays.primary")->value(),
        20.0 * 10.0 * 4.0);
}

TEST_F(CliTest, DefaultOutputIsNamedAfterTheScene) {
    const RunResult r = octray({"render", "random:3,width=8,height=6"});
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(entries(), std::vector<std::string>{"random-3.exr"});
}

TEST_F(CliTest, BrokenSceneFileIsASceneError) {
    { std::ofstream(dir_ / "broken.json") << "{ \"image\": { \"width\": 32, "; }
    const RunResult r = octray({"render", "broken.json", "-o", "out.exr"});
    EXPECT_EQ(r.status, 3) << r.output;
    EXPECT_TRUE(contains(r.output, "broken.json")) << r.output;
    EXPECT_EQ(entries(), std::vector<std::string>{"broken.json"});
}

TEST_F(CliTest, MissingSceneFileIsASceneError) {
    const RunResult r = octray({"render", "no-such-scene.json", "-o", "out.exr"});
    EXPECT_EQ(r.status, 3) << r.output;
    EXPECT_TRUE(contains(r.output, "no-such-scene.json")) << r.output;
    const RunResult s = octray({"scene", "no-such-scene.json"});
    EXPECT_EQ(s.status, 3) << s.output;
    EXPECT_TRUE(entries().empty());
}

// Issue 43: a mistyped built-in is named with the one probably meant, on every command.
TEST_F(CliTest, AMistypedBuiltInGetsASuggestion) {
    for (const std::string command : {"render", "verify", "scene", "info"}) {
        const RunResult r = octray({command, "sphereflak:3,width=8"});
        EXPECT_EQ(r.status, 3) << r.output;
        EXPECT_TRUE(contains(r.output,
                             "sphereflak:3,width=8: cannot open scene file: No such "
                             "file or directory; nor is it a built-in (did you mean "
                             "\"sphereflake:3,width=8\"?)"))
            << command << ": " << r.output;
    }
    // A file name like no built-in gets no suggestion.
    const RunResult far = octray({"render", "shot.json"});
    EXPECT_FALSE(contains(far.output, "did you mean")) << far.output;
}

// Issue 43: two scene files named alike in two folders collide under {scene}: the message
// names both and says how to keep them apart.
TEST_F(CliTest, ScenesThatShareANameSayHowToTellThemApart) {
    const std::string text = R"({"image": {"width": 8, "height": 6},
        "camera": {"eye": [0, 0, 5], "lookat": [0, 0, 0]}})";
    fs::create_directories(dir_ / "a");
    fs::create_directories(dir_ / "b");
    { std::ofstream(dir_ / "a/shot.json") << text; }
    { std::ofstream(dir_ / "b/shot.json") << text; }
    const RunResult r =
        octray({"render", "a/shot.json", "b/shot.json", "-o", "{scene}.{frame:04d}.exr"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output,
                         "two frames would write the same file shot.0000.exr: "
                         "a/shot.json frame 0 and b/shot.json frame 0 ({scene} is "
                         "\"shot\" for both"))
        << r.output;
    EXPECT_TRUE(contains(r.output,
                         "render them in separate runs, each with an -o of its own "
                         "(-o a/{scene}.{frame:04d}.exr)"))
        << r.output;
    EXPECT_FALSE(contains(r.output, "put {scene} in the pattern")) << r.output;
    // Without {scene}, that is what is missing.
    const RunResult plain = octray({"render", "a/shot.json", "whitted", "-o", "x.exr"});
    EXPECT_TRUE(contains(plain.output, "(put {scene} in the pattern)")) << plain.output;
}

// A device has no end: `octray render /dev/zero` read forever, growing without bound.
// Anything but a regular file is a scene error before the first byte is read.
TEST_F(CliTest, DeviceAsSceneFileIsRefusedBeforeReading) {
    for (const std::string device : {"/dev/null", "/dev/zero", "/dev/urandom"}) {
        const RunResult r = octray({"render", device, "-o", "out.exr"});
        EXPECT_EQ(r.status, 3) << device << "\n" << r.output;
        EXPECT_TRUE(contains(r.output, device + ": cannot read scene file: it is a character "
                                                "device; expected a regular file"))
            << r.output;
    }
    EXPECT_TRUE(entries().empty());
}

// Issue 26 changed this: a missing output directory is created (MissingOutputDirectoriesAre
// Created); one that cannot be created is still an I/O error found before rendering.
TEST_F(CliTest, MissingOutputDirectoryIsAnIoErrorAndLeavesNothing) {
    { std::ofstream(path("file")) << "not a directory"; }
    const RunResult r =
        octray({"render", "random:2,width=8,height=8", "-o", "file/sub/out.exr"});
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, "file/sub/out.exr")) << r.output;
    EXPECT_TRUE(contains(r.output, "file is a file, not a directory")) << r.output;

    // An unwritable preview is found before rendering, so the EXR is not written either.
    const RunResult png = octray(
        {"render", "random:2,width=8,height=8", "-o", "out.exr", "--png", "file/out.png"});
    EXPECT_EQ(png.status, 4) << png.output;

    const RunResult scene = octray({"scene", "random:2", "-o", "nope/x.json"});
    EXPECT_EQ(scene.status, 4) << scene.output;
    EXPECT_TRUE(contains(scene.output, "nope/x.json")) << scene.output;

    EXPECT_EQ(entries(), std::vector<std::string>{"file"});
}

// Issue 26: render creates the missing directories of its outputs (as Blender does) and
// says which, on stderr; the README's `-o out/bounce.####.exr` works in a fresh directory.
TEST_F(CliTest, MissingOutputDirectoriesAreCreated) {
    const RunResult r = octray({"render", "random:2,width=8,height=8", "-o", "out/sub/x.exr",
                                "--png", "previews/x.png", "--progress", "none"});
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(fs::is_regular_file(path("out/sub/x.exr")));
    EXPECT_TRUE(fs::is_regular_file(path("previews/x.png")));
    for (const char* dir : {"out/", "out/sub/", "previews/"})
        EXPECT_TRUE(
            contains(r.output, std::string("octray: created output directory ") + dir + "\n"))
            << dir << "\n"
            << r.output;
    // Nothing to create the second time: nothing said.
    const RunResult again = octray(
        {"render", "random:2,width=8,height=8", "-o", "out/sub/y.exr", "--progress", "none"});
    ASSERT_EQ(again.status, 0) << again.output;
    EXPECT_FALSE(contains(again.output, "created")) << again.output;
}

// Issue 23: the extension of -o decides the format (case-insensitive); a PNG output is the
// --png preview, byte for byte; frame patterns follow the same rule.
TEST_F(CliTest, OutputFormatFollowsTheExtension) {
    const std::string spec = "random:4,width=16,height=12";
    RunResult r = octray({"render", spec, "-o", "a.png"});
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(is_png_file(dir_ / "a.png"));
    r = octray({"render", spec, "-o", "b.PNG"});
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(is_png_file(dir_ / "b.PNG"));
    r = octray({"render", spec, "-o", "c.Exr"});
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(is_exr_file(dir_ / "c.Exr"));
    r = octray({"render", spec, "-o", "d.exr", "--png", "d.png"});
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(is_exr_file(dir_ / "d.exr"));
    EXPECT_EQ(test::png_inflated(dir_ / "a.png"), test::png_inflated(dir_ / "d.png"));
    r = octray({"render", spec, "--frames", "0-1", "-o", "f.####.png"});
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(is_png_file(dir_ / "f.0000.png"));
    EXPECT_TRUE(is_png_file(dir_ / "f.0001.png"));
    EXPECT_EQ(entries(), (std::vector<std::string>{"a.png", "b.PNG", "c.Exr", "d.exr", "d.png",
                                                   "f.0000.png", "f.0001.png"}));
}

TEST_F(CliTest, UnknownOutputExtensionIsAUsageErrorNamingTheFormats) {
    const std::string spec = "random:4,width=16,height=12";
    for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
             {"render", spec, "-o", "out.jpg"},
             {"render", spec, "-o", "out"},
             {"render", spec, "-o", "out.exr.bak"},
             {"render", spec, "--frames", "0-1", "-o", "f.####.tif"},
         }) {
        const RunResult r = octray(args);
        EXPECT_EQ(r.status, 2) << args[3] << "\n" << r.output;
        for (const char* part : {".exr", ".png", "--png", "--help"})
            EXPECT_TRUE(contains(r.output, part)) << part << "\n" << r.output;
    }
    EXPECT_TRUE(entries().empty());
}

// A PNG output holds 8-bit RGB only: what only an EXR can hold is refused, not dropped.
TEST_F(CliTest, PngOutputRefusesWhatOnlyAnExrHolds) {
    const std::string spec = "random:4,width=16,height=12";
    const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
        {{"--png", "b.png"}, "--png"},
        {{"--aov", "depth"}, "--aov"},
        {{"--float"}, "--float"},
        {{"--compression", "piz"}, "--compression"},
        {{"--progressive"}, "--progressive"},
    };
    for (const auto& [extra, option] : cases) {
        std::vector<std::string> args = {"render", spec, "-o", "a.png"};
        args.insert(args.end(), extra.begin(), extra.end());
        const RunResult r = octray(args);
        EXPECT_EQ(r.status, 2) << option << "\n" << r.output;
        EXPECT_TRUE(contains(r.output, option)) << option << "\n" << r.output;
        EXPECT_TRUE(contains(r.output, "PNG")) << option << "\n" << r.output;
    }
    EXPECT_TRUE(entries().empty());
}

// Issue 43: verify draws the error as compare does, --diff and --heatmap, so a failure
// comes with its picture; with several frames each gets its own files.
TEST_F(CliTest, VerifyWritesTheDifferenceAndTheHeatmap) {
    const RunResult r = octray({"verify", "random:8,width=16,height=12", "--threads", "2",
                                "--diff", "d.exr", "--heatmap", "h.png"});
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "wrote    d.exr (|scalar - simd|, float)")) << r.output;
    EXPECT_TRUE(contains(r.output, "wrote    h.png (error heatmap, linear")) << r.output;
    const Image diff = read_image(path("d.exr"));
    EXPECT_EQ(diff.width(), 16);
    EXPECT_EQ(diff.channel_names(), (std::vector<std::string>{"R", "G", "B"}));
    for (int c = 0; c < diff.channel_count(); ++c)
        for (std::size_t i = 0; i < diff.pixel_count(); ++i) EXPECT_EQ(diff.plane(c)[i], 0.0f);
    EXPECT_EQ(read_image(path("h.png")).file_format, "PNG 8-bit");

    const std::string bounce = std::string(OCTRAY_SOURCE_DIR) + "/scene/examples/bounce.json";
    const RunResult frames = octray({"verify", bounce, "--frames", "0,20", "--width", "16",
                                     "--height", "12", "--diff", "out/d.exr"});
    EXPECT_EQ(frames.status, 4) << "out/ does not exist: " << frames.output;
    fs::create_directory(path("out"));
    const RunResult written = octray({"verify", bounce, "--frames", "0,20", "--width", "16",
                                      "--height", "12", "--diff", "out/d.exr"});
    EXPECT_EQ(written.status, 0) << written.output;
    EXPECT_TRUE(fs::exists(path("out/d.0000.exr")) && fs::exists(path("out/d.0020.exr")));

    const RunResult png = octray({"verify", "whitted", "--diff", "d.png"});
    EXPECT_EQ(png.status, 2) << png.output;
    EXPECT_TRUE(contains(png.output, "--heatmap FILE.png")) << png.output;
}

// Issue 26: the two paths promise identical bits, so verify is exact by default (a
// tolerance stays available), and it verifies frames of an animated scene.
TEST_F(CliTest, VerifyIsExactByDefaultAndTakesFrames) {
    const RunResult help = octray({"verify", "--help"});
    EXPECT_TRUE(contains(help.output, "--frames")) << help.output;
    EXPECT_TRUE(contains(help.output, "--fail X")) << help.output;

    const RunResult exact = octray({"verify", "random:8,width=16,height=12", "--threads", "2"});
    EXPECT_EQ(exact.status, 0) << exact.output;
    EXPECT_TRUE(contains(exact.output, "check    exact: every value equal (the default)\n"))
        << exact.output;
    EXPECT_TRUE(contains(exact.output, "differ by more than 0 (0 pixels)")) << exact.output;
    EXPECT_TRUE(contains(exact.output, "\nPASS\n")) << exact.output;

    const RunResult tolerant = octray(
        {"verify", "random:8,width=16,height=12", "--fail", "1e-4", "--hardfail", "1e-3"});
    EXPECT_EQ(tolerant.status, 0) << tolerant.output;
    EXPECT_TRUE(contains(tolerant.output, "check    within the tolerance given"))
        << tolerant.output;

    const std::string bounce = std::string(OCTRAY_SOURCE_DIR) + "/scene/examples/bounce.json";
    const RunResult frames =
        octray({"verify", bounce, "--frames", "0,20-40:20", "--width", "32", "--height", "24"});
    EXPECT_EQ(frames.status, 0) << frames.output;
    for (const char* part :
         {"frame    0\n", "frame    20\n", "frame    40\n", "PASS: all 3 frames"})
        EXPECT_TRUE(contains(frames.output, part)) << part << "\n" << frames.output;
    const RunResult bad = octray({"verify", bounce, "--frames", "1-x"});
    EXPECT_EQ(bad.status, 2) << bad.output;
    EXPECT_TRUE(contains(bad.output, "--frames")) << bad.output;
    EXPECT_TRUE(entries().empty());
}

// Issue 23: -o and --png are the same file when they name one directory entry, however
// spelled (here through a symlink to "." and ".."); the check compares identities.
TEST_F(CliTest, OutputsAreComparedByIdentityNotSpelling) {
    fs::create_directory(dir_ / "sub");
    fs::create_directory_symlink(".", dir_ / "sub" / "self");
    const std::string spec = "random:2,width=8,height=8";
    for (const char* png : {"sub/self/../s3.exr", "./s3.exr", "sub/../s3.exr"}) {
        const RunResult r = octray({"render", spec, "-o", "s3.exr", "--png", png});
        EXPECT_EQ(r.status, 2) << png << "\n" << r.output;
        EXPECT_TRUE(contains(r.output, "same file")) << r.output;
        EXPECT_FALSE(fs::exists(dir_ / "s3.exr")) << png;
    }
    // Different names in one directory are different files.
    const RunResult ok = octray({"render", spec, "-o", "s3.exr", "--png", "sub/self/s3.png"});
    EXPECT_EQ(ok.status, 0) << ok.output;
    EXPECT_TRUE(is_exr_file(dir_ / "s3.exr"));
    EXPECT_TRUE(is_png_file(dir_ / "sub" / "s3.png"));
}

// Issue 23: an output below a regular file says so, rather than "does not exist".
TEST_F(CliTest, OutputBelowAFileSaysTheParentIsAFile) {
    { std::ofstream(dir_ / "plain") << "not a directory\n"; }
    for (const char* out : {"plain/out.exr", "plain/deeper/out.exr"}) {
        const RunResult r = octray({"render", "random:2,width=8,height=8", "-o", out});
        EXPECT_EQ(r.status, 4) << out << "\n" << r.output;
        EXPECT_TRUE(contains(r.output, "plain is a file, not a directory")) << r.output;
        EXPECT_FALSE(contains(r.output, "does not exist")) << r.output;
    }
    const RunResult png = octray(
        {"render", "random:2,width=8,height=8", "-o", "out.exr", "--png", "plain/p.png"});
    EXPECT_EQ(png.status, 4) << png.output;
    EXPECT_TRUE(contains(png.output, "plain is a file, not a directory")) << png.output;
    EXPECT_EQ(entries(), std::vector<std::string>{"plain"});
}

// The SIMD packet path (the default) writes the same pixels as the scalar reference, under
// every --isa; `verify` agrees and `info` names the ISA it uses.
TEST_F(CliTest, SimdPathMatchesScalarAndVerifyPasses) {
    const std::string spec = "whitted,width=40,height=30";
    ASSERT_EQ(
        octray({"render", spec, "--path", "scalar", "-o", "scalar.exr", "--float"}).status, 0);
    const RunResult simd = octray({"render", spec, "-o", "simd.exr", "--float"});
    ASSERT_EQ(simd.status, 0) << simd.output;
    EXPECT_TRUE(contains(simd.output, "simd (")) << simd.output;  // "simd (avx2) path"
    EXPECT_TRUE(
        same_bits(read_exr_pixels(path("scalar.exr")), read_exr_pixels(path("simd.exr"))));
    const RunResult sse2 =
        octray({"render", spec, "--isa", "sse2", "-o", "sse2.exr", "--float"});
    ASSERT_EQ(sse2.status, 0) << sse2.output;
    EXPECT_TRUE(
        same_bits(read_exr_pixels(path("scalar.exr")), read_exr_pixels(path("sse2.exr"))));
    // AVX-512 where the CPU has it (16-ray packets in BVH traversal and brute force; its
    // kernels are the AVX-512 build's), else a clear refusal.
    const RunResult avx512 =
        octray({"render", spec, "--isa", "avx512", "-o", "avx512.exr", "--float"});
    if (avx512.status == 0)
        EXPECT_TRUE(same_bits(read_exr_pixels(path("scalar.exr")),
                              read_exr_pixels(path("avx512.exr"))));
    else
        EXPECT_TRUE(contains(avx512.output, "this CPU does not support --isa avx512"))
            << avx512.output;
    EXPECT_EQ(octray({"render", spec, "--isa", "neon", "-o", "x.exr"}).status, 2);

    const RunResult verify = octray({"verify", spec, "--tile", "x"});
    EXPECT_EQ(verify.status, 2) << verify.output;  // no such option
    const RunResult ok = octray({"verify", "random:16,width=24,height=16", "--threads", "2"});
    EXPECT_EQ(ok.status, 0) << ok.output;
    EXPECT_TRUE(contains(ok.output, "PASS")) << ok.output;
    EXPECT_TRUE(contains(ok.output, "max abs")) << ok.output;
    EXPECT_TRUE(contains(ok.output, "psnr")) << ok.output;

    const RunResult info = octray({"info", "random:5"});
    EXPECT_EQ(info.status, 0) << info.output;
    EXPECT_TRUE(contains(info.output, "uses")) << info.output;
    EXPECT_TRUE(contains(info.output, "5 spheres")) << info.output;
}

}  // namespace
}  // namespace octray::testing
