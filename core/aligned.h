#pragma once
// 64-byte aligned storage for the SoA arrays the kernels stream through (one cache line,
// and the alignment of a 512-bit register).

#include <cstddef>
#include <new>
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

}  // namespace octray
