// `octray render` as a batch renderer, end to end, when runs are stopped, share frames or
// fail: resume after a kill, temporaries of live and dead writers, Ctrl-C, claims
// (placeholders and unfinished progressive passes), failed frames that let the rest go
// on, and bad input. The fixture: batch_cli_fixture.h.

#include <gtest/gtest.h>

#include "batch_cli_fixture.h"

namespace octray::testing {
namespace {

TEST_F(BatchCliTest, ResumeAfterAKillFinishesTheRestAndLeavesNoTemporaries) {
    // Slow enough frames (scalar path, one thread) that the kill lands mid-sequence.
    const std::string render =
        shell_quote(OCTRAY_EXE) +
        " render shot.json --width 320 --height 240 --spp 16 --path scalar"
        " --threads 1 --progress none -o out/r.##.exr";
    const int status = shell(
        render +
        " >/dev/null 2>&1 </dev/null & pid=$!; "
        "i=0; while [ ! -s out/r.00.exr ] && [ $i -lt 6000 ]; do sleep 0.01; i=$((i+1)); done; "
        "kill -9 $pid; wait $pid; exit 0");
    ASSERT_EQ(status, 0);
    const std::size_t after_kill = files_in("out").size() - temporaries("out").size();
    EXPECT_LT(after_kill, 6u) << "the kill came too late to test a resume";

    const auto resumed =
        run_octray({"render", "shot.json", "--width", "320", "--height", "240", "--spp", "16",
                    "--skip-existing", "-o", "out/r.##.exr", "--progress", "lines"},
                   dir_);
    ASSERT_EQ(resumed.status, 0) << resumed.output;
    EXPECT_TRUE(contains(resumed.output, "skipped (exists)")) << resumed.output;
    EXPECT_TRUE(temporaries("out").empty());
    ASSERT_EQ(files_in("out").size(), 6u);
    // Resumed frames equal a fresh render (the simd path resumed a scalar run: same images).
    const auto fresh = run_octray({"render", "shot.json", "--width", "320", "--height", "240",
                                   "--spp", "16", "--frames", "5", "-o", "fresh.exr"},
                                  dir_);
    ASSERT_EQ(fresh.status, 0) << fresh.output;
    expect_same_pixels(read("out/r.05.exr"), read("fresh.exr"), "frame 5");
}

// A run removed every ".<name>.tmp.*" next to a frame it rendered, also the temporary a
// live run was writing (which then failed with exit 4). A writer holds a lock on its
// temporary; only one whose lock is free (its writer is gone) is stale.
TEST_F(BatchCliTest, ALiveWritersTemporaryIsLeftAlone) {
    // This process plays the live writer: it holds the lock, as write_file_atomically does.
    const fs::path live = dir_ / "out/.t.0.exr.tmp.1.00000000000000aa";
    const fs::path stale = dir_ / "out/.t.0.exr.tmp.1.00000000000000bb";
    std::ofstream(live) << "half-written by a live run";
    std::ofstream(stale) << "left by a killed run";
    const int fd = ::open(live.c_str(), O_RDWR | O_CLOEXEC);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::flock(fd, LOCK_EX), 0);
    const auto r =
        run_octray({"render", "shot.json", "--frames", "0", "-o", "out/t.#.exr"}, dir_);
    ::close(fd);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(fs::exists(live)) << "a live run's temporary was removed";
    EXPECT_FALSE(fs::exists(stale)) << "a stale temporary stayed";
    EXPECT_TRUE(fs::exists(dir_ / "out/t.0.exr"));
}

TEST_F(BatchCliTest, InterruptStopsCleanlyWithASummary) {
    const int status = shell(
        shell_quote(OCTRAY_EXE) +
        " render shot.json --width 320 --height 240 --spp 16 --path scalar"
        " --threads 1 --progress lines -o out/i.##.exr >log.txt 2>&1 "
        "</dev/null & pid=$!; "
        "i=0; while [ ! -s out/i.00.exr ] && [ $i -lt 6000 ]; do sleep 0.01; i=$((i+1)); done; "
        "kill -INT $pid; wait $pid; echo $? > status.txt; exit 0");
    ASSERT_EQ(status, 0);
    std::ifstream status_file(dir_ / "status.txt");
    int exit_status = -1;
    status_file >> exit_status;
    EXPECT_EQ(exit_status, 130);
    std::ifstream log_file(dir_ / "log.txt");
    const std::string log((std::istreambuf_iterator<char>(log_file)), {});
    EXPECT_TRUE(contains(log, "interrupted")) << log;
    EXPECT_TRUE(contains(log, "not started")) << log;
    EXPECT_TRUE(contains(log, "resume with --skip-existing")) << log;
    EXPECT_TRUE(temporaries("out").empty());
    EXPECT_TRUE(fs::file_size(dir_ / "out/i.00.exr") > 0);
    EXPECT_LT(files_in("out").size(), 6u);
}

// A 40x30 image as an unfinished --progressive pass leaves it: octray.samplesSoFar, and
// the run that writes it as octray.owner ("" for none, as older octrays wrote it).
void write_unfinished_pass(const fs::path& path, const std::string& owner) {
    Imf::Header header(40, 30);
    header.insert("octray.samplesSoFar", Imf::IntAttribute(1));
    if (!owner.empty()) header.insert("octray.owner", Imf::StringAttribute(owner));
    header.channels().insert("R", Imf::Channel(Imf::FLOAT));
    std::vector<float> pixels(40 * 30, 0.5f);
    Imf::FrameBuffer frame_buffer;
    frame_buffer.insert("R", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(pixels.data()),
                                        sizeof(float), 40 * sizeof(float)));
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frame_buffer);
    file.writePixels(30);
}

