// Checks every command shares (tools/cli_checks.h).

#include "tools/cli_checks.h"

#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <limits>
#include <sstream>
#include <system_error>
#include <vector>

#include "core/decimal.h"
#include "render/batch/memory_estimate.h"
#include "scene/scene.h"
#include "scene/suggest.h"
#include "tools/commands.h"

namespace octray::tools {
namespace {

namespace fs = std::filesystem;

// A value quoted for a message: control bytes as \xNN, cut after 64 characters.
std::string quote_value(std::string_view text) {
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out = "\"";
    for (std::size_t i = 0; i < std::min<std::size_t>(text.size(), 64); ++i) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c < 0x20 || c == 0x7f) {
            out += "\\x";
            out += kHex[c >> 4];
            out += kHex[c & 15];
        } else {
            out += static_cast<char>(c);
        }
    }
    if (text.size() > 64) out += "...";
    return out + "\"";
}

std::string lowercase(std::string_view text) {
    std::string out(text);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

std::string format_real(double value) {
    char text[64];
    std::snprintf(text, sizeof text, "%g", value);
    return text;
}

}  // namespace

std::optional<std::uint64_t> parse_decimal_integer(std::string_view text) {
    return parse_decimal_digits(text);
}

std::string integer_range_text(std::uint64_t lo, std::uint64_t hi) {
    if (hi == kNoIntegerLimit) return std::to_string(lo) + " or more";
    return std::to_string(lo) + ".." + std::to_string(hi);
}

namespace {

constexpr std::string_view kIntegerValidatorName = "decimal_integer ";
constexpr std::string_view kDigitsOnly =
    "decimal digits only: no sign, blank, 0x prefix, fraction or exponent";

// "an integer from 1 to 65536", or "an integer >= 0" for an open range: the open end reads
// as no limit, not as 2147483647.
std::string integer_range_words(std::uint64_t lo, std::uint64_t hi) {
    return hi == kNoIntegerLimit
               ? "an integer >= " + std::to_string(lo)
               : "an integer from " + std::to_string(lo) + " to " + std::to_string(hi);
}

}  // namespace

CLI::Validator decimal_integer(std::uint64_t lo, std::uint64_t hi) {
    const std::string range = integer_range_words(lo, hi);
    return CLI::Validator(
        [range, lo, hi](std::string& text) -> std::string {
            const auto value = parse_decimal_integer(text);
            const bool digits =
                !text.empty() && std::all_of(text.begin(), text.end(),
                                             [](char c) { return c >= '0' && c <= '9'; });
            if (!digits)
                return "must be " + range + " (got " + quote_value(text) + "); " +
                       std::string(kDigitsOnly);
            if (!value || *value < lo || *value > hi)  // no value: above 2^64 - 1
                return "must be " + range + " (got " + quote_value(text) + ")";
            text = std::to_string(*value);  // what CLI11 converts: canonical decimal
            return {};
        },
        "", std::string(kIntegerValidatorName) + std::to_string(lo) + " " + std::to_string(hi));
}

namespace {

// The names of `option`'s validators, in order, that start with `prefix`, the prefix cut.
std::vector<std::string> validator_arguments(CLI::Option& option, std::string_view prefix) {
    std::vector<std::string> found;
    for (int i = 0;; ++i) {
        const CLI::Validator* validator = nullptr;
        try {
            validator = option.get_validator(i);
        } catch (const CLI::OptionNotFound&) {
            return found;
        }
        const std::string& name = validator->get_name();
        if (name.rfind(prefix, 0) == 0) found.push_back(name.substr(prefix.size()));
    }
}

}  // namespace

std::optional<IntegerLimits> integer_option_limits(CLI::Option& option) {
    for (const std::string& numbers : validator_arguments(option, kIntegerValidatorName)) {
        const std::size_t space = numbers.find(' ');
        const std::string_view text(numbers);
        const auto lo = parse_decimal_integer(text.substr(0, space));
        const auto hi = space == std::string_view::npos
                            ? std::nullopt
                            : parse_decimal_integer(text.substr(space + 1));
        if (lo && hi) return IntegerLimits{*lo, *hi};
    }
    return std::nullopt;
}

