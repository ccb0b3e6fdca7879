// The frame loop (render/batch/frame_loop.h) in process, through a recording observer:
// every frame reported once with its outcome, resume (a finished frame skipped and left
// as it was), a claim held by another run (an empty placeholder, an unfinished pass of a
// live run), a failing frame (reported, the others go on), and cancel (the frame in
// progress abandoned, nothing half-written, its claim released, stale temporaries gone).

#include "render/batch/frame_loop.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <atomic>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include "kernels/dispatch.h"
#include "render/aov.h"
#include "render/batch/camera_matrices.h"
#include "render/batch/claim_owner.h"
#include "render/batch/observer.h"
#include "render/batch/plan.h"
#include "render/image/image_read.h"
#include "render/packet_renderer.h"
#include "scene/animation.h"

namespace octray::batch {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 24, kHeight = 16;

// Everything the loop reports, in order.
class RecordingObserver : public BatchObserver {
  public:
    struct Started {
        std::size_t index;
        std::string scene;
        int frame;
        std::uint64_t work;
        int spp;
    };

    void run_started(const RunStart& start) override {
        ++runs_started;
        jobs_at_start = start.jobs.size();
        total_work = start.total_work;
        path = start.path;
    }
    std::atomic<std::uint64_t>* pixel_counter() override { return &pixels; }
    void frame_started(std::size_t index, const std::string& scene, int frame,
                       std::uint64_t work, int spp) override {
        pixels = 0;
        started.push_back({index, scene, frame, work, spp});
        events.push_back("start " + std::to_string(index));
        if (on_frame_started) on_frame_started(frame);
    }
    void frame_finished(const FrameReport& report, std::uint64_t work) override {
        finished.push_back(report);
        events.push_back("finish " + std::to_string(report.index));
        finished_work.push_back(work);
        pixels_at_finish.push_back(pixels.load());
    }
    void run_finished(const BatchSummary& s) override {
        ++runs_finished;
        summary = s;
    }

    // The outcome of each finished frame, by frame number.
    std::vector<std::pair<int, FrameOutcome>> outcomes() const {
        std::vector<std::pair<int, FrameOutcome>> out;
        for (const FrameReport& r : finished) out.emplace_back(r.frame, r.outcome);
        return out;
    }

