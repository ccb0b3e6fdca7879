#pragma once
// An RGB float image. Row 0 is the TOP row, as OpenEXR stores it and as a raster image
// is read; the cameras flip the row index when turning a pixel into a ray.

#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/color.h"

namespace octray {

// std::allocator, except that a value-less construct() leaves the element's bytes alone:
// a vector of trivially copyable pixels can then be sized without writing them. Storage
// starts on a cache line, so whole rows of pixels can be streamed to memory
// (render/packet_renderer.cpp).
template <class T>
struct UninitializedAllocator : std::allocator<T> {
    static constexpr std::align_val_t kAlignment{64};
    template <class U>
    struct rebind {
        using other = UninitializedAllocator<U>;
    };
    UninitializedAllocator() = default;
    template <class U>
    UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}

    T* allocate(std::size_t n) {
        if (n > std::size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
        return static_cast<T*>(::operator new(n * sizeof(T), kAlignment));
    }
    // The unsized form: clang declares sized deallocation only with -fsized-deallocation.
    void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, kAlignment); }

    template <class U>
    void construct(U*) noexcept {
        static_assert(std::is_trivially_copyable_v<U> && std::is_trivially_destructible_v<U>);
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

class Image {
  public:
    // A renderer about to write every pixel (in parallel) asks for unwritten storage: the
    // pages are then first touched by the threads that fill them, not zeroed serially.
    struct Uninitialized {};

    Image() = default;
    // Every pixel black.
    Image(int width, int height)
        : width_(width),
          height_(height),
          pixels_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), Rgb()) {}
    // Pixel values undefined until written: the caller writes every one.
    Image(int width, int height, Uninitialized)
        : width_(width),
          height_(height),
          pixels_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {}

    int width() const { return width_; }
    int height() const { return height_; }
    std::size_t pixel_count() const { return pixels_.size(); }

    // Column x (0 = left), row y (0 = top).
    Rgb& at(int x, int y) { return pixels_[index(x, y)]; }
    const Rgb& at(int x, int y) const { return pixels_[index(x, y)]; }

    Rgb* data() { return pixels_.data(); }
    const Rgb* data() const { return pixels_.data(); }
    const std::vector<Rgb, UninitializedAllocator<Rgb>>& pixels() const { return pixels_; }

    friend bool operator==(const Image& a, const Image& b) {
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
