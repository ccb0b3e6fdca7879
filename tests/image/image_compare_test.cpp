#include "render/image/image_compare.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "render/image/error_heatmap.h"
#include "render/image/image_io.h"
#include "tests/image/compare_fixtures.h"

namespace octray {
namespace {

using testing::make_image;

constexpr float nan_value = std::numeric_limits<float>::quiet_NaN();
constexpr float inf_value = std::numeric_limits<float>::infinity();

const std::vector<std::string> rgb{"R", "G", "B"};

TEST(CompareImages, IdenticalImagesPassWithInfinitePsnr) {
    const Image a = make_image(4, 4, rgb, 0.25f);
    const CompareResult r = compare_images(a, a);
    EXPECT_EQ(r.verdict, Verdict::pass);
    EXPECT_EQ(r.reason, "PASS: images are identical");
    EXPECT_EQ(r.overall.max_abs_error, 0.0);
    EXPECT_EQ(r.overall.mean_abs_error, 0.0);
    EXPECT_EQ(r.overall.rmse, 0.0);
    EXPECT_TRUE(std::isinf(r.overall.psnr));
    EXPECT_EQ(r.overall.fail_pixels, 0u);
    EXPECT_EQ(r.overall.finite_values, 48u);
    ASSERT_EQ(r.channels.size(), 3u);
    EXPECT_EQ(r.channels[1].channel, "G");
}

// 4x4 RGB of zeros; B differs by 0.25 in one value: G at (2, 1).
struct OnePixelOff : ::testing::Test {
    Image a = make_image(4, 4, rgb);
    Image b = make_image(4, 4, rgb);
    void SetUp() override { b.at(1, 2, 1) = 0.25f; }
};

TEST_F(OnePixelOff, MetricsAreExact) {
    const CompareResult r = compare_images(a, b);
    const ErrorStats& g = r.channels[1];
    EXPECT_EQ(g.channel, "G");
    EXPECT_EQ(g.max_abs_error, 0.25);
    EXPECT_EQ(g.worst.x, 2);
    EXPECT_EQ(g.worst.y, 1);
    EXPECT_EQ(g.worst.a, 0.0f);
    EXPECT_EQ(g.worst.b, 0.25f);
    EXPECT_DOUBLE_EQ(g.mean_abs_error, 0.25 / 16);
    EXPECT_DOUBLE_EQ(g.rmse, std::sqrt(0.0625 / 16));
    EXPECT_DOUBLE_EQ(g.psnr, 20.0 * std::log10(1.0 / std::sqrt(0.0625 / 16)));
    // |0 - 0.25| / max(0, 0.25, floor) = 1 at one pixel of 16.
    EXPECT_DOUBLE_EQ(g.mean_relative_error, 1.0 / 16);
    EXPECT_EQ(g.fail_pixels, 1u);
    EXPECT_DOUBLE_EQ(g.fail_percent, 6.25);
    EXPECT_EQ(r.channels[0].max_abs_error, 0.0);
    EXPECT_EQ(r.channels[0].fail_pixels, 0u);

    const ErrorStats& all = r.overall;
    EXPECT_EQ(all.channel, "all");
    EXPECT_EQ(all.max_abs_error, 0.25);
    EXPECT_EQ(all.worst.channel, "G");
    EXPECT_EQ(all.worst.x, 2);
    EXPECT_EQ(all.worst.y, 1);
    EXPECT_DOUBLE_EQ(all.mean_abs_error, 0.25 / 48);
    EXPECT_DOUBLE_EQ(all.rmse, std::sqrt(0.0625 / 48));
    EXPECT_DOUBLE_EQ(all.psnr, 20.0 * std::log10(1.0 / std::sqrt(0.0625 / 48)));
    EXPECT_DOUBLE_EQ(all.mean_relative_error, 1.0 / 48);
    EXPECT_EQ(all.fail_pixels, 1u);
    EXPECT_EQ(all.warn_pixels, 1u);
    EXPECT_DOUBLE_EQ(all.fail_percent, 6.25);
    EXPECT_EQ(all.nonfinite_pixels, 0u);
}

TEST_F(OnePixelOff, DefaultThresholdsFail) {
    const CompareResult r = compare_images(a, b);
    EXPECT_EQ(r.verdict, Verdict::fail);
    EXPECT_EQ(r.reason.rfind("FAIL: 1 of 16 pixels (6.25%) differ by more than 1e-06", 0), 0u)
        << r.reason;
}

TEST_F(OnePixelOff, FailPercentIsAStrictUpperBound) {
    CompareOptions options;
    options.fail_percent = 6.25;  // 1 of 16 is not MORE than 6.25%: no failure
    EXPECT_EQ(compare_images(a, b, options).verdict, Verdict::warn);
    options.fail_percent = 6.2;
    EXPECT_EQ(compare_images(a, b, options).verdict, Verdict::fail);
}

TEST_F(OnePixelOff, WarnThenPassAsAllowancesGrow) {
    CompareOptions options;
    options.fail_percent = 10;
    EXPECT_EQ(compare_images(a, b, options).verdict, Verdict::warn);
    options.warn_percent = 10;
    const CompareResult r = compare_images(a, b, options);
    EXPECT_EQ(r.verdict, Verdict::pass);
    EXPECT_EQ(r.reason.rfind("PASS: max error 0.25", 0), 0u) << r.reason;
}

TEST_F(OnePixelOff, ThresholdIsStrict) {
    // idiff: a pixel is over a threshold when its error is MORE than it.
    CompareOptions options;
    options.fail_threshold = 0.25;
    options.warn_threshold = 0.25;
    const CompareResult r = compare_images(a, b, options);
    EXPECT_EQ(r.overall.fail_pixels, 0u);
    EXPECT_EQ(r.overall.warn_pixels, 0u);
    EXPECT_EQ(r.verdict, Verdict::pass);
}

TEST_F(OnePixelOff, SeparateWarnAndFailThresholds) {
    CompareOptions options;
    options.fail_threshold = 0.5;
    options.warn_threshold = 0.1;
    const CompareResult r = compare_images(a, b, options);
    EXPECT_EQ(r.overall.fail_pixels, 0u);
    EXPECT_EQ(r.overall.warn_pixels, 1u);
    EXPECT_EQ(r.verdict, Verdict::warn);
}

TEST_F(OnePixelOff, HardFailAndHardWarn) {
    CompareOptions options;
    options.fail_percent = 100;
    options.warn_percent = 100;
    options.hard_fail = 0.2;
    CompareResult r = compare_images(a, b, options);
    EXPECT_EQ(r.verdict, Verdict::fail);
    EXPECT_EQ(r.reason, "FAIL: error 0.25 at (2, 1) G is over the hard limit 0.2");
    options.hard_fail = 0.25;  // not over
    EXPECT_EQ(compare_images(a, b, options).verdict, Verdict::pass);
    options.hard_warn = 0.1;
    EXPECT_EQ(compare_images(a, b, options).verdict, Verdict::warn);
}

TEST(CompareImages, ConstantOffsetEverywhere) {
    // A holds k/8 (exact in float), B = A + 0.5: every error is exactly 0.5.
    Image a = make_image(4, 2, {"R", "G"});
    Image b = a;
    double expected_rel = 0.0, largest = 0.0;
    const std::size_t pixels = a.pixel_count();
    for (std::size_t i = 0; i < 2 * pixels; ++i) {
        float& va = a.plane(static_cast<int>(i / pixels))[i % pixels];
        float& vb = b.plane(static_cast<int>(i / pixels))[i % pixels];
        va = static_cast<float>(i) / 8.0f;
        vb = va + 0.5f;
        expected_rel += 0.5 / vb;
        largest = std::max(largest, static_cast<double>(vb));
    }
    const CompareResult r = compare_images(a, b);
    EXPECT_EQ(r.overall.mean_abs_error, 0.5);
    EXPECT_EQ(r.overall.max_abs_error, 0.5);
    EXPECT_EQ(r.overall.rmse, 0.5);
    // The first of the equal errors: pixel (0, 0), channel R.
    EXPECT_EQ(r.overall.worst.x, 0);
    EXPECT_EQ(r.overall.worst.y, 0);
    EXPECT_EQ(r.overall.worst.channel, "R");
    // idiff's peak: the largest value seen, here B's 15/8 + 1/2, above 1.
    EXPECT_EQ(largest, 2.375);
    EXPECT_EQ(r.overall.peak, 2.375);
    EXPECT_DOUBLE_EQ(r.overall.psnr, 20.0 * std::log10(2.375 / 0.5));
    EXPECT_DOUBLE_EQ(r.channels[0].peak, 7.0 / 8.0 + 0.5);  // R holds 0..7/8
    EXPECT_DOUBLE_EQ(r.overall.mean_relative_error, expected_rel / 16);
    EXPECT_EQ(r.overall.fail_pixels, 8u);
    EXPECT_EQ(r.overall.fail_percent, 100.0);
    EXPECT_EQ(r.verdict, Verdict::fail);
}

// NaN in A at (1, 1) R, +Inf in B at (3, 0) B, and one finite error 0.125 at (0, 2) G.
struct NonFinite : ::testing::Test {
    Image a = make_image(4, 4, rgb, 0.5f);
    Image b = make_image(4, 4, rgb, 0.5f);
    void SetUp() override {
        a.at(0, 1, 1) = nan_value;
        b.at(2, 3, 0) = inf_value;
        b.at(1, 0, 2) = 0.625f;
    }
};

TEST_F(NonFinite, CountedAndReportedNotPropagated) {
    const CompareResult r = compare_images(a, b);
    const ErrorStats& all = r.overall;
    EXPECT_EQ(all.nonfinite_pixels, 2u);
    EXPECT_EQ(all.nan_a, 1u);
    EXPECT_EQ(all.inf_a, 0u);
    EXPECT_EQ(all.nan_b, 0u);
    EXPECT_EQ(all.inf_b, 1u);
    ASSERT_TRUE(all.first_nonfinite.has_value());
    EXPECT_EQ(all.first_nonfinite->x, 3);  // pixel 3 comes before pixel 5 in scan order
    EXPECT_EQ(all.first_nonfinite->y, 0);
    EXPECT_EQ(all.first_nonfinite->channel, "B");
    EXPECT_EQ(all.first_nonfinite->b, inf_value);
    // The error figures are over the 46 finite pairs, and stay finite.
    EXPECT_EQ(all.finite_values, 46u);
    EXPECT_EQ(all.max_abs_error, 0.125);
    EXPECT_DOUBLE_EQ(all.mean_abs_error, 0.125 / 46);
    EXPECT_DOUBLE_EQ(all.rmse, std::sqrt(0.125 * 0.125 / 46));
    EXPECT_TRUE(std::isfinite(all.psnr));
    // Both non-finite pixels fail, plus the finite one.
    EXPECT_EQ(all.fail_pixels, 3u);
    EXPECT_EQ(all.warn_pixels, 3u);
    EXPECT_EQ(r.channels[0].nonfinite_pixels, 1u);
    EXPECT_EQ(r.channels[0].nan_a, 1u);
    EXPECT_EQ(r.channels[0].finite_values, 15u);
    EXPECT_EQ(r.channels[0].fail_pixels, 1u);
    EXPECT_EQ(r.channels[2].inf_b, 1u);
    EXPECT_EQ(r.verdict, Verdict::fail);
    EXPECT_NE(r.reason.find("(2 with NaN or Inf)"), std::string::npos) << r.reason;
}

TEST_F(NonFinite, NanMatchingNanStillFails) {
    // Unlike idiff, a NaN is never "equal": a regression image must not hold one.
    Image both = make_image(2, 2, {"R"}, 1.0f);
    both.at(0, 1, 1) = nan_value;
    const CompareResult r = compare_images(both, both);
    EXPECT_EQ(r.overall.nonfinite_pixels, 1u);
    EXPECT_EQ(r.overall.nan_a, 1u);
    EXPECT_EQ(r.overall.nan_b, 1u);
    EXPECT_EQ(r.verdict, Verdict::fail);
}

TEST_F(NonFinite, NanIsAnInfiniteErrorForHardLimits) {
    CompareOptions options;
    options.fail_percent = 50;  // 3 of 16 pixels is allowed...
    options.warn_percent = 50;
    EXPECT_EQ(compare_images(a, b, options).verdict, Verdict::pass);
    options.hard_fail = 1.0;  // ...but no error may exceed 1, and NaN/Inf do
    const CompareResult r = compare_images(a, b, options);
    EXPECT_EQ(r.verdict, Verdict::fail);
    EXPECT_EQ(r.reason, "FAIL: 2 pixels hold NaN or Inf, an error over the hard limit 1");
}

TEST(CompareImages, SizeMismatchThrows) {
    try {
        compare_images(make_image(4, 4, rgb), make_image(4, 3, rgb));
        FAIL() << "no ImageMismatch";
    } catch (const ImageMismatch& e) {
        EXPECT_STREQ(e.what(), "size mismatch: A is 4x4, B is 4x3");
    }
}

TEST(CompareImages, DataWindowMismatchThrows) {
    Image b = make_image(2, 2, rgb);
    b.data_window = PixelRect{1, 0, 1 + b.width(), b.height()};
    EXPECT_THROW(compare_images(make_image(2, 2, rgb), b), ImageMismatch);
}

TEST(CompareImages, ChannelSetsMustMatchUnlessChannelsAreChosen) {
    const Image a = make_image(2, 2, {"R", "G", "B", "A"}, 0.5f);
    Image b = make_image(2, 2, {"B", "G", "R"}, 0.5f);  // order does not matter
    try {
        compare_images(a, b);
        FAIL() << "no ImageMismatch";
    } catch (const ImageMismatch& e) {
        // The caller says how to choose channels (octray compare: --channels; the viewer
        // and the API have no such option).
        EXPECT_STREQ(e.what(), "channel mismatch: A has R,G,B,A, B has B,G,R");
    }
    CompareOptions options;
    options.channels = {"G", "R"};
    b.at(b.channel_index("R"), 1, 0) = 0.75f;
    const CompareResult r = compare_images(a, b, options);
    ASSERT_EQ(r.channels.size(), 2u);
    EXPECT_EQ(r.channels[0].channel, "G");
    EXPECT_EQ(r.channels[1].channel, "R");
    EXPECT_EQ(r.channel_indices[1], std::make_pair(0, 2));
    EXPECT_EQ(r.overall.max_abs_error, 0.25);
    EXPECT_EQ(r.overall.worst.channel, "R");

    options.channels = {"A"};
    try {
        compare_images(a, b, options);
        FAIL() << "no ImageMismatch";
    } catch (const ImageMismatch& e) {
        EXPECT_STREQ(e.what(), "channel mismatch: 'A' is not in B (which has B,G,R)");
    }
}

TEST(CompareImages, SameSizeReorderedChannelsCompareByName) {
    Image a = make_image(1, 1, {"R", "G"});
    Image b = make_image(1, 1, {"G", "R"});
    a.at(0, 0, 0) = 1.0f;  // R
    b.at(1, 0, 0) = 1.0f;  // R
    EXPECT_EQ(compare_images(a, b).verdict, Verdict::pass);
}

TEST(CompareImages, ReportsUseFileCoordinates) {
    Image a = make_image(2, 2, {"Y"});
    a.data_window = PixelRect{100, 200, 100 + a.width(), 200 + a.height()};
    Image b = a;
    b.at(0, 1, 1) = 1.0f;
    const CompareResult r = compare_images(a, b);
    EXPECT_EQ(r.overall.worst.x, 101);
    EXPECT_EQ(r.overall.worst.y, 201);
}

TEST(DifferenceImage, IsAbsoluteDifferenceOfComparedChannels) {
    Image a = make_image(2, 1, {"R", "G", "Z"}, 1.0f);
    Image b = a;
    b.at(0, 0, 0) = 1.5f;
    b.at(1, 1, 0) = 0.25f;
    a.at(2, 1, 0) = nan_value;
    CompareOptions options;
    options.channels = {"G", "R"};
    const Image diff = difference_image(a, b, compare_images(a, b, options));
    EXPECT_EQ(diff.channel_names(), (std::vector<std::string>{"G", "R"}));
    EXPECT_EQ(diff.at(0, 1, 0), 0.75f);
    EXPECT_EQ(diff.at(1, 0, 0), 0.5f);
    EXPECT_EQ(diff.at(1, 1, 0), 0.0f);
}

class CompareFiles : public testing::ScratchDirTest {};

TEST_F(CompareFiles, DifferenceExrRoundTrips) {
    Image a = make_image(3, 2, {"R", "G", "B", "albedo.R"}, 0.5f);
    a.data_window = PixelRect{5, 0, 5 + a.width(), a.height()};
    Image b = a;
    b.at(3, 2, 1) = 0.125f;
    b.at(0, 0, 0) = inf_value;
    const Image diff = difference_image(a, b, compare_images(a, b));
    write_exr(path("d.exr"), diff);
    const Image back = read_image(path("d.exr"));
    EXPECT_EQ(back.channel_names(), diff.channel_names());
    EXPECT_EQ(back.data_window.x0, 5);
    EXPECT_EQ(back.file_format, "OpenEXR float");
    EXPECT_EQ(back.at(3, 2, 1), 0.375f);
    EXPECT_EQ(back.at(0, 0, 0), inf_value);
    EXPECT_EQ(back.at(1, 0, 0), 0.0f);
}

TEST(Magma, MatchesMatplotlibTableWithinOneStep) {
    // Entries of matplotlib's _magma_data that are not knots of our table, times 255.
    const struct {
        int index;
        double r, g, b;
    } entries[] = {{0, 0.001462, 0.000466, 0.013866},   {2, 0.003279, 0.002305, 0.023708},
                   {3, 0.004512, 0.003490, 0.029965},   {101, 0.544015, 0.159033, 0.506159},
                   {133, 0.748378, 0.226377, 0.464794}, {190, 0.984622, 0.520713, 0.376698},
                   {254, 0.987387, 0.984288, 0.742002}, {255, 0.987053, 0.991438, 0.749504}};
    for (const auto& e : entries) {
        const auto c = magma_color(e.index / 255.0);
        EXPECT_NEAR(c[0], e.r * 255.0, 1.0) << e.index;
        EXPECT_NEAR(c[1], e.g * 255.0, 1.0) << e.index;
        EXPECT_NEAR(c[2], e.b * 255.0, 1.0) << e.index;
    }
    EXPECT_EQ(magma_color(-3.0), magma_color(0.0));
    EXPECT_EQ(magma_color(7.0), magma_color(1.0));
    EXPECT_EQ(magma_color(std::nan("")), magma_color(0.0));
}

TEST(Heatmap, ColorsErrorsAndDrawsTheLegend) {
    Image a = make_image(8, 4, rgb, 0.5f);
    Image b = a;
    b.at(0, 1, 1) = 0.75f;   // error 0.25, the largest: top of the ramp
    b.at(2, 2, 2) = 0.625f;  // error 0.125: the middle
    a.at(1, 3, 3) = nan_value;
    const CompareResult r = compare_images(a, b);
    const ErrorHeatmap map = render_error_heatmap(a, b, r);
    EXPECT_EQ(map.zoom, 32);  // 256 / 8
    EXPECT_EQ(map.scale_max, 0.25);
    const auto center = [&](int x, int y) {
        return map.color(x * map.zoom + map.zoom / 2, y * map.zoom + map.zoom / 2);
    };
    EXPECT_EQ(center(0, 0), magma_color(0.0));
    EXPECT_EQ(center(1, 1), magma_color(1.0));
    EXPECT_EQ(center(2, 2), magma_color(0.5));
    EXPECT_EQ(center(3, 3), heatmap_nonfinite_color);

    // The bar runs the ramp left to right, below the map.
    EXPECT_GE(map.bar_y0, 4 * map.zoom);
    EXPECT_EQ(map.color(map.bar_x0, map.bar_y0), magma_color(0.0));
    EXPECT_EQ(map.color(map.bar_x1 - 1, map.bar_y1 - 1), magma_color(1.0));
    // Labels below the bar: some light text pixels at the left ("0") and right ("0.25").
    const auto lit_pixels = [&](int x0, int x1) {
        int lit = 0;
        for (int y = map.bar_y1; y < map.image.height(); ++y)
            for (int x = x0; x < x1; ++x) lit += map.color(x, y)[0] > 200;
        return lit;
    };
    EXPECT_GT(lit_pixels(map.bar_x0, map.bar_x0 + 8), 0);
    // "0.25" is 4 glyphs: 0 (12 lit font pixels), . (1), 2 (11), 5 (11), 4 font px each.
    EXPECT_EQ(lit_pixels(map.bar_x1 - 40, map.bar_x1), (12 + 1 + 11 + 11) * 4);
}

TEST(Heatmap, LargeImagesAreNotEnlargedAndZeroErrorIsBlack) {
    const Image a = make_image(300, 2, {"Y"});
    const CompareResult r = compare_images(a, a);
    const ErrorHeatmap map = render_error_heatmap(a, a, r);
    EXPECT_EQ(map.zoom, 1);
    EXPECT_EQ(map.image.width(), 300);
    EXPECT_EQ(map.color(299, 1), magma_color(0.0));
}

// Issue 26: an error of 0.001 beside one of 1 is all but black on the linear 0..max scale;
// a factor of 100 or the log scale make it visible.
TEST(Heatmap, ScaleAndLogMakeSmallErrorsVisible) {
    Image a = make_image(8, 4, rgb, 0.5f);
    Image b = a;
    b.at(0, 1, 1) = 1.5f;    // error 1: the largest
    b.at(1, 2, 2) = 0.501f;  // error 0.001
    const CompareResult r = compare_images(a, b);
    const auto small = [&](const HeatmapOptions& options) {
        const ErrorHeatmap map = render_error_heatmap(a, b, r, options);
        const auto c = map.color(2 * map.zoom + map.zoom / 2, 2 * map.zoom + map.zoom / 2);
        return std::max({c[0], c[1], c[2]});
    };
    EXPECT_LT(small({}), 12);                             // linear 0..1: black
    EXPECT_GT(small({HeatmapScale::linear, 100.0}), 40);  // 0.1 of the ramp
    EXPECT_GT(small({HeatmapScale::log, 0.0}), 150);      // the middle of 6 decades
    EXPECT_GT(small({HeatmapScale::log, 100.0}), 150);

    // The factor fixes the top of the ramp at 1 / F: the large error saturates.
    const ErrorHeatmap scaled = render_error_heatmap(a, b, r, {HeatmapScale::linear, 100.0});
    EXPECT_EQ(scaled.scale_max, 0.01);
    EXPECT_EQ(scaled.color(scaled.zoom + 1, scaled.zoom + 1), magma_color(1.0));
    const ErrorHeatmap log = render_error_heatmap(a, b, r, {HeatmapScale::log, 0.0});
    EXPECT_EQ(log.scale_max, 1.0);
    EXPECT_DOUBLE_EQ(log.scale_min, 1e-6);
}

TEST(Heatmap, TheLegendSaysWhichScale) {
    Image a = make_image(8, 4, rgb, 0.5f);
    Image b = a;
    b.at(0, 1, 1) = 0.75f;
    const CompareResult r = compare_images(a, b);
    // Lit pixels of the legend's last text row (the scale's name) and of the labels row.
    const auto lit = [](const ErrorHeatmap& map, int y0, int y1) {
        int n = 0;
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < map.image.width(); ++x) n += map.color(x, y)[0] > 200;
        return n;
    };
    const auto name_row = [&](const ErrorHeatmap& map) {
        return lit(map, map.bar_y1 + 14, map.image.height());
    };
    const auto labels_row = [&](const ErrorHeatmap& map) {
        return lit(map, map.bar_y1, map.bar_y1 + 14);
    };
    const ErrorHeatmap linear = render_error_heatmap(a, b, r);
    const ErrorHeatmap log = render_error_heatmap(a, b, r, {HeatmapScale::log, 0.0});
    const ErrorHeatmap log100 = render_error_heatmap(a, b, r, {HeatmapScale::log, 100.0});
    EXPECT_EQ(linear.legend, "linear");
    EXPECT_EQ(log.legend, "log");
    EXPECT_EQ(log100.legend, "log x100");
    EXPECT_EQ(render_error_heatmap(a, b, r, {HeatmapScale::linear, 2.5}).legend, "linear x2.5");
    EXPECT_GT(name_row(linear), 0);
    EXPECT_NE(name_row(linear), name_row(log));
    EXPECT_GT(name_row(log100), name_row(log));
    // The labels: "0 0.125 0.25" on the linear scale, "2.5e-07 0.00025 0.25" on the log.
    EXPECT_NE(labels_row(linear), labels_row(log));
}

TEST(Heatmap, PositionOnEachScale) {
    EXPECT_EQ(heatmap_position(0.0, 0.0, 1.0, HeatmapScale::linear), 0.0);
    EXPECT_EQ(heatmap_position(0.25, 0.0, 1.0, HeatmapScale::linear), 0.25);
    EXPECT_EQ(heatmap_position(4.0, 0.0, 1.0, HeatmapScale::linear), 1.0);
    EXPECT_EQ(heatmap_position(0.0, 1e-6, 1.0, HeatmapScale::log), 0.0);
    EXPECT_EQ(heatmap_position(1e-7, 1e-6, 1.0, HeatmapScale::log), 0.0);
    EXPECT_NEAR(heatmap_position(1e-3, 1e-6, 1.0, HeatmapScale::log), 0.5, 1e-12);
    EXPECT_EQ(heatmap_position(2.0, 1e-6, 1.0, HeatmapScale::log), 1.0);
    EXPECT_EQ(parse_heatmap_scale("log"), HeatmapScale::log);
    EXPECT_EQ(parse_heatmap_scale("linear"), HeatmapScale::linear);
    EXPECT_EQ(parse_heatmap_scale("Log"), std::nullopt);
}

TEST_F(CompareFiles, HeatmapPngReadsBack) {
    Image a = make_image(4, 4, rgb);
    Image b = a;
    b.at(0, 0, 0) = 1.0f;
    const CompareResult r = compare_images(a, b);
    write_error_heatmap(path("h.png"), a, b, r);
    const ErrorHeatmap map = render_error_heatmap(a, b, r);
    const Image png = read_image(path("h.png"));
    ASSERT_EQ(png.width(), map.image.width());
    ASSERT_EQ(png.height(), map.image.height());
    EXPECT_EQ(png.channel_names(), rgb);
    for (int c = 0; c < 3; ++c)
        EXPECT_EQ(png.at(c, 1, 1), map.color(1, 1)[static_cast<std::size_t>(c)] / 255.0f);
}

TEST(WritePngRgb8, RejectsAMismatchedBuffer) {
    EXPECT_THROW(write_png_rgb8("unused.png", 2, 2, std::vector<std::uint8_t>(11)), IoError);
}

TEST(CompareJson, CarriesTheFiguresAndNullForInfinitePsnr) {
    Image a = make_image(2, 1, {"R"});
    Image b = a;
    a.at(0, 1, 0) = nan_value;
    CompareOptions options;
    const CompareResult r = compare_images(a, b, options);
    const auto j = nlohmann::json::parse(format_compare_json(r, options, "a.exr", "b.exr"));
    EXPECT_EQ(j["a"], "a.exr");
    EXPECT_EQ(j["verdict"], "FAIL");
    EXPECT_EQ(j["exit_code"], 2);
    EXPECT_TRUE(j["overall"]["psnr_db"].is_null());  // no finite error: rmse 0
    EXPECT_EQ(j["overall"]["nonfinite_pixels"], 1);
    EXPECT_EQ(j["overall"]["first_nonfinite"]["a"], "nan");
    EXPECT_EQ(j["overall"]["first_nonfinite"]["x"], 1);
    EXPECT_EQ(j["overall"]["fail_percent"], 50.0);
    EXPECT_TRUE(j["options"]["hardfail"].is_null());
    EXPECT_EQ(j["options"]["fail"], 1e-6);
    EXPECT_EQ(j["channels"][0]["channel"], "R");
}

TEST(CompareReport, EndsWithTheReasonAndListsEveryChannel) {
    Image a = make_image(2, 2, rgb);
    Image b = a;
    b.at(2, 1, 1) = 0.5f;
    const CompareOptions options;
    const CompareResult r = compare_images(a, b, options);
    const std::string text = format_compare_report(r, options, "a.exr", "b.png");
    EXPECT_NE(text.find("A = a.exr"), std::string::npos);
    EXPECT_NE(text.find("max error 0.5 at (1, 1) B: A = 0, B = 0.5"), std::string::npos)
        << text;
    EXPECT_NE(text.find("1 pixels (25%) over fail 1e-06"), std::string::npos) << text;
    const std::string last_line = r.reason + "\n";
    EXPECT_EQ(text.substr(text.size() - last_line.size()), last_line);
}

}  // namespace
}  // namespace octray
