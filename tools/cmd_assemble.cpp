// `octray assemble`: stitch the cropped parts of one render (render --crop) into the full
// image, bit for bit (render/README.md, "Assembling crops").

#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "render/assemble.h"
#include "render/image_io.h"
#include "tools/commands.h"

namespace octray::tools {
namespace {

struct AssembleArguments {
    std::vector<std::string> parts;
    std::string output;
};

void run_assemble(const AssembleArguments& args) {
    AssembleSummary summary;
    try {
        summary = assemble_files(args.parts, args.output);
    } catch (const AssembleError& e) {
        // The parts named on the command line do not make one image: a usage error.
        throw UsageError(std::string("assemble: ") + e.what());
    }
    std::string channels;
    for (const std::string& c : summary.channels) {
        if (!channels.empty()) channels += ", ";
        channels += c;
    }
    std::cout << "wrote " << args.output << " (" << summary.display_window.width() << "x"
              << summary.display_window.height() << ", " << summary.parts << " part"
              << (summary.parts == 1 ? "" : "s") << "; " << channels << ")\n"
              << std::flush;
}

}  // namespace

void add_assemble_command(CLI::App& app, CommandRunner& run) {
    auto args = std::make_shared<AssembleArguments>();
    CLI::App* cmd = app.add_subcommand(
        "assemble",
        "Stitch cropped EXR parts of one render (render --crop) into the full image");
    cmd->add_option("parts", args->parts,
                    "The parts: OpenEXR files whose data windows are crops of one display\n"
                    "window, with the same channels and pixel types")
        ->type_name("PART.exr")
        ->required();
    cmd->add_option("-o,--output", args->output,
                    "The full image (data window = display window), written atomically")
        ->type_name("FILE")
        ->required();
    cmd->footer(
        "The parts must have the same display window and the same channels with the same\n"
        "pixel types; their data windows must lie inside the display window, must not\n"
        "overlap and must cover it completely. Samples are copied in their own type (half\n"
        "stays half, bit for bit), so the result equals the uncropped render. The header\n"
        "attributes and compression are those of the first part.\n\n"
        "Example (a 640x360 frame in four quarters, e.g. on four machines):\n"
        "  octray render scene.json --crop 0,0,320,180   -o q0.exr\n"
        "  octray render scene.json --crop 320,0,640,180 -o q1.exr\n"
        "  octray render scene.json --crop 0,180,320,360 -o q2.exr\n"
        "  octray render scene.json --crop 320,180,640,360 -o q3.exr\n"
        "  octray assemble q0.exr q1.exr q2.exr q3.exr -o full.exr\n\n"
        "Exit codes of assemble: 2 also when the parts do not fit together (overlap, gap,\n"
        "different display windows or channels; the message names the parts and pixels),\n"
        "4 when a part cannot be read or the output cannot be written.\n\n" +
        exit_code_help());
    cmd->callback([args, &run] { run.action = [args] { run_assemble(*args); }; });
}

}  // namespace octray::tools
