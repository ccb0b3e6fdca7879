// `octray assemble`: stitch the cropped parts of one render (render --crop) into the full
// image, bit for bit (render/batch/README.md, "Assembling crops").

#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "render/batch/assemble.h"
#include "render/image/image.h"
#include "render/image/image_io.h"
#include "render/image/image_read.h"
#include "tools/cli_checks.h"
#include "tools/commands.h"

namespace octray::tools {
namespace {

struct AssembleArguments {
    std::vector<std::string> parts;
    std::string output;
};

// The assembled R, G, B as the 8-bit sRGB preview `render --png` writes.
batch::AssembleSummary assemble_png(const std::vector<std::string>& part_paths,
                                    const std::string& output) {
    std::vector<Image> parts;
    parts.reserve(part_paths.size());
    for (const std::string& path : part_paths) parts.push_back(read_exr_image(path));
    const Image full = batch::assemble_parts(parts, part_paths);
    const ImageChannel* rgb[3] = {full.find_channel("R"), full.find_channel("G"),
                                  full.find_channel("B")};
    if (!rgb[0] || !rgb[1] || !rgb[2])
        throw UsageError("-o " + output +
                         ": a PNG holds R, G, B, and the parts have no R, G and B channels; "
                         "write an OpenEXR (.exr) instead");
    // R, G, B as float32, in that order: the picture a render hands to its preview.
    Image image = make_rgb_image(full.data_window, full.display_window);
    for (int c = 0; c < 3; ++c) {
        float* plane = image.plane(c);
        for (std::size_t k = 0; k < image.pixel_count(); ++k) plane[k] = rgb[c]->value(k);
    }
    write_png_preview(output, image);
    batch::AssembleSummary summary;
    summary.display_window = full.display_window;
    summary.parts = parts.size();
    for (const char* name : {"R", "G", "B"})
        summary.channels.push_back(std::string(name) + " (8-bit sRGB)");
    return summary;
}

void run_assemble(const AssembleArguments& args) {
    const ImageFormat format =
        require_image_format("-o", args.output, /*png_accepted=*/true,
                             "a .png is the 8-bit sRGB preview of the assembled R, G, B");
    check_output_target(args.output);  // a device or FIFO: refused before reading the parts
    batch::AssembleSummary summary;
    try {
        summary = format == ImageFormat::png ? assemble_png(args.parts, args.output)
                                             : batch::assemble_files(args.parts, args.output);
    } catch (const batch::AssembleError& e) {
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
                    "The full image (data window = display window), written atomically; the\n"
                    "extension (any case) picks the format: .exr OpenEXR, every channel;\n"
                    ".png the 8-bit sRGB preview of R, G, B (as render --png writes it)")
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
