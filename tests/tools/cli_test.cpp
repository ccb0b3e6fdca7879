// End-to-end tests of the `octray` executable: run it as a user would (through the shell),
// then check its exit status, its messages and the files it leaves behind.

#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfStringAttribute.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <png.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "run_octray.h"

namespace {

namespace fs = std::filesystem;

using octray::testing::run_octray;
using octray::testing::RunResult;

class CliTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::path(OCTRAY_TEST_TMPDIR) / "cli" /
               (std::string(info->test_suite_name()) + "." + info->name() + "." +
                std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        if (!HasFailure()) fs::remove_all(dir_);
    }

    RunResult octray(const std::vector<std::string>& args, bool capture_stderr = true) {
        return run_octray(args, dir_, capture_stderr);
    }

    std::vector<std::string> entries() const {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(dir_))
            names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }

    std::string path(const std::string& name) const { return (dir_ / name).string(); }

    fs::path dir_;
};

// EXR's capDate format, "YYYY:MM:DD HH:MM:SS". (Checked by hand: std::regex trips a false
// -Wmaybe-uninitialized in GCC 12 under the sanitizer build.)
bool is_exr_date(const std::string& text) {
    const std::string pattern = "dddd:dd:dd dd:dd:dd";
    if (text.size() != pattern.size()) return false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const bool digit = text[i] >= '0' && text[i] <= '9';
        if (pattern[i] == 'd' ? !digit : text[i] != pattern[i]) return false;
    }
    return true;
}

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

struct ExrPixels {
    int width = 0, height = 0;
    std::vector<float> rgb;  // as stored; FLOAT channels are read back bit for bit
};

ExrPixels read_exr_pixels(const std::string& file_path) {
    Imf::InputFile file(file_path.c_str());
    const Imath::Box2i window = file.header().dataWindow();
    ExrPixels out;
    out.width = window.max.x - window.min.x + 1;
    out.height = window.max.y - window.min.y + 1;
    out.rgb.resize(static_cast<std::size_t>(out.width) * out.height * 3);
    char* base = reinterpret_cast<char*>(out.rgb.data()) -
                 (static_cast<std::ptrdiff_t>(window.min.x) +
                  static_cast<std::ptrdiff_t>(window.min.y) * out.width) *
                     static_cast<std::ptrdiff_t>(3 * sizeof(float));
    const std::size_t xs = 3 * sizeof(float), ys = xs * static_cast<std::size_t>(out.width);
    Imf::FrameBuffer fb;
    fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
    fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
    fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
    file.setFrameBuffer(fb);
    file.readPixels(window.min.y, window.max.y);
    return out;
}

bool same_bits(const ExrPixels& a, const ExrPixels& b) {
    return a.width == b.width && a.height == b.height && a.rgb.size() == b.rgb.size() &&
           std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0;
}

bool any_nonzero(const ExrPixels& p) {
    return std::any_of(p.rgb.begin(), p.rgb.end(), [](float v) { return v != 0.0f; });
}

// The first `n` bytes of a file ("" if it cannot be read).
std::string file_head(const fs::path& file, std::size_t n) {
    std::ifstream in(file, std::ios::binary);
    std::string bytes(n, '\0');
    in.read(bytes.data(), static_cast<std::streamsize>(n));
    bytes.resize(static_cast<std::size_t>(in.gcount()));
    return bytes;
}

