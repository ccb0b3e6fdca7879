#pragma once
// Numeric image comparison with OpenImageIO idiff's thresholds and verdicts, as a library:
// `octray compare` reports it, `octray verify` and the tests judge images with it.
// render/image/COMPARE.md defines every figure and the NaN/Inf policy.

#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "render/image/image_read.h"

namespace octray {

// idiff's options, with idiff's defaults.
struct CompareOptions {
    double fail_threshold = 1e-6;  // a pixel fails when any channel differs by more
    double fail_percent = 0.0;     // FAIL when more than this % of the pixels fail
    double hard_fail = std::numeric_limits<double>::infinity();  // FAIL when any error exceeds
    double warn_threshold = 1e-6;
    double warn_percent = 0.0;
    double hard_warn = std::numeric_limits<double>::infinity();
    // idiff's relative thresholds: a value pair is over `fail` only when its error is also
    // over fail_relative times the mean of |A| and |B| (idiff's symmetric relative error);
    // 0, the default, leaves the absolute threshold alone. Likewise warn_relative.
    double fail_relative = 0.0;
    double warn_relative = 0.0;
    // idiff's --allowfailures: this many pixels may fail by any amount (over `fail` and over
    // `hard_fail`) on top of fail_percent, and the verdict is still not FAIL.
    std::uint64_t allow_failures = 0;
    // Channels to compare, by name; both images must have them. Empty: every channel, and
    // the two images must have the same set of names.
    std::vector<std::string> channels;
    // Relative error is |A - B| / max(|A|, |B|, floor): the floor keeps near-black pixels
    // from dominating the mean (0.01, as in the relMSE of the denoising literature).
    double relative_error_floor = 0.01;
};

// Ordered by severity; the numbers are the command's exit codes.
enum class Verdict { pass = 0, warn = 1, fail = 2 };
std::string_view to_string(Verdict verdict);  // "PASS", "WARN", "FAIL"

// The images cannot be compared value by value: different sizes, data windows or channel
// sets (idiff's "different size" outcome).
class ImageMismatch : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// One value pair: where it is (file coordinates, data-window origin included), in which
// channel, and what each image holds there.
struct PixelSample {
    int x = 0;
    int y = 0;
    std::string channel;
    float a = 0.0f;
    float b = 0.0f;
};

// The error figures of one channel, or of all compared channels together ("all"). Error
// figures are over the value pairs where both A and B are finite; see COMPARE.md.
struct ErrorStats {
    std::string channel;
    std::uint64_t finite_values = 0;  // value pairs the error figures are over
    double mean_abs_error = 0.0;
    double max_abs_error = 0.0;
    PixelSample worst;  // where max_abs_error is (first in scan order; channel order on ties)
    double rmse = 0.0;
    double peak = 1.0;  // PSNR's peak, as idiff: max(1, largest finite value in A or B)
    double psnr = std::numeric_limits<double>::infinity();  // 20 log10(peak / rmse)
    double mean_relative_error = 0.0;
    // Pixels over the thresholds: for "all", pixels where ANY compared channel is over.
    std::uint64_t fail_pixels = 0;
    std::uint64_t warn_pixels = 0;
    double fail_percent = 0.0;  // of all the image's pixels
    double warn_percent = 0.0;
    // Pixels where A or B holds NaN or Inf (in this channel; for "all", in any). They
    // count as failing and warning pixels too. Equal infinities (+Inf against +Inf, -Inf
    // against -Inf) are equal values, counted nowhere here.
    std::uint64_t nonfinite_pixels = 0;
    std::uint64_t nan_a = 0, inf_a = 0, nan_b = 0, inf_b = 0;  // values, not pixels
    std::optional<PixelSample> first_nonfinite;                // in scan order
};

struct CompareResult {
    int width = 0;
    int height = 0;
    int origin_x = 0;
    int origin_y = 0;
    std::vector<ErrorStats> channels;  // one per compared channel
    // For each compared channel, its index in A and in B.
    std::vector<std::pair<int, int>> channel_indices;
    ErrorStats overall;
    // Pixels over `hard_fail` (NaN and Inf included when it is finite), for allow_failures.
    std::uint64_t hard_fail_pixels = 0;
    // What the reader should know before trusting the figures: the two files store their
    // channels differently (half against float), or a display-referred PNG meets a linear
    // OpenEXR. Each a sentence; empty for images of the same format.
    std::vector<std::string> notes;
    Verdict verdict = Verdict::pass;
    std::string reason;  // one line: the verdict and why
};

// The notes of CompareResult for images in these formats (Image::format): empty when
// they are the same or unknown.
std::vector<std::string> format_notes(std::string_view format_a, std::string_view format_b);

// Compares B against A. Throws ImageMismatch when they cannot be compared.
CompareResult compare_images(const Image& a, const Image& b,
                             const CompareOptions& options = {});

// |A - B| for each compared channel (NaN where either value is NaN, Inf for an Inf against
// a finite value or the other infinity, 0 for equal infinities), named as the channels
// compared: a float32 image of A's data window (also its display window), ZIP-compressed
// when written (write_exr).
Image difference_image(const Image& a, const Image& b, const CompareResult& result);

// The human-readable report: a table per channel plus "all", the threshold counts, the
// NaN/Inf census, and the reason line last. `label_a` / `label_b` name the inputs.
std::string format_compare_report(const CompareResult& result, const CompareOptions& options,
                                  const std::string& label_a, const std::string& label_b);

// The same figures as one JSON object (schema in COMPARE.md). Infinite PSNR is null;
// non-finite sample values are the strings "nan", "inf", "-inf".
std::string format_compare_json(const CompareResult& result, const CompareOptions& options,
                                const std::string& label_a, const std::string& label_b);

}  // namespace octray
