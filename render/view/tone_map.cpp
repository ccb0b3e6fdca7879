#include "render/view/tone_map.h"

#include <cmath>

#include "render/image/image_io.h"

namespace octray::view {

std::vector<std::uint8_t> tone_map_srgb8(const Image& image, float exposure) {
    const float scale = std::exp2(exposure);
    std::vector<std::uint8_t> rgb(3 * image.pixel_count());
    const Rgb* pixels = image.data();
    for (std::size_t i = 0; i < image.pixel_count(); ++i) {
        rgb[3 * i + 0] = srgb8(pixels[i].r * scale);
        rgb[3 * i + 1] = srgb8(pixels[i].g * scale);
        rgb[3 * i + 2] = srgb8(pixels[i].b * scale);
    }
    return rgb;
}

}  // namespace octray::view