std::string owner_of(const fs::path& path) {
    Imf::InputFile file(path.c_str());
    const auto* owner = file.header().findTypedAttribute<Imf::StringAttribute>("octray.owner");
    return owner != nullptr ? owner->value() : std::string();
}

bool unfinished(const fs::path& path) {
    Imf::InputFile file(path.c_str());
    return file.header().findTypedAttribute<Imf::IntAttribute>("octray.samplesSoFar") !=
           nullptr;
}

// An unfinished progressive image is a claim held by the run writing it: other runs
// rendered over it. It is rendered over only when its owner is provably gone (it ran on
// this host and its process is not there any more).
TEST_F(BatchCliTest, AnUnfinishedPassIsAClaimWhileItsOwnerLives) {
    char host[256] = {};
    ASSERT_EQ(::gethostname(host, sizeof host - 1), 0);
    const pid_t child = ::fork();
    if (child == 0) ::_exit(0);
    ASSERT_GT(child, 0);
    ASSERT_EQ(::waitpid(child, nullptr, 0), child);  // reaped: its PID names no process
    const std::string live = batch::current_owner();
    write_unfinished_pass(dir_ / "out/u.0.exr", live);
    write_unfinished_pass(dir_ / "out/u.1.exr",
                          std::string(host) + ":" + std::to_string(child) + ":12345");
    write_unfinished_pass(dir_ / "out/u.2.exr", "another-host.invalid:1:1");
    write_unfinished_pass(dir_ / "out/u.3.exr", "");
    for (const std::string option : {"--placeholders", "--skip-existing"}) {
        const auto r =
            run_octray({"render", "shot.json", "--frames", "0-3", "--spp", "2", "--progressive",
                        option, "-o", "out/u.#.exr", "--progress", "lines"},
                       dir_);
        ASSERT_EQ(r.status, 0) << option << "\n" << r.output;
        EXPECT_TRUE(contains(r.output, "-> out/u.0.exr  skipped (claimed by another run)"))
            << option << "\n"
            << r.output;
        EXPECT_TRUE(contains(r.output, "-> out/u.2.exr  skipped (claimed by another run)"))
            << option << "\n"
            << r.output;
        EXPECT_EQ(owner_of(dir_ / "out/u.0.exr"), live) << option;
        EXPECT_TRUE(unfinished(dir_ / "out/u.2.exr")) << option;
        for (const int f : {1, 3}) {
            const std::string name = "out/u." + std::to_string(f) + ".exr";
            EXPECT_TRUE(contains(r.output, "-> " + name + "  ")) << option << "\n" << r.output;
            EXPECT_FALSE(unfinished(dir_ / name)) << option << " " << name;
            EXPECT_EQ(read(name).width(), 40) << option << " " << name;
        }
        write_unfinished_pass(dir_ / "out/u.1.exr",
                              std::string(host) + ":" + std::to_string(child) + ":12345");
        write_unfinished_pass(dir_ / "out/u.3.exr", "");
    }
    EXPECT_TRUE(temporaries("out").empty());
}

