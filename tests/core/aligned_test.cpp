#include "core/aligned.h"

#include <gtest/gtest.h>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

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

#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
// populate_pages maps the whole pages inside the range, and only those, writable without
// changing a byte: the pages are resident afterwards (mincore), the partial pages at either
// end are left to their first write, and what the storage held is still there.
TEST(PopulatePages, MapsTheWholePagesInsideTheRangeAndKeepsTheirBytes) {
    const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
    constexpr std::size_t kPages = 16;
    void* mapped = ::mmap(nullptr, kPages * page, PROT_READ | PROT_WRITE,
                          MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    ASSERT_NE(mapped, MAP_FAILED);
    auto* bytes = static_cast<unsigned char*>(mapped);
    // Page 2 holds data before the call; the others were never touched.
    for (std::size_t i = 0; i < page; ++i)
        bytes[2 * page + i] = static_cast<unsigned char>(i * 7);
    const auto resident = [&] {
        std::vector<unsigned char> in(kPages);
        EXPECT_EQ(::mincore(mapped, kPages * page, in.data()), 0);
        std::vector<bool> out(kPages);
        for (std::size_t k = 0; k < kPages; ++k) out[k] = (in[k] & 1) != 0;
        return out;
    };
    if (::madvise(bytes + 15 * page, page, MADV_POPULATE_WRITE) != 0) {
        ::munmap(mapped, kPages * page);
        GTEST_SKIP() << "this kernel has no MADV_POPULATE_WRITE (Linux 5.14 and later)";
    }
    // From inside page 1 to inside page 12: pages 2 ... 11 are whole.
    populate_pages(bytes + page + 100, 11 * page);
    const std::vector<bool> after = resident();
    for (std::size_t k = 0; k < kPages; ++k) {
        const bool expected = (k >= 2 && k <= 11) || k == 15;
        EXPECT_EQ(after[k], expected) << "page " << k;
    }
    for (std::size_t i = 0; i < page; ++i)
        ASSERT_EQ(bytes[2 * page + i], static_cast<unsigned char>(i * 7)) << i;
    for (std::size_t i = 3 * page; i < 12 * page; ++i) ASSERT_EQ(bytes[i], 0) << i;
    // An empty range, and one inside a single page, map nothing.
    populate_pages(bytes + 13 * page + 8, 0);
    populate_pages(bytes + 13 * page + 8, page - 16);
    EXPECT_FALSE(resident()[13]);
    ::munmap(mapped, kPages * page);
}
#endif

}  // namespace
}  // namespace octray
