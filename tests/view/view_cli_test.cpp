// `octray view` as a user runs it: its help, and the failures before it serves (a scene
// that cannot be loaded, an address that cannot be bound). Serving, the page and Ctrl-C
// are checked by browser_test.py, which runs the command too.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "tests/tools/run_octray.h"

namespace {

using octray::testing::run_octray;
using octray::testing::RunResult;

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

const std::filesystem::path kCwd = std::filesystem::temp_directory_path();

TEST(ViewCli, HelpExplainsTheTokenTheApiAndCtrlC) {
    const RunResult r = run_octray({"view", "--help"}, kCwd);
    EXPECT_EQ(r.status, 0) << r.output;
    for (const char* part : {"--bind", "--port", "--preview-divisor", "token", "403", "Ctrl-C",
                             "view/README.md", "Exit codes:"})
        EXPECT_TRUE(contains(r.output, part)) << part << "\n" << r.output;
}

TEST(ViewCli, AMissingSceneIsASceneError) {
    const RunResult r = run_octray({"view", "no_such_scene.json", "--port", "0"}, kCwd);
    EXPECT_EQ(r.status, 3) << r.output;
    EXPECT_TRUE(contains(r.output, "no_such_scene.json")) << r.output;
}

TEST(ViewCli, AnAddressThatCannotBeBoundIsAUsageError) {
    const RunResult bad_host = run_octray({"view", "--bind", "256.1.2.3", "--port", "0"}, kCwd);
    EXPECT_EQ(bad_host.status, 2) << bad_host.output;
    EXPECT_TRUE(contains(bad_host.output, "cannot listen on 256.1.2.3")) << bad_host.output;

    // A port some other socket listens on.
    const int fd = socket(AF_INET, SOCK_STREAM, 0);
    ASSERT_GE(fd, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
    ASSERT_EQ(listen(fd, 1), 0);
    socklen_t size = sizeof address;
    ASSERT_EQ(getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size), 0);
    const std::string port = std::to_string(ntohs(address.sin_port));
    const RunResult busy = run_octray({"view", "--port", port}, kCwd);
    close(fd);
    EXPECT_EQ(busy.status, 2) << busy.output;
    EXPECT_TRUE(contains(busy.output, "cannot listen on 127.0.0.1:" + port)) << busy.output;
}

TEST(ViewCli, AForcedIsaIsChecked) {
    const RunResult r = run_octray({"view", "--isa", "neon"}, kCwd);
    EXPECT_EQ(r.status, 2) << r.output;
}

// --bench serves nothing: it renders the first picture and N orbit updates and reports
// their rates (the figures themselves are not checked: no timing in tests).
TEST(ViewCli, BenchReportsTheFirstPictureAndTheOrbitUpdates) {
    const RunResult r = run_octray({"view", "whitted", "--width", "64", "--height", "36",
                                    "--threads", "1", "--bench", "12"},
                                   kCwd);
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "first picture: 64x36 at 1 spp after ")) << r.output;
    EXPECT_TRUE(contains(r.output, "orbit: 12 updates of 16x9 in ")) << r.output;
    EXPECT_TRUE(contains(r.output, "updates/s")) << r.output;
    EXPECT_TRUE(contains(r.output, "Mrays/s")) << r.output;
}

