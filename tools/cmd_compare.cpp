// `octray compare`: idiff-style numeric comparison of two images (OpenEXR or PNG), with an
// optional difference EXR, an error heatmap and JSON output. The figures, the thresholds
// and the exit codes are idiff's; render/image/COMPARE.md defines them.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "render/batch/output_paths.h"
#include "render/image/error_heatmap.h"
#include "render/image/image_compare.h"
#include "render/image/image_io.h"
#include "render/image/image_read.h"
#include "tools/cli_checks.h"
#include "tools/commands.h"

namespace octray::tools {
namespace {

// compare's own exit codes, idiff's: 0 pass, 1 warn, 2 fail (Verdict), 3 and 4 below;
// 5 a usage error (kExitCompareUsage, mapped in main.cpp).
constexpr int kCompareMismatch = 3;

struct CompareArguments {
    std::string a;
    std::string b;
    CompareOptions options;
    std::string diff;
    std::string heatmap;
    std::string heatmap_scale = "linear";  // --heatmapscale
    double scale = -1.0;                   // --scale; < 0: not given
    bool json = false;
};

// With --json, standard output carries JSON whatever happens, so a script can parse it
// before looking at the exit status.
void print_json_outcome(const CompareArguments& args, std::string_view verdict, int code,
                        const std::string& reason) {
    const nlohmann::ordered_json j = {{"a", args.a},
                                      {"b", args.b},
                                      {"verdict", verdict},
                                      {"exit_code", code},
                                      {"reason", reason}};
    std::cout << j.dump(2) << '\n' << std::flush;
}

void run_compare(const CompareArguments& args) {
    HeatmapOptions heatmap;
    heatmap.factor = std::max(args.scale, 0.0);
    heatmap.scale = parse_heatmap_scale(args.heatmap_scale).value_or(HeatmapScale::linear);
    if (args.scale == 0.0)
        throw UsageError(
            "--scale: expected a factor greater than 0, found 0 (it would map "
            "every error to black)");
    if (args.heatmap.empty() && (args.scale >= 0.0 || args.heatmap_scale != "linear"))
        throw UsageError(std::string(args.scale >= 0.0 ? "--scale" : "--heatmapscale") +
                         " sets how the --heatmap picture maps errors to colours, and no "
                         "--heatmap FILE.png was given");
    if (!args.diff.empty())
        require_image_format("--diff", args.diff, /*png_accepted=*/false,
                             "--diff is |A - B| in float; for a PNG picture of the error "
                             "use --heatmap FILE.png");
    if (!args.diff.empty() && !args.heatmap.empty() &&
        batch::output_identity(args.diff) == batch::output_identity(args.heatmap))
        throw UsageError("--diff and --heatmap name the same file: " + args.diff + " and " +
                         args.heatmap);

    Image a, b;
    CompareResult result;
    try {
        // A device or FIFO as --diff or --heatmap is refused before any reading (exit 4).
        for (const std::string* out : {&args.diff, &args.heatmap})
            if (!out->empty()) check_output_target(*out);
        a = read_image(args.a);
        b = read_image(args.b);
        result = compare_images(a, b, args.options);
    } catch (const ImageMismatch& e) {
        std::string reason =
            std::string(e.what()) + " (A = " + args.a + ", B = " + args.b + ")";
        if (args.options.channels.empty() && reason.rfind("channel mismatch", 0) == 0)
            reason += "; pick common channels with --channels";
        if (args.json) print_json_outcome(args, "MISMATCH", kCompareMismatch, reason);
        std::cerr << "octray: compare: " << reason << '\n';
        throw CommandExit{kCompareMismatch};
    } catch (const IoError& e) {
        if (args.json) print_json_outcome(args, "ERROR", kExitIo, e.what());
        throw;  // run_command reports it on stderr and exits 4
    }

    // The outputs first: a file that cannot be written is exit 4, whatever the verdict.
    if (!args.diff.empty()) write_exr(args.diff, difference_image(a, b, result));
    ErrorHeatmap map;
    if (!args.heatmap.empty()) map = write_error_heatmap(args.heatmap, a, b, result, heatmap);

    if (args.json) {
        std::cout << format_compare_json(result, args.options, args.a, args.b) << std::flush;
    } else {
        // The reason stays the last line, where scripts and people look for it.
        if (!args.diff.empty()) std::cout << "wrote " << args.diff << " (|A - B|, float)\n";
        if (!args.heatmap.empty())
            std::cout << "wrote " << args.heatmap << " (error heatmap, " << map.legend << ": "
                      << map.scale_min << " to " << map.scale_max << ")\n";
        std::cout << format_compare_report(result, args.options, args.a, args.b) << std::flush;
    }
    if (!std::cout)
        throw IoError(std::string("cannot write the report to standard output: ") +
                      std::strerror(errno));
    if (result.verdict != Verdict::pass) throw CommandExit{static_cast<int>(result.verdict)};
}

std::string compare_exit_code_help() {
    return "Exit codes (compare's own, as idiff's):\n"
           "  0  PASS\n"
           "  1  WARN: over the warn limits, within the fail limits\n"
           "  2  FAIL: over the fail limits\n"
           "  3  the images cannot be compared: size, data window or channel mismatch\n"
           "  4  file error: an input is missing, unreadable, not an image, truncated or\n"
           "     corrupt, or --diff / --heatmap / standard output cannot be written\n"
           "  5  usage error: a bad command line (reported on stderr), never a verdict\n"
           "The last line of the report (or \"reason\" in --json) says why.\n";
}

// The largest finite threshold: any double.
constexpr double kMaxThreshold = std::numeric_limits<double>::max();
// More pixels than any image has (65536 x 65536).
constexpr std::uint64_t kMaxAllowFailures = std::uint64_t{1} << 32;

}  // namespace

void add_compare_command(CLI::App& app, CommandRunner& run) {
    auto args = std::make_shared<CompareArguments>();
    CLI::App* cmd = app.add_subcommand(
        "compare",
        "Compare two images (OpenEXR or PNG) as idiff does: error figures per "
        "channel, a pass/warn/fail verdict and exit code");
    cmd->add_option("a", args->a, "First image (the reference)")->type_name("A")->required();
    cmd->add_option("b", args->b, "Second image")->type_name("B")->required();

    CompareOptions& o = args->options;
    cmd->add_option("--fail", o.fail_threshold,
                    "A pixel fails when any channel differs by more than X (" +
                        real_range_text(0.0, kMaxThreshold, true) + ")")
        ->type_name("X")
        ->transform(real_number(0.0, kMaxThreshold, true))
        ->capture_default_str();
    cmd->add_option(
           "--failpercent", o.fail_percent,
           "FAIL when more than P% of the pixels fail, " + real_range_text(0.0, 100.0, false))
        ->type_name("P")
        ->transform(real_number(0.0, 100.0, false))
        ->capture_default_str();
    cmd->add_option("--hardfail", o.hard_fail,
                    "FAIL when any one error exceeds H (" +
                        real_range_text(0.0, kMaxThreshold, true) + ": no hard limit)")
        ->type_name("H")
        ->transform(real_number(0.0, kMaxThreshold, true))
        ->capture_default_str();
    cmd->add_option("--warn", o.warn_threshold,
                    "A pixel warns when any channel differs by more than X (" +
                        real_range_text(0.0, kMaxThreshold, true) + ")")
        ->type_name("X")
        ->transform(real_number(0.0, kMaxThreshold, true))
        ->capture_default_str();
    cmd->add_option(
           "--warnpercent", o.warn_percent,
           "WARN when more than P% of the pixels warn, " + real_range_text(0.0, 100.0, false))
        ->type_name("P")
        ->transform(real_number(0.0, 100.0, false))
        ->capture_default_str();
    cmd->add_option("--hardwarn", o.hard_warn,
                    "WARN when any one error exceeds H (" +
                        real_range_text(0.0, kMaxThreshold, true) + ": no hard limit)")
        ->type_name("H")
        ->transform(real_number(0.0, kMaxThreshold, true))
        ->capture_default_str();
    cmd->add_option("--failrelative", o.fail_relative,
                    "A pixel over --fail fails only when its error is also over R times the\n"
                    "mean of |A| and |B| (idiff's relative threshold; " +
                        real_range_text(0.0, kMaxThreshold, true) + ", 0 = off)")
        ->type_name("R")
        ->transform(real_number(0.0, kMaxThreshold, true))
        ->capture_default_str();
    cmd->add_option("--warnrelative", o.warn_relative,
                    "A pixel over --warn warns only when its error is also over R times the\n"
                    "mean of |A| and |B| (" +
                        real_range_text(0.0, kMaxThreshold, true) + ", 0 = off)")
        ->type_name("R")
        ->transform(real_number(0.0, kMaxThreshold, true))
        ->capture_default_str();
    cmd->add_option("--allowfailures", o.allow_failures,
                    "N pixels may fail by any amount, over --fail and --hardfail, on top of\n"
                    "--failpercent (as idiff's; " +
                        integer_range_text(0, kMaxAllowFailures) + ")")
        ->type_name("N")
        ->transform(decimal_integer(0, kMaxAllowFailures))
        ->capture_default_str();
    cmd->add_option("--channels", o.channels,
                    "Compare only these channels, by name (e.g. R,G,B or diffuse.R);\n"
                    "default: all, and both images must have the same channel names")
        ->type_name("LIST")
        ->delimiter(',');
    cmd->add_option("--diff", args->diff,
                    "Write |A - B| of the compared channels as float OpenEXR; FILE must end\n"
                    "in .exr (any case)")
        ->type_name("FILE.exr");
    cmd->add_option("--heatmap", args->heatmap,
                    "Write a PNG heatmap of the largest channel error per pixel (magma,\n"
                    "0 to the max error, legend below; NaN/Inf in green)")
        ->type_name("FILE");
    cmd->add_option("--heatmapscale", args->heatmap_scale,
                    "How --heatmap maps errors to colours: linear (0 to the top) or log\n"
                    "(the 6 decades below the top, so small errors stay visible)")
        ->type_name("linear|log")
        ->check(one_of({"linear", "log"}))
        ->capture_default_str();
    cmd->add_option("--scale", args->scale,
                    "Multiply the error by F before --heatmap maps it (as idiff's -scale):\n"
                    "the top of the ramp is then 1/F, not the largest error (F " +
                        real_range_text(0.0, kMaxThreshold, false) + ", not 0)")
        ->type_name("F")
        ->transform(real_number(0.0, kMaxThreshold, false));
    cmd->add_flag("--json", args->json, "Print the figures as JSON instead of the report");
    cmd->footer(
        "NaN or Inf in either image is an infinite error: the pixel fails and is counted;\n"
        "the error figures are over the finite values. Equal infinities (+inf against\n"
        "+inf, as a depth AOV's background) are equal. Thresholds are decimal numbers\n"
        "(or inf); NaN is refused. PSNR = 20 log10(peak / RMSE), peak =\n"
        "max(1, largest value). See render/image/COMPARE.md.\n\n"
        "Examples:\n"
        "  octray compare ref.exr out.exr\n"
        "  octray compare ref.exr out.exr --fail 0.004 --failpercent 0.1 --warn 0.001\n"
        "  octray compare half.exr float.exr --failrelative 0.001  # half's rounding only\n"
        "  octray compare ref.exr out.exr --allowfailures 3  # 3 pixels may differ at all\n"
        "  octray compare ref.exr out.exr --channels R,G,B --heatmap err.png --diff err.exr\n"
        "  octray compare ref.exr out.exr --heatmap err.png --heatmapscale log --scale 100\n"
        "  octray compare ref.png out.png --json\n\n" +
        compare_exit_code_help());
    cmd->callback([args, &run] { run.action = [args] { run_compare(*args); }; });
}

}  // namespace octray::tools