// The same with real runs: a progressive run stopped after its first pass still holds
// its frame (another run skips it); killed, it does not (another run renders it).
TEST_F(BatchCliTest, AStoppedProgressiveRunKeepsItsFrameAndAKilledOneReleasesIt) {
    const std::string octray = shell_quote(OCTRAY_EXE);
    const int status = shell(
        octray +
        " render shot.json --frames 0 --width 160 --height 120 --spp 4096 --path scalar"
        " --threads 1 --progressive --placeholders --progress none -o out/s.exr"
        " >/dev/null 2>&1 </dev/null & pid=$!; echo $pid > pid.txt; "
        "i=0; while [ ! -s out/s.exr ] && [ $i -lt 6000 ]; do sleep 0.01; i=$((i+1)); done; "
        "kill -STOP $pid; cp out/s.exr first-pass.exr; " +
        octray +
        " render shot.json --frames 0 --spp 2 --progressive --placeholders --skip-existing"
        " --progress lines -o out/s.exr >second.txt 2>&1 </dev/null; echo $? >> second.txt; "
        "kill -KILL $pid; wait $pid; " +
        octray +
        " render shot.json --frames 0 --spp 2 --progressive --placeholders --skip-existing"
        " --progress lines -o out/s.exr >third.txt 2>&1 </dev/null; echo $? >> third.txt");
    ASSERT_EQ(status, 0);
    std::ifstream pid_file(dir_ / "pid.txt");
    std::string pid;
    pid_file >> pid;
    ASSERT_TRUE(unfinished(dir_ / "first-pass.exr")) << "the first pass came too late";
    const std::string owner = owner_of(dir_ / "first-pass.exr");
    EXPECT_TRUE(contains(owner, ":" + pid + ":")) << owner << " is not process " << pid;
    std::ifstream second_file(dir_ / "second.txt"), third_file(dir_ / "third.txt");
    const std::string second((std::istreambuf_iterator<char>(second_file)), {});
    const std::string third((std::istreambuf_iterator<char>(third_file)), {});
    EXPECT_TRUE(contains(second, "skipped (claimed by another run)")) << second;
    EXPECT_TRUE(contains(second, "\n0\n")) << second;
    EXPECT_TRUE(contains(third, "1 rendered")) << third;
    EXPECT_TRUE(contains(third, "\n0\n")) << third;
    EXPECT_FALSE(unfinished(dir_ / "out/s.exr"));
    EXPECT_TRUE(temporaries("out").empty());
}

TEST_F(BatchCliTest, AFailedFrameIsReportedAndTheRestGoOn) {
    // Frame 3's output path is taken by a directory: an I/O failure, worth retrying.
    fs::create_directories(dir_ / "out/g.3.exr/inside");
    const auto r =
        run_octray({"render", "shot.json", "-o", "out/g.#.exr", "--progress", "lines"}, dir_);
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, "FAILED")) << r.output;
    EXPECT_TRUE(contains(r.output, "5 rendered")) << r.output;
    EXPECT_TRUE(contains(r.output, "1 failed")) << r.output;
    for (int f : {0, 1, 2, 4, 5})
        EXPECT_TRUE(fs::exists(dir_ / ("out/g." + std::to_string(f) + ".exr")));
    EXPECT_TRUE(temporaries("out").empty());
}

// A frame is finished only when all its outputs exist: after a full disk kept the EXR but
// not the preview, the documented retry (--skip-existing) must write the preview.
TEST_F(BatchCliTest, AMissingPreviewMakesTheFrameRenderAgain) {
    const auto first = run_octray(
        {"render", "shot.json", "--frames", "0-1", "-o", "out/p.#.exr", "--png", "out/p.#.png"},
        dir_);
    ASSERT_EQ(first.status, 0) << first.output;
    fs::remove(dir_ / "out/p.1.png");
    const auto retry =
        run_octray({"render", "shot.json", "--frames", "0-1", "-o", "out/p.#.exr", "--png",
                    "out/p.#.png", "--skip-existing", "--progress", "lines"},
                   dir_);
    ASSERT_EQ(retry.status, 0) << retry.output;
    EXPECT_TRUE(contains(retry.output, "-> out/p.0.exr  skipped (exists)")) << retry.output;
    EXPECT_TRUE(contains(retry.output, "-> out/p.1.exr + out/p.1.png")) << retry.output;
    EXPECT_TRUE(fs::exists(dir_ / "out/p.1.png"));

    // Runs sharing the directory claim the missing preview, not the finished EXR.
    fs::remove(dir_ / "out/p.0.png");
    const auto claimed =
        run_octray({"render", "shot.json", "--frames", "0-1", "-o", "out/p.#.exr", "--png",
                    "out/p.#.png", "--placeholders", "--progress", "lines"},
                   dir_);
    ASSERT_EQ(claimed.status, 0) << claimed.output;
    EXPECT_TRUE(contains(claimed.output, "-> out/p.0.exr + out/p.0.png")) << claimed.output;
    EXPECT_TRUE(contains(claimed.output, "-> out/p.1.exr  skipped (exists)")) << claimed.output;
    ASSERT_TRUE(fs::exists(dir_ / "out/p.0.png"));
    EXPECT_GT(fs::file_size(dir_ / "out/p.0.png"), 0u);
    EXPECT_TRUE(temporaries("out").empty());
}

