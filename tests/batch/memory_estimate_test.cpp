// `octray render --max-memory` against what a render really takes: for a set of scenes
// (AOVs written as floats, progressive passes on the reference path, a large random scene
// with its BVH, a scene file whose parse dominates), the peak resident set size of the
// render, measured by the kernel (wait4's ru_maxrss), must not exceed the estimate. The
// estimate is read through the option itself: with the limit one byte below the measured
// peak, the same command line must be refused before rendering.

#include "render/batch/memory_estimate.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "run_octray.h"
#include "scene/load.h"

namespace {

namespace fs = std::filesystem;
using octray::testing::run_octray;

// ASan and TSan multiply a process's memory. The octray under test is sanitized where
// this test is, or where the build says so (OCTRAY_SANITIZED_BUILD: tests/CMakeLists.txt
// compiles this driver itself plain).
#if defined(OCTRAY_SANITIZED_BUILD) || defined(__SANITIZE_ADDRESS__) || \
    defined(__SANITIZE_THREAD__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

// Runs `octray args...` in `dir` with stdout and stderr discarded; returns the exit
// status (-1 if it did not exit normally) and the child's peak RSS in bytes.
struct Peak {
    int status = -1;
    std::uint64_t bytes = 0;
};

Peak run_measured(const std::vector<std::string>& args, const fs::path& dir) {
    std::vector<std::string> argv_storage = {OCTRAY_EXE};
    argv_storage.insert(argv_storage.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : argv_storage) argv.push_back(a.data());
    argv.push_back(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
        if (::chdir(dir.c_str()) != 0) ::_exit(98);
        if (!std::freopen("/dev/null", "w", stdout) || !std::freopen("/dev/null", "w", stderr))
            ::_exit(97);
        ::execv(OCTRAY_EXE, argv.data());
        ::_exit(99);
    }
    Peak peak;
    if (pid < 0) return peak;
    int status = 0;
    struct rusage usage {};
    if (::wait4(pid, &status, 0, &usage) != pid) return peak;
    if (WIFEXITED(status)) peak.status = WEXITSTATUS(status);
    peak.bytes = static_cast<std::uint64_t>(usage.ru_maxrss) * 1024;  // ru_maxrss: KiB
    return peak;
}

class MemoryEstimateTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = fs::path(OCTRAY_TEST_TMPDIR) / "memory_estimate" /
               ::testing::UnitTest::GetInstance()->current_test_info()->name();
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        if (!HasFailure()) fs::remove_all(dir_);
    }

    // Renders, measures the peak, then asks for a limit one byte below it: refused.
    void expect_estimate_covers_peak(std::vector<std::string> args) {
        if (kSanitized) GTEST_SKIP() << "a sanitizer's shadow memory is not in the estimate";
        std::string joined;
        for (const auto& a : args) joined += a + " ";
        const Peak peak = run_measured(args, dir_);
        ASSERT_EQ(peak.status, 0) << joined;
        ASSERT_GT(peak.bytes, 0u) << joined;
        args.insert(args.end(), {"--max-memory", std::to_string(peak.bytes - 1)});
        const auto refused = run_octray(args, dir_);
        EXPECT_EQ(refused.status, 2)
            << joined << "peaked at " << peak.bytes << " bytes, above its estimate\n"
            << refused.output;
        EXPECT_NE(refused.output.find("--max-memory"), std::string::npos) << refused.output;
    }

    fs::path dir_;
};

TEST_F(MemoryEstimateTest, AovsAsFloatsWithAPreview) {
    expect_estimate_covers_peak({"render", "whitted", "--width", "1280", "--height", "720",
                                 "--float", "--aov", "depth,normal,albedo,id", "--png", "w.png",
                                 "-o", "w.exr"});
}

TEST_F(MemoryEstimateTest, ProgressivePassesOnTheReferencePath) {
    expect_estimate_covers_peak({"render", "whitted", "--width", "960", "--height", "540",
                                 "--spp", "4", "--progressive", "--path", "scalar", "--aov",
                                 "depth", "--compression", "dwab", "-o", "p.exr"});
}