std::string file_bytes(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool is_png_file(const fs::path& file) {
    return file_head(file, 8) == std::string("\x89PNG\r\n\x1a\n", 8);
}

bool is_exr_file(const fs::path& file) {
    return file_head(file, 4) == std::string("\x76\x2f\x31\x01", 4);
}

struct ClosedStdoutRun {
    int wait_status = 0;
    std::string stderr_text;
};

// Runs `octray <args...>` in `cwd` with its standard output a pipe whose reading end is
// already closed (as `octray ... | head -0` leaves it), SIGPIPE at its default action.
ClosedStdoutRun run_with_closed_stdout(const std::vector<std::string>& args,
                                       const fs::path& cwd) {
    ClosedStdoutRun result;
    int fds[2];
    if (::pipe(fds) != 0) return result;
    ::close(fds[0]);
    const fs::path err = cwd / ".stderr.txt";
    const pid_t pid = ::fork();
    if (pid == 0) {
        std::signal(SIGPIPE, SIG_DFL);
        if (::chdir(cwd.c_str()) != 0) ::_exit(120);
        ::dup2(fds[1], STDOUT_FILENO);
        const int err_fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        ::dup2(err_fd, STDERR_FILENO);
        std::vector<char*> argv;
        std::string exe = OCTRAY_EXE;
        argv.push_back(exe.data());
        std::vector<std::string> copies = args;
        for (std::string& a : copies) argv.push_back(a.data());
        argv.push_back(nullptr);
        ::execv(exe.c_str(), argv.data());
        ::_exit(121);
    }
    ::close(fds[1]);
    ::waitpid(pid, &result.wait_status, 0);
    result.stderr_text = file_bytes(err);
    fs::remove(err);
    return result;
}

TEST_F(CliTest, VersionPrintsTheVersion) {
    const RunResult r = octray({"--version"});
    EXPECT_EQ(r.status, 0);
    EXPECT_EQ(r.output, "octray 0.1.0\n");
}

TEST_F(CliTest, HelpExplainsCommandsOptionsAndExitCodes) {
    const RunResult top = octray({"--help"});
    EXPECT_EQ(top.status, 0);
    EXPECT_TRUE(contains(top.output, "render")) << top.output;
    EXPECT_TRUE(contains(top.output, "scene")) << top.output;
    EXPECT_TRUE(contains(top.output, "Exit codes")) << top.output;

    const RunResult render = octray({"render", "--help"});
    EXPECT_EQ(render.status, 0);
    for (const char* option :
         {"--output", "--width", "--height", "--spp", "--threads", "--seed", "--max-depth",
          "--path", "--png", "--float", "--compression", "--tile", "Examples", "Exit codes"})
        EXPECT_TRUE(contains(render.output, option)) << option << "\n" << render.output;
}

// Issue 26: `octray help COMMAND` is `octray COMMAND --help`, `-V` is `--version`, and an
// unknown command is named as such.
TEST_F(CliTest, HelpCommandAndShortVersionFlag) {
    const RunResult v = octray({"-V"});
    EXPECT_EQ(v.status, 0) << v.output;
    EXPECT_EQ(v.output, "octray 0.1.0\n");

    for (const std::string command :
         {"render", "scene", "compare", "bench", "verify", "info", "assemble"}) {
        const RunResult help = octray({"help", command});
        const RunResult flag = octray({command, "--help"});
        EXPECT_EQ(help.status, 0) << command << "\n" << help.output;
        EXPECT_EQ(help.output, flag.output) << command;
    }
    const RunResult top = octray({"help"});
    EXPECT_EQ(top.status, 0) << top.output;
    EXPECT_EQ(top.output, octray({"--help"}).output);
    EXPECT_TRUE(contains(top.output, "octray help <command>")) << top.output;
    EXPECT_TRUE(contains(top.output, "(octray compare: 5, as 2 is its FAIL verdict"))
        << top.output;

    RunResult r = octray({"help", "rendr"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "unknown command \"rendr\" (did you mean \"render\"?)"))
        << r.output;
    r = octray({"frobnicate"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "unknown command \"frobnicate\"; the commands are render"))
        << r.output;
    r = octray({});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "no command given; the commands are render, scene,"))
        << r.output;
    r = octray({"-v"});
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "did you mean \"-V\"?")) << r.output;
    EXPECT_TRUE(entries().empty());
}

// Issue 26: bash and zsh completion scripts generated from the parser's own option
// definitions: every option that a command's --help lists is in both, and bash completes.
TEST_F(CliTest, CompletionScriptsCoverEveryCommandAndOption) {
    const RunResult bash = octray({"completion", "bash"});
    const RunResult zsh = octray({"completion", "zsh"});
    ASSERT_EQ(bash.status, 0) << bash.output;
    ASSERT_EQ(zsh.status, 0) << zsh.output;
    for (const std::string command :
         {"render", "scene", "compare", "bench", "verify", "info", "assemble", "completion"}) {
        EXPECT_TRUE(contains(bash.output, "        " + command + ") words=\"")) << command;
        EXPECT_TRUE(contains(zsh.output, "        '" + command + ":")) << command;
        // The options as --help lists them: lines that start with blanks and a dash.
        std::istringstream help(octray({command, "--help"}).output);
        std::size_t options = 0;
        for (std::string line; std::getline(help, line);) {
            const std::size_t dash = line.find_first_not_of(' ');
            if (dash < 2 || dash == std::string::npos || line[dash] != '-') continue;
            std::istringstream words(line.substr(dash));
            std::string names;  // "-o,--output"
            words >> names;
            std::istringstream split(names);
            for (std::string word; std::getline(split, word, ',');) {
                if (word.empty() || word[0] != '-') continue;
                ++options;
                EXPECT_TRUE(contains(bash.output, " " + word + " ") ||
                            contains(bash.output, " " + word + "\"") ||
                            contains(bash.output, "\"" + word + " "))
                    << command << " " << word;
                EXPECT_TRUE(contains(zsh.output, "'" + word + "[")) << command << " " << word;
            }
        }
        EXPECT_GT(options, 0u) << command;
    }
    // The bash script parses and completes a command and an option.
    { std::ofstream(path("octray.bash")) << bash.output; }
    const std::string script =
        "bash -n octray.bash && source octray.bash && "
        "COMP_WORDS=(octray rend) COMP_CWORD=1 && _octray && echo \"[${COMPREPLY[*]}]\" && "
        "COMP_WORDS=(octray render --thr) COMP_CWORD=2 && _octray && "
        "echo \"[${COMPREPLY[*]}]\"";
    const std::string command = "cd " + octray::testing::shell_quote(dir_.string()) +
                                " && bash -c " + octray::testing::shell_quote(script);
    FILE* pipe = ::popen(command.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string out;
    char buffer[256];
    while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) out += buffer;
    EXPECT_EQ(::pclose(pipe), 0) << out;
    EXPECT_EQ(out, "[render]\n[--threads]\n");
    const RunResult fish = octray({"completion", "fish"});
    EXPECT_EQ(fish.status, 2) << fish.output;
}

