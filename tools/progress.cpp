#include "tools/progress.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

namespace octray::tools {
namespace {

using Clock = std::chrono::steady_clock;

constexpr auto kBarInterval = std::chrono::milliseconds(200);
// "Progress: NN%" lines: at most this often, and only when the percentage changed.
constexpr auto kPercentLineInterval = std::chrono::seconds(2);

const char* outcome_name(FrameOutcome outcome) {
    switch (outcome) {
        case FrameOutcome::rendered:
            return "rendered";
        case FrameOutcome::skipped_existing:
            return "skipped (exists)";
        case FrameOutcome::skipped_claimed:
            return "skipped (claimed by another run)";
        case FrameOutcome::failed:
            return "FAILED";
    }
    return "?";
}

const char* outcome_key(FrameOutcome outcome) {
    switch (outcome) {
        case FrameOutcome::rendered:
            return "rendered";
        case FrameOutcome::skipped_existing:
            return "skipped_existing";
        case FrameOutcome::skipped_claimed:
            return "skipped_claimed";
        case FrameOutcome::failed:
            return "failed";
    }
    return "unknown";
}

double seconds_since(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}

}  // namespace

std::optional<ProgressMode> parse_progress_mode(std::string_view name,
                                                bool stderr_is_terminal) {
    if (name == "auto") return stderr_is_terminal ? ProgressMode::bar : ProgressMode::lines;
    if (name == "bar") return ProgressMode::bar;
    if (name == "lines") return ProgressMode::lines;
    if (name == "json") return ProgressMode::json;
    if (name == "none") return ProgressMode::none;
    return std::nullopt;
}

std::string format_duration(double seconds) {
    if (!std::isfinite(seconds) || seconds < 0.0) return "?";
    char text[32];
    if (seconds < 60.0) {
        std::snprintf(text, sizeof text, "%.1fs", seconds);
        return text;
    }
    const auto total = static_cast<long long>(seconds + 0.5);
    const long long h = total / 3600, m = total / 60 % 60, s = total % 60;
    if (h > 0)
        std::snprintf(text, sizeof text, "%lld:%02lld:%02lld", h, m, s);
    else
        std::snprintf(text, sizeof text, "%lld:%02lld", m, s);
    return text;
}

ProgressReporter::ProgressReporter(ProgressMode mode, bool stats)
    : mode_(mode), stats_(stats) {}

ProgressReporter::~ProgressReporter() {
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
}

void ProgressReporter::run_started(const batch::RunStart& start) {
    if (mode_ != ProgressMode::json && mode_ != ProgressMode::none) {
        for (std::size_t s = 0; s < start.scenes.size(); ++s) {
            const Scene& scene = start.scenes[s].scene;
            std::size_t frames = 0;
            for (const batch::BatchJob& job : start.jobs) frames += job.scene == s ? 1 : 0;
            std::printf(
                "scene    %s (%zu objects, %zu lights%s), %dx%d, %d spp, max depth %d, "
                "seed %llu, %zu frame%s\n",
                start.scenes[s].spec.c_str(), scene.objects.size(), scene.lights.size(),
                scene.animation ? ", animated" : "", scene.image.width, scene.image.height,
                scene.image.spp, scene.render.max_depth,
                static_cast<unsigned long long>(scene.render.seed), frames,
                frames == 1 ? "" : "s");
        }
        std::printf("render   %s path, %zu threads, %dx%d tiles\n", start.path.c_str(),
                    start.threads, start.tile_width, start.tile_height);
        std::fflush(stdout);
    }
    std::lock_guard lock(mutex_);
    frame_count_ = start.jobs.size();
    total_work_ = std::max<std::uint64_t>(start.total_work, 1);
    start_ = Clock::now();
    if (mode_ == ProgressMode::bar || mode_ == ProgressMode::lines ||
        mode_ == ProgressMode::json)
        thread_ = std::thread([this] { ticker(); });
}

double ProgressReporter::fraction_locked() const {
    const std::uint64_t pixels = pixels_done_.load(std::memory_order_relaxed);
    const std::uint64_t current =
        std::min(current_work_, pixels * static_cast<std::uint64_t>(current_spp_));
    return std::min(
        1.0, static_cast<double>(work_done_ + current) / static_cast<double>(total_work_));
}

double ProgressReporter::mrays_per_second_locked() const {
    return render_seconds_ > 0.0 ? static_cast<double>(rays_done_) / render_seconds_ / 1e6
                                 : 0.0;
}

void ProgressReporter::draw_bar_locked(bool final_draw) {
    const double fraction = fraction_locked();
    const double elapsed = seconds_since(start_);
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(fraction * kWidth);
    std::string bar(static_cast<std::size_t>(filled), '#');
    bar.append(static_cast<std::size_t>(kWidth - filled), '.');
    std::string eta = fraction > 0.0 && fraction < 1.0
                          ? format_duration(elapsed * (1.0 - fraction) / fraction)
                          : (fraction >= 1.0 ? "0.0s" : "?");
    char rate[32] = "-";
    if (render_seconds_ > 0.0)
        std::snprintf(rate, sizeof rate, "%.1f", mrays_per_second_locked());
    std::fprintf(stderr,
                 "\r\033[K[%s] %3d%%  frame %zu/%zu  %s  elapsed %s  ETA %s  %s Mrays/s",
                 bar.c_str(), static_cast<int>(fraction * 100.0), current_index_, frame_count_,
                 current_label_.c_str(), format_duration(elapsed).c_str(), eta.c_str(), rate);
    if (final_draw) std::fputc('\n', stderr);
    std::fflush(stderr);
    bar_drawn_ = !final_draw;
}

void ProgressReporter::maybe_progress_line_locked(bool force) {
    int percent = static_cast<int>(fraction_locked() * 100.0);
    // 100% only once every frame is finished (its line printed): the pixel counter of the
    // last frame reaches its end before the frame is written, and the ticker would then
    // print "Progress: 100%" before or after the frame line, as the threads raced.
    if (work_done_ < total_work_) percent = std::min(percent, 99);
    const auto now = Clock::now();
    if (percent == last_percent_line_) return;
    if (!force && last_percent_line_ >= 0 && now - last_percent_time_ < kPercentLineInterval)
        return;
    last_percent_line_ = percent;
    last_percent_time_ = now;
    if (mode_ == ProgressMode::lines) {
        std::printf("Progress: %d%%\n", percent);
    } else {
        nlohmann::json event = {{"event", "progress"},
                                {"percent", percent},
                                {"elapsed_seconds", seconds_since(start_)}};
        std::printf("%s\n", event.dump().c_str());
    }
    std::fflush(stdout);
}

void ProgressReporter::ticker() {
    std::unique_lock lock(mutex_);
    while (!stopping_) {
        wake_.wait_for(lock, kBarInterval);
        if (stopping_) break;
        if (mode_ == ProgressMode::bar) {
            if (current_index_ > 0) draw_bar_locked(false);
        } else {
            maybe_progress_line_locked(false);
        }
    }
}

void ProgressReporter::frame_started(std::size_t index, const std::string& scene, int frame,
                                     std::uint64_t work, int spp) {
    std::lock_guard lock(mutex_);
    pixels_done_.store(0, std::memory_order_relaxed);
    current_work_ = work;
    current_spp_ = std::max(spp, 1);
    current_index_ = index;
    current_label_ = scene + " frame " + std::to_string(frame);
}

void ProgressReporter::frame_finished(const FrameReport& report, std::uint64_t work) {
    std::lock_guard lock(mutex_);
    if (stats_ && report.outcome == FrameOutcome::rendered)
        // The scene is loaded once for all its frames: its load time is on each line.
        std::fprintf(stderr,
                     "stats: %s frame %d: load %.3f s, compile %.3f s, BVH %.3f s, "
                     "render %.3f s, write %.3f s\n",
                     report.scene.c_str(), report.frame, report.load_seconds,
                     report.compile_seconds, report.bvh_seconds, report.render_seconds,
                     report.write_seconds);
    if (report.outcome == FrameOutcome::failed)
        note_locked("octray: frame " + std::to_string(report.frame) + " of " +
                    report.scene_spec + " failed: " + report.message);
    work_done_ += work;
    // A frame written behind ends while the next one renders: that one's progress stays.
    if (report.index >= current_index_) {
        current_work_ = 0;
        pixels_done_.store(0, std::memory_order_relaxed);
        current_index_ = report.index;
    }
    if (report.outcome == FrameOutcome::rendered) {
        rays_done_ += report.rays;
        render_seconds_ += report.trace_seconds;
    }
    const double mrays = report.trace_seconds > 0.0
                             ? static_cast<double>(report.rays) / report.trace_seconds / 1e6
                             : 0.0;
    switch (mode_) {
        case ProgressMode::bar:
            if (report.outcome == FrameOutcome::failed) {
                std::fprintf(stderr, "\r\033[Kframe %zu/%zu %s frame %d FAILED: %s\n",
                             report.index, frame_count_, report.scene.c_str(), report.frame,
                             report.message.c_str());
                bar_drawn_ = false;
            }
            draw_bar_locked(false);
            break;
        case ProgressMode::lines:
            if (report.outcome == FrameOutcome::rendered)
                std::printf(
                    "frame %zu/%zu  %s frame %d  -> %s%s%s  prepare %.3f s  trace %.3f s  "
                    "%.2f Mrays/s  write %.3f s\n",
                    report.index, frame_count_, report.scene.c_str(), report.frame,
                    report.output.c_str(), report.preview.empty() ? "" : " + ",
                    report.preview.c_str(), report.prepare_seconds, report.trace_seconds, mrays,
                    report.write_seconds);
            else if (report.outcome == FrameOutcome::failed)
                std::printf("frame %zu/%zu  %s frame %d  FAILED: %s\n", report.index,
                            frame_count_, report.scene.c_str(), report.frame,
                            report.message.c_str());
            else
                std::printf("frame %zu/%zu  %s frame %d  -> %s  %s\n", report.index,
                            frame_count_, report.scene.c_str(), report.frame,
                            report.output.c_str(), outcome_name(report.outcome));
            std::fflush(stdout);
            maybe_progress_line_locked(true);
            break;
        case ProgressMode::json: {
            nlohmann::json event = {{"event", "frame"},
                                    {"index", report.index},
                                    {"count", frame_count_},
                                    {"scene", report.scene},
                                    {"frame", report.frame},
                                    {"output", report.output},
                                    {"outcome", outcome_key(report.outcome)},
                                    {"seconds", report.seconds},
                                    {"prepare_seconds", report.prepare_seconds},
                                    {"trace_seconds", report.trace_seconds},
                                    {"write_seconds", report.write_seconds},
                                    {"rays", report.rays},
                                    {"mrays_per_second", mrays}};
            if (report.outcome == FrameOutcome::rendered)
                event["phases"] = {{"load_seconds", report.load_seconds},
                                   {"compile_seconds", report.compile_seconds},
                                   {"bvh_seconds", report.bvh_seconds},
                                   {"render_seconds", report.render_seconds},
                                   {"write_seconds", report.write_seconds}};
            if (!report.preview.empty()) event["preview"] = report.preview;
            if (!report.message.empty()) event["message"] = report.message;
            std::printf("%s\n", event.dump().c_str());
            std::fflush(stdout);
            maybe_progress_line_locked(true);
            break;
        }
        case ProgressMode::none:
            break;
    }
}

void ProgressReporter::note_locked(const std::string& line) {
    if (mode_ == ProgressMode::bar && bar_drawn_) std::fputs("\r\033[K", stderr);
    std::fprintf(stderr, "%s\n", line.c_str());
    if (mode_ == ProgressMode::bar && bar_drawn_) draw_bar_locked(false);
    std::fflush(stderr);
}

void ProgressReporter::run_finished(const BatchSummary& summary) {
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();

    std::lock_guard lock(mutex_);
    if (mode_ == ProgressMode::bar && bar_drawn_) draw_bar_locked(true);
    const double mrays = summary.trace_seconds > 0.0
                             ? static_cast<double>(summary.rays) / summary.trace_seconds / 1e6
                             : 0.0;
    if (mode_ == ProgressMode::json) {
        nlohmann::json event = {{"event", "summary"},
                                {"frames", frame_count_},
                                {"rendered", summary.rendered},
                                {"skipped", summary.skipped},
                                {"failed", summary.failed},
                                {"interrupted_frames", summary.interrupted_frames},
                                {"not_started", summary.not_started},
                                {"interrupted", summary.interrupted},
                                {"seconds", summary.seconds},
                                {"prepare_seconds", summary.prepare_seconds},
                                {"trace_seconds", summary.trace_seconds},
                                {"write_seconds", summary.write_seconds},
                                {"rays", summary.rays},
                                {"mrays_per_second", mrays}};
        std::printf("%s\n", event.dump().c_str());
    } else {
        if (mode_ == ProgressMode::lines && !summary.interrupted && summary.failed == 0)
            maybe_progress_line_locked(true);
        std::printf("%s%zu frame%s: %zu rendered, %zu skipped, %zu failed",
                    summary.interrupted ? "interrupted: " : "done: ", frame_count_,
                    frame_count_ == 1 ? "" : "s", summary.rendered, summary.skipped,
                    summary.failed);
        if (summary.interrupted_frames > 0)
            std::printf(", %zu interrupted", summary.interrupted_frames);
        if (summary.not_started > 0) std::printf(", %zu not started", summary.not_started);
        // The run and its phases in milliseconds' precision when short: "0.0s" says
        // nothing.
        const auto phase = [](double seconds) {
            if (seconds >= 10.0) return format_duration(seconds);
            char text[32];
            std::snprintf(text, sizeof text, "%.3fs", seconds);
            return std::string(text);
        };
        std::printf(" in %s: prepare %s, trace %s (%.2f Mrays/s), write %s\n",
                    phase(summary.seconds).c_str(), phase(summary.prepare_seconds).c_str(),
                    phase(summary.trace_seconds).c_str(), mrays,
                    phase(summary.write_seconds).c_str());
        // What to do next: the finished frames stay, so the same command with
        // --skip-existing renders only the rest.
        if (summary.interrupted && summary.interrupted_frames + summary.not_started > 0)
            std::printf(
                "resume with --skip-existing: the same command renders only the "
                "frames not finished\n");
    }
    std::fflush(stdout);
}

}  // namespace octray::tools