    std::function<void(int frame)> on_frame_started;
    int runs_started = 0, runs_finished = 0;
    std::size_t jobs_at_start = 0;
    std::uint64_t total_work = 0;
    std::string path;
    std::atomic<std::uint64_t> pixels{0};
    std::vector<Started> started;
    std::vector<FrameReport> finished;
    std::vector<std::string> events;  // "start 2", "finish 1", ...
    std::vector<std::uint64_t> finished_work, pixels_at_finish;
    BatchSummary summary;
};

class FrameLoopTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = fs::path(OCTRAY_TEST_TMPDIR) / "frame_loop" /
               ::testing::UnitTest::GetInstance()->current_test_info()->name();
        fs::remove_all(dir_);
        fs::create_directories(dir_);
        request_.overrides.width = kWidth;
        request_.overrides.height = kHeight;
        request_.frames = "0-2";
        request_.output = (dir_ / "w.#.exr").string();
        scenes_.push_back(load_batch_input("whitted", request_));
        settings_.render.resolve_isa();
        settings_.render.threads = 2;
    }

    std::vector<BatchJob> jobs() const { return plan_jobs(scenes_, request_); }

    BatchSummary run(RecordingObserver& observer, const std::atomic<bool>* cancel = nullptr) {
        return run_batch(scenes_, jobs(), settings_, observer, cancel);
    }

    fs::path output(int frame) const { return dir_ / ("w." + std::to_string(frame) + ".exr"); }

    // Spheres s0 ... s47 on a grid over a plane (past the 32 spheres from which the simd
    // path builds a BVH), with `animation`, as NAME.json, rendered to PREFIX.#.exr in float.
    static constexpr int kGridSpheres = 48;
    static Vec3 grid_center(int k) {
        return {float(k % 8 - 4), float(k / 8 % 3), float(k / 24 - 1)};
    }
    void load_grid_scene(const std::string& name, const std::string& animation,
                         const std::string& prefix) {
        std::string json = R"({"image": {"width": 24, "height": 16},
            "camera": {"eye": [0, 3, 12], "lookat": [0, 0, 0], "fov": 50},
            "materials": {"m": {"color": [0.8, 0.5, 0.3], "ks": 0.3, "reflect": 0.3}},
            "lights": [{"type": "point", "position": [5, 9, 6], "color": 1}],
            "objects": [{"type": "plane", "point": [0, -2, 0], "normal": [0, 1, 0],
                         "material": "m"})";
        for (int k = 0; k < kGridSpheres; ++k) {
            const Vec3 c = grid_center(k);
            json += R"(, {"type": "sphere", "name": "s)" + std::to_string(k) +
                    R"(", "center": [)" + std::to_string(c.x) + ", " + std::to_string(c.y) +
                    ", " + std::to_string(c.z) + R"(], "radius": 0.4, "material": "m"})";
        }
        json += R"(], "animation": )" + animation + "}";
        const fs::path file = dir_ / (name + ".json");
        std::ofstream(file) << json;
        request_ = BatchRequest{};
        request_.output = (dir_ / (prefix + ".#.exr")).string();
        scenes_ = {load_batch_input(file.string(), request_)};
        settings_.exr.float32 = true;
    }

    // Frames 0 .. frames - 1 of the first scene, written as PREFIX.F.exr, are each the
    // frame rendered on its own (pixels_unlike_alone), bit for bit.
    void expect_frames_as_rendered_alone(const std::string& prefix, int frames) const;

    std::set<std::string> files() const {
        std::set<std::string> names;
        for (const auto& entry : fs::directory_iterator(dir_))
            names.insert(entry.path().filename().string());
        return names;
    }

    fs::path dir_;
    BatchRequest request_;
    std::vector<BatchInput> scenes_;
    BatchSettings settings_;
};

std::string file_bytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A 2x2 image as a --progressive pass before the last leaves it: octray.samplesSoFar and
// the run writing it as octray.owner.
void write_unfinished_pass(const fs::path& path, const std::string& owner) {
    Imf::Header header(2, 2);
    header.insert("octray.samplesSoFar", Imf::IntAttribute(1));
    header.insert("octray.owner", Imf::StringAttribute(owner));
    header.channels().insert("R", Imf::Channel(Imf::FLOAT));
    std::vector<float> pixels(4, 0.5f);
    Imf::FrameBuffer frame_buffer;
    frame_buffer.insert("R", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(pixels.data()),
                                        sizeof(float), 2 * sizeof(float)));
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frame_buffer);
    file.writePixels(2);
}