// A directory where an output goes is neither a finished frame nor a claim, and is found
// before the frame renders (the EXR of a frame whose preview path is a directory is not
// written at all).
TEST_F(BatchCliTest, ADirectoryAtAnOutputPathFailsTheFrameBeforeItRenders) {
    fs::create_directories(dir_ / "out/d.3.exr");
    for (const std::string option : {"--skip-existing", "--placeholders"}) {
        const auto r = run_octray(
            {"render", "shot.json", "-o", "out/d.#.exr", option, "--progress", "lines"}, dir_);
        EXPECT_EQ(r.status, 4) << option << "\n" << r.output;
        EXPECT_TRUE(contains(r.output,
                             "cannot write out/d.3.exr: it is a directory; expected "
                             "an image file (or nothing) there"))
            << option << "\n"
            << r.output;
        EXPECT_TRUE(contains(r.output, "1 failed")) << option << "\n" << r.output;
    }
    EXPECT_TRUE(fs::is_directory(dir_ / "out/d.3.exr"));

    fs::create_directories(dir_ / "out/e.3.png");
    const auto r = run_octray({"render", "shot.json", "-o", "out/e.#.exr", "--png",
                               "out/e.#.png", "--progress", "lines"},
                              dir_);
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, "cannot write out/e.3.png: it is a directory")) << r.output;
    EXPECT_TRUE(contains(r.output, "5 rendered")) << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "out/e.3.exr")) << "frame 3 was rendered before failing";
    EXPECT_TRUE(temporaries("out").empty());
}

TEST_F(BatchCliTest, BadInputIsAClearErrorAndLeavesNothing) {
    struct Case {
        std::vector<std::string> args;
        int status;
        std::string mentions;
    };
    const std::vector<Case> cases = {
        {{"render", "shot.json", "-o", "out/one.exr"}, 2, "frame field"},
        {{"render", "shot.json", "--frames", "5-1", "-o", "out/x#.exr"}, 2, "--frames"},
        {{"render", "shot.json", "--frames", "a-b", "-o", "out/x#.exr"}, 2, "--frames"},
        {{"render", "shot.json", "--frames", "1-3:0", "-o", "out/x#.exr"}, 2, "--frames"},
        {{"render", "shot.json", "--shard", "3/3", "-o", "out/x#.exr"}, 2, "--shard"},
        {{"render", "shot.json", "--crop", "5,5,2,2", "-o", "out/x#.exr"}, 2, "--crop"},
        {{"render", "shot.json", "--aov", "depth,color", "-o", "out/x#.exr"}, 2, "--aov"},
        {{"render", "shot.json", "--max-memory", "1K", "-o", "out/x#.exr"}, 2, "max-memory"},
        {{"render", "shot.json", "--max-memory", "lots", "-o", "out/x#.exr"},
         2,
         "--max-memory: expected a size such as 512M, 4G or 1T, not lots"},
        {{"view", "shot.json", "--max-memory", "lots", "--bench", "1"},
         2,
         "--max-memory: expected a size such as 512M, 4G or 1T, not lots"},
        {{"render", "shot.json", "-o", "shot.json/x#.exr"}, 4, "shot.json"},
        {{"render", "shot.json", "-o", "out/x{frame:q}.exr"}, 2, "{frame:q}"},
    };
    for (const Case& c : cases) {
        std::string joined;
        for (const auto& a : c.args) joined += a + " ";
        const auto r = run_octray(c.args, dir_);
        EXPECT_EQ(r.status, c.status) << joined << "\n" << r.output;
        EXPECT_TRUE(contains(r.output, c.mentions)) << joined << "\n" << r.output;
    }
    EXPECT_TRUE(files_in("out").empty());
    if (::geteuid() != 0) {  // root writes into any directory
        fs::create_directories(dir_ / "locked");
        fs::permissions(dir_ / "locked", fs::perms::owner_read | fs::perms::owner_exec);
        const auto r = run_octray({"render", "shot.json", "-o", "locked/x#.exr"}, dir_);
        fs::permissions(dir_ / "locked", fs::perms::owner_all);
        EXPECT_EQ(r.status, 4) << r.output;
        EXPECT_TRUE(contains(r.output, "not writable")) << r.output;
    }
}

TEST_F(BatchCliTest, FileSizeLimitHitMidWriteLeavesNothingPartial) {
    // `ulimit -f 8`: 8 blocks of 512 bytes; an uncompressed float frame is far larger.
    const int status = shell("ulimit -f 8; " + shell_quote(OCTRAY_EXE) +
                             " render shot.json --frames 0 --width 160 --height 120 --float"
                             " --compression none -o out/big.exr >log.txt 2>&1 </dev/null");
    EXPECT_EQ(status, 4);
    std::ifstream log_file(dir_ / "log.txt");
    const std::string log((std::istreambuf_iterator<char>(log_file)), {});
    EXPECT_TRUE(contains(log, "out/big.exr")) << log;
    EXPECT_TRUE(files_in("out").empty()) << "a partial file or temporary was left";
}

}  // namespace
}  // namespace octray::testing
