#pragma once
// 64-byte aligned storage for the SoA arrays the kernels stream through (one cache line,
// and the alignment of a 512-bit register). Large arrays go on transparent huge pages.

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace octray {

inline constexpr std::size_t kSimdAlignment = 64;

// Arrays from 4 MiB on (a big scene's BVH and spheres, the builder's buffers, a frame)
// start on a 2 MiB boundary and are offered to Linux's transparent huge pages, which
// Debian's kernel gives only where asked (madvise): a 2 MiB page takes one page fault
// where 4 KiB pages take 512, and one TLB entry covers it. Building the BVH of
// random:1048576 took 15 % less time with them.
inline constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;
inline constexpr std::size_t kHugePageMinBytes = std::size_t{4} << 20;

inline std::align_val_t storage_alignment(std::size_t bytes) {
    return std::align_val_t{bytes >= kHugePageMinBytes ? kHugePageBytes : kSimdAlignment};
}

// `bytes` of uninitialised storage aligned as above; release with free_aligned(p, bytes).
inline void* allocate_aligned(std::size_t bytes) {
    void* p = ::operator new(bytes, storage_alignment(bytes));
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    // Advice only: where the kernel has no huge pages the call fails and nothing changes.
    if (bytes >= kHugePageMinBytes) (void)madvise(p, bytes, MADV_HUGEPAGE);
#endif
    return p;
}
// The unsized form: clang declares sized deallocation only with -fsized-deallocation.
inline void free_aligned(void* p, std::size_t bytes) noexcept {
    ::operator delete(p, storage_alignment(bytes));
}

template <class T>
struct AlignedAllocator {
    using value_type = T;

    AlignedAllocator() = default;
    template <class U>
    constexpr AlignedAllocator(const AlignedAllocator<U>&) noexcept {}

    T* allocate(std::size_t n) {
        if (n > std::size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
        return static_cast<T*>(allocate_aligned(n * sizeof(T)));
    }
    void deallocate(T* p, std::size_t n) noexcept { free_aligned(p, n * sizeof(T)); }

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
// that fill them. Storage is aligned as above (at least a cache line), so whole rows of
// pixels can be streamed to memory (render/packet_renderer.cpp).
template <class T>
struct UninitializedAllocator : std::allocator<T> {
    template <class U>
    struct rebind {
        using other = UninitializedAllocator<U>;
    };
    UninitializedAllocator() = default;
    template <class U>
    UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}

    T* allocate(std::size_t n) {
        if (n > std::size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
        return static_cast<T*>(allocate_aligned(n * sizeof(T)));
    }
    void deallocate(T* p, std::size_t n) noexcept { free_aligned(p, n * sizeof(T)); }

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
