#pragma once
// The compare heatmap: each pixel's error through matplotlib's magma ramp (perceptually
// uniform, black at zero error), a legend bar under it, and the scale printed on the bar
// with a tiny built-in digit font, for people who would rather look than read.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "render/image_compare.h"
#include "render/image_read.h"

namespace octray {

// Pixels holding NaN or Inf in either image: a green that magma never produces.
inline constexpr std::array<std::uint8_t, 3> heatmap_nonfinite_color{0, 255, 0};

// 8-bit sRGB, interleaved RGB, row 0 on top.
struct Rgb8Image {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgb;

    std::array<std::uint8_t, 3> at(int x, int y) const {
        const std::size_t i = 3 * (static_cast<std::size_t>(y) * width + x);
        return {rgb[i], rgb[i + 1], rgb[i + 2]};
    }
};

struct ErrorHeatmap {
    Rgb8Image image;
    int zoom = 1;                // each source pixel is a zoom x zoom block at the top left
    double scale_max = 0.0;      // the error that maps to the ramp's top (the max finite error)
    int bar_x0 = 0, bar_x1 = 0;  // the legend bar's columns [x0, x1) and rows [y0, y1)
    int bar_y0 = 0, bar_y1 = 0;
};

// magma at t in [0, 1] (clamped; NaN reads as 0).
std::array<std::uint8_t, 3> magma_color(double t);

// The per-pixel error is the largest |A - B| over the compared channels, mapped linearly
// from 0 to the largest finite error. Small images are enlarged (nearest neighbour) so the
// picture is at least about 256 pixels wide.
ErrorHeatmap render_error_heatmap(const ChannelImage& a, const ChannelImage& b,
                                  const CompareResult& result);

// render_error_heatmap() written as a PNG. Throws IoError.
void write_error_heatmap(const std::string& path, const ChannelImage& a, const ChannelImage& b,
                         const CompareResult& result);

}  // namespace octray
