// `octray view` and `octray bench` run in executables of their own (tools/own_executable.h):
// octray itself loads neither the viewer's HTTP/TLS libraries nor Embree, the commands
// still work through it, and an octray without them says where it looked.

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "cli_fixture.h"

namespace octray::testing {
namespace {

// Runs a shell command line; its exit status and its stdout and stderr together.
RunResult run_shell(const std::string& command) {
    RunResult result;
    FILE* pipe = ::popen((command + " </dev/null 2>&1").c_str(), "r");
    if (pipe == nullptr) return result;
    char buffer[4096];
    std::size_t n = 0;
    while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0)
        result.output.append(buffer, n);
    const int status = ::pclose(pipe);
    if (status != -1 && WIFEXITED(status)) result.status = WEXITSTATUS(status);
    return result;
}

TEST_F(CliTest, OctrayLoadsNeitherTheViewersLibrariesNorEmbree) {
    const RunResult r = run_shell("ldd " + shell_quote(OCTRAY_EXE));
    ASSERT_EQ(r.status, 0) << r.output;
    ASSERT_TRUE(contains(r.output, "libOpenEXR")) << r.output;  // ldd did list libraries
    for (const char* library : {"httplib", "libssl", "brotli", "libjpeg", "embree"})
        EXPECT_FALSE(contains(r.output, library)) << library << " in\n" << r.output;
}

TEST_F(CliTest, ViewAndBenchRunThroughOctray) {
    const RunResult view = octray({"view", "whitted", "--width", "32", "--height", "18",
                                   "--threads", "1", "--bench", "2"});
    EXPECT_EQ(view.status, 0) << view.output;
    EXPECT_TRUE(contains(view.output, "first picture: 32x18")) << view.output;
    const RunResult bench = octray({"bench", "random:4", "--rays", "primary", "--threads", "1",
                                    "--reps", "1", "--warmup", "0", "--min-time", "0",
                                    "--width", "16", "--height", "8", "--no-embree"});
    EXPECT_EQ(bench.status, 0) << bench.output;
    EXPECT_TRUE(contains(bench.output, "random:4")) << bench.output;
    // Their usage errors are octray's: found before anything is run.
    const RunResult typo = octray({"bench", "--repz", "2"});
    EXPECT_EQ(typo.status, 2) << typo.output;
    EXPECT_TRUE(contains(typo.output, "--reps")) << typo.output;
}

TEST_F(CliTest, AnOctrayWithoutItsOwnExecutablesSaysWhereItLooked) {
    const fs::path bin = dir_ / "prefix" / "bin";
    fs::create_directories(bin);
    fs::copy_file(OCTRAY_EXE, bin / "octray");
    const std::string octray = shell_quote((bin / "octray").string());
    const RunResult render = run_shell(octray + " --version");
    EXPECT_EQ(render.status, 0) << render.output;  // every other command needs neither
    for (const std::string command : {"view", "bench"}) {
        const std::string args = command == "view" ? " whitted --bench 1" : " --reps 1";
        const RunResult r = run_shell(octray + " " + command + args);
        EXPECT_EQ(r.status, 1) << r.output;
        const std::string name = "octray-" + command;
        EXPECT_TRUE(contains(r.output, "cannot run " + name)) << r.output;
        EXPECT_TRUE(contains(r.output, (bin / name).string() + ": No such file")) << r.output;
        const fs::path installed = bin / OCTRAY_OWN_EXECUTABLES_RELATIVE_DIR / name;
        EXPECT_TRUE(contains(r.output, installed.lexically_normal().string())) << r.output;
    }
}

}  // namespace
}  // namespace octray::testing
