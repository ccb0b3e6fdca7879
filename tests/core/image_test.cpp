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

}  // namespace
}  // namespace octray