TEST_F(FrameLoopTest, EveryFrameIsRenderedWrittenAndReportedOnce) {
    RecordingObserver observer;
    const BatchSummary summary = run(observer);
    EXPECT_EQ(observer.runs_started, 1);
    EXPECT_EQ(observer.runs_finished, 1);
    EXPECT_EQ(observer.jobs_at_start, 3u);
    const std::uint64_t frame_work = std::uint64_t{kWidth} * kHeight;  // whitted: 1 spp
    EXPECT_EQ(observer.total_work, 3 * frame_work);
    EXPECT_EQ(observer.path, render_path_label(settings_));
    ASSERT_EQ(observer.started.size(), 3u);
    for (std::size_t k = 0; k < 3; ++k) {
        EXPECT_EQ(observer.started[k].index, k + 1);
        EXPECT_EQ(observer.started[k].scene, "whitted");
        EXPECT_EQ(observer.started[k].frame, static_cast<int>(k));
        EXPECT_EQ(observer.started[k].work, frame_work);
    }
    ASSERT_EQ(observer.finished.size(), 3u);
    for (std::size_t k = 0; k < 3; ++k) {
        const FrameReport& r = observer.finished[k];
        EXPECT_EQ(r.outcome, FrameOutcome::rendered);
        EXPECT_EQ(r.index, k + 1);
        EXPECT_EQ(r.scene_spec, "whitted");
        EXPECT_EQ(r.output, output(static_cast<int>(k)).string());
        EXPECT_GT(r.rays, 0u);
        EXPECT_TRUE(r.message.empty()) << r.message;
        // The renderer advanced the observer's counter over every pixel of the frame.
        EXPECT_EQ(observer.pixels_at_finish[k], frame_work);
        EXPECT_EQ(observer.finished_work[k], frame_work);
        const Image image = read_image(r.output);
        EXPECT_EQ(image.width(), kWidth);
        EXPECT_EQ(image.height(), kHeight);
    }
    EXPECT_EQ(summary.rendered, 3u);
    EXPECT_EQ(summary.skipped + summary.failed + summary.not_started, 0u);
    EXPECT_FALSE(summary.interrupted);
    EXPECT_FALSE(summary.scene_failure || summary.io_failure || summary.internal_failure);
    EXPECT_EQ(observer.summary.rendered, 3u);
    EXPECT_EQ(files(), (std::set<std::string>{"w.0.exr", "w.1.exr", "w.2.exr"}));
}

TEST_F(FrameLoopTest, ResumeSkipsAFinishedFrameAndLeavesItAsItWas) {
    request_.frames = "1";
    RecordingObserver first;
    ASSERT_EQ(run(first).rendered, 1u);
    const std::string before = file_bytes(output(1));
    ASSERT_FALSE(before.empty());

    request_.frames = "0-2";
    settings_.skip_existing = true;
    RecordingObserver resumed;
    const BatchSummary summary = run(resumed);
    EXPECT_EQ(resumed.outcomes(),
              (std::vector<std::pair<int, FrameOutcome>>{{0, FrameOutcome::rendered},
                                                         {1, FrameOutcome::skipped_existing},
                                                         {2, FrameOutcome::rendered}}));
    ASSERT_EQ(resumed.started.size(), 2u) << "a skipped frame does not start";
    EXPECT_EQ(resumed.started[0].frame, 0);
    EXPECT_EQ(resumed.started[1].frame, 2);
    EXPECT_EQ(summary.rendered, 2u);
    EXPECT_EQ(summary.skipped, 1u);
    EXPECT_EQ(file_bytes(output(1)), before) << "a finished frame was written again";
}

TEST_F(FrameLoopTest, AFrameClaimedByAnotherRunIsSkipped) {
    // Frame 0: another run's --placeholders claim; frame 1: the unfinished --progressive
    // pass of a live run (this process: its claim cannot be stale).
    std::ofstream(output(0)).close();
    write_unfinished_pass(output(1), current_owner());
    const std::string pass = file_bytes(output(1));
    settings_.placeholders = true;
    RecordingObserver observer;
    const BatchSummary summary = run(observer);
    EXPECT_EQ(observer.outcomes(),
              (std::vector<std::pair<int, FrameOutcome>>{{0, FrameOutcome::skipped_claimed},
                                                         {1, FrameOutcome::skipped_claimed},
                                                         {2, FrameOutcome::rendered}}));
    EXPECT_EQ(summary.skipped, 2u);
    EXPECT_EQ(summary.rendered, 1u);
    EXPECT_EQ(fs::file_size(output(0)), 0u) << "another run's claim was taken";
    EXPECT_EQ(file_bytes(output(1)), pass) << "a live run's pass was rendered over";

    // --skip-existing alone honours both claims the same way.
    settings_.placeholders = false;
    settings_.skip_existing = true;
    RecordingObserver again;
    run(again);
    EXPECT_EQ(again.outcomes(),
              (std::vector<std::pair<int, FrameOutcome>>{{0, FrameOutcome::skipped_claimed},
                                                         {1, FrameOutcome::skipped_claimed},
                                                         {2, FrameOutcome::skipped_existing}}));
}