// Issue 26: every usage error names the help of the command it was given to, whether the
// parser or the command found it.
TEST_F(CliTest, UsageErrorsNameTheCommandsOwnHelp) {
    const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
        {{"render", "--no-such-option"}, "render"},
        {{"render", "random:2", "--threads", "-1"}, "render"},
        {{"render", "random:2", "-o", "same.exr", "--png", "same.exr"}, "render"},
        {{"render", "random:2", "-o", "x.tif"}, "render"},
        {{"scene"}, "scene"},
        {{"verify", "--wdth", "8"}, "verify"},
        {{"bench", "--reps", "0x2", "--no-embree"}, "bench"},
        {{"info", "--nope"}, "info"},
        {{"assemble"}, "assemble"},
    };
    for (const auto& [args, command] : cases) {
        const RunResult r = octray(args);
        EXPECT_EQ(r.status, 2) << args[0] << " " << args[1] << "\n" << r.output;
        EXPECT_TRUE(
            contains(r.output, "\nRun 'octray " + command + " --help' for more information.\n"))
            << r.output;
    }
    for (const std::vector<std::string>& args :
         std::vector<std::vector<std::string>>{{}, {"frobnicate"}, {"--nope"}}) {
        const RunResult r = octray(args);
        EXPECT_EQ(r.status, 2) << r.output;
        EXPECT_TRUE(contains(r.output, "\nRun 'octray --help' for more information.\n"))
            << r.output;
    }
    EXPECT_TRUE(entries().empty());
}

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

TEST_F(CliTest, UsageErrorsExitWithTwo) {
    const std::vector<std::vector<std::string>> bad = {
        {"render", "--no-such-option"},
        {"render", "random:2", "--threads", "-1"},
        {"render", "random:2", "--width", "0"},
        {"render", "random:2", "--spp", "many"},
        {"render", "random:2", "--tile", "0x16"},
        {"render", "random:2", "--tile", "16by16"},
        {"render", "random:2", "--compression", "jpeg"},
        {"render", "random:2", "--path", "gpu"},
        {"render", "random:2", "-o", "same.exr", "--png", "same.exr"},
        {"render", "random:2", "--frames", "1-x"},
        {"render", "random:2", "--progress", "loud"},
        {"render", "random:2", "--accel", "kd-tree"},
        {"scene"},
        {"frobnicate"},
        {},
    };
    for (const auto& args : bad) {
        std::string joined;
        for (const auto& a : args) joined += a + " ";
        const RunResult r = octray(args);
        EXPECT_EQ(r.status, 2) << joined << "\n" << r.output;
        EXPECT_TRUE(contains(r.output, "--help")) << joined << "\n" << r.output;
    }
    EXPECT_TRUE(entries().empty());
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
    EXPECT_EQ(file_bytes(dir_ / "a.png"), file_bytes(dir_ / "d.png"));
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

// Issue 23: a mistyped option (or command) names the one probably meant, in every command.
TEST_F(CliTest, MistypedOptionsSuggestTheClosestOne) {
    const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
        {{"render", "--threds", "2"}, "--threads"},
        {{"render", "--threds=2"}, "--threads"},
        {{"render", "random:2", "--sed", "1"}, "--seed"},
        {{"scene", "whitted", "--ouput", "x.json"}, "--output"},
        {{"compare", "a.exr", "b.exr", "--hardfial", "1"}, "--hardfail"},
        {{"verify", "--wdth", "8"}, "--width"},
        {{"bench", "--no-embre"}, "--no-embree"},
        {{"info", "--hepl"}, "--help"},
        {{"assemble", "a.exr", "--ouptut", "x.exr"}, "--output"},
        {{"rendr", "whitted"}, "render"},
        {{"--verison"}, "--version"},
    };
    for (const auto& [args, meant] : cases) {
        const RunResult r = octray(args);
        // compare's usage errors exit 5 (issue 26): 2 is its FAIL verdict.
        EXPECT_EQ(r.status, args[0] == "compare" ? 5 : 2) << args[0] << " " << args[1] << "\n"
                                                          << r.output;
        EXPECT_TRUE(contains(r.output, "did you mean \"" + meant + "\"?")) << args[0] << "\n"
                                                                           << r.output;
        EXPECT_TRUE(contains(r.output, "--help")) << r.output;
    }
    // Nothing close: no guess.
    const RunResult far = octray({"render", "--frobnicate"});
    EXPECT_EQ(far.status, 2) << far.output;
    EXPECT_FALSE(contains(far.output, "did you mean")) << far.output;
    EXPECT_TRUE(entries().empty());
}

