#pragma once
// The renderers' framebuffer: RGB floats, interleaved. Row 0 is the TOP row, as OpenEXR
// stores it and as a raster image is read; the cameras flip the row index when turning a
// pixel into a ray. Past the renderer an image is render/image/image.h's Image (named
// channels, formats, windows, metadata): make_image() makes one from an RgbImage.

#include <cstddef>
#include <utility>
#include <vector>

#include "core/aligned.h"
#include "core/color.h"

namespace octray {

class RgbImage {
  public:
    // A renderer about to write every pixel (in parallel) asks for unwritten storage: the
    // pages are then first touched by the threads that fill them, not zeroed serially.
    struct Uninitialized {};

    RgbImage() = default;
    // Every pixel black.
    RgbImage(int width, int height)
        : width_(width),
          height_(height),
          pixels_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), Rgb()) {}
    // Pixel values undefined until written: the caller writes every one.
    RgbImage(int width, int height, Uninitialized)
        : width_(width),
          height_(height),
          pixels_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {}

    // A width x height image with undefined pixels in the storage of `spare`, where it
    // holds exactly that many pixels: a frame loop hands back the frame it has written,
    // and the next frame then touches no freshly mapped pages. Fresh storage otherwise,
    // after `spare`'s is freed (never two frames at once). `spare` is left empty.
    static RgbImage reuse(RgbImage&& spare, int width, int height) {
        RgbImage image;
        if (!spare.fits(width, height)) {
            spare = RgbImage();
            return RgbImage(width, height, Uninitialized{});
        }
        image.width_ = width, image.height_ = height;
        image.pixels_ = std::move(spare.pixels_);
        spare = RgbImage();
        return image;
    }

    // Whether reuse() would hand this image's storage to a width x height image.
    bool fits(int width, int height) const {
        return pixels_.size() ==
               static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    }

    int width() const { return width_; }
    int height() const { return height_; }
    std::size_t pixel_count() const { return pixels_.size(); }

    // Column x (0 = left), row y (0 = top).
    Rgb& at(int x, int y) { return pixels_[index(x, y)]; }
    const Rgb& at(int x, int y) const { return pixels_[index(x, y)]; }

    Rgb* data() { return pixels_.data(); }
    const Rgb* data() const { return pixels_.data(); }
    const std::vector<Rgb, UninitializedAllocator<Rgb>>& pixels() const { return pixels_; }

    friend bool operator==(const RgbImage& a, const RgbImage& b) {
        return a.width_ == b.width_ && a.height_ == b.height_ && a.pixels_ == b.pixels_;
    }

  private:
    std::size_t index(int x, int y) const {
        return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
               static_cast<std::size_t>(x);
    }

    int width_ = 0;
    int height_ = 0;
    std::vector<Rgb, UninitializedAllocator<Rgb>> pixels_;
};

}  // namespace octray
