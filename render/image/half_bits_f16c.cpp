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
