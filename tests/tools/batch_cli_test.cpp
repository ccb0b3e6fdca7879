// `octray render` as a batch renderer, end to end: animations and frame lists, a frame
// rendered alone equal to the same frame of a sequence, shards run concurrently as array
// tasks would, resume after a kill, Ctrl-C, crop + assemble, progress formats,
// progressive passes, per-frame attributes, failures that let the rest go on, and bad
// input. Every image comparison is bit for bit.

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfOutputFile.h>
#include <ImfRationalAttribute.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/sha256.h"
#include "render/batch/claim_owner.h"
#include "render/image_read.h"
#include "run_octray.h"

namespace octray {
namespace {

namespace fs = std::filesystem;
using testing::run_octray;
using testing::shell_quote;

// A ball rolling over a checkered floor while the camera moves: 6 frames at 24 fps.
constexpr const char* kAnimatedScene = R"({
  "image": {"width": 40, "height": 30},
  "camera": {"type": "pinhole", "eye": [0, 1.5, 5], "lookat": [0, 0.5, 0], "fov": 50},
  "background": {"type": "gradient", "bottom": [0.8, 0.85, 1.0], "top": [0.2, 0.4, 0.8]},
  "materials": {
    "floor": {"color": [0.8, 0.2, 0.1], "checker": {"color": [0.9, 0.9, 0.2], "size": 1}},
    "ball": {"color": [0.2, 0.6, 0.9], "ks": 0.4, "reflect": 0.3}
  },
  "objects": [
    {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "floor"},
    {"type": "sphere", "name": "ball", "center": [-1, 0.5, 0], "radius": 0.5, "material": "ball"}
  ],
  "lights": [{"type": "point", "position": [3, 6, 4]}],
  "animation": {"frames": 6, "fps": 24,
    "camera": [{"frame": 0, "eye": [0, 1.5, 5]}, {"frame": 5, "eye": [1, 2, 4.5]}],
    "objects": {"ball": [{"frame": 0, "center": [-1, 0.5, 0]}, {"frame": 5, "center": [1, 0.5, 0]}]}}
})";

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

class BatchCliTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = fs::path(OCTRAY_TEST_TMPDIR) / "batch" /
               ::testing::UnitTest::GetInstance()->current_test_info()->name();
        fs::remove_all(dir_);
        fs::create_directories(dir_ / "out");
        std::ofstream(dir_ / "shot.json") << kAnimatedScene;
    }

    // Every file in `sub`, by name.
    std::set<std::string> files_in(const std::string& sub) const {
        std::set<std::string> names;
        for (const auto& entry : fs::directory_iterator(dir_ / sub))
            names.insert(entry.path().filename().string());
        return names;
    }

    // Hidden temporaries the atomic writer uses (".<name>.tmp.*").
    std::vector<std::string> temporaries(const std::string& sub) const {
        std::vector<std::string> found;
        for (const auto& name : files_in(sub))
            if (contains(name, ".tmp.")) found.push_back(name);
        return found;
    }

    ChannelImage read(const std::string& name) const {
        return read_image((dir_ / name).string());
    }

    // Runs a shell command line in the test directory; returns its exit status.
    int shell(const std::string& command) const {
        const std::string line = "cd " + shell_quote(dir_.string()) + " || exit 99; " + command;
        const int status = std::system(line.c_str());
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }

    fs::path dir_;
};

void expect_same_pixels(const ChannelImage& a, const ChannelImage& b, const std::string& what) {
    ASSERT_EQ(a.width, b.width) << what;
    ASSERT_EQ(a.height, b.height) << what;
    ASSERT_EQ(a.channel_names, b.channel_names) << what;
    EXPECT_TRUE(a.planes == b.planes) << what << ": pixels differ";
}

