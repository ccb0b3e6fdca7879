// The SHA-extensions build of SHA-256's compression function (digest.h), compiled with
// -msha -msse4.1 (render/batch/CMakeLists.txt) and called only where the CPU has them.
// Intel's scheme ("Intel SHA Extensions", 2013): the state held as ABEF and CDGH, each
// sha256rnds2 doing two rounds, sha256msg1 and sha256msg2 extending the message schedule
// four words at a time.

#include <immintrin.h>

#include "render/batch/digest.h"

namespace octray::batch::detail {

void sha256_blocks_shani(std::uint32_t state[8], const unsigned char* data,
                         std::size_t blocks) {
    // Each 32-bit word of the message is big-endian.
    const __m128i byte_swap = _mm_set_epi64x(0x0c0d0e0f08090a0bULL, 0x0405060700010203ULL);
    __m128i tmp = _mm_loadu_si128(reinterpret_cast<const __m128i*>(state));         // DCBA
    __m128i state1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(state + 4));  // HGFE
    tmp = _mm_shuffle_epi32(tmp, 0xB1);                                             // CDAB
    state1 = _mm_shuffle_epi32(state1, 0x1B);                                       // EFGH
    __m128i state0 = _mm_alignr_epi8(tmp, state1, 8);                               // ABEF
    state1 = _mm_blend_epi16(state1, tmp, 0xF0);                                    // CDGH

    for (; blocks > 0; --blocks, data += 64) {
        const __m128i abef = state0, cdgh = state1;
        __m128i msg[4];
        // Sixteen groups of four rounds; msg[g % 4] holds words 4g ... 4g + 3 of the
        // schedule when group g runs.
#pragma GCC unroll 16
        for (int g = 0; g < 16; ++g) {
            if (g < 4)
                msg[g] = _mm_shuffle_epi8(
                    _mm_loadu_si128(reinterpret_cast<const __m128i*>(data + 16 * g)),
                    byte_swap);
            __m128i words = _mm_add_epi32(
                msg[g % 4],
                _mm_loadu_si128(reinterpret_cast<const __m128i*>(kSha256Round + 4 * g)));
            state1 = _mm_sha256rnds2_epu32(state1, state0, words);
            if (g >= 3 && g <= 14) {  // words 4(g + 1) ...: msg2 over msg1's partial sums
                __m128i& next = msg[(g + 1) % 4];
                next = _mm_add_epi32(next, _mm_alignr_epi8(msg[g % 4], msg[(g + 3) % 4], 4));
                next = _mm_sha256msg2_epu32(next, msg[g % 4]);
            }
            words = _mm_shuffle_epi32(words, 0x0E);
            state0 = _mm_sha256rnds2_epu32(state0, state1, words);
            if (g >= 1 && g <= 12)
                msg[(g + 3) % 4] = _mm_sha256msg1_epu32(msg[(g + 3) % 4], msg[g % 4]);
        }
        state0 = _mm_add_epi32(state0, abef);
        state1 = _mm_add_epi32(state1, cdgh);
    }

    tmp = _mm_shuffle_epi32(state0, 0x1B);        // FEBA
    state1 = _mm_shuffle_epi32(state1, 0xB1);     // DCHG
    state0 = _mm_blend_epi16(tmp, state1, 0xF0);  // DCBA
    state1 = _mm_alignr_epi8(state1, tmp, 8);     // HGFE
    _mm_storeu_si128(reinterpret_cast<__m128i*>(state), state0);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(state + 4), state1);
}

}  // namespace octray::batch::detail