TEST_F(MemoryEstimateTest, ALargeRandomSceneWithItsBvh) {
    expect_estimate_covers_peak(
        {"render", "random:300000,width=64,height=36", "--float", "-o", "r.exr"});
}

TEST_F(MemoryEstimateTest, ASceneFileWhoseParseDominates) {
    const auto written = run_octray({"scene", "random:60000", "-o", "big.json"}, dir_);
    ASSERT_EQ(written.status, 0) << written.output;
    expect_estimate_covers_peak({"render", "big.json", "--width", "32", "--height", "18",
                                 "--accel", "none", "-o", "b.exr"});
}

// Frames written behind the next frame's render (a multi-frame run holds two frames at a
// time): the peak of the run stays within the estimate with RenderMemoryParams::
// write_behind, the one `octray render` admits such a run with.
TEST_F(MemoryEstimateTest, FramesWrittenWhileTheNextRendersStayWithinTheEstimate) {
    if (kSanitized) GTEST_SKIP() << "a sanitizer's shadow memory is not in the estimate";
    const Peak peak =
        run_measured({"render", "whitted", "--width", "1920", "--height", "1080", "--frames",
                      "0-3", "--float", "--png", "w.#.png", "-o", "w.#.exr", "--threads", "2"},
                     dir_);
    ASSERT_EQ(peak.status, 0);
    octray::batch::RenderMemoryParams params;
    params.threads = 2;
    params.float32_output = true;
    params.png_preview = true;
    params.write_behind = true;
    const octray::Scene scene = octray::load_scene("whitted,width=1920,height=1080");
    EXPECT_LE(peak.bytes, octray::batch::estimate_render_memory(scene, params).total);
}

// An image whose framebuffer alone exceeds this machine's memory (the largest the pixel
// cap allows, 24 GiB): a valid scene, refused by the render command at its default limit,
// the machine's memory (exit 2), with the framebuffer's size and where the limit comes
// from in the message, before anything is allocated. (Scene validation once refused it;
// whether an image fits depends on the machine, so the render command decides.)
TEST_F(MemoryEstimateTest, AFramebufferLargerThanThisMachinesMemoryIsRefused) {
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    ASSERT_GT(pages, 0);
    ASSERT_GT(page, 0);
    const double memory = static_cast<double>(pages) * static_cast<double>(page);
    // On machines with more memory than that, the estimate may fit and the image render.
    if (memory >= 2147483647.0 * 12.0)
        GTEST_SKIP() << "more memory than any allowed image needs";
    const int side = 46340;  // 46340^2 < 2^31 - 1
    ASSERT_GT(static_cast<double>(side) * side * 12.0, memory);
    const auto r = run_octray({"render", "whitted", "--width", std::to_string(side), "--height",
                               std::to_string(side), "-o", "big.exr"},
                              dir_);
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("whitted: image: a 46340 x 46340 image at"), std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("framebuffer 24.0 GiB"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("(the limit is this machine's memory; --max-memory sets another)"),
              std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "big.exr"));
}

// A 5 M-sphere JSON with --max-memory 1K was refused only after 30 s and 3.2 GB of parsing.
// The file's size alone tells: this one is not even valid JSON, and is refused for its
// size (exit 2), not parsed (a parse would end in a scene error, exit 3).
TEST_F(MemoryEstimateTest, ASceneFileTooLargeForTheLimitIsRefusedBeforeItIsParsed) {
    {
        std::ofstream out(dir_ / "huge.json", std::ios::binary);
        out << "[" << std::string(8 << 20, ' ');
    }
    const auto r =
        run_octray({"render", "huge.json", "--max-memory", "64M", "-o", "h.exr"}, dir_);
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("huge.json: loading this 8388609-byte scene file needs about"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("(--max-memory 64M)"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "h.exr"));
}

}  // namespace