TEST_F(BatchCliTest, FrameRenderedAloneEqualsTheSameFrameOfTheSequence) {
    const auto all = run_octray(
        {"render", "shot.json", "-o", "out/shot.####.exr", "--progress", "lines"}, dir_);
    ASSERT_EQ(all.status, 0) << all.output;
    EXPECT_EQ(files_in("out"),
              (std::set<std::string>{"shot.0000.exr", "shot.0001.exr", "shot.0002.exr",
                                     "shot.0003.exr", "shot.0004.exr", "shot.0005.exr"}));
    const auto alone = run_octray({"render", "shot.json", "--frames", "3", "-o",
                                   "alone.{frame:04d}.exr", "--path", "scalar"},
                                  dir_);
    ASSERT_EQ(alone.status, 0) << alone.output;
    expect_same_pixels(read("out/shot.0003.exr"), read("alone.0003.exr"), "frame 3");
    // The animation moves things: frames differ.
    EXPECT_FALSE(read("out/shot.0000.exr").planes == read("out/shot.0005.exr").planes);
}

TEST_F(BatchCliTest, FrameSpecsPickTheFramesInOrder) {
    const auto r = run_octray({"render", "shot.json", "--frames", "0-4:2,5", "-o", "out/f#.exr",
                               "--progress", "json"},
                              dir_);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(files_in("out"), (std::set<std::string>{"f0.exr", "f2.exr", "f4.exr", "f5.exr"}));
    std::vector<int> order;
    std::istringstream lines(r.output);
    int summaries = 0;
    for (std::string line; std::getline(lines, line);) {
        const auto event = nlohmann::json::parse(line);  // every line is JSON
        if (event["event"] == "frame") order.push_back(event["frame"].get<int>());
        if (event["event"] == "summary") {
            ++summaries;
            EXPECT_EQ(event["rendered"], 4);
            EXPECT_EQ(event["failed"], 0);
        }
    }
    EXPECT_EQ(order, (std::vector<int>{0, 2, 4, 5}));
    EXPECT_EQ(summaries, 1);
}

// Issue 26: the frame line and the summary report trace time and rate apart from write time
// (EXR/PNG encoding), and `Progress: 100%` always follows the last frame's line.
TEST_F(BatchCliTest, FrameLinesReportTraceAndWriteTimesInAFixedOrder) {
    const std::regex frame_line(
        R"(frame [1-3]/3  shot frame [0-2]  -> out/t\.[0-2]\.exr \+ out/t\.[0-2]\.png  )"
        R"(trace [0-9]+\.[0-9]{3} s  [0-9]+\.[0-9]{2} Mrays/s  write [0-9]+\.[0-9]{3} s)");
    const std::regex summary(R"(done: 3 frames: 3 rendered, 0 skipped, 0 failed in \S+: )"
                             R"(trace \S+ \([0-9]+\.[0-9]{2} Mrays/s\), write \S+)");
    for (int run = 0; run < 4; ++run) {
        const auto r = run_octray(
            {"render", "shot.json", "--frames", "0-2", "--width", "64", "--height", "48", "-o",
             "out/t.#.exr", "--png", "out/t.#.png", "--progress", "lines"},
            dir_, /*capture_stderr=*/false);
        ASSERT_EQ(r.status, 0) << r.output;
        std::vector<std::string> lines;
        std::istringstream in(r.output);
        for (std::string line; std::getline(in, line);) lines.push_back(line);
        ASSERT_GE(lines.size(), 3u) << r.output;
        int frames = 0, hundreds = 0;
        for (const std::string& line : lines) {
            if (line.rfind("frame ", 0) == 0) {
                ++frames;
                EXPECT_TRUE(std::regex_match(line, frame_line)) << line;
            }
            hundreds += line == "Progress: 100%" ? 1 : 0;
        }
        EXPECT_EQ(frames, 3) << r.output;
        EXPECT_EQ(hundreds, 1) << r.output;
        const std::size_t n = lines.size();
        EXPECT_EQ(lines[n - 3].rfind("frame 3/3 ", 0), 0u) << r.output;
        EXPECT_EQ(lines[n - 2], "Progress: 100%") << r.output;
        EXPECT_TRUE(std::regex_match(lines[n - 1], summary)) << lines[n - 1];
    }

    // --progress json: the same figures as numbers; trace and write fit in the frame's time.
    const auto r = run_octray({"render", "shot.json", "--frames", "0", "--width", "64",
                               "--height", "48", "-o", "out/j.#.exr", "--progress", "json"},
                              dir_, false);
    ASSERT_EQ(r.status, 0) << r.output;
    std::istringstream in(r.output);
    int checked = 0;
    for (std::string line; std::getline(in, line);) {
        const auto event = nlohmann::json::parse(line);
        if (event["event"] == "progress") continue;
        for (const char* key :
             {"trace_seconds", "write_seconds", "seconds", "mrays_per_second"})
            ASSERT_TRUE(event.contains(key)) << key << "\n" << line;
        EXPECT_GT(event["trace_seconds"].get<double>(), 0.0) << line;
        EXPECT_GT(event["write_seconds"].get<double>(), 0.0) << line;
        EXPECT_LE(event["trace_seconds"].get<double>() + event["write_seconds"].get<double>(),
                  event["seconds"].get<double>() + 1e-3)
            << line;
        if (event["event"] == "frame") {
            // The phases of --stats: compile, BVH and render within the trace time; the
            // write time the frame's own.
            const nlohmann::json& phases = event.at("phases");
            double traced = 0.0;
            for (const char* key : {"compile_seconds", "bvh_seconds", "render_seconds"}) {
                ASSERT_TRUE(phases.at(key).is_number()) << key << "\n" << line;
                EXPECT_GE(phases[key].get<double>(), 0.0) << key;
                traced += phases[key].get<double>();
            }
            EXPECT_GT(phases["render_seconds"].get<double>(), 0.0) << line;
            EXPECT_LE(traced, event["trace_seconds"].get<double>() + 1e-3) << line;
            EXPECT_GT(phases.at("load_seconds").get<double>(), 0.0) << line;
            EXPECT_EQ(phases.at("write_seconds"), event["write_seconds"]) << line;
        }
        ++checked;
    }
    EXPECT_EQ(checked, 2) << r.output;  // the frame and the summary
}

