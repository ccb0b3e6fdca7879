#pragma once
// `octray view A.exr B.exr`: two images read once, compared as `octray compare` compares
// them (same defaults), and the four pictures the page flips between: A, B, |A - B| and
// the error heatmap.

#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"
#include "render/image/error_heatmap.h"
#include "render/image/image_compare.h"
#include "render/image/image_read.h"

namespace octray::view {

// The pictures of an A/B view. `rgb` pictures are what the page shows and what the pixel
// endpoint reads: R, G, B of the image (its unprefixed layer), Y as gray when it has no
// colour, else its first channel as gray.
struct CompareView {
    std::string path_a, path_b;
    ChannelImage a, b;
    CompareOptions options;
    CompareResult result;
    std::string figures_json;  // format_compare_json(): the figures of `octray compare --json`
    Image rgb_a, rgb_b, rgb_diff;
    ErrorHeatmap heatmap;  // render_error_heatmap() with compare's defaults (8-bit sRGB)
};

// Reads and compares the two files. Throws IoError (unreadable, not an image: `octray
// compare`'s exit 4) or ImageMismatch (sizes or channels differ: its exit 3), as compare.
CompareView load_compare_view(const std::string& path_a, const std::string& path_b,
                              const CompareOptions& options = {});

// The displayed RGB of a channel image (see CompareView).
Image display_rgb(const ChannelImage& image);

}  // namespace octray::view
