#pragma once
// The packet renderer's last step of a tile (render/packet_renderer.cpp): its sums of
// samples written into the image's R, G and B planes as means, with non-temporal stores
// where the CPU has them. Internal to octray::render.

#include <cstdint>

#if defined(__x86_64__)
#include <immintrin.h>

#include "core/cpu_features.h"
#endif

namespace octray {

// Writes n samples of one channel, in[x] / divisor. A frame's image is far larger than the
// caches and each sample is written once: with SSE2 the aligned groups of samples go
// straight to memory (non-temporal stores), so the CPU does not first read every line of
// the image only to overwrite it. Division is IEEE-exact either way (the same bits as the
// scalar in[x] / divisor), and skipped for a divisor of 1, where x / 1 == x.
//
// The widths: a whole cache line per store with AVX-512, half a line with AVX2, a quarter
// with SSE2. A line's non-temporal stores hold a fill buffer until the line is complete,
// so fewer, wider stores free it sooner: the rows' writing took 6.4 % of a random:1024
// frame in 16-byte stores, 4.9 % in 32-byte and 3.9 % in 64-byte ones (an Intel Xeon, the
// same run's profiles; docs/performance-log.md, session 29).
#if defined(__x86_64__)
// The loop, written once and compiled three times, each inside a function whose target
// attribute gives it its width's instructions (a template cannot carry the attribute):
// kWidth floats a store, the width's load, division, non-temporal store and broadcast.
#define OCTRAY_STREAM_ROW_BODY(kWidth, load, div, stream, set1)                                \
    const bool divide = divisor != 1.0f;                                                       \
    const auto sample = [&](int x) { return divide ? in[x] / divisor : in[x]; };               \
    int x = 0;                                                                                 \
    for (; x < n && (reinterpret_cast<std::uintptr_t>(out + x) & (4u * kWidth - 1)) != 0; ++x) \
        out[x] = sample(x);                                                                    \
    if (divide) {                                                                              \
        for (; x + kWidth <= n; x += kWidth)                                                   \
            stream(out + x, div(load(in + x), set1(divisor)));                                 \
    } else {                                                                                   \
        for (; x + kWidth <= n; x += kWidth) stream(out + x, load(in + x));                    \
    }                                                                                          \
    for (; x < n; ++x) out[x] = sample(x);

inline void stream_row_sse2(float* out, const float* in, int n, float divisor) {
    OCTRAY_STREAM_ROW_BODY(4, _mm_loadu_ps, _mm_div_ps, _mm_stream_ps, _mm_set1_ps)
}
__attribute__((target("avx2"))) inline void stream_row_avx2(float* out, const float* in, int n,
                                                            float divisor) {
    OCTRAY_STREAM_ROW_BODY(8, _mm256_loadu_ps, _mm256_div_ps, _mm256_stream_ps, _mm256_set1_ps)
}
__attribute__((target("avx512f"))) inline void stream_row_avx512(float* out, const float* in,
                                                                 int n, float divisor) {
    OCTRAY_STREAM_ROW_BODY(16, _mm512_loadu_ps, _mm512_div_ps, _mm512_stream_ps, _mm512_set1_ps)
}
#undef OCTRAY_STREAM_ROW_BODY
#endif

// stream_row_* for this CPU (core/cpu_features.h); a plain loop off x86-64.
inline void stream_row(float* out, const float* in, int n, float divisor) {
#if defined(__x86_64__)
    static const auto row = cpu_features().avx512 ? &stream_row_avx512
                            : cpu_features().avx2 ? &stream_row_avx2
                                                  : &stream_row_sse2;
    row(out, in, n, divisor);
#else
    const bool divide = divisor != 1.0f;
    for (int x = 0; x < n; ++x) out[x] = divide ? in[x] / divisor : in[x];
#endif
}

// Non-temporal stores are weakly ordered: fence them before the tile counts as written.
inline void finish_streaming() {
#if defined(__x86_64__)
    _mm_sfence();
#endif
}

}  // namespace octray
