#pragma once
// `octray view A.exr B.exr`: two images read once, compared as `octray compare` compares
// them (same defaults), and the four pictures the page flips between: A, B, |A - B| and
// the error heatmap.

#include <cstdint>
#include <string>
#include <vector>

#include "render/image/error_heatmap.h"
#include "render/image/image.h"
#include "render/image/image_compare.h"
#include "render/image/image_read.h"

namespace octray::view {

// The pictures of an A/B view. `rgb` pictures are what the page shows and what the pixel
// endpoint reads: R, G, B of the image (its unprefixed layer), Y as gray when it has no
// colour, else its first channel as gray.
struct CompareView {
    std::string path_a, path_b;
    Image a, b;
    Image diff;  // |A - B| of every channel (difference_image)
    CompareOptions options;
    CompareResult result;
    std::string figures_json;  // format_compare_json(): the figures of `octray compare --json`
    Image rgb_a, rgb_b, rgb_diff;  // float32 R, G, B planes
    ErrorHeatmap heatmap;  // render_error_heatmap() with compare's defaults (8-bit sRGB)
    // The layers the page can show (display_layers of A; B has the same channels): "" the
    // colour, then each AOV ("N", "albedo", "depth", "id", ...).
    std::vector<std::string> layers;
};

// The layers of `image` the page can show: "" (R, G, B, or Y, or the first channel: what
// display_rgb shows), then each name before a channel's last '.' ("N" of N.X, N.Y, N.Z)
// and each other channel without one ("Z", "id"), sorted.
std::vector<std::string> display_layers(const Image& image);

// The displayed RGB of `layer` of a channel image: its channels R, G, B or X, Y, Z as
// colour, else its first channel as gray (an unprefixed layer: that channel). Throws
// std::invalid_argument for a layer the image does not have.
Image display_rgb(const Image& image, const std::string& layer);

// Reads and compares the two files. Throws IoError (unreadable, not an image: `octray
// compare`'s exit 4) or ImageMismatch (sizes or channels differ: its exit 3), as compare.
CompareView load_compare_view(const std::string& path_a, const std::string& path_b,
                              const CompareOptions& options = {});

// The displayed RGB of a channel image (see CompareView).
Image display_rgb(const Image& image);

}  // namespace octray::view