TEST_F(FrameLoopTest, AFailingFrameIsReportedAndTheOthersGoOn) {
    fs::create_directories(output(1) / "inside");
    RecordingObserver observer;
    const BatchSummary summary = run(observer);
    EXPECT_EQ(observer.outcomes(),
              (std::vector<std::pair<int, FrameOutcome>>{{0, FrameOutcome::rendered},
                                                         {1, FrameOutcome::failed},
                                                         {2, FrameOutcome::rendered}}));
    ASSERT_EQ(observer.finished.size(), 3u);
    EXPECT_EQ(observer.finished[1].message,
              "I/O error: cannot write " + output(1).string() +
                  ": it is a directory; expected an image file (or nothing) there");
    ASSERT_EQ(observer.started.size(), 2u) << "the failing frame was rendered first";
    EXPECT_EQ(summary.rendered, 2u);
    EXPECT_EQ(summary.failed, 1u);
    EXPECT_TRUE(summary.io_failure);
    EXPECT_FALSE(summary.scene_failure || summary.internal_failure || summary.interrupted);
    EXPECT_TRUE(fs::is_directory(output(1)));
    EXPECT_TRUE(fs::exists(output(0)) && fs::exists(output(2)));
}

TEST_F(FrameLoopTest, CancelAbandonsTheFrameInProgressAndLeavesNothingBehind) {
    // A temporary a killed run left next to frame 0 (no writer holds its lock): stale.
    const fs::path stale = dir_ / ".w.0.exr.tmp.1.00000000000000bb";
    std::ofstream(stale) << "left by a killed run";
    settings_.placeholders = true;  // frame 0 is claimed, then released when cancelled
    std::atomic<bool> cancel{false};
    RecordingObserver observer;
    observer.on_frame_started = [&](int) { cancel = true; };  // as Ctrl-C mid-frame
    const BatchSummary summary = run(observer, &cancel);
    ASSERT_EQ(observer.started.size(), 1u);
    EXPECT_EQ(observer.started[0].frame, 0);
    EXPECT_TRUE(observer.finished.empty()) << "the abandoned frame was reported finished";
    EXPECT_EQ(observer.runs_finished, 1);
    EXPECT_TRUE(summary.interrupted);
    EXPECT_EQ(summary.interrupted_frames, 1u) << "the abandoned frame is interrupted";
    EXPECT_EQ(summary.not_started, 2u) << "the abandoned frame was started";
    EXPECT_EQ(summary.rendered + summary.skipped + summary.failed, 0u);
    EXPECT_FALSE(summary.scene_failure || summary.io_failure || summary.internal_failure);
    EXPECT_TRUE(files().empty()) << "a file, a claim or a temporary was left: "
                                 << (files().empty() ? "" : *files().begin());

    // Set before the run: no frame starts at all.
    RecordingObserver idle;
    const BatchSummary none = run(idle, &cancel);
    EXPECT_TRUE(idle.started.empty());
    EXPECT_TRUE(none.interrupted);
    EXPECT_EQ(none.not_started, 3u);
    EXPECT_EQ(none.interrupted_frames, 0u);
    EXPECT_TRUE(files().empty());
}

// Pixels of the float EXR `file` (frame `frame` of `scene`, written by the frame loop) that
// differ from the frame rendered on its own: the scene posed at that frame, compiled and
// built afresh.
std::size_t pixels_unlike_alone(const Scene& scene, int frame, const fs::path& file) {
    RenderOptions options;
    options.frame = static_cast<std::uint32_t>(frame);
    const RenderResult alone =
        render_packet(scene_at_frame(scene, frame), options, resolve_isa(Isa::automatic));
    const Image image = read_image(file.string());
    if (image.pixel_count() != alone.image.pixel_count()) return alone.image.pixel_count();
    const float* r = image.plane(image.channel_index("R"));
    const float* g = image.plane(image.channel_index("G"));
    const float* b = image.plane(image.channel_index("B"));
    std::size_t differ = 0;
    for (std::size_t k = 0; k < alone.image.pixel_count(); ++k) {
        const Rgb c = rgb_at(alone.image, k);
        differ += r[k] != c.r || g[k] != c.g || b[k] != c.b;
    }
    return differ;
}