// `octray view A B` reads and compares the images before it serves, and fails as
// `octray compare A B` does: 4 for an image that cannot be read, 3 for two that cannot be
// compared; scene options with two images are a usage error.
TEST(ViewCli, TwoImagesFailAsCompareFails) {
    const std::filesystem::path dir = kCwd / ("octray_view_cli_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    for (const auto& [size, name] : {std::pair{"16", "a.exr"}, std::pair{"8", "b.exr"}}) {
        const RunResult r = run_octray(
            {"render", "whitted", "--width", size, "--height", "8", "--spp", "1", "-o", name},
            dir);
        ASSERT_EQ(r.status, 0) << r.output;
    }
    const RunResult missing = run_octray({"view", "a.exr", "missing.exr", "--port", "0"}, dir);
    EXPECT_EQ(missing.status, 4) << missing.output;
    EXPECT_TRUE(contains(missing.output, "missing.exr")) << missing.output;
    const RunResult mismatch = run_octray({"view", "a.exr", "b.exr", "--port", "0"}, dir);
    EXPECT_EQ(mismatch.status, 3) << mismatch.output;
    const RunResult compare = run_octray({"compare", "a.exr", "b.exr"}, dir);
    EXPECT_EQ(compare.status, 3) << compare.output;
    const RunResult scene_option =
        run_octray({"view", "a.exr", "a.exr", "--spp", "4", "--port", "0"}, dir);
    EXPECT_EQ(scene_option.status, 2) << scene_option.output;
    EXPECT_TRUE(contains(scene_option.output, "apply to a scene")) << scene_option.output;
    const RunResult three = run_octray({"view", "a.exr", "a.exr", "a.exr"}, dir);
    EXPECT_EQ(three.status, 2) << three.output;
    std::filesystem::remove_all(dir);
}

// Issue 38: the viewer has no --channels; a channel mismatch suggested it. It names
// `octray compare --channels` instead.
TEST(ViewCli, AChannelMismatchPointsToCompareChannels) {
    const std::filesystem::path dir =
        kCwd / ("octray_view_cli_channels_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    RunResult r = run_octray({"render", "whitted,width=8,height=8", "-o", "a.exr"}, dir);
    ASSERT_EQ(r.status, 0) << r.output;
    r = run_octray({"render", "whitted,width=8,height=8", "--aov", "depth", "-o", "b.exr"},
                   dir);
    ASSERT_EQ(r.status, 0) << r.output;
    r = run_octray({"view", "a.exr", "b.exr", "--port", "0"}, dir);
    EXPECT_EQ(r.status, 3) << r.output;
    EXPECT_TRUE(contains(r.output, "channel mismatch")) << r.output;
    EXPECT_TRUE(contains(r.output, "octray compare A B --channels")) << r.output;
    EXPECT_FALSE(contains(r.output, "(pick common ones with --channels)")) << r.output;
    r = run_octray({"compare", "a.exr", "b.exr"}, dir);
    EXPECT_EQ(r.status, 3) << r.output;
    EXPECT_TRUE(contains(r.output, "pick common channels with --channels")) << r.output;
    std::filesystem::remove_all(dir);
}

// Issue 38: `view --width 65536 --height 32767` started and failed on its first picture
// with std::bad_alloc; it is refused up front by render's memory estimate (exit 2). The
// watchdog ends a viewer that started serving instead.
TEST(ViewCli, AnImageOverTheMemoryLimitIsRefusedBeforeServing) {
    const std::string octray = OCTRAY_EXE;
    const double memory_gib = static_cast<double>(::sysconf(_SC_PHYS_PAGES)) *
                              static_cast<double>(::sysconf(_SC_PAGESIZE)) / (1u << 30);
    for (const std::string limit : {"--max-memory 1G", ""}) {
        // Without --max-memory the limit is this machine's memory: the picture's 114 GiB
        // must be more than that.
        if (limit.empty() && memory_gib > 100.0) continue;
        const std::string line = "timeout -s KILL 60 " + octray +
                                 " view whitted --width 65536 --height 32767 --port 0 " +
                                 limit + " </dev/null >" +
                                 (kCwd / "octray_view_mem.txt").string() + " 2>&1";
        const int status = std::system(line.c_str());
        std::ifstream in(kCwd / "octray_view_mem.txt");
        const std::string output((std::istreambuf_iterator<char>(in)), {});
        ASSERT_TRUE(WIFEXITED(status)) << output;
        EXPECT_EQ(WEXITSTATUS(status), 2) << limit << ": " << output;
        EXPECT_TRUE(contains(output, "needs about")) << output;
        EXPECT_TRUE(contains(output, "memory limit")) << output;
    }
    std::filesystem::remove(kCwd / "octray_view_mem.txt");
}

}  // namespace
