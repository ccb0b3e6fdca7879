#pragma once
// 64-byte aligned storage for the SoA arrays the kernels stream through (one cache line,
// and the alignment of a 512-bit register); large scratch buffers on huge pages.

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include <cstddef>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace octray {

inline constexpr std::size_t kSimdAlignment = 64;

// Storage that asks for Pages::huge and holds 4 MiB or more starts on a 2 MiB boundary and
// is offered to Linux's transparent huge pages, which Debian's kernel gives only where
// asked (madvise): a 2 MiB page takes one page fault where 4 KiB pages take 512. The BVH
// and its builder's buffers ask (it builds faster); frames do not: a frame is allocated
// per render, and renders went slower with its pages huge (the kernel zeroes, and may
// first compact, 2 MiB at a time). Measured: docs/performance-log.md, "Figures from
// source comments".
enum class Pages { normal, huge };
inline constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;
inline constexpr std::size_t kHugePageMinBytes = std::size_t{4} << 20;

inline std::align_val_t storage_alignment(std::size_t bytes, Pages pages) {
    return std::align_val_t{
        pages == Pages::huge && bytes >= kHugePageMinBytes ? kHugePageBytes : kSimdAlignment};
}

// `bytes` of uninitialised storage aligned as above; release with free_aligned(p, bytes,
// pages).
inline void* allocate_aligned(std::size_t bytes, Pages pages = Pages::normal) {
    void* p = ::operator new(bytes, storage_alignment(bytes, pages));
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    // Advice only: where the kernel has no huge pages the call fails and nothing changes.
    if (pages == Pages::huge && bytes >= kHugePageMinBytes)
        (void)madvise(p, bytes, MADV_HUGEPAGE);
#endif
    return p;
}
// The same offer for storage allocated elsewhere (a std::string or std::vector that is
// about to be filled): the whole 2 MiB pages inside [p, p + bytes), if it holds 4 MiB or
// more: a large scene file is read faster into a string offered this way (measured there
// too). Advice only.
inline void offer_huge_pages([[maybe_unused]] void* p, [[maybe_unused]] std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (bytes < kHugePageMinBytes) return;
    const std::size_t mask = kHugePageBytes - 1;
    const std::size_t begin = (reinterpret_cast<std::size_t>(p) + mask) & ~mask;
    const std::size_t end = (reinterpret_cast<std::size_t>(p) + bytes) & ~mask;
    if (end > begin) (void)madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#endif
}

// Maps the whole 4 KiB pages inside [p, p + bytes) writable without writing them
// (MADV_POPULATE_WRITE): their contents stay as they are, and a page already mapped is
// passed over. The kernel still zeroes each fresh page, but on the calling thread, which
// takes that work off a thread about to fill the storage: the frame's pages are mapped on
// the render's threads (render/packet_renderer.cpp), a large scene's objects on the
// thread the file's hash leaves idle while the parse fills them (scene/load_fast.cpp).
// Advice only: a kernel before Linux 5.14 refuses it, and the first write maps each page
// as before.
inline void populate_pages([[maybe_unused]] void* p, [[maybe_unused]] std::size_t bytes) {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
    constexpr std::size_t kPage = 4096;
    const std::size_t begin = (reinterpret_cast<std::size_t>(p) + kPage - 1) & ~(kPage - 1);
    const std::size_t end = (reinterpret_cast<std::size_t>(p) + bytes) & ~(kPage - 1);
    if (end > begin)
        (void)madvise(reinterpret_cast<void*>(begin), end - begin, MADV_POPULATE_WRITE);
#endif
}

// The unsized form: clang declares sized deallocation only with -fsized-deallocation.
inline void free_aligned(void* p, std::size_t bytes, Pages pages = Pages::normal) noexcept {
    ::operator delete(p, storage_alignment(bytes, pages));
}

template <class T, Pages kPages = Pages::normal>
struct AlignedAllocator {
    using value_type = T;
    template <class U>
    struct rebind {
        using other = AlignedAllocator<U, kPages>;
    };

    AlignedAllocator() = default;
    template <class U>
    constexpr AlignedAllocator(const AlignedAllocator<U, kPages>&) noexcept {}

    T* allocate(std::size_t n) {
        if (n > std::size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
        return static_cast<T*>(allocate_aligned(n * sizeof(T), kPages));
    }
    void deallocate(T* p, std::size_t n) noexcept { free_aligned(p, n * sizeof(T), kPages); }

    template <class U>
    friend bool operator==(const AlignedAllocator&, const AlignedAllocator<U, kPages>&) {
        return true;
    }
};

template <class T, Pages kPages = Pages::normal>
using AlignedVector = std::vector<T, AlignedAllocator<T, kPages>>;

// AlignedAllocator, except that a value-less construct() leaves the element's bytes alone:
// a vector of trivially copyable elements (pixels, the BVH builder's sphere references)
// can then be sized without writing them, and its pages are first touched by the threads
// that fill them. Storage is aligned as above (at least a cache line), so whole rows of
// pixels can be streamed to memory (render/packet_renderer.cpp).
template <class T, Pages kPages = Pages::normal>
struct UninitializedAllocator : AlignedAllocator<T, kPages> {
    template <class U>
    struct rebind {
        using other = UninitializedAllocator<U, kPages>;
    };
    UninitializedAllocator() = default;
    template <class U>
    UninitializedAllocator(const UninitializedAllocator<U, kPages>&) noexcept {}

    template <class U>
    void construct(U*) noexcept {
        static_assert(std::is_trivially_copyable_v<U> && std::is_trivially_destructible_v<U>);
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

// A vector whose resize() leaves the new elements' bytes to be written by the caller.
template <class T, Pages kPages = Pages::normal>
using UninitializedVector = std::vector<T, UninitializedAllocator<T, kPages>>;

}  // namespace octray
