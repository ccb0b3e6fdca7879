#pragma once
// The table behind srgb8 (image_io.h), and the two builds of srgb8_interleaved that read
// it: baseline x86-64 (png.cpp) and AVX2 with gathers (srgb8_avx2.cpp, compiled with
// -mavx2 and called only where the CPU has it, checked once at run time). Internal to
// octray::image.

#include <bit>
#include <cstddef>
#include <cstdint>

namespace octray::detail {

// The byte's thresholds (the constructor's): threshold[v] (v = 1 ... 255) is the smallest
// float that srgb8_formula maps to v or more. The formula never decreases as its argument
// grows, so the byte of x is the number of thresholds at or below x. Each is found by bisection
// over the bit patterns of the floats in [0, 1], which are ordered as their values. To find a
// byte without a search, the floats of [0, 1] are cut into buckets by their top 16 bits (1/128
// of a power of two each), and within a bucket the byte steps up at most once (the OETF's slope
// times a bucket's width stays below one step, which the constructor checks). A bucket's word
// holds the byte at its first float (bits 17 and up) and where in the bucket the byte
// steps up (bits 0 ... 16): the low 16 bits of that threshold, whose top 16 bits are the
// bucket's own, or 0x10000, above every float of the bucket, where it does not. A float's
// byte is then one lookup and one comparison of its low 16 bits (srgb8_in); the AVX2
// build gathers one word per sample, where a table of first bytes and one of thresholds
// took two gathers, the second waiting on the first.
struct SrgbTable {
    static constexpr std::uint32_t kOneBits = 0x3F800000u;  // 1.0f
    static constexpr std::uint32_t kBuckets = (kOneBits >> 16) + 1;
    static constexpr std::uint32_t kNoStep = 0x10000u;
    std::uint32_t bucket_word[kBuckets];
    SrgbTable();  // checks its own bucket rule: throws std::logic_error if broken
};

// Made on first use, shared by every thread.
const SrgbTable& srgb_table();

inline std::uint8_t srgb8_in(const SrgbTable& table, float linear) {
    // Clamped to [0, 1] without branches (NaN fails the first comparison and becomes 0);
    // 1.0's bucket starts at 255 and steps nowhere.
    float x = linear > 0.0f ? linear : 0.0f;
    x = x < 1.0f ? x : 1.0f;
    const std::uint32_t bits = std::bit_cast<std::uint32_t>(x);
    const std::uint32_t word = table.bucket_word[bits >> 16];
    return static_cast<std::uint8_t>((word >> 17) + ((bits & 0xFFFFu) >= (word & 0x1FFFFu)));
}

// Whether srgb8_interleaved uses the AVX2 build on this CPU.
bool srgb8_use_avx2();
// The two builds of srgb8_interleaved, the same bytes (the tests hold them to srgb8); the
// AVX2 one only where srgb8_use_avx2().
void srgb8_interleaved_scalar(const float* r, const float* g, const float* b, std::size_t count,
                              float scale, std::uint8_t* out);
void srgb8_interleaved_avx2(const float* r, const float* g, const float* b, std::size_t count,
                            float scale, std::uint8_t* out);

}  // namespace octray::detail
