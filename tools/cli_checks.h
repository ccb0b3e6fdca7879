#pragma once
// Checks every command shares: strict numbers for options, output formats chosen by the
// file name, output files compared by identity, "did you mean" for mistyped options, and
// standard output that cannot be written. Each failure is a message saying what was given
// and what is expected.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/pixel_rect.h"
#include "render/render_options.h"

namespace CLI {
class App;
class Option;
class Validator;
}  // namespace CLI

namespace octray {
struct Scene;
}

namespace octray::tools {

// ---- Words an option takes, and completes ----------------------------------------------

// The value must be one of `words` (the check's own list stays out of --help, whose text
// names them); the words are also what the shell completions offer for the option.
CLI::Validator one_of(const std::vector<std::string>& words);
// No check, only what the completions offer: the items of a list option, the built-in
// scenes next to file names.
CLI::Validator completes(const std::vector<std::string>& words);
// The words one_of or completes gave `option`, for the completion scripts; empty for none.
std::vector<std::string> completion_words(const CLI::Option& option);
// What a SCENE argument completes to besides file names: the built-ins' names.
std::vector<std::string> builtin_scene_words();

// ---- Numbers on the command line -------------------------------------------------------

// Decimal digits only (as scene files have them): no sign, blank, "0x" prefix, fraction or
// exponent; nullopt for anything else or above 2^64 - 1 (nothing is clamped). The same
// reading as core/decimal.h's parse_decimal_digits, which the specs of render/batch/spec.h use.
std::optional<std::uint64_t> parse_decimal_integer(std::string_view text);

// Limits of integer options that more than one command shares; each option's help text
// and its check are both made from them (integer_range_text, decimal_integer).
inline constexpr std::uint64_t kMaxImageSide = 65536;                      // --width, --height
inline constexpr std::uint64_t kMaxSamples = octray::kMaxSamplesPerPixel;  // --spp
inline constexpr std::uint64_t kMaxThreadCount = octray::kMaxRenderThreads;  // --threads
inline constexpr std::uint64_t kMaxTileSide = octray::kMaxTileSide;          // --tile WxH
inline constexpr std::uint64_t kMaxShardCount = 1u << 20;                    // --shard-count
// An upper limit that only says "fits an int": the range reads as open (">= lo").
inline constexpr std::uint64_t kNoIntegerLimit = 2147483647;

// A range for help text: "1..65536", or "0 or more" for an open one (hi kNoIntegerLimit).
std::string integer_range_text(std::uint64_t lo, std::uint64_t hi);

// An integer option in [lo, hi], written as parse_decimal_integer reads it. Use with
// CLI::Option::transform: it hands CLI11 the number in canonical form (CLI11 alone would
// read "0x10" as 16, "010" as 8, " 5" as 5 and clamp 2^64 to 2^64 - 1). With a delimiter
// (a list option such as --threads 1,2,4) it checks each item. A value refused reads
// "--spp must be an integer from 1 to 1048576 (got "0x10"); ..." once main() has dropped
// CLI11's colon.
CLI::Validator decimal_integer(std::uint64_t lo, std::uint64_t hi);

// The limits of an option checked by decimal_integer, nullopt for any other option: lets
// a test walk every integer option of the real command line.
struct IntegerLimits {
    std::uint64_t lo = 0, hi = 0;
};
std::optional<IntegerLimits> integer_option_limits(CLI::Option& option);

// A tile size "WxH", or "N" for NxN, with sides in [1, max_side] written as
// parse_decimal_integer reads them. A transform: hands CLI11 the canonical "WxH".
CLI::Validator tile_size(std::uint64_t max_side);

// A real option (a threshold): a decimal number in [lo, hi], or "inf" / "infinity" (any
// case) when `allow_infinity`. NaN, hex floats, signs other than a leading '-', blanks and
// values that overflow to infinity are refused. Use with CLI::Option::transform.
CLI::Validator real_number(double lo, double hi, bool allow_infinity);

// The range of such an option for its help: "0..100", ">= 0, or inf" (hi the largest double
// reads as open). real_option_range_text gives it for an option checked by real_number
// (nullopt for others), so a test holds each help to its check.
std::string real_range_text(double lo, double hi, bool allow_infinity);
std::optional<std::string> real_option_range_text(CLI::Option& option);

// ---- Output files --------------------------------------------------------------------

enum class ImageFormat { exr, png };

// The format a file name asks for by its extension, case-insensitively: ".exr" or ".png";
// nullopt for any other or none.
std::optional<ImageFormat> image_format_of(std::string_view path);

// The format of an output named by `option` (such as "-o"): its extension's, which must be
// one of `accepted` (".exr", or ".exr and .png"); else a UsageError that names the file,
// the formats and `advice`.
ImageFormat require_image_format(std::string_view option, const std::string& path,
                                 bool png_accepted, std::string_view advice);

// ---- Memory -------------------------------------------------------------------------------

// The memory limit a command's --max-memory VALUE sets (512M, 4G, ...; render/batch/
// memory_estimate.h), or this machine's physical memory when VALUE is empty (0 when that is
// unknown: no limit). A VALUE that is not a size is a UsageError naming the option.
std::uint64_t max_memory_limit(const std::string& value);

// ---- Scene warnings ----------------------------------------------------------------------

// Prints scene_warnings(scene) (scene/scene.h: what is legal but probably not meant, such as
// a fov below 2 degrees) on stderr, one "octray: warning: ..." line each, unless `quiet`
// (the --quiet of the commands that load scenes).
void print_scene_warnings(const Scene& scene, bool quiet);

// The help of those --quiet options.
inline constexpr const char* kQuietHelp =
    "Print no warnings about the scene (such as a camera fov below 2 degrees:\n"
    "probably radians, where fov is in degrees)";

// ---- Command-line errors and standard output -------------------------------------------

// After a failed parse: "unknown option "--threds" (did you mean "--threads"?)" for the
// first argument CLI11 could not place that is close to an option of the command it was
// given to (or to a command name), else "".
std::string mistyped_argument_hint(const CLI::App& app);

// Flushes standard output. A write that failed (a closed pipe: EPIPE, since octray ignores
// SIGPIPE; a full disk) is reported on stderr as an I/O error and turns a success into
// kExitIo; any other status stays.
int finish_standard_output(int status);

}  // namespace octray::tools
