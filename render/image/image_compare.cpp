#include "render/image/image_compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>

#include "render/image/image_io.h"

namespace octray {

std::string_view to_string(Verdict verdict) {
    switch (verdict) {
        case Verdict::pass:
            return "PASS";
        case Verdict::warn:
            return "WARN";
        case Verdict::fail:
            return "FAIL";
    }
    return "FAIL";
}

namespace {

constexpr double infinity = std::numeric_limits<double>::infinity();

std::string join(const std::vector<std::string>& names) {
    std::string out;
    for (const std::string& name : names) out += (out.empty() ? "" : ",") + name;
    return out;
}

// "%g" with enough digits to tell thresholds like 1e-06 and 1.5e-06 apart.
std::string number(double value) {
    if (std::isnan(value)) return "nan";
    if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", value);
    return text;
}

std::string percent(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.4g%%", value);
    return text;
}

// Pairs each compared channel's index in A with its index in B.
std::vector<std::pair<int, int>> match_channels(const Image& a, const Image& b,
                                                const std::vector<std::string>& wanted) {
    std::vector<std::pair<int, int>> pairs;
    if (wanted.empty()) {
        std::vector<std::string> names_a = a.channel_names(), names_b = b.channel_names();
        std::sort(names_a.begin(), names_a.end());
        std::sort(names_b.begin(), names_b.end());
        if (names_a != names_b)
            throw ImageMismatch("channel mismatch: A has " + join(a.channel_names()) +
                                ", B has " + join(b.channel_names()));
        for (int c = 0; c < a.channel_count(); ++c)
            pairs.emplace_back(c,
                               b.channel_index(a.channels[static_cast<std::size_t>(c)].name));
        return pairs;
    }
    for (const std::string& name : wanted) {
        const int in_a = a.channel_index(name), in_b = b.channel_index(name);
        if (in_a < 0 || in_b < 0)
            throw ImageMismatch("channel mismatch: '" + name + "' is not in " +
                                (in_a < 0 ? "A (which has " + join(a.channel_names()) + ")"
                                          : "B (which has " + join(b.channel_names()) + ")"));
        if (std::find(pairs.begin(), pairs.end(), std::make_pair(in_a, in_b)) == pairs.end())
            pairs.emplace_back(in_a, in_b);
    }
    return pairs;
}

// Running sums for one channel, or for all of them.
struct Accumulator {
    double sum_abs = 0.0;
    double sum_sq = 0.0;
    double sum_rel = 0.0;
};

void finish(ErrorStats& stats, const Accumulator& sums, std::size_t pixels) {
    if (stats.finite_values > 0) {
        const double n = static_cast<double>(stats.finite_values);
        stats.mean_abs_error = sums.sum_abs / n;
        stats.rmse = std::sqrt(sums.sum_sq / n);
        stats.mean_relative_error = sums.sum_rel / n;
    }
    // idiff's PSNR: 20 log10(peak / RMS error); identical images have no noise, so +inf.
    stats.psnr = stats.rmse > 0.0 ? 20.0 * std::log10(stats.peak / stats.rmse) : infinity;
    const double total = static_cast<double>(pixels);
    stats.fail_percent = pixels ? 100.0 * static_cast<double>(stats.fail_pixels) / total : 0.0;
    stats.warn_percent = pixels ? 100.0 * static_cast<double>(stats.warn_pixels) / total : 0.0;
}

std::string nonfinite_note(const ErrorStats& overall) {
    if (overall.nonfinite_pixels == 0) return "";
    return " (" + std::to_string(overall.nonfinite_pixels) + " with NaN or Inf)";
}

std::string where(const PixelSample& s) {
    return "(" + std::to_string(s.x) + ", " + std::to_string(s.y) + ") " + s.channel;
}

// " and 0.01 relative" when a relative threshold is given.
std::string relative_note(double relative) {
    return relative > 0.0 ? " and " + number(relative) + " relative" : "";
}

// " + 3 pixels" when --allowfailures is given.
std::string allowed_failures_note(const CompareOptions& options) {
    if (options.allow_failures == 0) return "";
    return " + " + std::to_string(options.allow_failures) +
           (options.allow_failures == 1 ? " pixel" : " pixels");
}

// idiff's decision: FAIL when more than fail_percent of the pixels fail or any error is
// over hard_fail; else WARN likewise; else PASS. A NaN or Inf counts as an infinite error.
void judge(CompareResult& result, const CompareOptions& options) {
    const ErrorStats& all = result.overall;
    const double pixels = static_cast<double>(result.width) * result.height;
    const std::string of_pixels = " of " + std::to_string(static_cast<long long>(pixels)) +
                                  " pixels (" + percent(all.fail_percent) + ")";
    const bool infinite_error = all.nonfinite_pixels > 0;

    const std::string allowed = percent(options.fail_percent) + allowed_failures_note(options);
    const std::string over_fail =
        number(options.fail_threshold) + relative_note(options.fail_relative);
    if (static_cast<double>(all.fail_pixels) >
        options.fail_percent / 100.0 * pixels + static_cast<double>(options.allow_failures)) {
        result.verdict = Verdict::fail;
        result.reason = "FAIL: " + std::to_string(all.fail_pixels) + of_pixels +
                        " differ by more than " + over_fail + nonfinite_note(all) +
                        "; allowed " + allowed;
        return;
    }
    if (result.hard_fail_pixels > options.allow_failures) {
        result.verdict = Verdict::fail;
        result.reason = infinite_error && !(all.max_abs_error > options.hard_fail)
                            ? "FAIL: " + std::to_string(all.nonfinite_pixels) +
                                  " pixels hold NaN or Inf, an error over the hard limit " +
                                  number(options.hard_fail)
                            : "FAIL: error " + number(all.max_abs_error) + " at " +
                                  where(all.worst) + " is over the hard limit " +
                                  number(options.hard_fail);
        return;
    }
    const std::string warn_of_pixels = " of " + std::to_string(static_cast<long long>(pixels)) +
                                       " pixels (" + percent(all.warn_percent) + ")";
    if (static_cast<double>(all.warn_pixels) > options.warn_percent / 100.0 * pixels) {
        result.verdict = Verdict::warn;
        result.reason = "WARN: " + std::to_string(all.warn_pixels) + warn_of_pixels +
                        " differ by more than " + number(options.warn_threshold) +
                        relative_note(options.warn_relative) + nonfinite_note(all) +
                        "; allowed " + percent(options.warn_percent);
        return;
    }
    if (all.max_abs_error > options.hard_warn ||
        (infinite_error && options.hard_warn < infinity)) {
        result.verdict = Verdict::warn;
        result.reason = infinite_error && !(all.max_abs_error > options.hard_warn)
                            ? "WARN: " + std::to_string(all.nonfinite_pixels) +
                                  " pixels hold NaN or Inf, an error over the hard warning "
                                  "limit " +
                                  number(options.hard_warn)
                            : "WARN: error " + number(all.max_abs_error) + " at " +
                                  where(all.worst) + " is over the hard warning limit " +
                                  number(options.hard_warn);
        return;
    }
    result.verdict = Verdict::pass;
    if (all.max_abs_error == 0.0 && !infinite_error)
        result.reason = "PASS: images are identical";
    else
        result.reason = "PASS: max error " + number(all.max_abs_error) + "; " +
                        std::to_string(all.fail_pixels) + of_pixels + " over " + over_fail +
                        nonfinite_note(all) + ", within the " + allowed + " allowed";
}

// The options as `octray compare` takes them: thresholds from 0 to infinity, percentages
// from 0 to 100, a positive finite floor. A NaN would compare false with every error, and
// so pass images that differ: std::invalid_argument naming the option, as for the rest.
void check_compare_options(const CompareOptions& o) {
    const auto threshold = [](double v, const char* name) {
        if (!(v >= 0.0))
            throw std::invalid_argument(std::string("compare: ") + name +
                                        " must be a number from 0 to infinity, not " +
                                        number(v));
    };
    const auto percent_of = [](double v, const char* name) {
        if (!(v >= 0.0 && v <= 100.0))
            throw std::invalid_argument(std::string("compare: ") + name +
                                        " must be a percentage from 0 to 100, not " +
                                        number(v));
    };
    threshold(o.fail_threshold, "fail_threshold");
    threshold(o.hard_fail, "hard_fail");
    threshold(o.warn_threshold, "warn_threshold");
    threshold(o.hard_warn, "hard_warn");
    percent_of(o.fail_percent, "fail_percent");
    percent_of(o.warn_percent, "warn_percent");
    if (!(o.relative_error_floor > 0.0 && std::isfinite(o.relative_error_floor)))
        throw std::invalid_argument(
            "compare: relative_error_floor must be positive and finite, not " +
            number(o.relative_error_floor));
}

}  // namespace

std::vector<std::string> format_notes(std::string_view format_a, std::string_view format_b) {
    std::vector<std::string> notes;
    if (format_a.empty() || format_b.empty() || format_a == format_b) return notes;
    const std::string formats =
        "A is " + std::string(format_a) + ", B is " + std::string(format_b);
    const auto is_png = [](std::string_view f) { return f.starts_with("PNG"); };
    const auto is_exr = [](std::string_view f) { return f.starts_with("OpenEXR"); };
    const auto has = [](std::string_view f, std::string_view type) {
        return f.find(type) != std::string_view::npos;
    };
    if (is_png(format_a) != is_png(format_b) && (is_exr(format_a) || is_exr(format_b))) {
        notes.push_back(formats +
                        ": a PNG holds display-referred sRGB-encoded values in [0, 1], an "
                        "OpenEXR linear ones, and both are compared as stored, without "
                        "converting, so the encoding counts as error; compare a PNG with a "
                        "PNG (render --png) or an OpenEXR with an OpenEXR");
    } else if (is_exr(format_a) && is_exr(format_b) &&
               has(format_a, " half") != has(format_b, " half")) {
        notes.push_back(formats +
                        ": half keeps 11 significant bits, so the same image stored as half "
                        "and as float differs by up to 2^-11 (4.9e-4) of each value; "
                        "--failrelative 0.001 passes that rounding and nothing larger");
    } else {
        notes.push_back(formats +
                        ": the channel formats differ, and the figures include "
                        "what converting between them rounds");
    }
    return notes;
}

CompareResult compare_images(const Image& a, const Image& b, const CompareOptions& options) {
    // The figures are over float values: half and uint channels compare as the floats they
    // hold.
    if (!a.all_float32() || !b.all_float32())
        return compare_images(to_float32(a), to_float32(b), options);
    check_compare_options(options);
    if (a.pixel_count() == 0 || b.pixel_count() == 0)
        throw ImageMismatch("an image without pixels: A is " + std::to_string(a.width()) + "x" +
                            std::to_string(a.height()) + ", B is " + std::to_string(b.width()) +
                            "x" + std::to_string(b.height()) + "; expected at least 1x1");
    if (a.width() != b.width() || a.height() != b.height())
        throw ImageMismatch("size mismatch: A is " + std::to_string(a.width()) + "x" +
                            std::to_string(a.height()) + ", B is " + std::to_string(b.width()) +
                            "x" + std::to_string(b.height()));
    if (a.data_window.x0 != b.data_window.x0 || a.data_window.y0 != b.data_window.y0)
        throw ImageMismatch(
            "data window mismatch: A starts at (" + std::to_string(a.data_window.x0) + ", " +
            std::to_string(a.data_window.y0) + "), B at (" + std::to_string(b.data_window.x0) +
            ", " + std::to_string(b.data_window.y0) + ")");

    CompareResult result;
    result.width = a.width();
    result.height = a.height();
    result.origin_x = a.data_window.x0;
    result.origin_y = a.data_window.y0;
    result.channel_indices = match_channels(a, b, options.channels);

    const std::size_t pixels = a.pixel_count();
    // Per pixel, over all compared channels: which thresholds it is over, and whether it
    // holds a NaN or Inf. One byte a pixel keeps "any channel" counting exact.
    enum : std::uint8_t { over_fail = 1, over_warn = 2, nonfinite = 4, over_hard = 8 };
    std::vector<std::uint8_t> flags(pixels, 0);

    ErrorStats& all = result.overall;
    all.channel = "all";
    Accumulator all_sums;
    std::size_t all_worst_index = 0;
    std::size_t all_first_nonfinite = pixels;

    const auto sample_at = [&](std::size_t i, const std::string& name, float va, float vb) {
        const std::size_t width = static_cast<std::size_t>(a.width());
        return PixelSample{a.data_window.x0 + static_cast<int>(i % width),
                           a.data_window.y0 + static_cast<int>(i / width), name, va, vb};
    };

    for (const auto& [index_a, index_b] : result.channel_indices) {
        ErrorStats stats;
        stats.channel = a.channels[static_cast<std::size_t>(index_a)].name;
        Accumulator sums;
        std::size_t worst_index = 0;
        const float* plane_a = a.plane(index_a);
        const float* plane_b = b.plane(index_b);

        for (std::size_t i = 0; i < pixels; ++i) {
            const float va = plane_a[i], vb = plane_b[i];
            if (std::isinf(va) && va == vb) {
                // Equal infinities are equal (as in idiff): a depth AOV's +inf background
                // matches itself. Neither an error nor counted in the NaN/Inf census.
                continue;
            }
            if (!std::isfinite(va) || !std::isfinite(vb)) {
                // Policy (COMPARE.md): NaN or Inf in either image is an infinite error. It
                // fails and warns the pixel and is counted, but stays out of the sums, which
                // would otherwise turn into NaN and say nothing.
                stats.nan_a += std::isnan(va);
                stats.inf_a += std::isinf(va);
                stats.nan_b += std::isnan(vb);
                stats.inf_b += std::isinf(vb);
                ++stats.nonfinite_pixels;
                ++stats.fail_pixels;
                ++stats.warn_pixels;
                if (!stats.first_nonfinite)
                    stats.first_nonfinite = sample_at(i, stats.channel, va, vb);
                if (i < all_first_nonfinite) {
                    all_first_nonfinite = i;
                    all.first_nonfinite = sample_at(i, stats.channel, va, vb);
                }
                flags[i] |= over_fail | over_warn | nonfinite |
                            (options.hard_fail < infinity ? over_hard : 0);
                continue;
            }
            // In double, so neither the difference nor its square loses the float's bits.
            const double da = va, db = vb;
            const double error = std::fabs(da - db);
            ++stats.finite_values;
            sums.sum_abs += error;
            sums.sum_sq += error * error;
            sums.sum_rel +=
                error / std::max({std::fabs(da), std::fabs(db), options.relative_error_floor});
            stats.peak = std::max({stats.peak, da, db});
            if (error > stats.max_abs_error) {
                stats.max_abs_error = error;
                worst_index = i;
            }
            // idiff's rule: over the absolute threshold and over the relative one times
            // the mean magnitude (a relative threshold of 0 adds nothing, as error > 0).
            const double mean_magnitude = 0.5 * (std::fabs(da) + std::fabs(db));
            if (error > options.fail_threshold &&
                error > options.fail_relative * mean_magnitude) {
                ++stats.fail_pixels;
                flags[i] |= over_fail;
            }
            if (error > options.warn_threshold &&
                error > options.warn_relative * mean_magnitude) {
                ++stats.warn_pixels;
                flags[i] |= over_warn;
            }
            if (error > options.hard_fail) flags[i] |= over_hard;
        }
        stats.worst =
            sample_at(worst_index, stats.channel, plane_a[worst_index], plane_b[worst_index]);
        finish(stats, sums, pixels);

        // The overall worst: the largest error; on a tie the earlier pixel, then the
        // earlier channel (so a single-channel result reads the same either way).
        if (result.channels.empty() || stats.max_abs_error > all.max_abs_error ||
            (stats.max_abs_error == all.max_abs_error && worst_index < all_worst_index)) {
            all.max_abs_error = stats.max_abs_error;
            all.worst = stats.worst;
            all_worst_index = worst_index;
        }
        all.finite_values += stats.finite_values;
        all_sums.sum_abs += sums.sum_abs;
        all_sums.sum_sq += sums.sum_sq;
        all_sums.sum_rel += sums.sum_rel;
        all.peak = std::max(all.peak, stats.peak);
        all.nan_a += stats.nan_a;
        all.inf_a += stats.inf_a;
        all.nan_b += stats.nan_b;
        all.inf_b += stats.inf_b;
        result.channels.push_back(std::move(stats));
    }

    for (std::uint8_t f : flags) {
        all.fail_pixels += (f & over_fail) != 0;
        all.warn_pixels += (f & over_warn) != 0;
        all.nonfinite_pixels += (f & nonfinite) != 0;
        result.hard_fail_pixels += (f & over_hard) != 0;
    }
    result.notes = format_notes(a.file_format, b.file_format);
    finish(all, all_sums, pixels);
    judge(result, options);
    return result;
}

Image difference_image(const Image& a, const Image& b, const CompareResult& result) {
    if (!a.all_float32() || !b.all_float32())
        return difference_image(to_float32(a), to_float32(b), result);
    std::vector<std::string> names;
    for (const ErrorStats& stats : result.channels) names.push_back(stats.channel);
    Image diff(a.width(), a.height(), names);
    diff.data_window = a.data_window;
    diff.display_window = a.data_window;
    diff.compression = ExrCompression::zip;
    diff.file_format = "OpenEXR float";
    const std::size_t pixels = a.pixel_count();
    for (std::size_t k = 0; k < result.channel_indices.size(); ++k) {
        const float* plane_a = a.plane(result.channel_indices[k].first);
        const float* plane_b = b.plane(result.channel_indices[k].second);
        float* out = diff.plane(static_cast<int>(k));
        for (std::size_t i = 0; i < pixels; ++i)
            out[i] = std::isinf(plane_a[i]) && plane_a[i] == plane_b[i]
                         ? 0.0f  // equal infinities are equal
                         : static_cast<float>(std::fabs(static_cast<double>(plane_a[i]) -
                                                        static_cast<double>(plane_b[i])));
    }
    return diff;
}

// ---- Reports -------------------------------------------------------------------------

std::string format_compare_report(const CompareResult& result, const CompareOptions& options,
                                  const std::string& label_a, const std::string& label_b) {
    std::ostringstream out;
    out << "Comparing A = " << label_a << "\n          B = " << label_b << "\n";
    out << "  " << result.width << "x" << result.height << ", channels ";
    for (std::size_t k = 0; k < result.channels.size(); ++k)
        out << (k ? "," : "") << result.channels[k].channel;
    out << "\n\n";

    char line[512];
    std::snprintf(line, sizeof line, "  %-10s %12s %12s %18s %12s %12s %12s %9s %12s %9s %9s\n",
                  "channel", "mean abs", "max abs", "at (x, y)", "A", "B", "RMSE", "PSNR dB",
                  "mean rel", "> fail", "> warn");
    out << line;
    const auto row = [&](const ErrorStats& s) {
        const std::string at =
            "(" + std::to_string(s.worst.x) + ", " + std::to_string(s.worst.y) + ")";
        std::snprintf(
            line, sizeof line, "  %-10s %12s %12s %18s %12s %12s %12s %9s %12s %9llu %9llu\n",
            s.channel.c_str(), number(s.mean_abs_error).c_str(),
            number(s.max_abs_error).c_str(), at.c_str(), number(s.worst.a).c_str(),
            number(s.worst.b).c_str(), number(s.rmse).c_str(),
            std::isinf(s.psnr) ? "inf" : number(std::round(s.psnr * 100) / 100).c_str(),
            number(s.mean_relative_error).c_str(),
            static_cast<unsigned long long>(s.fail_pixels),
            static_cast<unsigned long long>(s.warn_pixels));
        out << line;
    };
    for (const ErrorStats& s : result.channels) row(s);
    row(result.overall);

    const ErrorStats& all = result.overall;
    out << "\n  max error " << number(all.max_abs_error) << " at " << where(all.worst)
        << ": A = " << number(all.worst.a) << ", B = " << number(all.worst.b) << "\n";
    out << "  " << all.warn_pixels << " pixels (" << percent(all.warn_percent) << ") over warn "
        << number(options.warn_threshold) << relative_note(options.warn_relative) << "\n";
    out << "  " << all.fail_pixels << " pixels (" << percent(all.fail_percent) << ") over fail "
        << number(options.fail_threshold) << relative_note(options.fail_relative) << "\n";
    if (all.nonfinite_pixels > 0) {
        out << "  " << all.nonfinite_pixels << " pixels hold NaN or Inf (A: " << all.nan_a
            << " NaN, " << all.inf_a << " Inf; B: " << all.nan_b << " NaN, " << all.inf_b
            << " Inf values); first at " << where(*all.first_nonfinite)
            << ": A = " << number(all.first_nonfinite->a)
            << ", B = " << number(all.first_nonfinite->b) << "\n";
    }
    for (const std::string& note : result.notes) out << "  note: " << note << "\n";
    out << result.reason << "\n";
    return out.str();
}

namespace {

nlohmann::ordered_json value_json(float v) {
    if (std::isfinite(v)) return v;
    return number(v);
}

nlohmann::ordered_json sample_json(const PixelSample& s) {
    return {{"x", s.x},
            {"y", s.y},
            {"channel", s.channel},
            {"a", value_json(s.a)},
            {"b", value_json(s.b)}};
}

nlohmann::ordered_json stats_json(const ErrorStats& s) {
    nlohmann::ordered_json j = {
        {"channel", s.channel},
        {"finite_values", s.finite_values},
        {"mean_abs_error", s.mean_abs_error},
        {"max_abs_error", s.max_abs_error},
        {"max_at", sample_json(s.worst)},
        {"rmse", s.rmse},
        {"psnr_db",
         std::isinf(s.psnr) ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(s.psnr)},
        {"psnr_peak", s.peak},
        {"mean_relative_error", s.mean_relative_error},
        {"fail_pixels", s.fail_pixels},
        {"fail_percent", s.fail_percent},
        {"warn_pixels", s.warn_pixels},
        {"warn_percent", s.warn_percent},
        {"nonfinite_pixels", s.nonfinite_pixels},
        {"nan_a", s.nan_a},
        {"inf_a", s.inf_a},
        {"nan_b", s.nan_b},
        {"inf_b", s.inf_b},
        {"first_nonfinite",
         s.first_nonfinite ? sample_json(*s.first_nonfinite) : nlohmann::ordered_json(nullptr)},
    };
    return j;
}

nlohmann::ordered_json threshold_json(double v) {
    return std::isinf(v) ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(v);
}

}  // namespace

std::string format_compare_json(const CompareResult& result, const CompareOptions& options,
                                const std::string& label_a, const std::string& label_b) {
    nlohmann::ordered_json channels = nlohmann::ordered_json::array();
    for (const ErrorStats& s : result.channels) channels.push_back(stats_json(s));
    const nlohmann::ordered_json j = {
        {"a", label_a},
        {"b", label_b},
        {"width", result.width},
        {"height", result.height},
        {"options",
         {{"fail", options.fail_threshold},
          {"failpercent", options.fail_percent},
          {"hardfail", threshold_json(options.hard_fail)},
          {"warn", options.warn_threshold},
          {"warnpercent", options.warn_percent},
          {"hardwarn", threshold_json(options.hard_warn)},
          {"failrelative", options.fail_relative},
          {"warnrelative", options.warn_relative},
          {"allowfailures", options.allow_failures}}},
        {"channels", channels},
        {"overall", stats_json(result.overall)},
        {"notes", result.notes},
        {"verdict", std::string(to_string(result.verdict))},
        {"exit_code", static_cast<int>(result.verdict)},
        {"reason", result.reason},
    };
    return j.dump(2) + "\n";
}

}  // namespace octray
