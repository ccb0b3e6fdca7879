#pragma once
// Progress of a batch render, for people and for farm managers (tools/README.md,
// "Progress"):
//   bar    a live line on stderr (a terminal): frame k/n, percent, ETA, Mrays/s
//   lines  one line per finished frame on stdout, plus "Progress: NN%" lines
//   json   the same events as one JSON object per line on stdout
//   none   nothing but errors and the final summary
// Work is counted in pixel samples (pixels x spp), so a frame's share of the bar is its
// share of the work; within a frame the renderers advance a counter tile by tile. The
// reporter is the observer of the frame loop (render/batch/observer.h).

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

#include "render/batch/observer.h"

namespace octray::tools {

enum class ProgressMode { bar, lines, json, none };

// "auto" picks bar when stderr is a terminal, else lines. nullopt for an unknown name.
std::optional<ProgressMode> parse_progress_mode(std::string_view name, bool stderr_is_terminal);

using batch::BatchSummary;
using batch::FrameOutcome;
using batch::FrameReport;

class ProgressReporter final : public batch::BatchObserver {
  public:
    // `stats`: --stats, each rendered frame's phases on stderr.
    ProgressReporter(ProgressMode mode, bool stats);
    ~ProgressReporter() override;
    ProgressReporter(const ProgressReporter&) = delete;
    ProgressReporter& operator=(const ProgressReporter&) = delete;

    // Prints the run's header (scenes, path, threads, tiles; not in json and none modes)
    // and starts the ticker that draws the bar or prints the "Progress" lines.
    void run_started(const batch::RunStart& start) override;
    // The counter the renderer advances (pixels done); reset by frame_started.
    std::atomic<std::uint64_t>* pixel_counter() override { return &pixels_done_; }
    // `work` is the frame's pixel samples; `spp` converts the pixel counter into work.
    void frame_started(std::size_t index, const std::string& scene, int frame,
                       std::uint64_t work, int spp) override;
    // A failed frame's reason first goes to stderr as "octray: frame F of SCENE failed:
    // ...", a rendered frame's phases with --stats as "stats: ..." lines.
    void frame_finished(const FrameReport& report, std::uint64_t work) override;
    // The summary, after the ticker has stopped.
    void run_finished(const BatchSummary& summary) override;

  private:
    void ticker();
    // A line for the user (a failed frame's reason) on stderr, not breaking the bar.
    void note_locked(const std::string& line);
    void draw_bar_locked(bool final_draw);
    void maybe_progress_line_locked(bool force);
    double fraction_locked() const;
    double mrays_per_second_locked() const;

    const ProgressMode mode_;
    const bool stats_;
    std::size_t frame_count_ = 0;
    std::uint64_t total_work_ = 1;
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();

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
