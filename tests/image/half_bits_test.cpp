// floats_to_half_bits (render/image/half_bits.h): F16C and Imath's software conversion give
// the same bits wherever rounding can go wrong, and every caller's stride and length work.

#include "render/image/half_bits.h"

#include <gtest/gtest.h>
#include <half.h>

#include <bit>
#include <cstdint>
#include <limits>
#include <vector>

namespace octray {
namespace {

// The float bit patterns where a conversion to half can go wrong: both sides of every
// rounding midpoint between neighbouring halves (ties to even), the largest finite half and
// the overflow boundary, subnormal halves and the flush to zero, infinities, quiet and
// signalling NaNs of both signs, and a sweep over all 2^32 patterns in steps of 4099.
float half_value(std::uint32_t bits) {
    half h;
    h.setBits(static_cast<std::uint16_t>(bits));
    return static_cast<float>(h);
}

std::vector<float> hard_floats() {
    std::vector<std::uint32_t> bits;
    for (std::uint32_t h = 0; h < 0x7c00; ++h) {
        // The float halfway between half h and half h + 1, and its neighbours.
        const float lo = half_value(h);
        const float hi = h + 1 == 0x7c00
                             ? 65536.0f  // past the largest half (65504): the midpoint 65520
                             : half_value(h + 1);
        const std::uint32_t mid = std::bit_cast<std::uint32_t>((lo + hi) * 0.5f);
        for (const std::uint32_t m : {mid - 1, mid, mid + 1, std::bit_cast<std::uint32_t>(lo)})
            for (const std::uint32_t sign : {0u, 0x80000000u}) bits.push_back(m | sign);
    }
    for (const std::uint32_t b :
         {0x7f800000u, 0xff800000u, 0x7fc00000u, 0xffc00000u, 0x7f800001u, 0x7fa00000u,
          0xff800001u, 0x7fbfffffu, 0x7fffffffu, 0x00000001u, 0x33000000u, 0x33000001u,
          0x387fffffu, 0x38800000u, 0x477fefffu, 0x477ff000u, 0x47800000u})
        bits.push_back(b);
    for (std::uint64_t b = 0; b <= 0xffffffffu; b += 4099)
        bits.push_back(static_cast<std::uint32_t>(b));
    std::vector<float> out;
    out.reserve(bits.size());
    for (const std::uint32_t b : bits) out.push_back(std::bit_cast<float>(b));
    return out;
}

TEST(HalfBits, ImathBuildIsImathsHalf) {
    const std::vector<float> v = hard_floats();
    std::vector<std::uint16_t> out(v.size());
    detail::floats_to_half_bits_imath(v.data(), v.size(), 1, out.data());
    for (std::size_t k = 0; k < v.size(); ++k)
        ASSERT_EQ(out[k], half(v[k]).bits())
            << "float bits " << std::bit_cast<std::uint32_t>(v[k]);
}

TEST(HalfBits, F16cGivesImathsBitsEverywhereRoundingIsHard) {
    if (!half_bits_use_f16c())
        GTEST_SKIP() << "this CPU has no F16C (or no AVX state): nothing to compare";
    const std::vector<float> v = hard_floats();
    std::vector<std::uint16_t> f16c(v.size()), imath(v.size());
    detail::floats_to_half_bits_f16c(v.data(), v.size(), 1, f16c.data());
    detail::floats_to_half_bits_imath(v.data(), v.size(), 1, imath.data());
    std::size_t wrong = 0;
    for (std::size_t k = 0; k < v.size() && wrong < 10; ++k)
        if (f16c[k] != imath[k]) {
            ++wrong;
            ADD_FAILURE() << "float bits " << std::hex << std::bit_cast<std::uint32_t>(v[k])
                          << ": f16c " << f16c[k] << ", Imath " << imath[k];
        }
}

// Every third float (stride 3), lengths that leave 0 to 8 values after the 8-wide blocks,
// a NaN inside a block; each out[k] written, nothing past count, nothing read past the
// buffer (which holds exactly the count's pixels: ASan checks the reads).
TEST(HalfBits, StridesAndTailsGiveEachValueItsHalf) {
    for (std::size_t count = 1; count <= 35; ++count) {
        std::vector<float> rgb(3 * count);
        for (std::size_t k = 0; k < rgb.size(); ++k)
            rgb[k] = 0.1f * static_cast<float>(k) - 2.0f;
        if (count > 5) rgb[3 * 5 + 1] = std::numeric_limits<float>::signaling_NaN();
        for (std::size_t channel = 0; channel < 3; ++channel) {
            std::vector<std::uint16_t> out(count + 1, 0xabcd);
            floats_to_half_bits(rgb.data() + channel, count, 3, out.data());
            for (std::size_t k = 0; k < count; ++k)
                ASSERT_EQ(out[k], half(rgb[3 * k + channel]).bits()) << count << " " << k;
            EXPECT_EQ(out[count], 0xabcd) << "written past count " << count;
        }
    }
}

// The F16C build with a stride (the floats gathered 8 at a time): every hard float, at
// each of three offsets.
TEST(HalfBits, F16cWithAStrideGivesImathsBits) {
    if (!half_bits_use_f16c())
        GTEST_SKIP() << "this CPU has no F16C (or no AVX state): nothing to compare";
    const std::vector<float> v = hard_floats();
    const std::size_t pixels = v.size() / 3;
    for (std::size_t channel = 0; channel < 3; ++channel) {
        std::vector<std::uint16_t> f16c(pixels), imath(pixels);
        detail::floats_to_half_bits_f16c(v.data() + channel, pixels, 3, f16c.data());
        detail::floats_to_half_bits_imath(v.data() + channel, pixels, 3, imath.data());
        for (std::size_t k = 0; k < pixels; ++k)
            ASSERT_EQ(f16c[k], imath[k]) << "channel " << channel << ", float bits " << std::hex
                                         << std::bit_cast<std::uint32_t>(v[3 * k + channel]);
    }
}

}  // namespace
}  // namespace octray
