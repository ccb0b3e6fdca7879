#pragma once
// 64-byte aligned storage for the SoA arrays the kernels stream through (one cache line,
// and the alignment of a 512-bit register).

#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace octray {

inline constexpr std::size_t kSimdAlignment = 64;

template <class T>
struct AlignedAllocator {
    using value_type = T;

    AlignedAllocator() = default;
    template <class U>
    constexpr AlignedAllocator(const AlignedAllocator<U>&) noexcept {}

    T* allocate(std::size_t n) {
        return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{kSimdAlignment}));
    }
    void deallocate(T* p, std::size_t) noexcept {
        ::operator delete(p, std::align_val_t{kSimdAlignment});
    }

    template <class U>
    friend bool operator==(const AlignedAllocator&, const AlignedAllocator<U>&) {
        return true;
    }
};

template <class T>
using AlignedVector = std::vector<T, AlignedAllocator<T>>;

// std::allocator, except that a value-less construct() leaves the element's bytes alone:
// a vector of trivially copyable elements (pixels, the BVH builder's sphere references)
// can then be sized without writing them, and its pages are first touched by the threads
// that fill them. Storage starts on a cache line, so whole rows of pixels can be streamed
// to memory (render/packet_renderer.cpp).
template <class T>
struct UninitializedAllocator : std::allocator<T> {
    static constexpr std::align_val_t kAlignment{kSimdAlignment};
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

}  // namespace octray
