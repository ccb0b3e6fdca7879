#pragma once
// The packet renderer's last step of a tile (render/packet_renderer.cpp): its sums of
// samples written into the image's R, G and B planes as means, with non-temporal stores
// where the CPU has them. Internal to octray::render.

#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace octray {

// Writes n samples of one channel, in[x] / divisor. A frame's image is far larger than the
// caches and each sample is written once: with SSE2 the aligned groups of four samples go
// straight to memory (non-temporal stores), so the CPU does not first read every line of
// the image only to overwrite it. Division is IEEE-exact either way (the same bits as the
// scalar in[x] / divisor), and skipped for a divisor of 1, where x / 1 == x.
inline void stream_row(float* out, const float* in, int n, float divisor) {
    const bool divide = divisor != 1.0f;
    const auto sample = [&](int x) { return divide ? in[x] / divisor : in[x]; };
    int x = 0;
#if defined(__SSE2__)
    for (; x < n && (reinterpret_cast<std::uintptr_t>(out + x) & 15u) != 0; ++x)
        out[x] = sample(x);
    const __m128 d = _mm_set1_ps(divisor);
    for (; x + 4 <= n; x += 4) {
        __m128 v = _mm_loadu_ps(in + x);
        if (divide) v = _mm_div_ps(v, d);
        _mm_stream_ps(out + x, v);
    }
#endif
    for (; x < n; ++x) out[x] = sample(x);
}

// Non-temporal stores are weakly ordered: fence them before the tile counts as written.
inline void finish_streaming() {
#if defined(__SSE2__)
    _mm_sfence();
#endif
}

}  // namespace octray
