// `octray render`: load scenes, apply command-line overrides, then render a list of frames
// (one still by default; animations, frame ranges, several scenes, shards of a farm job)
// to EXR (+ PNG previews). Planning and the frame loop are the library octray::batch
// (render/batch/); this file reads the options, checks them and reports.

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "core/thread_check.h"
#include "kernels/dispatch.h"
#include "render/aov.h"
#include "render/batch/frame_loop.h"
#include "render/batch/memory_estimate.h"
#include "render/batch/output_paths.h"
#include "render/batch/plan.h"
#include "render/batch/spec.h"
#include "render/image/image_io.h"
#include "scene/animation.h"
#include "scene/builtin.h"
#include "scene/load.h"
#include "scene/max_depth.h"
#include "scene/scene.h"
#include "scene/scene_error.h"
#include "tools/cli_checks.h"
#include "tools/commands.h"
#include "tools/interrupt.h"
#include "tools/progress.h"

namespace octray::tools {
namespace {

namespace fs = std::filesystem;

// ---- Options ---------------------------------------------------------------------------

struct RenderArguments {
    std::vector<std::string> scenes{"whitted"};
    std::string output;  // a pattern; empty: {scene}.exr, or {scene}.####.exr for sequences
    std::string frames;
    std::string shard;
    int shard_count = 0;
    bool skip_existing = false;
    bool placeholders = false;
    bool stats = false;
    bool quiet = false;
    std::string crop;
    std::string aov;
    std::string progress = "auto";
    bool progressive = false;
    std::string max_memory;
    int width = 0, height = 0, spp = 0, max_depth = 0;
    std::uint64_t seed = 0;
    int threads = 0;
    std::string path{"simd"};
    std::string isa = "auto";
    std::string accel = "auto";
    std::string png;
    bool float32 = false;
    std::string compression{to_string(ExrWriteOptions{}.compression)};
    std::string tile = tile_size_name(TileSize{});
    // Set only when the user gave the option, so the scene's own value stays otherwise.
    CLI::Option* width_option = nullptr;
    CLI::Option* height_option = nullptr;
    CLI::Option* spp_option = nullptr;
    CLI::Option* max_depth_option = nullptr;
    CLI::Option* seed_option = nullptr;
    CLI::Option* shard_count_option = nullptr;
    CLI::Option* compression_option = nullptr;
};

// ---- Pre-flight: everything that can be checked before the first frame ----------------

// The library's RequestError is a mistake on the command line: exit 2, as a parse error.
template <class F>
auto usage_errors(F&& f) -> decltype(f()) {
    try {
        return f();
    } catch (const batch::RequestError& e) {
        throw UsageError(e.what());
    }
}

// What the options ask of octray::batch, as its plain request, with the scene overrides
// of the render's description.
batch::BatchRequest batch_request(const RenderArguments& args, const RenderConfig& config) {
    batch::BatchRequest request;
    request.overrides = config.overrides;
    request.threads = config.threads;
    request.frames = args.frames;
    request.output = args.output;
    request.png = args.png;
    return request;
}

// The description of the render (render/render_config.h) that the options give, its
// settings parsed and checked there; a bad one is a usage error naming its option.
RenderConfig render_config(const RenderArguments& args) {
    RenderConfig config;
    try {
        config.set_path(args.path);
        config.set_isa(args.isa);
        config.set_accel(args.accel);
        config.set_tile(args.tile);
        if (!args.aov.empty()) config.set_aovs(args.aov);
        config.threads = args.threads;
        // The overrides only where the user gave the option, so the scene's own value
        // stays otherwise.
        if (args.width_option->count()) config.overrides.width = args.width;
        if (args.height_option->count()) config.overrides.height = args.height;
        if (args.spp_option->count()) config.overrides.spp = args.spp;
        if (args.max_depth_option->count()) config.overrides.max_depth = args.max_depth;
        if (args.seed_option->count()) config.overrides.seed = args.seed;
        config.check();
        config.resolve_isa();
    } catch (const ConfigError& e) {
        const std::string option = e.setting() == "aovs" ? "aov" : e.setting();
        throw UsageError("--" + option + ": " + e.detail());
    }
    return config;
}

// The exit status of a finished run (commands.h, plus 128 + the signal when interrupted).
int exit_status(const batch::BatchSummary& summary) {
    if (summary.interrupted) return 128 + InterruptGuard::signal_number();
    if (summary.scene_failure) return kExitScene;
    if (summary.io_failure) return kExitIo;
    if (summary.internal_failure) return kExitInternal;
    return kExitSuccess;
}

// The format of -o, from its extension: OpenEXR, or the 8-bit sRGB PNG that --png writes.
// A PNG holds 8-bit R, G, B and no header attributes, so the options that only an EXR can
// carry are refused with it rather than silently dropped.
ImageFormat output_format(const RenderArguments& args) {
    if (args.output.empty()) return ImageFormat::exr;
    const ImageFormat format =
        require_image_format("-o", args.output, /*png_accepted=*/true,
                             "--png FILE.png writes an 8-bit PNG preview next to an EXR -o");
    if (format == ImageFormat::exr) return format;
    const std::string png = "-o " + args.output + " writes an 8-bit sRGB PNG";
    if (!args.png.empty())
        throw UsageError(png +
                         " already; --png adds a PNG preview next to an OpenEXR -o "
                         "(-o FILE.exr --png FILE.png writes both)");
    if (!args.aov.empty())
        throw UsageError(png + ", which holds R, G, B only; --aov needs an OpenEXR -o (.exr)");
    if (args.float32)
        throw UsageError(png + "; --float sets the channel type of an OpenEXR -o (.exr)");
    if (args.compression_option->count())
        throw UsageError(png + "; --compression is the codec of an OpenEXR -o (.exr)");
    if (args.progressive)
        throw UsageError(png +
                         "; --progressive needs an OpenEXR -o (.exr): it marks an unfinished "
                         "pass in the EXR header (octray.samplesSoFar), which a PNG cannot "
                         "carry, so a resume could not tell it from a finished frame");
    return format;
}

batch::Shard resolve_shard(const RenderArguments& args) {
    try {
        if (args.shard == "auto") {
            std::optional<int> count;
            if (args.shard_count_option->count()) count = args.shard_count;
            return batch::shard_from_environment(
                [](const char* name) { return std::getenv(name); }, count);
        }
        if (args.shard_count_option->count())
            throw UsageError("--shard-count goes with --shard auto (Kubernetes Indexed Jobs)");
        return batch::parse_shard(args.shard);
    } catch (const batch::SpecError& e) {
        throw UsageError(std::string("--shard: ") + e.what());
    }
}

void run_render(const RenderArguments& args) {
    // Everything about the command line first: no render time is spent on a bad one.
    batch::BatchSettings settings;
    settings.render = render_config(args);
    const auto compression = parse_exr_compression(args.compression);
    if (!compression) throw UsageError("--compression: unknown codec " + args.compression);
    settings.exr = {args.float32, *compression};
    settings.progressive = args.progressive;
    settings.png_output = output_format(args) == ImageFormat::png;
    settings.skip_existing = args.skip_existing;
    settings.placeholders = args.placeholders;
    const auto progress = parse_progress_mode(args.progress, ::isatty(STDERR_FILENO) == 1);
    if (!progress) throw UsageError("--progress: expected auto, bar, lines, json or none");
    const std::uint64_t memory_limit = max_memory_limit(args.max_memory);  // 0: no limit
    batch::Shard shard{0, 1};
    if (!args.shard.empty())
        shard = resolve_shard(args);
    else if (args.shard_count_option->count())
        throw UsageError("--shard-count goes with --shard auto (Kubernetes Indexed Jobs)");

    const auto limit_note = [&] {
        return args.max_memory.empty()
                   ? std::string(
                         " (the limit is this machine's memory; --max-memory sets another)")
                   : " (--max-memory " + args.max_memory + ")";
    };
    // A scene file too large to parse within the limit is refused from its size, before
    // any scene is read.
    std::map<std::string, std::uint64_t> file_sizes;
    for (const std::string& spec : args.scenes) {
        if (is_builtin_scene(spec)) continue;
        std::error_code error;
        const fs::file_status status = fs::status(spec, error);
        if (error || !fs::is_regular_file(status)) continue;  // the loader says why
        const std::uint64_t size = fs::file_size(spec, error);
        if (error) continue;
        file_sizes[spec] = size;
        if (memory_limit > 0) {
            try {
                batch::check_load_memory_limit(spec, size, memory_limit);
            } catch (const SceneError& e) {
                throw UsageError(e.what() + limit_note());
            }
        }
    }

    // Before oneTBB starts a worker (loading a scene file may): it would abort where they
    // cannot all start (ulimit -v); this says so instead, exit 1.
    check_threads_can_start(args.threads);
    const batch::BatchRequest request = batch_request(args, settings.render);
    std::vector<batch::BatchInput> scenes;
    for (const std::string& spec : args.scenes) {
        scenes.push_back(usage_errors([&] { return batch::load_batch_input(spec, request); }));
        print_scene_warnings(scenes.back().scene, args.quiet);
    }

    batch::RenderMemoryParams memory = batch::memory_params(settings.render);
    memory.float32_output = args.float32;
    memory.exr_lines_per_chunk = exr_lines_per_chunk(*compression);
    memory.png_preview = !args.png.empty();
    memory.progressive = args.progressive;
    // A frame is written while the next one renders (--progressive writes its passes as
    // they finish).
    bool write_behind = !args.progressive;
    memory.write_behind = write_behind;
    for (batch::BatchInput& scene : scenes) {
        if (!args.crop.empty()) {
            try {
                scene.crop = batch::parse_crop(args.crop, scene.scene.image.width,
                                               scene.scene.image.height);
            } catch (const batch::SpecError& e) {
                throw UsageError("--crop for " + scene.spec + ": " + e.what());
            }
        }
        if (memory_limit > 0) {
            const auto size = file_sizes.find(scene.spec);
            memory.scene_file_bytes = size != file_sizes.end() ? size->second : 0;
            // Writing a frame while the next renders holds a second frame: within the
            // limit, or the frames are written one after another instead.
            try {
                batch::fit_memory_limit(scene.scene, memory_limit, memory);
                write_behind = write_behind && memory.write_behind;
            } catch (const SceneError& e) {
                throw UsageError(e.what() + limit_note());
            }
        }
    }

    std::vector<batch::BatchJob> jobs =
        usage_errors([&] { return batch::plan_jobs(scenes, request); });
    const std::size_t planned = jobs.size();
    jobs = batch::select_shard(jobs, shard);
    settings.write_behind = write_behind && jobs.size() > 1;
    // On stderr, so that standard output stays the progress format (--progress json).
    for (const std::string& dir : batch::prepare_output_directories(jobs))
        std::fprintf(stderr, "octray: created output directory %s/\n", dir.c_str());
    if (shard.count > 1 && *progress != ProgressMode::json)
        std::printf("shard    %d/%d: %zu of %zu frames\n", shard.index, shard.count,
                    jobs.size(), planned);

    int status = kExitSuccess;
    {
        InterruptGuard interrupt;  // Ctrl-C and SIGTERM set the flag the frame loop polls
        ProgressReporter reporter(*progress, args.stats);
        status = exit_status(
            batch::run_batch(scenes, jobs, settings, reporter, &InterruptGuard::flag()));
    }
    // Every frame is on disk (or reported failed) and the summary printed: the scenes are
    // not freed one object at a time.
    end_command(status);
}

}  // namespace

void add_render_command(CLI::App& app, CommandRunner& run) {
    auto args = std::make_shared<RenderArguments>();
    CLI::App* cmd =
        app.add_subcommand("render", "Render scenes, stills or animations, to OpenEXR images");

    cmd->add_option("scenes", args->scenes,
                    "Scenes: JSON files or built-ins (whitted, random:N, sphereflake:L, each\n"
                    "with optional ,width=W,height=H,spp=N,seed=S,max_depth=D); several are\n"
                    "rendered one after another")
        ->type_name("SCENE...")
        ->check(completes(builtin_scene_words()))
        ->capture_default_str();
    cmd->add_option("-o,--output", args->output,
                    "Output file or pattern: # runs or {frame:04d} become the frame\n"
                    "number, {scene} the scene's name. The extension (any case) picks the\n"
                    "format: .exr OpenEXR, .png the 8-bit sRGB preview --png writes (no\n"
                    "--png, --aov, --float, --compression or --progressive with it)\n"
                    "[default: {scene}.exr for a still, {scene}.####.exr for a sequence,\n"
                    "in the current directory]")
        ->type_name("PATTERN");
    cmd->add_option("--frames", args->frames,
                    "Frames to render: 5, 1-100, 1-100:2 (every 2nd), lists: 1-10,20,30-40:5\n"
                    "[default: the scene's animation frames 0..frames-1, or 0 for a still]")
        ->type_name("SPEC");
    cmd->add_option(
           "--shard", args->shard,
           "Render only the i-th of n interleaved subsets of the frame list: i/n with\n"
           "0 <= i < n, or auto: Slurm's SLURM_ARRAY_TASK_ID/SLURM_ARRAY_TASK_COUNT\n"
           "(minus SLURM_ARRAY_TASK_MIN), or Kubernetes' JOB_COMPLETION_INDEX with\n"
           "--shard-count")
        ->type_name("i/n|auto");
    args->shard_count_option =
        cmd->add_option("--shard-count", args->shard_count,
                        "The number of shards for --shard auto with JOB_COMPLETION_INDEX, " +
                            integer_range_text(1, kMaxShardCount))
            ->type_name("N")
            ->transform(decimal_integer(1, kMaxShardCount));
    cmd->add_flag("--skip-existing", args->skip_existing,
                  "Resume: leave frames whose outputs (the EXR and the --png preview) all\n"
                  "exist (outputs are written atomically, so an existing file is finished;\n"
                  "an empty one is a --placeholders claim, an unfinished --progressive image\n"
                  "the claim of the run writing it while that run lives)");
    cmd->add_flag("--placeholders", args->placeholders,
                  "Claim each frame with an empty output file before rendering it, so runs\n"
                  "sharing one output directory never render a frame twice (empty claims of\n"
                  "a run that crashed stay: delete empty files to release them; unfinished\n"
                  "--progressive images of a run gone from this host are taken over)");
    cmd->add_flag("--stats", args->stats,
                  "After each frame, print the seconds of each phase on stderr: load (read,\n"
                  "hash and parse the scene, once per scene), compile, BVH, render, write");
    cmd->add_flag("-q,--quiet", args->quiet, kQuietHelp);
    cmd->add_option("--crop", args->crop,
                    "Render only pixels x0..x1-1, y0..y1-1 (row 0 on top) into an EXR whose\n"
                    "data window is that region; `octray assemble` stitches regions together")
        ->type_name("x0,y0,x1,y1");
    cmd->add_option(
           "--aov", args->aov,
           "Extra channels from each pixel's first camera ray: depth (Z), normal\n"
           "(N.X N.Y N.Z), albedo (albedo.R albedo.G albedo.B), id (UINT, object index\n"
           "+ 1, 0 = background); comma-separated")
        ->type_name("LIST")
        ->check(completes({"depth", "normal", "albedo", "id"}));
    cmd->add_option("--progress", args->progress,
                    "auto (bar on a terminal, else lines), bar, lines (one line per frame and\n"
                    "'Progress: NN%' lines), json (one JSON object per line), none")
        ->type_name("MODE")
        ->check(one_of({"auto", "bar", "lines", "json", "none"}))
        ->capture_default_str();
    cmd->add_flag("--progressive", args->progressive,
                  "Render each frame in passes of 1, 2, 4, ... samples per pixel, rewriting\n"
                  "the image after each; the final image equals the plain render bit for bit");
    cmd->add_option("--max-memory", args->max_memory,
                    "Refuse a render whose memory estimate exceeds this (512M, 4G, ...);\n"
                    "a scene file is first checked from its size, before it is parsed\n"
                    "[default: this machine's physical memory]")
        ->type_name("SIZE");
    args->width_option =
        cmd->add_option("--width", args->width,
                        "Image width in pixels, " + integer_range_text(1, kMaxImageSide) +
                            " (overrides the scene)")
            ->type_name("W")
            ->transform(decimal_integer(1, kMaxImageSide));
    args->height_option =
        cmd->add_option("--height", args->height,
                        "Image height in pixels, " + integer_range_text(1, kMaxImageSide) +
                            " (overrides the scene)")
            ->type_name("H")
            ->transform(decimal_integer(1, kMaxImageSide));
    args->spp_option =
        cmd->add_option("--spp", args->spp,
                        "Samples per pixel, " + integer_range_text(1, kMaxSamples) +
                            "; square counts are stratified, others\n"
                            "jittered (overrides the scene)")
            ->type_name("N")
            ->transform(decimal_integer(1, kMaxSamples));
    args->max_depth_option =
        cmd->add_option("--max-depth", args->max_depth,
                        "Reflection/refraction bounces, " +
                            integer_range_text(0, kMaxDepthLimit) +
                            "; 0 = primary rays only\n(overrides the scene)")
            ->type_name("D")
            ->transform(decimal_integer(0, kMaxDepthLimit));
    args->seed_option =
        cmd->add_option("--seed", args->seed,
                        "Seed of the sample jitter, " +
                            integer_range_text(0, std::numeric_limits<std::uint64_t>::max()) +
                            "\n(overrides the scene)")
            ->type_name("S")
            ->transform(decimal_integer(0, std::numeric_limits<std::uint64_t>::max()));
    cmd->add_option("--threads", args->threads,
                    "Worker threads, " + integer_range_text(0, kMaxThreadCount) +
                        "; 0 = every core available (the image does not\n"
                        "depend on it)")
        ->type_name("N")
        ->transform(decimal_integer(0, kMaxThreadCount))
        ->capture_default_str();
    cmd->add_option("--path", args->path,
                    "Render path: simd (8-ray packets) or scalar (the reference renderer);\n"
                    "both give the same image")
        ->type_name("PATH")
        ->check(one_of({"scalar", "simd"}))
        ->capture_default_str();
    cmd->add_option(
           "--isa", args->isa,
           "Instruction set of the simd path: auto (the best this CPU has), avx512,\n"
           "avx2, sse4.1 or sse2 (`octray info` lists them; the image does not depend on it)")
        ->type_name("ISA")
        ->check(one_of({"auto", "avx512", "avx2", "sse4.1", "sse2"}))
        ->capture_default_str();
    cmd->add_option("--accel", args->accel,
                    "Sphere acceleration: auto (simd: a BVH above a measured sphere count;\n"
                    "scalar: its own BVH), bvh, or none (every ray against every object: the\n"
                    "scalar reference at its most literal); the image does not depend on it")
        ->type_name("MODE")
        ->check(one_of({"auto", "bvh", "none"}))
        ->capture_default_str();
    cmd->add_option("--png", args->png,
                    "Also write an 8-bit sRGB PNG preview (clamped to [0,1]) next to an\n"
                    "OpenEXR -o; a pattern like -o. Always PNG, whatever the name; it must\n"
                    "name another file than -o")
        ->type_name("FILE");
    cmd->add_flag("--float", args->float32, "Write 32-bit float channels instead of half");
    args->compression_option =
        cmd->add_option("--compression", args->compression,
                        "EXR codec: none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa, dwab\n"
                        "(pxr24 is lossy for --float; b44*, dwa* are lossy)")
            ->type_name("C")
            ->check(one_of(
                {"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"}))
            ->capture_default_str();
    cmd->add_option("--tile", args->tile,
                    "Tile size WxH (or N for NxN), sides " +
                        integer_range_text(1, kMaxTileSide) +
                        ", handed to the worker threads;\nthe image does not depend on it")
        ->type_name("WxH")
        ->transform(tile_size(kMaxTileSide))
        ->capture_default_str();
    cmd->footer(
        "Examples:\n"
        "  octray render                                  # whitted scene -> whitted.exr\n"
        "  octray render whitted -o whitted.exr --png whitted.png\n"
        "  octray render whitted -o whitted.png            # only the 8-bit sRGB PNG\n"
        "  octray render random:1024,width=640,height=360 --spp 4 -o random.exr\n"
        "  octray render shot.json --frames 1-100:2,150 -o out/shot.####.exr\n"
        "  octray render a.json b.json -o 'out/{scene}.{frame:04d}.exr' --skip-existing\n"
        "  octray render shot.json --shard auto --placeholders -o out/shot.####.exr\n"
        "  octray render whitted --crop 0,0,640,360 -o part0.exr   # then octray assemble\n\n"
        "Each frame's randomness is hash(seed, frame): a frame rendered alone equals the same\n"
        "frame of a whole sequence. Files are written to a hidden temporary and renamed, so "
        "an\n"
        "output is either complete or absent. A frame that fails is reported and the others\n"
        "go on. Ctrl-C (or SIGTERM) stops after abandoning the frame in progress; a second\n"
        "one kills at once.\n\n"
        "The EXR carries software, capDate, utcOffset, samplesPerPixel, framesPerSecond,\n"
        "worldToCamera, worldToNDC (not for a fisheye), renderTimeSeconds, and octray.scene,\n"
        "octray.sceneSha256, "
        "octray.frame, octray.time, octray.path, octray.seed, octray.maxDepth,\n"
        "octray.rays.{primary,shadow,reflected,refracted,total}.\n\n" +
        exit_code_help() +
        "  3  also: a frame failed with a scene error (not worth retrying)\n"
        "  4  also: frames failed only with I/O errors (worth retrying: --skip-existing)\n"
        "130  interrupted by Ctrl-C (SIGINT); 143 by SIGTERM; finished frames stay\n"
        "     (resume: the same command with --skip-existing)\n");
    cmd->callback([args, &run] { run.action = [args] { run_render(*args); }; });
}

}  // namespace octray::tools
