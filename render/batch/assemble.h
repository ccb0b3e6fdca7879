#pragma once
// `octray assemble`: stitching the cropped parts of one render (render --crop, each an EXR
// whose data window is its crop inside the full display window) back into the full image,
// sample for sample in each channel's own pixel type (render/batch/README.md, "Assembling
// crops").

#include <stdexcept>
#include <string>
#include <vector>

#include "render/image/image_io.h"

namespace octray::batch {

// The parts do not make one image: they overlap, leave a gap, disagree on the display
// window or the channels, or lie outside the display window. The message names the parts
// and the pixels concerned.
class AssembleError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// Stitches `parts` (named `names[k]` in messages) into one image whose data window is
// their common display window. Every part must have the same display window and the same
// channels with the same pixel types; the data windows must lie inside the display
// window, must not overlap and must together cover it. The result carries the first
// part's compression and attributes. Throws AssembleError.
Image assemble_parts(const std::vector<Image>& parts, const std::vector<std::string>& names);

struct AssembleSummary {
    PixelRect display_window;
    std::size_t parts = 0;
    std::vector<std::string> channels;  // "R (half)", ... in the file's order
};

// Reads `part_paths` (read_exr_image), assembles them and writes `output` atomically
// (write_exr). Throws IoError for a part that cannot be read or an output that cannot be
// written, AssembleError for parts that do not fit together, std::invalid_argument for
// an empty list.
AssembleSummary assemble_files(const std::vector<std::string>& part_paths,
                               const std::string& output);

}  // namespace octray::batch
