// The F16C build of floats_to_half_bits (render/image/half_bits.h), compiled with -mf16c
// -mavx (render/image/CMakeLists.txt) and called only where the CPU has them. It calls no
// inline code shared with baseline translation units, but for NaN lanes, which go back to
// the baseline build (detail::floats_to_half_bits_imath).

#include <immintrin.h>

#include "render/image/half_bits.h"

namespace octray::detail {

void floats_to_half_bits_f16c(const float* values, std::size_t count, std::size_t stride,
                              std::uint16_t* out) {
    alignas(32) float block[8];
    std::size_t k = 0;
    if (stride == 3) {
        // Every third float of interleaved RGB (values points at R, G or B): 24 floats in
        // a row are converted, and every third half picked out, without the scalar loads
        // of the general case. The 24 reach 2 floats past sample k + 7, which the bound
        // keeps inside the buffer. pickN moves the wanted halves of the Nth 8 into place.
        const __m128i pick0 =
            _mm_setr_epi8(0, 1, 6, 7, 12, 13, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1);
        const __m128i pick1 =
            _mm_setr_epi8(-1, -1, -1, -1, -1, -1, 2, 3, 8, 9, 14, 15, -1, -1, -1, -1);
        const __m128i pick2 =
            _mm_setr_epi8(-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 4, 5, 10, 11);
        for (; k + 9 <= count; k += 8) {
            const float* v = values + k * 3;
            const __m256 a = _mm256_loadu_ps(v);
            const __m256 b = _mm256_loadu_ps(v + 8);
            const __m256 c = _mm256_loadu_ps(v + 16);
            const __m256 nan = _mm256_or_ps(_mm256_cmp_ps(a, a, _CMP_UNORD_Q),
                                            _mm256_or_ps(_mm256_cmp_ps(b, b, _CMP_UNORD_Q),
                                                         _mm256_cmp_ps(c, c, _CMP_UNORD_Q)));
            if (_mm256_movemask_ps(nan) != 0) {
                floats_to_half_bits_imath(v, 8, 3, out + k);
                continue;
            }
            constexpr int kRound = _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC;
            const __m128i h =
                _mm_or_si128(_mm_shuffle_epi8(_mm256_cvtps_ph(a, kRound), pick0),
                             _mm_or_si128(_mm_shuffle_epi8(_mm256_cvtps_ph(b, kRound), pick1),
                                          _mm_shuffle_epi8(_mm256_cvtps_ph(c, kRound), pick2)));
            _mm_storeu_si128(reinterpret_cast<__m128i*>(out + k), h);
        }
    }
    for (; k + 8 <= count; k += 8) {
        __m256 v;
        if (stride == 1) {
            v = _mm256_loadu_ps(values + k);
        } else {
            for (std::size_t j = 0; j < 8; ++j) block[j] = values[(k + j) * stride];
            v = _mm256_load_ps(block);
        }
        // vcvtps2ph rounds to nearest even like Imath; a NaN's bits it may change.
        if (_mm256_movemask_ps(_mm256_cmp_ps(v, v, _CMP_UNORD_Q)) != 0) {
            floats_to_half_bits_imath(values + k * stride, 8, stride, out + k);
            continue;
        }
        const __m128i h = _mm256_cvtps_ph(v, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out + k), h);
    }
    floats_to_half_bits_imath(values + k * stride, count - k, stride, out + k);
}

}  // namespace octray::detail
