#pragma once
// The frame loop of a batch render: claims, skips, renders and writes each frame of a
// list of jobs (plan.h), survives failed frames, stops when its cancel flag is set, and
// reports everything to an observer (observer.h). tools/README.md, "Batch rendering",
// describes what it does from the user's side.

#include <atomic>
#include <string>
#include <vector>

#include "kernels/isa.h"
#include "render/aov.h"
#include "render/batch/observer.h"
#include "render/batch/plan.h"
#include "render/image/image_io.h"
#include "render/render_config.h"
#include "render/render_result.h"

namespace octray::batch {

struct BatchSettings {
    // How each frame renders (render/render_config.h): path, ISA (resolved:
    // RenderConfig::resolve_isa), acceleration, threads, tiles and AOVs. Its crop and
    // overrides are not read here: each scene carries its own (BatchInput::crop, and the
    // overrides applied when it was loaded: BatchRequest).
    RenderConfig render;
    ExrWriteOptions exr;
    bool progressive = false;
    // The outputs are PNG files: each job's output is the 8-bit sRGB preview, its png empty.
    bool png_output = false;
    bool skip_existing = false;
    bool placeholders = false;
    // Write behind: a frame's files are written while the next frame renders (at most one
    // frame in flight; its image and encoded channels are memory a run holds twice:
    // RenderMemoryParams::write_behind). The writer reports it once its files are on
    // disk, which may be after the next frame started. Not for --progressive, whose passes are
    // written as they finish.
    bool write_behind = false;
};

// The render path as the EXR attribute octray.path names it: "scalar", "simd (avx2)"
// (settings.render.path_label()).
std::string render_path_label(const BatchSettings& settings);

// The header attributes `octray render` writes with frame `frame` of `scene` (posed as
// `posed`: its spp and depth; seen through `camera`): software, capture date, the scene's spec
// and SHA-256, `path_label` (render_path_label), seed, spp, depth, frame and time, the ray
// counts and render time of `result`, the camera matrices and the frame rate; and for an
// unfinished progressive image (samples_so_far < the spp) the samples so far and `owner`.
ExrAttributes render_exr_attributes(const BatchInput& scene, const Scene& posed,
                                    const Camera& camera, int frame, const RenderResult& result,
                                    const std::string& path_label, int samples_so_far,
                                    const std::string& owner);

// Renders every job in order on at most settings.render.threads threads (0: every core)
// and returns the summary. Each frame is reported to the observer once, in job order; with
// settings.write_behind a frame is reported by the thread that wrote it, as soon as its
// files are on disk, which may be while the next frame renders (after its frame_started;
// the observer's calls never overlap). A frame that fails is reported and the others go
// on. Once *cancel is set (a signal handler may set it), the frame in progress is
// abandoned at its next tile, leaving nothing half-written and its claim released, and no
// further frame starts; `cancel` may be nullptr.
BatchSummary run_batch(const std::vector<BatchInput>& scenes, const std::vector<BatchJob>& jobs,
                       const BatchSettings& settings, BatchObserver& observer,
                       const std::atomic<bool>* cancel);

}  // namespace octray::batch