CLI::Validator tile_size(std::uint64_t max_side) {
    const std::string expected = "must be WxH or N (NxN) with sides from 1 to " +
                                 std::to_string(max_side) + ", such as 16x16";
    return CLI::Validator(
        [expected, max_side](std::string& text) -> std::string {
            const std::size_t x = text.find_first_of("xX");
            const std::string_view all = text;
            const auto w = parse_decimal_integer(all.substr(0, x));
            const auto h =
                x == std::string::npos ? w : parse_decimal_integer(all.substr(x + 1));
            if (!w || !h)
                return expected + " (got " + quote_value(text) + "); " +
                       std::string(kDigitsOnly);
            if (*w < 1 || *h < 1 || *w > max_side || *h > max_side)
                return expected + " (got " + quote_value(text) + ")";
            text = std::to_string(*w) + "x" + std::to_string(*h);
            return {};
        },
        "");
}

std::string real_range_text(double lo, double hi, bool allow_infinity) {
    std::string range = hi == std::numeric_limits<double>::max()
                            ? ">= " + format_real(lo)
                            : format_real(lo) + ".." + format_real(hi);
    return allow_infinity ? range + ", or inf" : range;
}

std::optional<std::string> real_option_range_text(CLI::Option& option) {
    const std::vector<std::string> found = validator_arguments(option, "real_number ");
    if (found.empty()) return std::nullopt;
    return found.front();
}

CLI::Validator real_number(double lo, double hi, bool allow_infinity) {
    std::string range =
        hi == std::numeric_limits<double>::max()
            ? "a decimal number >= " + format_real(lo)
            : "a decimal number from " + format_real(lo) + " to " + format_real(hi);
    if (allow_infinity) range += ", or inf";
    return CLI::Validator(
        [range, lo, hi, allow_infinity](std::string& text) -> std::string {
            double value = 0.0;
            const char* first = text.data();
            const char* last = text.data() + text.size();
            const auto [end, error] = std::from_chars(first, last, value);
            const std::string lower = lowercase(text);
            const bool infinity_word = lower == "inf" || lower == "infinity";
            if (error != std::errc() || end != last || text.empty() ||
                (std::isinf(value) && !infinity_word))
                return "expected " + range + ", found " + quote_value(text);
            if (std::isnan(value))
                return "expected " + range + ", found " + quote_value(text) +
                       " (NaN compares false with everything, so it would pass any pair)";
            if (std::isinf(value) && (!allow_infinity || value < 0))
                return "expected " + range + ", found " + quote_value(text);
            if (std::isfinite(value) && (value < lo || value > hi))
                return "expected " + range + ", found " + quote_value(text);
            if (std::isinf(value)) {
                text = "inf";
            } else {
                char exact[64];
                std::snprintf(exact, sizeof exact, "%a", value);  // exact, for CLI11's strtold
                text = exact;
            }
            return {};
        },
        "", "real_number " + real_range_text(lo, hi, allow_infinity));
}

std::uint64_t max_memory_limit(const std::string& value) {
    if (value.empty()) return batch::machine_memory_bytes();
    const auto parsed = batch::parse_memory_size(value);
    if (!parsed)
        throw UsageError("--max-memory: expected a size such as 512M, 4G or 1T, not " + value);
    return *parsed;
}

void print_scene_warnings(const Scene& scene, bool quiet) {
    if (quiet) return;
    for (const std::string& warning : scene_warnings(scene))
        std::cerr << "octray: warning: " << warning << '\n';
}

std::optional<ImageFormat> image_format_of(std::string_view path) {
    const std::string name = fs::path(path).filename().string();
    const std::size_t dot = name.rfind('.');
    if (dot == std::string::npos || dot == 0) return std::nullopt;
    const std::string extension = lowercase(std::string_view(name).substr(dot));
    if (extension == ".exr") return ImageFormat::exr;
    if (extension == ".png") return ImageFormat::png;
    return std::nullopt;
}

ImageFormat require_image_format(std::string_view option, const std::string& path,
                                 bool png_accepted, std::string_view advice) {
    const auto format = image_format_of(path);
    if (format && (png_accepted || *format == ImageFormat::exr)) return *format;
    std::string message = std::string(option) + " " + quote_value(path) +
                          ": the file name's extension chooses the format, and octray writes " +
                          (png_accepted ? "OpenEXR (.exr) and 8-bit sRGB PNG (.png) here"
                                        : "only OpenEXR (.exr) here");
    if (!advice.empty()) message += "; " + std::string(advice);
    throw UsageError(message);
}

namespace {

// The name a word list's validator carries; CLI11 keeps it with the option, where
// completion_words() reads it back.
constexpr std::string_view kWordsName = "completes:";

std::string words_name(const std::vector<std::string>& words) {
    std::string name(kWordsName);
    for (const std::string& word : words) name += " " + word;
    return name;
}

}  // namespace