void FrameLoopTest::expect_frames_as_rendered_alone(const std::string& prefix,
                                                    int frames) const {
    for (int f = 0; f < frames; ++f)
        EXPECT_EQ(pixels_unlike_alone(scenes_[0].scene, f,
                                      dir_ / (prefix + "." + std::to_string(f) + ".exr")),
                  0u)
            << "frame " << f;
}

// Refit (frame_loop.cpp, PreparedScene::update): an animation of moving and growing
// spheres is prepared for its first frame and updated in place for the next ones (no
// compile); every frame is, bit for bit, the frame rendered on its own.
TEST_F(FrameLoopTest, AnAnimationOfMovingSpheresIsRefitAndEachFrameIsTheSameBits) {
    std::string tracks;
    for (int k = 0; k < kGridSpheres; ++k) {
        const Vec3 c = grid_center(k);
        tracks += std::string(k == 0 ? "" : ", ") + "\"s" + std::to_string(k) +
                  R"(": [{"frame": 0, "radius": 0.4}, {"frame": 3, "center": [)" +
                  std::to_string(c.x + 0.5f) + ", " + std::to_string(c.y + 0.25f) + ", " +
                  std::to_string(c.z) + R"(], "radius": 0.45}])";
    }
    load_grid_scene("moving", R"({"frames": 4, "objects": {)" + tracks + "}}", "m");

    RecordingObserver observer;
    const BatchSummary summary = run(observer);
    ASSERT_EQ(summary.rendered, 4u);
    ASSERT_EQ(observer.finished.size(), 4u);
    EXPECT_GT(observer.finished[0].compile_seconds, 0.0);
    for (int f = 1; f < 4; ++f) {
        EXPECT_EQ(observer.finished[f].compile_seconds, 0.0) << "frame " << f;
        EXPECT_GT(observer.finished[f].prepare_seconds, 0.0) << "frame " << f;
    }
    expect_frames_as_rendered_alone("m", 4);
}

// Prepare once (frame_loop.cpp): a camera-only animation on the simd path compiles the
// scene and builds its BVH for its first frame only, and every frame is, bit for bit, the
// frame rendered on its own (the scene posed at that frame, compiled and built afresh).
// The scene is not copied for such a pose (frame_renderer.cpp): each file's camera
// matrices and AOVs are still the frame's own.
TEST_F(FrameLoopTest, ACameraOnlyAnimationIsPreparedOnceAndEachFrameIsTheSameBits) {
    load_grid_scene("orbit", R"({"frames": 3, "camera": [
        {"frame": 0, "eye": [0, 3, 12]}, {"frame": 2, "eye": [9, 5, 7], "fov": 40}]})",
                    "o");
    settings_.render.aovs = AovSet{.depth = true, .normal = true};

    RecordingObserver observer;
    const BatchSummary summary = run(observer);
    ASSERT_EQ(summary.rendered, 3u);
    ASSERT_EQ(observer.finished.size(), 3u);
    EXPECT_GT(observer.finished[0].prepare_seconds, 0.0);
    EXPECT_GT(observer.finished[0].bvh_seconds, 0.0);
    for (int f = 1; f < 3; ++f) {
        EXPECT_EQ(observer.finished[f].prepare_seconds, 0.0) << "frame " << f;
        EXPECT_EQ(observer.finished[f].bvh_seconds, 0.0) << "frame " << f;
    }
    expect_frames_as_rendered_alone("o", 3);
    for (int f = 0; f < 3; ++f) {
        SCOPED_TRACE("frame " + std::to_string(f));
        const Scene posed = scene_at_frame(scenes_[0].scene, f);
        const std::string file = (dir_ / ("o." + std::to_string(f) + ".exr")).string();
        const ExrAttributes attributes = read_exr_attributes(file);
        ASSERT_FALSE(attributes.matrices.empty());
        EXPECT_EQ(attributes.matrices[0].first, "worldToCamera");
        EXPECT_EQ(attributes.matrices[0].second, world_to_camera(posed));
        RenderOptions options;
        options.frame = static_cast<std::uint32_t>(f);
        const Image alone = compute_aovs(posed, options, settings_.render.aovs);
        const Image image = read_image(file);
        for (const char* name : {"Z", "N.X", "N.Y", "N.Z"}) {
            ASSERT_GE(image.channel_index(name), 0) << name;
            const ImageChannel& got = image.channels[image.channel_index(name)];
            const ImageChannel& want = alone.channels[alone.channel_index(name)];
            EXPECT_TRUE(got.samples == want.samples) << name;
        }
    }
}

