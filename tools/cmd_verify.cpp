// `octray verify SCENE`: renders the scene with the scalar reference and with the SIMD
// packet path and compares them with the compare library (render/image/image_compare.h):
// max abs error, RMSE, PSNR, the share of pixels over the fail threshold and the worst
// pixel with both values. The two paths promise identical bits, so the default is exact
// (every threshold 0); a tolerance can be given. --frames verifies frames of an animated
// scene. Exit 0 within the thresholds, 1 otherwise.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/thread_check.h"
#include "kernels/dispatch.h"
#include "render/batch/memory_estimate.h"
#include "render/batch/output_paths.h"
#include "render/batch/spec.h"
#include "render/image/error_heatmap.h"
#include "render/image/image_compare.h"
#include "render/image/image_read.h"
#include "render/packet_renderer.h"
#include "render/reference.h"
#include "render/render_config.h"
#include "scene/animation.h"
#include "scene/load.h"
#include "tools/cli_checks.h"
#include "tools/commands.h"

namespace octray::tools {
namespace {

struct VerifyArguments {
    std::string scene = "whitted";
    int width = 0, height = 0, spp = 0;
    int threads = 0;
    std::string isa = "auto";
    std::string frames;         // --frames; empty: frame 0
    double fail = 0.0;          // a pixel fails when a channel is off by more
    double fail_percent = 0.0;  // ... and at most this % of the pixels may
    double hard_fail = 0.0;     // no value may be off by more
    bool quiet = false;
    std::string diff;     // --diff FILE.exr: |scalar - simd|, as compare writes it
    std::string heatmap;  // --heatmap FILE.png: the error picture, as compare draws it
};

// The file of `frame` when several frames are verified: "diff.exr" -> "diff.0012.exr".
std::string frame_file(const std::string& path, int frame, bool several) {
    if (!several) return path;
    const std::size_t slash = path.rfind('/');
    std::size_t dot = path.rfind('.');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash) ||
        dot == (slash == std::string::npos ? 0 : slash + 1))
        dot = path.size();
    char number[16];
    std::snprintf(number, sizeof number, ".%04d", frame);
    return path.substr(0, dot) + number + path.substr(dot);
}

// Renders frame `frame` of the posed `scene` with both paths and reports; true when they
// agree. The frame number is the samples' hash counter, as `octray render` sets it, so the
// jitter checked is the frame's own. `diff` and `heatmap` name the pictures of this frame,
// or are empty.
bool verify_frame(const VerifyArguments& args, const Scene& scene, int frame,
                  const RenderConfig& config, const std::string& diff,
                  const std::string& heatmap) {
    const Isa isa = config.isa;
    RenderOptions options = config.render_options();
    options.frame = static_cast<std::uint32_t>(frame);
    const RenderResult ref = render_reference(scene, options);
    const RenderResult simd = render_packet(scene, options, isa);
    std::printf("scalar   %.3f s, %llu rays\n", ref.seconds,
                static_cast<unsigned long long>(ref.rays.total()));
    std::printf("simd     %.3f s, %llu rays (%s), %.2fx\n", simd.seconds,
                static_cast<unsigned long long>(simd.rays.total()), isa_name(isa),
                simd.seconds > 0.0 ? ref.seconds / simd.seconds : 0.0);

    CompareOptions compare;
    compare.fail_threshold = compare.warn_threshold = args.fail;
    compare.fail_percent = compare.warn_percent = args.fail_percent;
    compare.hard_fail = compare.hard_warn = args.hard_fail;
    const Image& scalar_channels = ref.image;
    const Image& simd_channels = simd.image;
    const CompareResult r = compare_images(scalar_channels, simd_channels, compare);
    const ErrorStats& all = r.overall;
    // The pictures compare writes, A the scalar image and B the simd one.
    if (!diff.empty()) {
        write_exr(diff, difference_image(scalar_channels, simd_channels, r));
        std::printf("wrote    %s (|scalar - simd|, float)\n", diff.c_str());
    }
    if (!heatmap.empty()) {
        const ErrorHeatmap map =
            write_error_heatmap(heatmap, scalar_channels, simd_channels, r);
        std::printf("wrote    %s (error heatmap, %s: %g to %g)\n", heatmap.c_str(),
                    map.legend.c_str(), map.scale_min, map.scale_max);
    }

    std::size_t identical = 0;
    for (int y = 0; y < ref.image.height(); ++y)
        for (int x = 0; x < ref.image.width(); ++x)
            identical += rgb_at(ref.image, x, y) == rgb_at(simd.image, x, y) ? 1 : 0;
    std::printf("max abs  %.6g\n", all.max_abs_error);
    std::printf("rmse     %.6g\n", all.rmse);
    std::printf("psnr     %.2f dB\n", all.psnr);
    std::printf("over     %.4f%% of pixels differ by more than %g (%llu pixels)\n",
                all.fail_percent, args.fail, static_cast<unsigned long long>(all.fail_pixels));
    std::printf("worst    pixel (%d, %d) %s: scalar %.9g, simd %.9g\n", all.worst.x,
                all.worst.y, all.worst.channel.c_str(), all.worst.a, all.worst.b);
    std::printf("exact    %zu of %zu pixels bit-identical\n", identical,
                ref.image.pixel_count());
    const bool same_rays =
        ref.rays.primary == simd.rays.primary && ref.rays.shadow == simd.rays.shadow &&
        ref.rays.reflected == simd.rays.reflected && ref.rays.refracted == simd.rays.refracted;
    if (!same_rays) std::printf("rays     the two paths traced different numbers of rays\n");
    const bool pass = r.verdict == Verdict::pass && same_rays;
    std::printf("%s\n", pass ? "PASS" : ("FAIL: " + r.reason).c_str());
    std::fflush(stdout);
    return pass;
}