TEST_F(BatchCliTest, OnATerminalAutoProgressIsALiveBar) {
    // `script` gives octray a pseudo-terminal, as a user's shell would.
    if (shell("command -v script >/dev/null") != 0) GTEST_SKIP() << "no script(1) here";
    const int status = shell("script -qec " +
                             shell_quote(shell_quote(OCTRAY_EXE) +
                                         " render shot.json --frames 0-2 -o 'out/b.#.exr'") +
                             " /dev/null > tty.txt 2>&1 </dev/null");
    ASSERT_EQ(status, 0);
    std::ifstream tty_file(dir_ / "tty.txt", std::ios::binary);
    const std::string tty((std::istreambuf_iterator<char>(tty_file)), {});
    EXPECT_TRUE(contains(tty, "\r\033[K[")) << tty;  // redrawn in place
    EXPECT_TRUE(contains(tty, "] 100%  frame 3/3")) << tty;
    EXPECT_TRUE(contains(tty, "ETA")) << tty;
    EXPECT_TRUE(contains(tty, "Mrays/s")) << tty;
    EXPECT_TRUE(contains(tty, "done: 3 frames: 3 rendered")) << tty;
    EXPECT_FALSE(contains(tty, "Progress: ")) << "lines mode on a terminal\n" << tty;
}

