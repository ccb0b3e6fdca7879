#include "view/tone_map.h"

#include <cmath>
#include <stdexcept>

#include "render/image/image_io.h"
#include "view/jpeg.h"

namespace octray::view {

std::vector<std::uint8_t> tone_map_srgb8(const Image& image, float exposure) {
    if (!is_rgb_image(image))
        throw std::invalid_argument("tone_map_srgb8: a picture is float32 R, G, B planes");
    std::vector<std::uint8_t> rgb(3 * image.pixel_count());
    srgb8_interleaved(image.plane(0), image.plane(1), image.plane(2), image.pixel_count(),
                      std::exp2(exposure), rgb.data());
    return rgb;
}

PagePicture encode_for_page(const ViewFrame& frame, float exposure) {
    const int width = frame.image.width(), height = frame.image.height();
    const std::vector<std::uint8_t> rgb = tone_map_srgb8(frame.image, exposure);
    if (!frame.preview && frame.spp >= frame.target_spp && frame.coverage >= 1.0)
        return {encode_png_rgb8(width, height, rgb), "png"};
    return {encode_jpeg_rgb8(width, height, rgb, kStreamJpegQuality), "jpeg"};
}

}  // namespace octray::view
