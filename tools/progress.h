#pragma once
// Progress of a batch render, for people and for farm managers (tools/README.md,
// "Progress"):
//   bar    a live line on stderr (a terminal): frame k/n, percent, ETA, Mrays/s
//   lines  one line per finished frame on stdout, plus "Progress: NN%" lines
//   json   the same events as one JSON object per line on stdout
//   none   nothing but errors and the final summary
// Work is counted in pixel samples (pixels x spp), so a frame's share of the bar is its
// share of the work; within a frame the renderers advance a counter tile by tile.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

namespace octray::tools {

enum class ProgressMode { bar, lines, json, none };

// "auto" picks bar when stderr is a terminal, else lines. nullopt for an unknown name.
std::optional<ProgressMode> parse_progress_mode(std::string_view name, bool stderr_is_terminal);

enum class FrameOutcome { rendered, skipped_existing, skipped_claimed, failed };

struct FrameReport {
    std::size_t index = 0;  // 1-based position in this run's frame list
    std::string scene;
    int frame = 0;
    std::string output;
    std::string preview;  // the PNG, if any
    FrameOutcome outcome = FrameOutcome::rendered;
    double seconds = 0.0;        // everything: claims, trace, write
    double trace_seconds = 0.0;  // rendering (AOVs included), what Mrays/s is over
    double write_seconds = 0.0;  // EXR and PNG encoding and writing (every progressive pass)
    std::uint64_t rays = 0;      // rendered frames
    std::string message;         // failed frames: the reason
    // Rendered frames, the phases of `--stats`: the scene's load (once per scene, on each
    // of its frames), compile, BVH build and the render itself (parts of trace_seconds).
    double load_seconds = 0.0, compile_seconds = 0.0, bvh_seconds = 0.0, render_seconds = 0.0;
};

struct BatchSummary {
    std::size_t rendered = 0, skipped = 0, failed = 0, not_started = 0;
    double seconds = 0.0;                             // wall time of the run
    double trace_seconds = 0.0, write_seconds = 0.0;  // of the rendered frames
    std::uint64_t rays = 0;
    bool interrupted = false;
};

class ProgressReporter {
  public:
    // `total_work`: pixel samples of every frame of the run.
    ProgressReporter(ProgressMode mode, std::size_t frame_count, std::uint64_t total_work);
    ~ProgressReporter();
    ProgressReporter(const ProgressReporter&) = delete;
    ProgressReporter& operator=(const ProgressReporter&) = delete;

    // The counter the renderer advances (pixels done); reset by frame_started.
    std::atomic<std::uint64_t>& pixel_counter() { return pixels_done_; }

    // `work` is the frame's pixel samples; `spp` converts the pixel counter into work.
    void frame_started(std::size_t index, const std::string& scene, int frame,
                       std::uint64_t work, int spp);
    void frame_finished(const FrameReport& report, std::uint64_t work);
    // A line for the user (a warning, a failed frame's reason) on stderr, not breaking
    // the bar.
    void note(const std::string& line);
    void finish(const BatchSummary& summary);

  private:
    void ticker();
    void draw_bar_locked(bool final_draw);
    void maybe_progress_line_locked(bool force);
    double fraction_locked() const;
    double mrays_per_second_locked() const;

    const ProgressMode mode_;
    const std::size_t frame_count_;
    const std::uint64_t total_work_;
    const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();

    std::atomic<std::uint64_t> pixels_done_{0};
    std::mutex mutex_;
    std::condition_variable wake_;
    bool stopping_ = false;
    std::uint64_t work_done_ = 0;     // of finished (or skipped) frames
    std::uint64_t current_work_ = 0;  // of the frame being rendered
    int current_spp_ = 1;
    std::size_t current_index_ = 0;
    std::string current_label_;
    std::uint64_t rays_done_ = 0;
    double render_seconds_ = 0.0;
    int last_percent_line_ = -1;
    std::chrono::steady_clock::time_point last_percent_time_{};
    bool bar_drawn_ = false;
    std::thread thread_;
};

// Seconds as "1:02:03", "4:05" or "12.3s".
std::string format_duration(double seconds);

}  // namespace octray::tools
