#pragma once
// The compare heatmap: each pixel's error through matplotlib's magma ramp (perceptually
// uniform, black at zero error), a legend bar under it, and the scale printed on the bar
// with a tiny built-in digit font, for people who would rather look than read.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "render/image/image_compare.h"
#include "render/image/image_read.h"

namespace octray {

// How errors become colours. Linear: error / top, where the top of the ramp is the
// largest finite error, or 1 / factor when a factor is given (idiff's --scale: the error
// is multiplied by it, and anything from 1 / factor up is the ramp's top). Log: the
// decades from top / 10^heatmap_log_decades up to the top spread evenly over the ramp, so
// errors a thousand times smaller than the largest are still visible; zero stays black.
enum class HeatmapScale { linear, log };
inline constexpr int heatmap_log_decades = 6;

struct HeatmapOptions {
    HeatmapScale scale = HeatmapScale::linear;
    double factor = 0.0;  // > 0: multiply the error by it; 0: the largest error is the top
};

// "linear", "log"; and the scale a name stands for.
std::string_view to_string(HeatmapScale scale);
std::optional<HeatmapScale> parse_heatmap_scale(std::string_view name);

// Pixels holding NaN or Inf in either image: a green that magma never produces.
inline constexpr std::array<std::uint8_t, 3> heatmap_nonfinite_color{0, 255, 0};

struct ErrorHeatmap {
    Image image;                 // uint8 channels R, G, B: sRGB values, row 0 on top
    int zoom = 1;                // each source pixel is a zoom x zoom block at the top left
    double scale_max = 0.0;      // the error that maps to the ramp's top
    double scale_min = 0.0;      // the error at the ramp's bottom (0, or the log scale's)
    std::string legend;          // what the legend says of the scale: "linear", "log x100"
    int bar_x0 = 0, bar_x1 = 0;  // the legend bar's columns [x0, x1) and rows [y0, y1)
    int bar_y0 = 0, bar_y1 = 0;

    // The colour of pixel (x, y) of the picture.
    std::array<std::uint8_t, 3> color(int x, int y) const;
};

// magma at t in [0, 1] (clamped; NaN reads as 0).
std::array<std::uint8_t, 3> magma_color(double t);

// The colour of an error under `options`, given the ramp's top and bottom (scale_max and
// scale_min of the map).
double heatmap_position(double error, double scale_min, double scale_max, HeatmapScale scale);

// The per-pixel error is the largest |A - B| over the compared channels, mapped through
// `options`. Small images are enlarged (nearest neighbour) so the picture is at least
// about 256 pixels wide. The legend under the map is the ramp with its bottom, middle and
// top errors printed, and a line naming the scale and factor ("linear", "log x100").
ErrorHeatmap render_error_heatmap(const Image& a, const Image& b, const CompareResult& result,
                                  const HeatmapOptions& options = {});

// render_error_heatmap() written as a PNG, and returned. Throws IoError.
ErrorHeatmap write_error_heatmap(const std::string& path, const Image& a, const Image& b,
                                 const CompareResult& result,
                                 const HeatmapOptions& options = {});

}  // namespace octray