void run_verify(const VerifyArguments& args) {
    check_threads_can_start(args.threads);  // before oneTBB starts a worker (ulimit -v)
    // The description of the simd side's render (render/render_config.h).
    RenderConfig config;
    try {
        config.set_isa(args.isa);
        config.threads = args.threads;
        if (args.width > 0) config.overrides.width = args.width;
        if (args.height > 0) config.overrides.height = args.height;
        if (args.spp > 0) config.overrides.spp = args.spp;
        config.check();
        config.resolve_isa();
    } catch (const ConfigError& e) {
        throw UsageError("--" + e.setting() + ": " + e.detail());
    }
    std::vector<int> frames{0};
    if (!args.frames.empty()) {
        try {
            frames = batch::parse_frame_spec(args.frames);
        } catch (const batch::SpecError& e) {
            throw UsageError(std::string("--frames: ") + e.what());
        }
    }
    if (!args.diff.empty())
        require_image_format("--diff", args.diff, /*png_accepted=*/false,
                             "--diff is |scalar - simd| in float; for a PNG picture of the "
                             "error use --heatmap FILE.png");
    if (!args.diff.empty() && !args.heatmap.empty() &&
        batch::output_identity(args.diff) == batch::output_identity(args.heatmap))
        throw UsageError("--diff and --heatmap name the same file: " + args.diff + " and " +
                         args.heatmap);
    Scene scene = load_scene(args.scene);
    print_scene_warnings(scene, args.quiet);
    apply_overrides(scene, config.overrides);
    validate_scene(scene);
    // Both renders' framebuffers must fit in this machine's memory; the estimate counts one
    // render (render/batch/memory_estimate.h). A scene's validity does not depend on the
    // machine.
    if (const std::uint64_t memory = batch::machine_memory_bytes(); memory > 0)
        batch::check_memory_limit(scene, memory);

    std::printf("scene    %s (%zu objects, %zu lights%s), %dx%d, %d spp\n", args.scene.c_str(),
                scene.objects.size(), scene.lights.size(), scene.animation ? ", animated" : "",
                scene.image.width, scene.image.height, scene.image.spp);
    std::printf("check    %s\n",
                args.fail == 0.0 && args.fail_percent == 0.0 && args.hard_fail == 0.0
                    ? "exact: every value equal (the default)"
                    : "within the tolerance given (--fail, --failpercent, --hardfail)");
    std::fflush(stdout);
    std::size_t failed = 0;
    for (const int frame : frames) {
        if (!args.frames.empty()) std::printf("frame    %d\n", frame);
        const bool several = frames.size() > 1;
        const std::string diff = args.diff.empty() ? "" : frame_file(args.diff, frame, several);
        const std::string heatmap =
            args.heatmap.empty() ? "" : frame_file(args.heatmap, frame, several);
        failed += verify_frame(args, args.frames.empty() ? scene : scene_at_frame(scene, frame),
                               frame, config, diff, heatmap)
                      ? 0
                      : 1;
    }
    if (frames.size() > 1) {
        if (failed == 0)
            std::printf("PASS: all %zu frames\n", frames.size());
        else
            std::printf("FAIL: %zu of %zu frames\n", failed, frames.size());
        std::fflush(stdout);
    }
    if (failed > 0) throw CommandExit{1};
}

}  // namespace