TEST_F(BatchCliTest, ConcurrentSlurmShardsRenderEachFrameOnceAndMatchOneProcess) {
    // The directory does not exist yet: render creates it (issue 26; it used to refuse).
    ASSERT_EQ(run_octray({"render", "shot.json", "-o", "single/s.####.exr"}, dir_).status, 0);

    // Three array tasks (ids 1..3, as `sbatch --array=1-3` numbers them) at once, sharing
    // one output directory, each claiming frames with placeholders.
    std::string command;
    for (int task = 1; task <= 3; ++task) {
        command += "SLURM_ARRAY_TASK_ID=" + std::to_string(task) +
                   " SLURM_ARRAY_TASK_MIN=1 SLURM_ARRAY_TASK_COUNT=3 " +
                   shell_quote(OCTRAY_EXE) +
                   " render shot.json --shard auto --placeholders --progress lines -o "
                   "out/s.####.exr > log" +
                   std::to_string(task) + ".txt 2>&1 </dev/null & ";
    }
    command += "wait";
    ASSERT_EQ(shell(command), 0);

    std::map<std::string, int> renders;  // frame file -> how many runs rendered it
    for (int task = 1; task <= 3; ++task) {
        std::ifstream log(dir_ / ("log" + std::to_string(task) + ".txt"));
        for (std::string line; std::getline(log, line);) {
            const auto arrow = line.find("-> out/");
            if (arrow != std::string::npos && contains(line, "Mrays/s"))
                ++renders[line.substr(arrow + 3, line.find(' ', arrow + 3) - (arrow + 3))];
        }
    }
    ASSERT_EQ(renders.size(), 6u);
    for (const auto& [file, count] : renders) EXPECT_EQ(count, 1) << file;
    for (int f = 0; f < 6; ++f) {
        const std::string name = "s.000" + std::to_string(f) + ".exr";
        expect_same_pixels(read("out/" + name), read("single/" + name), name);
    }
    EXPECT_TRUE(temporaries("out").empty());
}

TEST_F(BatchCliTest, KubernetesIndexNeedsAShardCount) {
    const auto r =
        run_octray({"render", "shot.json", "--shard", "auto", "-o", "out/k.#.exr"}, dir_);
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "SLURM_ARRAY_TASK_ID")) << r.output;
    const int status = shell("JOB_COMPLETION_INDEX=1 " + shell_quote(OCTRAY_EXE) +
                             " render shot.json --shard auto --shard-count 2 -o out/k.#.exr "
                             ">log.txt 2>&1 </dev/null");
    EXPECT_EQ(status, 0);
    EXPECT_EQ(files_in("out"), (std::set<std::string>{"k.1.exr", "k.3.exr", "k.5.exr"}));
}

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
    EXPECT_TRUE(temporaries("out").empty());
    EXPECT_TRUE(fs::file_size(dir_ / "out/i.00.exr") > 0);
    EXPECT_LT(files_in("out").size(), 6u);
}

TEST_F(BatchCliTest, CropsAssembleIntoTheFullFrameBitForBit) {
    ASSERT_EQ(run_octray({"render", "shot.json", "--frames", "2", "-o", "full.exr", "--aov",
                          "depth,id"},
                         dir_)
                  .status,
              0);
    const char* crops[] = {"0,0,17,11", "17,0,40,11", "0,11,40,30"};
    std::vector<std::string> args = {"assemble"};
    for (int i = 0; i < 3; ++i) {
        const std::string part = "part" + std::to_string(i) + ".exr";
        const auto r = run_octray({"render", "shot.json", "--frames", "2", "--crop", crops[i],
                                   "-o", part, "--aov", "depth,id"},
                                  dir_);
        ASSERT_EQ(r.status, 0) << r.output;
        args.push_back(part);
    }
    args.insert(args.end(), {"-o", "assembled.exr"});
    const auto assembled = run_octray(args, dir_);
    ASSERT_EQ(assembled.status, 0) << assembled.output;
    expect_same_pixels(read("assembled.exr"), read("full.exr"), "assembled");

    const auto outside = run_octray({"render", "shot.json", "--crop", "0,0,41,30"}, dir_);
    EXPECT_EQ(outside.status, 2) << outside.output;
}

