#include "core/image.h"

#include <gtest/gtest.h>

#include <cstdint>

#include "core/aligned.h"

namespace octray {
namespace {

TEST(Image, RowZeroIsTheTopRowStoredFirst) {
    Image img(3, 2);
    img.at(0, 0) = Rgb(1.0f);  // top-left
    img.at(2, 1) = Rgb(2.0f);  // bottom-right
    EXPECT_EQ(img.data()[0], Rgb(1.0f));
    EXPECT_EQ(img.data()[5], Rgb(2.0f));
    EXPECT_EQ(img.pixel_count(), 6u);
}

TEST(Image, NonSquareDimensionsAreKeptApart) {
    Image img(4, 2);
    img.at(3, 0) = Rgb(7.0f);
    EXPECT_EQ(img.width(), 4);
    EXPECT_EQ(img.height(), 2);
    EXPECT_EQ(img.data()[3], Rgb(7.0f));  // (3, 0) is in the first row, not (0, 3)
}

TEST(AlignedVector, StorageIsSixtyFourByteAligned) {
    for (std::size_t n : {1u, 7u, 8u, 1000u}) {
        AlignedVector<float> v(n);
        EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % kSimdAlignment, 0u);
    }
}

// From 4 MiB on, storage starts on a huge page (2 MiB); both allocators free what they
// allocated with the alignment they allocated it with (ASan checks the pairing).
TEST(AlignedVector, LargeStorageStartsOnAHugePage) {
    const std::size_t large = kHugePageMinBytes / sizeof(float);
    for (std::size_t n : {large - 1, large, 3 * large + 5}) {
        AlignedVector<float> v(n, 1.0f);
        const auto at = reinterpret_cast<std::uintptr_t>(v.data());
        EXPECT_EQ(at % (n >= large ? kHugePageBytes : kSimdAlignment), 0u) << n;
        EXPECT_EQ(v[n - 1], 1.0f);
        std::vector<float, UninitializedAllocator<float>> u(n);
        EXPECT_EQ(reinterpret_cast<std::uintptr_t>(u.data()) %
                      (n >= large ? kHugePageBytes : kSimdAlignment),
                  0u)
            << n;
        u[n - 1] = 2.0f;
        EXPECT_EQ(u[n - 1], 2.0f);
    }
}

}  // namespace
}  // namespace octray