// The observer's events of `frames` frames: each started and finished once, every
// frame's start before its finish, the finishes in frame order.
void expect_reported_in_order(const std::vector<std::string>& events, std::size_t frames) {
    ASSERT_EQ(events.size(), 2 * frames) << ::testing::PrintToString(events);
    std::size_t next_finish = 1;
    std::set<std::size_t> started;
    for (const std::string& e : events) {
        const std::size_t k = std::stoul(e.substr(e.find(' ') + 1));
        if (e.rfind("start ", 0) == 0) {
            EXPECT_TRUE(started.insert(k).second) << "started twice: " << e;
        } else {
            EXPECT_TRUE(started.count(k)) << "finished before it started: " << e;
            EXPECT_EQ(k, next_finish++) << ::testing::PrintToString(events);
        }
    }
}

// Write behind (BatchSettings::write_behind): each frame's files are written while the
// next frame renders. The frames are those written one by one (bit for bit the frame
// rendered alone), each is reported once, in order, with its preview, and nothing else is
// left in the directory.
TEST_F(FrameLoopTest, WritingBehindGivesEveryFrameAsRenderedAloneReportedOnceInOrder) {
    std::string tracks;
    for (int k = 0; k < kGridSpheres; k += 3)
        tracks += std::string(k == 0 ? "" : ", ") + "\"s" + std::to_string(k) +
                  R"(": [{"frame": 0, "radius": 0.4}, {"frame": 4, "radius": 0.7}])";
    load_grid_scene("behind", R"({"frames": 5, "objects": {)" + tracks + "}}", "b");
    request_.png = (dir_ / "b.#.png").string();
    settings_.write_behind = true;

    RecordingObserver observer;
    const BatchSummary summary = run(observer);
    EXPECT_EQ(summary.rendered, 5u);
    EXPECT_FALSE(summary.io_failure || summary.internal_failure || summary.interrupted);
    // Each frame is reported by its writer once its files are on disk: after its own
    // start, in job order (while the next frame renders, or before it starts).
    expect_reported_in_order(observer.events, 5);
    ASSERT_EQ(observer.started.size(), 5u);
    ASSERT_EQ(observer.finished.size(), 5u);
    std::set<std::string> expected;
    for (int f = 0; f < 5; ++f) {
        const FrameReport& r = observer.finished[static_cast<std::size_t>(f)];
        EXPECT_EQ(r.index, static_cast<std::size_t>(f) + 1);
        EXPECT_EQ(r.frame, f);
        EXPECT_EQ(r.outcome, FrameOutcome::rendered);
        EXPECT_GT(r.write_seconds, 0.0) << "frame " << f;
        const std::string name = "b." + std::to_string(f);
        expected.insert(name + ".exr");
        expected.insert(name + ".png");
    }
    expect_frames_as_rendered_alone("b", 5);
    expected.insert("behind.json");
    EXPECT_EQ(files(), expected);
}

