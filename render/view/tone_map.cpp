#include "render/view/tone_map.h"

#include <png.h>

#include <cmath>
#include <stdexcept>

namespace octray::view {
namespace {

std::uint8_t to_srgb8(float linear) {
    const float v = linear > 0.0f ? (linear < 1.0f ? linear : 1.0f) : 0.0f;  // NaN -> 0
    const float encoded =
        v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
    return static_cast<std::uint8_t>(std::lround(encoded * 255.0f));
}

void append_to_string(png_structp png, png_bytep data, png_size_t size) {
    auto* out = static_cast<std::string*>(png_get_io_ptr(png));
    out->append(reinterpret_cast<const char*>(data), size);
}

}  // namespace

std::vector<std::uint8_t> tone_map_srgb8(const Image& image, float exposure) {
    const float scale = std::exp2(exposure);
    std::vector<std::uint8_t> rgb(3 * image.pixel_count());
    const Rgb* pixels = image.data();
    for (std::size_t i = 0; i < image.pixel_count(); ++i) {
        rgb[3 * i + 0] = to_srgb8(pixels[i].r * scale);
        rgb[3 * i + 1] = to_srgb8(pixels[i].g * scale);
        rgb[3 * i + 2] = to_srgb8(pixels[i].b * scale);
    }
    return rgb;
}

std::string encode_png_rgb8(int width, int height, const std::vector<std::uint8_t>& rgb) {
    if (width <= 0 || height <= 0 ||
        rgb.size() != 3 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height))
        throw std::runtime_error("PNG encoding: the pixel count does not match the size");
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    if (!png) throw std::runtime_error("PNG encoding: libpng could not start");
    png_infop info = png_create_info_struct(png);
    std::string out;
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        throw std::runtime_error("PNG encoding: libpng failed");
    }
    png_set_write_fn(png, &out, append_to_string, nullptr);
    png_set_compression_level(png, 1);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
    png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height),
                 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    for (int y = 0; y < height; ++y) {
        png_write_row(png,
                      const_cast<png_bytep>(rgb.data() + 3 * static_cast<std::size_t>(width) *
                                                             static_cast<std::size_t>(y)));
    }
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return out;
}

}  // namespace octray::view
