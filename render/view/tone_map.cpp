#include "render/view/tone_map.h"

#include <cmath>

#include "render/image/image_io.h"

namespace octray::view {

std::vector<std::uint8_t> tone_map_srgb8(const Image& image, float exposure) {
    static_assert(sizeof(Rgb) == 3 * sizeof(float));
    std::vector<std::uint8_t> rgb(3 * image.pixel_count());
    srgb8_scaled(reinterpret_cast<const float*>(image.data()), rgb.size(), std::exp2(exposure),
                 rgb.data());
    return rgb;
}

}  // namespace octray::view