void add_verify_command(CLI::App& app, CommandRunner& run) {
    auto args = std::make_shared<VerifyArguments>();
    CLI::App* cmd = app.add_subcommand(
        "verify", "Render a scene with the scalar and the SIMD path and compare the images");
    cmd->add_option("scene", args->scene, "Scene: a JSON file or a built-in (as for render)")
        ->type_name("SCENE")
        ->check(completes(builtin_scene_words()))
        ->capture_default_str();
    cmd->add_option(
           "--width", args->width,
           "Image width, " + integer_range_text(1, kMaxImageSide) + " (overrides the scene)")
        ->type_name("W")
        ->transform(decimal_integer(1, kMaxImageSide));
    cmd->add_option(
           "--height", args->height,
           "Image height, " + integer_range_text(1, kMaxImageSide) + " (overrides the scene)")
        ->type_name("H")
        ->transform(decimal_integer(1, kMaxImageSide));
    cmd->add_option("--spp", args->spp,
                    "Samples per pixel, " + integer_range_text(1, kMaxSamples) +
                        " (overrides the scene)")
        ->type_name("N")
        ->transform(decimal_integer(1, kMaxSamples));
    cmd->add_option(
           "--threads", args->threads,
           "Worker threads, " + integer_range_text(0, kMaxThreadCount) + "; 0 = every core")
        ->type_name("N")
        ->transform(decimal_integer(0, kMaxThreadCount))
        ->capture_default_str();
    cmd->add_option("--frames", args->frames,
                    "Frames of an animated scene to verify, as render takes them: 5, 1-100,\n"
                    "1-100:2,150 [default: frame 0]")
        ->type_name("SPEC");
    cmd->add_option("--isa", args->isa,
                    "ISA of the simd path: auto, avx512, avx2, sse4.1, sse2")
        ->type_name("ISA")
        ->check(one_of({"auto", "avx512", "avx2", "sse4.1", "sse2"}))
        ->capture_default_str();
    cmd->add_option("--fail", args->fail,
                    "A pixel fails when any channel differs by more than X (" +
                        real_range_text(0.0, std::numeric_limits<double>::max(), true) +
                        "); 0 = exact")
        ->type_name("X")
        ->transform(real_number(0.0, std::numeric_limits<double>::max(), true))
        ->capture_default_str();
    cmd->add_option(
           "--failpercent", args->fail_percent,
           "FAIL when more than P% of the pixels fail, " + real_range_text(0.0, 100.0, false))
        ->type_name("P")
        ->transform(real_number(0.0, 100.0, false))
        ->capture_default_str();
    cmd->add_option("--hardfail", args->hard_fail,
                    "FAIL when any one error exceeds H (" +
                        real_range_text(0.0, std::numeric_limits<double>::max(), true) + ")")
        ->type_name("H")
        ->transform(real_number(0.0, std::numeric_limits<double>::max(), true))
        ->capture_default_str();
    cmd->add_option("--diff", args->diff,
                    "Write |scalar - simd| as float OpenEXR, as compare --diff does; FILE\n"
                    "must end in .exr (any case). With several --frames, each frame's\n"
                    "number goes before the extension (diff.0012.exr)")
        ->type_name("FILE.exr");
    cmd->add_option("--heatmap", args->heatmap,
                    "Write a PNG heatmap of the largest channel error per pixel, as compare\n"
                    "--heatmap draws it (magma, 0 to the max error; NaN/Inf in green)")
        ->type_name("FILE");
    cmd->add_flag("-q,--quiet", args->quiet, kQuietHelp);
    cmd->footer(
        "Examples:\n"
        "  octray verify whitted\n"
        "  octray verify random:64,width=320,height=180 --isa sse2\n"
        "  octray verify scene/examples/bounce.json --frames 0-47:8\n"
        "  octray verify scene.json --spp 4 --fail 1e-5 --failpercent 0.1  # a tolerance\n"
        "  octray verify scene.json --diff diff.exr --heatmap diff.png  # the error, drawn\n\n"
        "The two paths promise identical bits: by default every value must be equal\n"
        "(--fail 0 --failpercent 0 --hardfail 0).\n\n"
        "Exit codes: 0 within the thresholds (and equal ray counts) for every frame,\n"
        "1 otherwise;\n"
        "2 usage error, 3 scene error, as every command.\n");
    cmd->callback([args, &run] { run.action = [args] { run_verify(*args); }; });
}

}  // namespace octray::tools