// Issue 23: integer options take decimal digits only, as scene files do: no hex, no sign,
// no blanks, and nothing out of range is clamped.
TEST_F(CliTest, IntegerOptionsTakeDecimalDigitsOnly) {
    const std::vector<std::vector<std::string>> bad = {
        {"render", "random:2", "--seed", "18446744073709551616"},
        {"render", "random:2", "--seed", "99999999999999999999999"},
        {"render", "random:2", "--seed", "0x10"},
        {"render", "random:2", "--seed", "+5"},
        {"render", "random:2", "--seed", " 5"},
        {"render", "random:2", "--seed", "5 "},
        {"render", "random:2", "--width", "0x10"},
        {"render", "random:2", "--height", "+8"},
        {"render", "random:2", "--spp", " 4"},
        {"render", "random:2", "--threads", "1e1"},
        {"render", "random:2", "--max-depth", "010x"},
        {"verify", "random:2", "--width", "0x10"},
        {"verify", "random:2", "--threads", "+1"},
        {"bench", "no-such-scene.json", "--no-embree", "--reps", "0x2"},
    };
    for (const auto& args : bad) {
        const RunResult r = octray(args);
        EXPECT_EQ(r.status, 2) << args[2] << " " << args[3] << "\n" << r.output;
        EXPECT_TRUE(contains(r.output, args[args.size() - 2])) << r.output;
        EXPECT_TRUE(contains(r.output, "--help")) << r.output;
    }
    EXPECT_TRUE(entries().empty());

    const RunResult top = octray({"render", "random:2,width=4,height=4", "--seed",
                                  "18446744073709551615", "-o", "s.exr"});
    ASSERT_EQ(top.status, 0) << top.output;
    Imf::InputFile file(path("s.exr").c_str());
    const auto* seed = file.header().findTypedAttribute<Imf::StringAttribute>("octray.seed");
    ASSERT_NE(seed, nullptr);
    EXPECT_EQ(seed->value(), "18446744073709551615");
}

// Issue 26: --max-depth's help and its limit are the scene's limit, from one constant.
TEST_F(CliTest, MaxDepthHelpAndLimitAgreeWithTheScene) {
    const RunResult help = octray({"render", "--help"});
    EXPECT_TRUE(contains(help.output, "bounces, 0..64;")) << help.output;
    const RunResult over = octray({"render", "random:2,width=4,height=4", "--max-depth", "65"});
    EXPECT_EQ(over.status, 2) << over.output;
    EXPECT_TRUE(contains(over.output, "--max-depth must be an integer from 0 to 64"))
        << over.output;
    const RunResult spec = octray({"render", "random:2,width=4,height=4,max_depth=65"});
    EXPECT_EQ(spec.status, 3) << spec.output;
    EXPECT_TRUE(contains(spec.output, "from 0 to 64")) << spec.output;
    EXPECT_TRUE(entries().empty());
    const RunResult top = octray({"render", "random:2,width=4,height=4", "--max-depth", "64",
                                  "-o", "d.exr", "--progress", "none"});
    EXPECT_EQ(top.status, 0) << top.output;
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

// Issue 23: a closed standard output (`octray ... | head -0`) is an I/O error, exit 4 with
// the reason, not death by SIGPIPE (141 in a shell).
TEST_F(CliTest, ClosedStandardOutputIsAnIoError) {
    for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
             {"scene", "whitted"},
             {"info"},
             {"render", "random:2,width=8,height=8", "-o", "r.exr", "--progress", "lines"},
         }) {
        const ClosedStdoutRun r = run_with_closed_stdout(args, dir_);
        EXPECT_FALSE(WIFSIGNALED(r.wait_status))
            << args[0] << " killed by signal " << WTERMSIG(r.wait_status);
        ASSERT_TRUE(WIFEXITED(r.wait_status)) << args[0];
        EXPECT_EQ(WEXITSTATUS(r.wait_status), 4) << args[0] << "\n" << r.stderr_text;
        EXPECT_TRUE(contains(r.stderr_text, "standard output")) << r.stderr_text;
        EXPECT_TRUE(contains(r.stderr_text, "Broken pipe")) << r.stderr_text;
    }
    // The render itself was done: only its report could not be written.
    EXPECT_TRUE(is_exr_file(dir_ / "r.exr"));
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
    EXPECT_EQ(octray({"render", spec, "--isa", "avx512", "-o", "x.exr"}).status, 2);

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

