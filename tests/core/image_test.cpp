#include "core/image.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <utility>

#include "core/aligned.h"

namespace octray {
namespace {

TEST(RgbImage, RowZeroIsTheTopRowStoredFirst) {
    RgbImage img(3, 2);
    img.at(0, 0) = Rgb(1.0f);  // top-left
    img.at(2, 1) = Rgb(2.0f);  // bottom-right
    EXPECT_EQ(img.data()[0], Rgb(1.0f));
    EXPECT_EQ(img.data()[5], Rgb(2.0f));
    EXPECT_EQ(img.pixel_count(), 6u);
}

TEST(RgbImage, NonSquareDimensionsAreKeptApart) {
    RgbImage img(4, 2);
    img.at(3, 0) = Rgb(7.0f);
    EXPECT_EQ(img.width(), 4);
    EXPECT_EQ(img.height(), 2);
    EXPECT_EQ(img.data()[3], Rgb(7.0f));  // (3, 0) is in the first row, not (0, 3)
}

// A batch renders each frame into the last one's storage (RenderOptions::spare_image).
TEST(RgbImage, ReuseTakesTheSparesStorageOnlyWhenThePixelCountsAgreeAndFreesItElse) {
    RgbImage spare(6, 4);
    const Rgb* storage = spare.data();
    const RgbImage taken = RgbImage::reuse(std::move(spare), 8, 3);  // 24 pixels either way
    EXPECT_EQ(taken.data(), storage);
    EXPECT_EQ(taken.width(), 8);
    EXPECT_EQ(taken.height(), 3);
    EXPECT_EQ(spare.pixel_count(), 0u);  // NOLINT(bugprone-use-after-move): left empty

    RgbImage other(5, 5);
    const RgbImage fresh = RgbImage::reuse(std::move(other), 8, 3);
    EXPECT_EQ(fresh.pixel_count(), 24u);
    EXPECT_EQ(fresh.width(), 8);
    EXPECT_EQ(other.pixel_count(), 0u);  // NOLINT(bugprone-use-after-move): freed first
}

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
