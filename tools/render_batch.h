#pragma once
// The frame loop of `octray render`: claims, skips, renders and writes each frame of a
// batch, reports progress, survives failed frames and Ctrl-C, and ends with a summary
// and an exit status (tools/README.md, "Batch rendering").

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "kernels/isa.h"
#include "render/accel.h"
#include "render/aov.h"
#include "render/image_io.h"
#include "render/types.h"
#include "scene/scene.h"
#include "tools/batch.h"
#include "tools/progress.h"

namespace octray::tools {

struct BatchScene {
    std::string spec;               // as given on the command line
    std::string name;               // {scene} in output patterns
    std::string sha256;             // octray.sceneSha256
    Scene scene;                    // loaded, overrides applied, validated
    std::optional<PixelRect> crop;  // --crop, checked against the image
    double load_seconds = 0.0;      // reading (and hashing) and parsing it, for --stats
};

struct BatchJob {
    std::size_t scene = 0;  // index into the scenes
    int frame = 0;
    std::string output;
    std::string png;  // empty: no preview
};

struct BatchSettings {
    RenderPath path = RenderPath::simd;
    Isa isa = Isa::automatic;  // resolved (simd path)
    RenderOptions options;     // threads, tiles, accel; frame/crop/cancel set per frame
    ExrWriteOptions exr;
    AovSet aovs;
    bool progressive = false;
    // -o names PNG files: each job's output is the 8-bit sRGB preview, its png empty.
    bool png_output = false;
    bool skip_existing = false;
    bool placeholders = false;
    ProgressMode progress = ProgressMode::lines;
    // --stats: each frame's phases (load, compile, BVH, render, write) on stderr.
    bool stats = false;
};

// The jobs of one shard: positions k of the whole list with k % count == index.
std::vector<BatchJob> select_jobs(const std::vector<BatchJob>& jobs, batch::Shard shard);

// --aov and --accel values, as UsageErrors when bad.
AovSet parse_aov_option(const std::string& text);
Accel parse_accel_option(const std::string& text);

// Renders every job; returns the exit status (commands.h, plus 128 + signal when
// interrupted). Prints progress and the summary.
int run_batch(const std::vector<BatchScene>& scenes, const std::vector<BatchJob>& jobs,
              const BatchSettings& settings);

}  // namespace octray::tools
