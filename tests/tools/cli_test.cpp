// End-to-end tests of the `octray` executable: run it as a user would (through the shell),
// then check its exit status, its messages and the files it leaves behind. Here the
// program as a whole: --version, --help, completions, usage errors and their hints,
// integer options, a closed standard output, scene warnings. Rendering, scenes and
// output files: cli_render_test.cpp.

#include <gtest/gtest.h>

#include "cli_fixture.h"

namespace octray::testing {
namespace {

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
    // The options' words are the user's, never a type's name (a code rename once reached
    // "RgbImage width in pixels" here).
    for (const char* command : {"render", "view", "verify"}) {
        const std::string help = octray({command, "--help"}).output;
        EXPECT_TRUE(contains(help, "Image width")) << command << "\n" << help;
        EXPECT_FALSE(contains(help, "RgbImage")) << command << "\n" << help;
    }
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

// Issue 43: the completions complete values too: the words an option takes and the
// built-in scenes next to file names.
TEST_F(CliTest, CompletionScriptsCompleteValues) {
    const RunResult bash = octray({"completion", "bash"});
    ASSERT_EQ(bash.status, 0) << bash.output;
    { std::ofstream(path("octray.bash")) << bash.output; }
    { std::ofstream(path("shot.json")) << "{}"; }
    const auto complete = [&](const std::string& words, int cword) {
        const std::string script = "source octray.bash && COMP_WORDS=(" + words +
                                   ") COMP_CWORD=" + std::to_string(cword) +
                                   " && _octray && echo \"[${COMPREPLY[*]}]\"";
        const std::string command = "cd " + octray::testing::shell_quote(dir_.string()) +
                                    " && bash -c " + octray::testing::shell_quote(script);
        FILE* pipe = ::popen(command.c_str(), "r");
        std::string out;
        char buffer[256];
        while (pipe != nullptr && std::fgets(buffer, sizeof buffer, pipe) != nullptr)
            out += buffer;
        if (pipe != nullptr) ::pclose(pipe);
        return out;
    };
    EXPECT_EQ(complete("octray render --path ''", 3), "[scalar simd]\n");
    EXPECT_EQ(complete("octray render --progress l", 3), "[lines]\n");
    EXPECT_EQ(complete("octray render --isa avx", 3), "[avx512 avx2]\n");
    EXPECT_EQ(complete("octray render --compression dw", 3), "[dwaa dwab]\n");
    EXPECT_EQ(complete("octray render --aov ''", 3), "[depth normal albedo id]\n");
    EXPECT_EQ(complete("octray view --order f", 3), "[frameless]\n");
    EXPECT_EQ(complete("octray bench --order m", 3), "[morton]\n");
    EXPECT_EQ(complete("octray compare a.exr b.exr --heatmapscale l", 5), "[linear log]\n");
    // A SCENE argument: the built-ins and the files.
    EXPECT_EQ(complete("octray render sphere", 2), "[sphereflake:]\n");
    EXPECT_EQ(complete("octray verify s", 2), "[sphereflake: shot.json]\n");
    // A value that is no scene: files only.
    EXPECT_EQ(complete("octray render -o s", 3), "[shot.json]\n");

    const RunResult zsh = octray({"completion", "zsh"});
    ASSERT_EQ(zsh.status, 0) << zsh.output;
    EXPECT_TRUE(contains(zsh.output, "]:value:(scalar simd)' \\\n")) << zsh.output;
    EXPECT_TRUE(contains(zsh.output,
                         "compadd -- whitted\n    compadd -S '' -- random\\: "
                         "sphereflake\\:\n"))
        << zsh.output;
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
    EXPECT_TRUE(contains(refused.output, bad + ":1:104: camera.fov_units: expected one of "
                                               "\"degrees\", found the string \"radians\""))
        << refused.output;
    EXPECT_FALSE(fs::exists(path("b.exr")));
}

}  // namespace
}  // namespace octray::testing
