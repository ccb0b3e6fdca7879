// The AVX2 build of srgb8_interleaved (render/image/srgb_table.h), compiled with -mavx2
// (render/image/CMakeLists.txt) and called only where the CPU has it. Eight pixels at a
// time: each channel's byte found as srgb8_in finds it, with one gather (the bucket's
// word), and the three channels' bytes interleaved by one shuffle. It calls no inline code
// shared with baseline translation units but the scalar build, for the last pixels.

#include <immintrin.h>

#include "render/image/srgb_table.h"

namespace octray::detail {
namespace {

// srgb8_in of 8 samples times `scale`, as 32-bit lanes.
__m256i srgb8_lanes(const SrgbTable& table, const float* linear, __m256 scale) {
    const __m256 x0 = _mm256_mul_ps(_mm256_loadu_ps(linear), scale);
    // max returns its second operand for a NaN (and for -0 against +0): 0, as srgb8_in's
    // comparison gives; then at most 1.
    const __m256i bits = _mm256_castps_si256(
        _mm256_min_ps(_mm256_max_ps(x0, _mm256_setzero_ps()), _mm256_set1_ps(1.0f)));
    const __m256i word = _mm256_i32gather_epi32(reinterpret_cast<const int*>(table.bucket_word),
                                                _mm256_srli_epi32(bits, 16), 4);
    // -1 where the float lies below its bucket's step (both operands below 2^17).
    const __m256i below = _mm256_cmpgt_epi32(_mm256_and_si256(word, _mm256_set1_epi32(0x1FFFF)),
                                             _mm256_and_si256(bits, _mm256_set1_epi32(0xFFFF)));
    return _mm256_add_epi32(_mm256_srli_epi32(word, 17),
                            _mm256_add_epi32(below, _mm256_set1_epi32(1)));
}

}  // namespace

void srgb8_interleaved_avx2(const float* r, const float* g, const float* b, std::size_t count,
                            float scale, std::uint8_t* out) {
    const SrgbTable& table = srgb_table();
    const __m256 s = _mm256_set1_ps(scale);
    // Each 128-bit half holds 4 pixels as R | G << 8 | B << 16: their 12 bytes to the front.
    const __m256i pack =
        _mm256_setr_epi8(0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, -1, -1, -1, -1, 0, 1, 2, 4, 5,
                         6, 8, 9, 10, 12, 13, 14, -1, -1, -1, -1);
    std::size_t i = 0;
    // Each half is stored as 16 bytes, 4 past its 12: while 10 pixels remain, those 4
    // are inside the row (and the next 8 pixels write them again).
    for (; i + 10 <= count; i += 8) {
        const __m256i pixels = _mm256_or_si256(
            srgb8_lanes(table, r + i, s),
            _mm256_or_si256(_mm256_slli_epi32(srgb8_lanes(table, g + i, s), 8),
                            _mm256_slli_epi32(srgb8_lanes(table, b + i, s), 16)));
        const __m256i bytes = _mm256_shuffle_epi8(pixels, pack);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 3 * i),
                         _mm256_castsi256_si128(bytes));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 3 * i + 12),
                         _mm256_extracti128_si256(bytes, 1));
    }
    srgb8_interleaved_scalar(r + i, g + i, b + i, count - i, scale, out + 3 * i);
}

}  // namespace octray::detail