CLI::Validator one_of(const std::vector<std::string>& words) {
    return CLI::IsMember(words).description("").name(words_name(words));
}

CLI::Validator completes(const std::vector<std::string>& words) {
    return CLI::Validator([](const std::string&) { return std::string(); }, "",
                          words_name(words));
}

std::vector<std::string> completion_words(const CLI::Option& option) {
    // CLI11 2.1 lists an option's validators only through a non-const accessor.
    auto& mutable_option = const_cast<CLI::Option&>(option);
    for (int i = 0;; ++i) {
        const CLI::Validator* validator = nullptr;
        try {
            validator = mutable_option.get_validator(i);
        } catch (const CLI::OptionNotFound&) {
            return {};
        }
        const std::string& name = validator->get_name();
        if (name.rfind(kWordsName, 0) != 0) continue;
        std::vector<std::string> words;
        std::istringstream list(name.substr(kWordsName.size()));
        for (std::string word; list >> word;) words.push_back(word);
        return words;
    }
}

std::vector<std::string> builtin_scene_words() {
    return {"whitted", "random:", "sphereflake:"};
}

std::string mistyped_argument_hint(const CLI::App& app) {
    // The command the arguments were given to: the deepest one that parsed.
    const CLI::App* command = &app;
    std::vector<std::string> unknown = app.remaining();
    for (;;) {
        const auto parsed = command->get_subcommands();
        if (parsed.empty()) break;
        command = parsed.front();
        const std::vector<std::string> more = command->remaining();
        unknown.insert(unknown.end(), more.begin(), more.end());
    }
    std::vector<std::string> names;
    for (const CLI::Option* option : command->get_options()) {
        for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
        for (const std::string& name : option->get_snames()) names.push_back("-" + name);
    }
    const bool top = command == &app;
    if (top) {
        for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
            names.push_back(sub->get_name());
    }
    const std::vector<std::string_view> candidates(names.begin(), names.end());
    for (const std::string& argument : unknown) {
        const bool option = argument.size() > 1 && argument.front() == '-';
        if (!option && !top) continue;  // a stray value, not a name
        const std::string_view word =
            std::string_view(argument).substr(0, option ? argument.find('=') : argument.npos);
        // idiff's -o writes the difference image; compare names it --diff.
        if (word == "-o" && command->get_name() == "compare")
            return "unknown option \"-o\": idiff's -o is --diff FILE.exr here (|A - B| as "
                   "float OpenEXR), or --heatmap FILE.png for a picture of the error";
        // A wrong case first ("-v" is "-V", not "-h"), then the closest spelling. A
        // one-letter option is one edit from every other one ("-o" from "-h"), so its
        // spelling suggests nothing.
        std::optional<std::string_view> best;
        for (std::string_view candidate : candidates)
            if (lowercase(candidate) == lowercase(word) && candidate != word) best = candidate;
        const bool short_option = word.size() == 2 && word[0] == '-' && word[1] != '-';
        if (!best && !short_option) best = closest_word(word, candidates);
        if (!best) continue;
        return std::string("unknown ") + (option ? "option " : "command ") + quote_value(word) +
               " (did you mean " + quote_value(*best) + "?)";
    }
    return {};
}

namespace {

// Why standard output failed, when a failed write left no errno behind (stdio drops what it
// could not write): a pipe whose reading end is closed shows POLLERR on its writing end.
int standard_output_error() {
    struct stat info {};
    if (::fstat(STDOUT_FILENO, &info) == 0 && S_ISFIFO(info.st_mode)) {
        pollfd p{STDOUT_FILENO, POLLOUT, 0};
        if (::poll(&p, 1, 0) == 1 && (p.revents & POLLERR) != 0) return EPIPE;
    }
    return 0;
}

}  // namespace

int finish_standard_output(int status) {
    std::cout.flush();
    bool failed = !std::cout || std::ferror(stdout) != 0;
    int error = 0;
    if (std::fflush(stdout) != 0) {
        failed = true;
        error = errno;
    }
    if (!failed || status != kExitSuccess) return status;
    if (error == 0) error = standard_output_error();
    std::cerr << "octray: I/O error: cannot write to standard output: "
              << (error != 0 ? std::strerror(error) : "write error") << '\n';
    return kExitIo;
}

}  // namespace octray::tools