// Write behind: a write that fails while the next frame renders fails its own frame (an
// I/O error, nothing left of it, its claim released) and the others are written. The
// failure: a file size limit (RLIMIT_FSIZE, which binds root too) that only the large
// frame's uncompressed EXR exceeds.
TEST_F(FrameLoopTest, AWriteThatFailsWhileTheNextFrameRendersFailsThatFrameAlone) {
    BatchRequest small_request, large_request;
    small_request.overrides.width = 8, small_request.overrides.height = 8;
    large_request.overrides.width = 160, large_request.overrides.height = 160;
    scenes_ = {load_batch_input("whitted", small_request),
               load_batch_input("whitted", large_request)};
    const std::vector<BatchJob> jobs = {{0, 0, (dir_ / "small.0.exr").string(), ""},
                                        {1, 0, (dir_ / "large.0.exr").string(), ""},
                                        {0, 1, (dir_ / "small.1.exr").string(), ""}};
    settings_.exr = {true, ExrCompression::none};  // 160 x 160 x 12 bytes: 300 KiB
    settings_.write_behind = true;
    settings_.placeholders = true;  // the large frame's claim is released when it fails

    rlimit before{};
    ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &before), 0);
    rlimit limit = before;
    limit.rlim_cur = 64 * 1024;
    const auto previous_handler = std::signal(SIGXFSZ, SIG_IGN);  // EFBIG, not a signal
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limit), 0);
    RecordingObserver observer;
    const BatchSummary summary = run_batch(scenes_, jobs, settings_, observer, nullptr);
    setrlimit(RLIMIT_FSIZE, &before);
    std::signal(SIGXFSZ, previous_handler);

    expect_reported_in_order(observer.events, 3);
    ASSERT_EQ(observer.finished.size(), 3u);
    EXPECT_EQ(observer.finished[0].outcome, FrameOutcome::rendered);
    EXPECT_EQ(observer.finished[1].outcome, FrameOutcome::failed);
    EXPECT_EQ(observer.finished[1].output, jobs[1].output);
    EXPECT_EQ(observer.finished[1].message.rfind("I/O error: ", 0), 0u)
        << observer.finished[1].message;
    EXPECT_EQ(observer.finished[2].outcome, FrameOutcome::rendered);
    EXPECT_EQ(summary.rendered, 2u);
    EXPECT_EQ(summary.failed, 1u);
    EXPECT_TRUE(summary.io_failure);
    EXPECT_FALSE(summary.internal_failure || summary.interrupted);
    EXPECT_EQ(files(), (std::set<std::string>{"small.0.exr", "small.1.exr"}));
}

// Write behind and cancel: the frame being written when the next one is cancelled is
// finished and reported; the cancelled one is abandoned as always.
TEST_F(FrameLoopTest, CancelWhileAFrameIsWrittenBehindKeepsThatFrame) {
    settings_.write_behind = true;
    std::atomic<bool> cancel{false};
    RecordingObserver observer;
    observer.on_frame_started = [&](int frame) {
        if (frame == 1) cancel = true;
    };
    const BatchSummary summary = run(observer, &cancel);
    ASSERT_EQ(observer.started.size(), 2u);
    ASSERT_EQ(observer.finished.size(), 1u);
    EXPECT_EQ(observer.finished[0].frame, 0);
    EXPECT_EQ(observer.finished[0].outcome, FrameOutcome::rendered);
    EXPECT_TRUE(summary.interrupted);
    EXPECT_EQ(summary.rendered, 1u);
    EXPECT_EQ(summary.interrupted_frames, 1u);
    EXPECT_EQ(summary.not_started, 1u);
    EXPECT_EQ(files(), (std::set<std::string>{"w.0.exr"}));
    EXPECT_EQ(read_image(output(0).string()).width(), kWidth);
}

}  // namespace
}  // namespace octray::batch
