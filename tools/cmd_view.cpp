// `octray view`: its options (a scene rendering live in the browser, view/README.md). The
// viewer itself runs in octray-view (tools/own_executable.h, tools/view_run.cpp).

#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "scene/max_depth.h"
#include "tools/cli_checks.h"
#include "tools/commands.h"
#include "tools/own_executable.h"
#include "tools/view_arguments.h"

namespace octray::tools {

void add_view_command(CLI::App& app, CommandRunner& run) {
    auto args = std::make_shared<ViewArguments>();
    CLI::App* cmd = app.add_subcommand(
        "view", "Watch a scene render live in a web browser, and move its camera");
    cmd->add_option("scene", args->inputs,
                    "Scene file (JSON) or built-in spec, as for render (default whitted);\n"
                    "or two images A B (OpenEXR or PNG) to compare as octray compare does")
        ->type_name("SCENE | A B")
        ->check(completes(builtin_scene_words()))
        ->expected(1, 2);
    cmd->add_option("--bind", args->bind,
                    "Address to listen on; the default serves this machine only (use an\n"
                    "SSH tunnel, ssh -L 8090:127.0.0.1:8090 host, to watch a remote one)")
        ->type_name("ADDR")
        ->capture_default_str();
    cmd->add_option("--port", args->port,
                    "TCP port, " + integer_range_text(0, 65535) + "; 0 = a free one")
        ->type_name("PORT")
        ->transform(decimal_integer(0, 65535))
        ->capture_default_str();
    cmd->add_option("--width", args->width,
                    "Image width in pixels, " + integer_range_text(1, kMaxImageSide) +
                        " (overrides the scene)")
        ->type_name("W")
        ->transform(decimal_integer(1, kMaxImageSide));
    cmd->add_option("--height", args->height,
                    "Image height in pixels, " + integer_range_text(1, kMaxImageSide) +
                        " (overrides the scene)")
        ->type_name("H")
        ->transform(decimal_integer(1, kMaxImageSide));
    cmd->add_option("--spp", args->spp,
                    "Samples per pixel of the refined picture, " +
                        integer_range_text(1, kMaxSamples) +
                        ", reached in passes of 1, 2, 4, ...\n(overrides the scene)")
        ->type_name("N")
        ->transform(decimal_integer(1, kMaxSamples));
    cmd->add_option("--max-depth", args->max_depth,
                    "Reflection/refraction bounces, " + integer_range_text(1, kMaxDepthLimit) +
                        " (overrides the scene)")
        ->type_name("D")
        ->transform(decimal_integer(1, kMaxDepthLimit));
    cmd->add_option("--threads", args->threads,
                    "Render threads, " + integer_range_text(0, kMaxThreadCount) +
                        "; 0 = every core available")
        ->type_name("N")
        ->transform(decimal_integer(0, kMaxThreadCount))
        ->capture_default_str();
    cmd->add_option("--max-memory", args->max_memory,
                    "Refuse a scene whose memory estimate (as octray render's, for a\n"
                    "progressive render with a PNG) exceeds this (512M, 4G, ...)\n"
                    "[default: this machine's physical memory]")
        ->type_name("SIZE");
    cmd->add_option("--preview-divisor", args->preview_divisor,
                    "While the camera moves, render width/D x height/D at 1 spp, " +
                        integer_range_text(1, 64))
        ->type_name("D")
        ->transform(decimal_integer(1, 64))
        ->capture_default_str();
    cmd->add_option("--bench", args->bench,
                    "Serve nothing: measure the time to the first picture and the pictures\n"
                    "a second while the camera orbits, over N updates, " +
                        integer_range_text(1, 1000000) +
                        " (each rendered as a moving\ncamera is and encoded as the page is "
                        "sent it: JPEG)")
        ->type_name("N")
        ->transform(decimal_integer(1, 1000000));
    cmd->add_option(
           "--order", args->order,
           "Pixel order: tiled (whole pictures, progressive passes, previews while\n"
           "moving), rows (the same, one tile a row: row-major) or frameless (blocks\n"
           "of --frameless-block pixels re-rendered in a fixed random order and shown\n"
           "as they land, no frame boundaries; Bishop et al. 1994); the page can\n"
           "switch it")
        ->type_name("ORDER")
        ->check(one_of({"tiled", "rows", "frameless"}))
        ->capture_default_str();
    cmd->add_option("--frameless-block", args->frameless_block,
                    "Side in pixels of the frameless order's blocks, " +
                        integer_range_text(1, 64) +
                        ": 1 re-renders single pixels in a\nrandom order (each a packet with "
                        "one live ray of 8)")
        ->type_name("N")
        ->transform(decimal_integer(1, 64))
        ->capture_default_str();
    cmd->add_option("--path", args->path,
                    "Render path: simd (8-ray packets) or scalar (the reference renderer)")
        ->type_name("PATH")
        ->check(one_of({"scalar", "simd"}))
        ->capture_default_str();
    cmd->add_option("--isa", args->isa,
                    "Instruction set of the simd path: auto, avx512, avx2, sse4.1 or sse2")
        ->type_name("ISA")
        ->check(one_of({"auto", "avx512", "avx2", "sse4.1", "sse2"}))
        ->capture_default_str();
    cmd->footer(
        "The command prints a URL such as http://127.0.0.1:8090/?token=3f9c...: open it in a\n"
        "browser. The token is 128 random bits, new each run; a request without it gets\n"
        "403, and a connection that has not presented it within 5 s is closed. At most 256\n"
        "connections are served at once (event streams included); one more gets a 503.\n"
        "The page shows the picture refining pass by pass (1, 2, 4, ... samples per\n"
        "pixel) with spp, Mrays/s and frame time; drag orbits the camera about its look-at\n"
        "point, the wheel dollies, and a moving camera renders at reduced resolution\n"
        "(--preview-divisor) until it stops. The mouse shows the linear RGB value under it.\n"
        "The page switches threads, spp, max depth, the order, the path and the ISA\n"
        "(those this CPU runs) while it runs, and an animated scene's frame (a slider).\n"
        "Save writes the refined picture as octray render writes it, to a file name in the\n"
        "current directory, and shows the octray render command line that makes it.\n"
        "Nothing but the scene (or the two images) named here is served.\n\n"
        "With two images, octray view A B compares them as octray compare A B does (same\n"
        "defaults, same figures) and the page flips between A, B, |A - B| and the error\n"
        "heatmap; an image that cannot be read exits 4, two that cannot be compared exit 3.\n"
        "The HTTP API (status, events, the picture stream, PNG and float32 pictures,\n"
        "camera) is described in view/README.md. Ctrl-C (or SIGTERM) stops the\n"
        "server.\n\n"
        "Examples:\n"
        "  octray view                                  # the built-in whitted scene\n"
        "  octray view scene.json --port 0              # any free port\n"
        "  octray view random:1024 --width 640 --height 360 --spp 16\n"
        "  octray view whitted --width 640 --height 360 --threads 2 --bench 200\n"
        "  octray view ref.exr out.exr                  # A/B: difference and heatmap\n\n" +
        exit_code_help());
    cmd->callback([args, &run] {
        run.action = [args] { OwnExecutable<ViewArguments>::run("view", *args); };
    });
}

}  // namespace octray::tools