// Issue 26: a pinhole fov below 2 degrees is probably radians: every command that loads the
// scene warns on stderr, naming the file and the key; --quiet, or the camera's
// "fov_units": "degrees", silences it; any other fov_units is a scene error.
TEST_F(CliTest, SmallFovWarnsThatFovIsInDegrees) {
    const auto scene = [&](const std::string& name, const std::string& camera_extra) {
        std::ofstream(path(name))
            << R"({ "image": { "width": 4, "height": 4 }, "camera": { "eye": [0, 0, 5], )"
               R"("lookat": [0, 0, 0], )"
            << camera_extra
            << R"( }, "objects": [ { "type": "sphere", "center": [0, 0, 0], "radius": 1, )"
               R"("material": { "color": 0.5 } } ] })";
        return path(name);
    };
    const std::string radians = scene("radians.json", R"("fov": 0.87)");
    const std::string warning =
        "octray: warning: " + radians + ": camera.fov: fov 0.87 is below 2; fov is in degrees";
    const RunResult render = octray({"render", radians, "-o", "r.exr", "--progress", "none"});
    EXPECT_EQ(render.status, 0) << render.output;
    EXPECT_TRUE(contains(render.output, warning)) << render.output;
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"scene", radians, "-o", "s.json"},
          std::vector<std::string>{"verify", radians},
          std::vector<std::string>{"info", radians}}) {
        const RunResult r = octray(args);
        EXPECT_EQ(r.status, 0) << args[0] << "\n" << r.output;
        EXPECT_TRUE(contains(r.output, warning)) << args[0] << "\n" << r.output;
        std::vector<std::string> quiet = args;
        quiet.push_back("--quiet");
        const RunResult q = octray(quiet);
        EXPECT_EQ(q.status, 0) << args[0] << "\n" << q.output;
        EXPECT_FALSE(contains(q.output, "warning")) << args[0] << "\n" << q.output;
    }
    // Warnings go to stderr: stdout stays the command's own output.
    EXPECT_FALSE(contains(octray({"info", radians}, false).output, "warning"));

    const RunResult quiet =
        octray({"render", radians, "-o", "q.exr", "--progress", "none", "-q"});
    EXPECT_EQ(quiet.status, 0) << quiet.output;
    EXPECT_FALSE(contains(quiet.output, "warning")) << quiet.output;

    const RunResult two = octray(
        {"render", scene("two.json", R"("fov": 2)"), "-o", "t.exr", "--progress", "none"});
    EXPECT_EQ(two.status, 0) << two.output;
    EXPECT_FALSE(contains(two.output, "warning")) << two.output;

    const RunResult stated =
        octray({"render", scene("stated.json", R"("fov": 0.5, "fov_units": "degrees")"), "-o",
                "d.exr", "--progress", "none"});
    EXPECT_EQ(stated.status, 0) << stated.output;
    EXPECT_FALSE(contains(stated.output, "warning")) << stated.output;

    const std::string bad = scene("bad.json", R"("fov": 0.5, "fov_units": "radians")");
    const RunResult refused = octray({"render", bad, "-o", "b.exr"});
    EXPECT_EQ(refused.status, 3) << refused.output;
    EXPECT_TRUE(contains(refused.output, bad + ": camera.fov_units: expected one of "
                                               "\"degrees\", found the string \"radians\""))
        << refused.output;
    EXPECT_FALSE(fs::exists(path("b.exr")));
}

}  // namespace
