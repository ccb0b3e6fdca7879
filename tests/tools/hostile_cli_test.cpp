// Hostile input against the executable (issue 38): outputs that are device nodes or FIFOs,
// signals in the middle of a long tile, thread counts the machine cannot start, stray
// directories, the viewer's size limit.

#include <sys/stat.h>
#include <sys/types.h>

#include <cstdlib>

#include "cli_fixture.h"

namespace octray::testing {
namespace {

class HostileCliTest : public CliTest {
  protected:
    // Runs a shell command line in the test directory; returns its exit status.
    int shell(const std::string& command) const {
        const std::string line = "cd " + shell_quote(dir_.string()) + " || exit 99; " + command;
        const int status = std::system(line.c_str());
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }

    bool is_fifo(const std::string& name) const {
        struct stat info {};
        return ::lstat(path(name).c_str(), &info) == 0 && S_ISFIFO(info.st_mode);
    }

    // No hidden temporary of a write was left in the directory.
    bool no_temporaries() const {
        for (const std::string& name : entries())
            if (name.rfind('.', 0) == 0) return false;
        return true;
    }
};

// Every writer renames a new file over its target, which turned a FIFO or a device node
// (as root: /dev/full) into a regular file. Each command refuses such a target with exit 4
// before doing the work, names it and what it is, and leaves it as it was.
TEST_F(HostileCliTest, DeviceAndFifoOutputsAreRefusedAndLeftAlone) {
    ASSERT_EQ(::mkfifo(path("n.png").c_str(), 0666), 0);
    ASSERT_EQ(::mkfifo(path("n.exr").c_str(), 0666), 0);
    ASSERT_EQ(::mkfifo(path("n.json").c_str(), 0666), 0);
    fs::create_symlink("/dev/null", dir_ / "null.png");

    RunResult r = octray({"render", "whitted,width=32,height=18", "-o", "ok.exr", "--png",
                          "n.png", "--progress", "none"});
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, "n.png")) << r.output;
    EXPECT_TRUE(contains(r.output, "FIFO")) << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "ok.exr")) << "refused only after rendering";
    EXPECT_TRUE(is_fifo("n.png"));

    r = octray({"render", "whitted,width=32,height=18", "-o", "n.exr", "--progress", "none"});
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(is_fifo("n.exr"));

    // A symlink to a device is the device: refused, and the link stays a link to it.
    r = octray({"render", "whitted,width=32,height=18", "-o", "ok.exr", "--png", "null.png",
                "--progress", "none"});
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, "character device")) << r.output;
    EXPECT_TRUE(fs::is_symlink(dir_ / "null.png"));
    EXPECT_EQ(fs::read_symlink(dir_ / "null.png"), fs::path("/dev/null"));

    r = octray({"scene", "whitted", "-o", "n.json"});
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(is_fifo("n.json"));

    // compare and assemble: a.exr is a real image to read.
    r = octray({"render", "whitted,width=32,height=18", "-o", "a.exr", "--progress", "none"});
    ASSERT_EQ(r.status, 0) << r.output;
    r = octray({"compare", "a.exr", "a.exr", "--diff", "n.exr"});
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(is_fifo("n.exr"));
    r = octray({"compare", "a.exr", "a.exr", "--heatmap", "n.png"});
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(is_fifo("n.png"));
    r = octray({"assemble", "a.exr", "-o", "n.exr"});
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(is_fifo("n.exr"));
    EXPECT_TRUE(no_temporaries());

    // A symlink to a regular file is written as before.
    fs::create_symlink("a.exr", dir_ / "link.exr");
    r = octray(
        {"render", "whitted,width=32,height=18", "-o", "link.exr", "--progress", "none"});
    EXPECT_EQ(r.status, 0) << r.output;
}

// SIGTERM in the middle of a tile stops the frame within a chunk of packets (the simd
// path) or a ray (the scalar one), not at the end of the tile: one 64x64 tile at 2^20 spp
// is hours of work, so a render that finished its tile first would not end before the
// watchdog's SIGKILL. The exit status and the summary are those of an interrupted run.
TEST_F(HostileCliTest, TermInTheMiddleOfATileStopsTheFrameOnBothPaths) {
    for (const char* render_path : {"simd", "scalar"}) {
        SCOPED_TRACE(render_path);
        const std::string log = std::string("log-") + render_path + ".txt";
        const int status = shell(
            shell_quote(OCTRAY_EXE) +
            " render whitted,width=64,height=64 --tile 64 --spp 1048576 --threads 1 --path " +
            render_path + " --progress lines -o s.exr >" + log +
            " 2>&1 </dev/null & pid=$!; "
            // The header is printed once the signal handlers are in place.
            "i=0; while ! grep -q '^render ' " +
            log +
            " && [ $i -lt 6000 ]; do sleep 0.01; i=$((i+1)); done; sleep 0.3; "
            "kill -TERM $pid; (sleep 120; kill -KILL $pid) >/dev/null 2>&1 </dev/null & "
            "watchdog=$!; wait $pid; echo $? > status.txt; pkill -P $watchdog sleep; "
            "kill $watchdog 2>/dev/null; exit 0");
        ASSERT_EQ(status, 0);
        EXPECT_EQ(file_bytes(dir_ / "status.txt"), "143\n") << file_bytes(dir_ / log);
        EXPECT_TRUE(contains(file_bytes(dir_ / log), "interrupted")) << file_bytes(dir_ / log);
        EXPECT_FALSE(fs::exists(dir_ / "s.exr"));
        EXPECT_TRUE(no_temporaries());
    }
}

// oneTBB aborts (exit 134, "pthread_create has failed") when it cannot start a worker;
// under an address-space limit, --threads 64 and 4096 did. They are refused first: exit 1
// (the machine's limits, as out of memory), naming the count and the limit.
TEST_F(HostileCliTest, ThreadsTheAddressSpaceLimitCannotHoldAreRefused) {
    const std::string limited = "ulimit -v 1000000 && " + shell_quote(OCTRAY_EXE);
    // A sanitizer build reserves terabytes of shadow memory and cannot run under the limit.
    if (shell(limited + " --version >/dev/null 2>&1") != 0)
        GTEST_SKIP() << "octray does not start under ulimit -v 1000000 (a sanitizer build)";
    for (const char* threads : {"64", "4096"}) {
        SCOPED_TRACE(threads);
        const int status = shell(limited + " render whitted,width=32,height=18 --threads " +
                                 threads + " -o x.exr --progress none >log.txt 2>&1");
        const std::string log = file_bytes(dir_ / "log.txt");
        EXPECT_EQ(status, 1) << log;
        EXPECT_TRUE(contains(log, std::string("cannot start ") + threads + " threads")) << log;
        EXPECT_TRUE(contains(log, "ulimit -v")) << log;
        EXPECT_FALSE(fs::exists(dir_ / "x.exr"));
    }
    // Two threads fit.
    EXPECT_EQ(shell(limited + " render whitted,width=32,height=18 --threads 2 -o x.exr "
                              "--progress none >log.txt 2>&1"),
              0)
        << file_bytes(dir_ / "log.txt");
}

// "x.exr/../y.exr" created x.exr/ to write y.exr through it, and left it behind.
TEST_F(HostileCliTest, AnOutputThatGoesUpOutOfAMissingDirectoryLeavesNoStrayDirectory) {
    const RunResult r = octray(
        {"render", "whitted,width=32,height=18", "-o", "x.exr/../y.exr", "--progress", "none"});
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, "x.exr does not exist")) << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "x.exr"));
    EXPECT_FALSE(fs::exists(dir_ / "y.exr"));
}

}  // namespace
}  // namespace octray::testing
