#pragma once
// The packet renderer's last step of a tile (render/packet_renderer.cpp): its sums of
// samples written into the image as means, with non-temporal stores where the CPU has
// them. Internal to octray::render.

#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/color.h"

namespace octray {

// Writes n pixels (r, g, b) / divisor. A frame's image is far larger than the caches and
// each pixel is written once: with SSE2 the aligned groups of four pixels go straight to
// memory (non-temporal stores), so the CPU does not first read every line of the image
// only to overwrite it. Division is IEEE-exact either way (the same bits as the scalar
// r / divisor), and skipped for a divisor of 1, where x / 1 == x.
inline void stream_row(Rgb* out, const float* r, const float* g, const float* b, int n,
                       float divisor) {
    const bool divide = divisor != 1.0f;
    const auto pixel = [&](int x) {
        const Rgb sum(r[x], g[x], b[x]);
        return divide ? sum / divisor : sum;
    };
    int x = 0;
#if defined(__SSE2__)
    // Four pixels are 48 bytes: aligned groups start where the address is 16-aligned.
    for (; x < n && (reinterpret_cast<std::uintptr_t>(out + x) & 15u) != 0; ++x)
        out[x] = pixel(x);
    const __m128 d = _mm_set1_ps(divisor);
    for (; x + 4 <= n; x += 4) {
        __m128 vr = _mm_loadu_ps(r + x), vg = _mm_loadu_ps(g + x), vb = _mm_loadu_ps(b + x);
        if (divide) vr = _mm_div_ps(vr, d), vg = _mm_div_ps(vg, d), vb = _mm_div_ps(vb, d);
        // (r0 g0 b0 r1) (g1 b1 r2 g2) (b2 r3 g3 b3)
        const __m128 rg_lo = _mm_unpacklo_ps(vr, vg), rg_hi = _mm_unpackhi_ps(vr, vg);
        const __m128 b0r1 = _mm_shuffle_ps(vb, vr, _MM_SHUFFLE(1, 1, 0, 0));
        const __m128 g1b1 = _mm_shuffle_ps(vg, vb, _MM_SHUFFLE(1, 1, 1, 1));
        const __m128 b2r3 = _mm_shuffle_ps(vb, vr, _MM_SHUFFLE(3, 3, 2, 2));
        const __m128 g3b3 = _mm_shuffle_ps(vg, vb, _MM_SHUFFLE(3, 3, 3, 3));
        float* dst = &out[x].r;
        _mm_stream_ps(dst, _mm_shuffle_ps(rg_lo, b0r1, _MM_SHUFFLE(2, 0, 1, 0)));
        _mm_stream_ps(dst + 4, _mm_shuffle_ps(g1b1, rg_hi, _MM_SHUFFLE(1, 0, 2, 0)));
        _mm_stream_ps(dst + 8, _mm_shuffle_ps(b2r3, g3b3, _MM_SHUFFLE(2, 0, 2, 0)));
    }
#endif
    for (; x < n; ++x) out[x] = pixel(x);
}

// Non-temporal stores are weakly ordered: fence them before the tile counts as written.
inline void finish_streaming() {
#if defined(__SSE2__)
    _mm_sfence();
#endif
}

}  // namespace octray