TEST_F(BatchCliTest, ProgressiveFinalImageEqualsThePlainRender) {
    ASSERT_EQ(
        run_octray({"render", "shot.json", "--frames", "1", "--spp", "5", "-o", "plain.exr"},
                   dir_)
            .status,
        0);
    const auto r = run_octray({"render", "shot.json", "--frames", "1", "--spp", "5",
                               "--progressive", "-o", "passes.exr"},
                              dir_);
    ASSERT_EQ(r.status, 0) << r.output;
    expect_same_pixels(read("passes.exr"), read("plain.exr"), "progressive");
    Imf::InputFile file((dir_ / "passes.exr").c_str());
    EXPECT_EQ(file.header().findTypedAttribute<Imf::IntAttribute>("octray.samplesSoFar"),
              nullptr)
        << "the final image is marked unfinished";
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
            EXPECT_EQ(read(name).width, 40) << option << " " << name;
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

TEST_F(BatchCliTest, EveryFrameCarriesItsAttributes) {
    ASSERT_EQ(run_octray({"render", "shot.json", "--frames", "4", "-o", "a.exr"}, dir_).status,
              0);
    Imf::InputFile file((dir_ / "a.exr").c_str());
    const Imf::Header& h = file.header();
    ASSERT_NE(h.findTypedAttribute<Imf::IntAttribute>("octray.frame"), nullptr);
    EXPECT_EQ(h.typedAttribute<Imf::IntAttribute>("octray.frame").value(), 4);
    ASSERT_TRUE(Imf::hasFramesPerSecond(h));
    EXPECT_EQ(Imf::framesPerSecond(h), Imf::Rational(24, 1));
    EXPECT_TRUE(Imf::hasWorldToCamera(h));
    EXPECT_TRUE(Imf::hasWorldToNDC(h));
    std::ifstream scene_file(dir_ / "shot.json", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(scene_file)), {});
    ASSERT_NE(h.findTypedAttribute<Imf::StringAttribute>("octray.sceneSha256"), nullptr);
    EXPECT_EQ(h.typedAttribute<Imf::StringAttribute>("octray.sceneSha256").value(),
              sha256_hex(bytes));
}

// A built-in is identified by its spec string as given: hashing it is free, where the JSON
// of random:1048576 took seconds to write and hash.
TEST_F(BatchCliTest, ABuiltInsDigestIsItsSpecString) {
    const std::string spec = "random:4,width=16,height=12,seed=3";
    ASSERT_EQ(run_octray({"render", spec, "-o", "b.exr"}, dir_).status, 0);
    Imf::InputFile file((dir_ / "b.exr").c_str());
    const auto* digest =
        file.header().findTypedAttribute<Imf::StringAttribute>("octray.sceneSha256");
    ASSERT_NE(digest, nullptr);
    EXPECT_EQ(digest->value(), sha256_hex(spec));
}

// --stats: one line per frame with the seconds of each phase (issue 19).
TEST_F(BatchCliTest, StatsPrintEachPhaseOfEachFrame) {
    const auto r =
        run_octray({"render", "shot.json", "--frames", "0,1", "--stats", "-o", "s#.exr"}, dir_,
                   /*with_stderr=*/true);
    ASSERT_EQ(r.status, 0) << r.output;
    for (const char* frame : {"stats: shot frame 0: load ", "stats: shot frame 1: load "})
        EXPECT_TRUE(contains(r.output, frame)) << r.output;
    for (const char* phase : {" s, compile ", " s, BVH ", " s, render ", " s, write "})
        EXPECT_TRUE(contains(r.output, phase)) << r.output;
}

TEST_F(BatchCliTest, SeveralScenesNeedSceneInThePattern) {
    const auto clash = run_octray(
        {"render", "shot.json", "random:4,width=16,height=12", "-o", "out/x.exr"}, dir_);
    EXPECT_EQ(clash.status, 2) << clash.output;
    const auto r = run_octray({"render", "shot.json", "random:4,width=16,height=12", "--frames",
                               "0-1", "-o", "out/{scene}.#.exr"},
                              dir_);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(files_in("out"), (std::set<std::string>{"shot.0.exr", "shot.1.exr",
                                                      "random-4.0.exr", "random-4.1.exr"}));
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
}  // namespace octray
