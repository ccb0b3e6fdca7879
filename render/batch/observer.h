#pragma once
// What the frame loop (frame_loop.h) tells whoever runs it: the run's start, each frame's
// start and end (rendered, skipped or failed, with its times and phases), the pixels done
// inside a frame, and the summary. `octray render` prints them as a bar, lines or JSON
// (tools/progress.h); a test records them. The loop calls an observer from its own
// thread only, never two calls at once; the renderers advance pixel_counter() from their
// worker threads.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "render/batch/plan.h"

namespace octray::batch {

enum class FrameOutcome { rendered, skipped_existing, skipped_claimed, failed };

struct FrameReport {
    std::size_t index = 0;   // 1-based position in this run's frame list
    std::string scene;       // BatchInput::name
    std::string scene_spec;  // BatchInput::spec, as given
    int frame = 0;
    std::string output;
    std::string preview;  // the PNG, if any
    FrameOutcome outcome = FrameOutcome::rendered;
    double seconds = 0.0;          // everything: claims, prepare, trace, write
    double prepare_seconds = 0.0;  // compile + BVH build (0 on a frame of a prepared scene)
    double trace_seconds = 0.0;    // rendering (AOVs included), what Mrays/s is over
    double write_seconds = 0.0;    // EXR and PNG encoding and writing (every progressive pass)
    std::uint64_t rays = 0;        // rendered frames
    std::string message;           // failed frames: the reason
    // Rendered frames, the phases of `--stats`: the scene's load (once per scene, on each
    // of its frames), compile and BVH build (prepare_seconds), and the render itself.
    double load_seconds = 0.0, compile_seconds = 0.0, bvh_seconds = 0.0, render_seconds = 0.0;
};

struct BatchSummary {
    std::size_t rendered = 0, skipped = 0, failed = 0, not_started = 0;
    // The frame the cancel flag stopped mid-render (0 or 1): abandoned, nothing written.
    std::size_t interrupted_frames = 0;
    double seconds = 0.0;  // wall time of the run, and of loading its scenes before it
    double prepare_seconds = 0.0, trace_seconds = 0.0, write_seconds = 0.0;  // rendered frames
    std::uint64_t rays = 0;
    bool interrupted = false;  // the cancel flag was set
    // What kinds of failure the failed frames had (a frame stopped by the cancel flag is
    // none of them): a SceneError, an IoError, anything else (a bug, out of memory).
    bool scene_failure = false, io_failure = false, internal_failure = false;
};

// What a run is about to do, before its first frame.
struct RunStart {
    const std::vector<BatchInput>& scenes;
    const std::vector<BatchJob>& jobs;
    std::string path;         // the render path as octray.path names it: "simd (avx2)"
    std::size_t threads = 0;  // the worker threads of the run
    int tile_width = 0, tile_height = 0;
    std::uint64_t total_work = 0;  // pixel samples of every frame (pixels x spp)
};

class BatchObserver {
  public:
    virtual ~BatchObserver() = default;

    virtual void run_started(const RunStart& start) { (void)start; }
    // The counter the renderers advance by each finished tile's pixel count, reset by the
    // observer in frame_started; nullptr: no pixel progress.
    virtual std::atomic<std::uint64_t>* pixel_counter() { return nullptr; }
    // Frame `index` (1-based) starts rendering: `work` pixel samples at `spp` per pixel.
    // Not called for a frame skipped or failed before it renders.
    virtual void frame_started(std::size_t index, const std::string& scene, int frame,
                               std::uint64_t work, int spp) {
        (void)index, (void)scene, (void)frame, (void)work, (void)spp;
    }
    // Every frame of the run ends here once, whatever its outcome, except the one the cancel
    // flag stops (the summary counts it as interrupted). `work`: its pixel samples.
    virtual void frame_finished(const FrameReport& report, std::uint64_t work) {
        (void)report, (void)work;
    }
    virtual void run_finished(const BatchSummary& summary) { (void)summary; }
};

}  // namespace octray::batch
