#include "core/aligned.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace octray {
namespace {

TEST(AlignedVector, StorageIsSixtyFourByteAligned) {
    for (std::size_t n : {1u, 7u, 8u, 1000u}) {
        AlignedVector<float> v(n);
        EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % kSimdAlignment, 0u);
    }
}

// Storage that asks for huge pages starts on a 2 MiB boundary from 4 MiB on; other storage
// on a cache line. Each allocator frees with the alignment it allocated with (ASan checks
// the pairing).
TEST(AlignedStorage, HugePagesOnlyWhereAskedAndLarge) {
    const std::size_t large = kHugePageMinBytes / sizeof(float);
    for (std::size_t n : {large - 1, large, 3 * large + 5}) {
        std::vector<float, UninitializedAllocator<float, Pages::huge>> huge(n);
        const std::size_t want = n >= large ? kHugePageBytes : kSimdAlignment;
        EXPECT_EQ(reinterpret_cast<std::uintptr_t>(huge.data()) % want, 0u) << n;
        huge[n - 1] = 2.0f;
        EXPECT_EQ(huge[n - 1], 2.0f);
        AlignedVector<float, Pages::huge> huge_aligned(n, 3.0f);
        EXPECT_EQ(reinterpret_cast<std::uintptr_t>(huge_aligned.data()) % want, 0u) << n;
        EXPECT_EQ(huge_aligned[n - 1], 3.0f);
        std::vector<float, UninitializedAllocator<float>> normal(n);
        EXPECT_EQ(reinterpret_cast<std::uintptr_t>(normal.data()) % kSimdAlignment, 0u) << n;
        AlignedVector<float> aligned(n, 1.0f);
        EXPECT_EQ(reinterpret_cast<std::uintptr_t>(aligned.data()) % kSimdAlignment, 0u) << n;
        EXPECT_EQ(aligned[n - 1], 1.0f);
    }
}

}  // namespace
}  // namespace octray
