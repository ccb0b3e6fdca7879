#pragma once
// The table behind srgb8 (image_io.h), and the two builds of srgb8_interleaved that read
// it: baseline x86-64 (png.cpp) and AVX2 with gathers (srgb8_avx2.cpp, compiled with
// -mavx2 and called only where the CPU has it, checked once at run time). Internal to
// octray::image.

#include <bit>
#include <cstddef>
#include <cstdint>

namespace octray::detail {

// threshold[v] (v = 1 ... 255): the smallest float that srgb8_formula maps to v or more.
// The formula never decreases as its argument grows, so the byte of x is the number of
// thresholds at or below x. Each is found by bisection over the bit patterns of the
// floats in [0, 1], which are ordered as their values. To find a byte without a search,
// the floats of (0, 1) are cut into buckets by their top 16 bits (1/128 of a power of two
// each): bucket_start holds the byte at each bucket's first float, and within a bucket the
// byte steps up at most once (the OETF's slope times a bucket's width stays below one
// step, which the constructor checks), which one comparison finds.
// bucket_start has 3 bytes more than buckets: the AVX2 build gathers 4 bytes from each
// bucket's and keeps the first.
struct SrgbTable {
    static constexpr std::uint32_t kOneBits = 0x3F800000u;  // 1.0f
    static constexpr std::uint32_t kBuckets = (kOneBits >> 16) + 1;
    float threshold[257];  // [256]: +inf, a sentinel
    std::uint8_t bucket_start[kBuckets + 3] = {};
    SrgbTable();  // checks its own bucket rule: throws std::logic_error if broken
};

// Made on first use, shared by every thread.
const SrgbTable& srgb_table();

inline std::uint8_t srgb8_in(const SrgbTable& table, float linear) {
    // Clamped to [0, 1] without branches (NaN fails the first comparison and becomes 0);
    // 1.0's bucket starts at 255, whose next threshold is +inf.
    float x = linear > 0.0f ? linear : 0.0f;
    x = x < 1.0f ? x : 1.0f;
    const int v = table.bucket_start[std::bit_cast<std::uint32_t>(x) >> 16];
    return static_cast<std::uint8_t>(v + (x >= table.threshold[v + 1] ? 1 : 0));
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
