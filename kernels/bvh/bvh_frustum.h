#pragma once
// The packet frustum of the BVH packet traversal (bvh_packet_traversal.h).
//
// Included ONLY by the per-ISA translation units, under their OCTRAY_KERNEL_NAMESPACE
// (packet_math.h; kernels/README.md, "the ODR rule").

#ifndef OCTRAY_KERNEL_NAMESPACE
#error "define OCTRAY_KERNEL_NAMESPACE (one per ISA translation unit) before including"
#endif

#include <immintrin.h>

#include <cstdint>

#include "kernels/bvh/bvh_packet.h"

namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE {

// The packet as one bundle (a frustum, after embree's stream traversal): where every live
// lane's direction has one sign on each axis, all eight children of a node are tested
// against the bundle in one pass, and only the children it enters get the per-lane tests.
//
// Per lane, a child is entered on axis x at fms(near_x, inv, near_off) (near_x: the box's
// min_x for a positive direction, max_x for a negative one) and left at
// fms(far_x, inv, far_off). Over the bundle, with inv in [inv_lo, inv_hi] (one sign) and
// the offsets bounded by the lanes' largest near_off and smallest far_off, the exact value
// near_x * inv - near_off is at least min(near_x * inv_lo, near_x * inv_hi) - near_off_max,
// and rounding is monotonic: the bundle's rounded entry is never above any lane's rounded
// entry, its exit never below. A child some lane enters is entered by the bundle, so the
// bundle test culls nothing the per-lane tests would keep: the traversal and its hits
// are the same with it or without it.
//
// Where the live lanes also share their origin (a pinhole camera's packet), the bundle is
// nearly as tight as its rays: the per-lane tests drop few of the children it enters.
// They then cost more than they cull, and every child the bundle enters takes all the
// packet's lanes; the bundle's own t_far (the farthest closest hit so far) still culls the
// children behind every lane's hit. Rays from many origins (reflections, shadows) spread
// the bundle's offsets and keep the per-lane tests (docs/performance-log.md, "Packets from
// one origin; leaf prefetches").
template <class F>
struct PacketFrustum {
    using Plane = const float (BvhNode8::*)[kBvhWidth];
    bool valid = false;       // every axis has one direction sign over the lanes
    bool one_origin = false;  // ... and the lanes share their origin
    Plane near[3], far[3];
    F inv_lo[3], inv_hi[3], near_off[3], far_off[3];
};

// Lanes of `bits` (of 8) as an AVX mask. Translation units with AVX2 only (8-wide
// registers, or push_children's keys); a template, so that no other translation unit
// compiles it (the ODR rule).
template <class F>
__m256 lane_mask8(std::uint32_t bits) {
    const __m256i lane_bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    return _mm256_castsi256_ps(_mm256_cmpeq_epi32(
        _mm256_and_si256(_mm256_set1_epi32(static_cast<int>(bits)), lane_bit), lane_bit));
}

// The largest / smallest of v[i] over the lanes i in `bits` (not empty) of a traversal
// packet (F: its registers). Exact: min and max do not round, so the order of the
// reduction does not matter.
template <class F>
float masked_max(const float* v, std::uint32_t bits) {
    if constexpr (F::size == 16) {
        return _mm512_mask_reduce_max_ps(static_cast<__mmask16>(bits), _mm512_load_ps(v));
    } else if constexpr (F::size == 8) {
        const __m256 x =
            _mm256_blendv_ps(_mm256_set1_ps(-kInf), _mm256_load_ps(v), lane_mask8<F>(bits));
        __m128 m = _mm_max_ps(_mm256_castps256_ps128(x), _mm256_extractf128_ps(x, 1));
        m = _mm_max_ps(m, _mm_movehl_ps(m, m));
        return _mm_cvtss_f32(_mm_max_ss(m, _mm_shuffle_ps(m, m, 1)));
    } else {
        float m = -kInf;
        for (; bits != 0; bits &= bits - 1) {
            const float x = v[__builtin_ctz(bits)];
            m = x > m ? x : m;
        }
        return m;
    }
}
template <class F>
float masked_min(const float* v, std::uint32_t bits) {
    if constexpr (F::size == 16) {
        return _mm512_mask_reduce_min_ps(static_cast<__mmask16>(bits), _mm512_load_ps(v));
    } else if constexpr (F::size == 8) {
        const __m256 x =
            _mm256_blendv_ps(_mm256_set1_ps(kInf), _mm256_load_ps(v), lane_mask8<F>(bits));
        __m128 m = _mm_min_ps(_mm256_castps256_ps128(x), _mm256_extractf128_ps(x, 1));
        m = _mm_min_ps(m, _mm_movehl_ps(m, m));
        return _mm_cvtss_f32(_mm_min_ss(m, _mm_shuffle_ps(m, m, 1)));
    } else {
        float m = kInf;
        for (; bits != 0; bits &= bits - 1) {
            const float x = v[__builtin_ctz(bits)];
            m = x < m ? x : m;
        }
        return m;
    }
}
// Whether v[i] == v[first lane of bits] for every lane i in `bits`.
template <class F>
bool masked_all_equal(const float* v, std::uint32_t bits) {
    const float v0 = v[__builtin_ctz(bits)];
    if constexpr (F::size == 16) {
        const __mmask16 eq =
            _mm512_cmp_ps_mask(_mm512_load_ps(v), _mm512_set1_ps(v0), _CMP_EQ_OQ);
        return (static_cast<std::uint32_t>(eq) & bits) == bits;
    } else if constexpr (F::size == 8) {
        const __m256 eq = _mm256_cmp_ps(_mm256_load_ps(v), _mm256_set1_ps(v0), _CMP_EQ_OQ);
        const auto eq_bits = static_cast<std::uint32_t>(_mm256_movemask_ps(eq));
        return (eq_bits & bits) == bits;
    } else {
        for (; bits != 0; bits &= bits - 1)
            if (!(v[__builtin_ctz(bits)] == v0)) return false;
        return true;
    }
}

// `live`: not empty. F: the node tests' registers (8 children); FR: the packet's.
template <class F, class FR = F>
PacketFrustum<F> packet_frustum(const BvhPacket& p, std::uint32_t live) {
    using Plane = typename PacketFrustum<F>::Plane;
    const float* const inv[3] = {p.inv_x, p.inv_y, p.inv_z};
    const float* const lo_off[3] = {p.lo_off_x, p.lo_off_y, p.lo_off_z};
    const float* const hi_off[3] = {p.hi_off_x, p.hi_off_y, p.hi_off_z};
    const Plane mins[3] = {&BvhNode8::min_x, &BvhNode8::min_y, &BvhNode8::min_z};
    const Plane maxs[3] = {&BvhNode8::max_x, &BvhNode8::max_y, &BvhNode8::max_z};
    PacketFrustum<F> f;
    for (int a = 0; a < 3; ++a) {
        const float lo = masked_min<FR>(inv[a], live), hi = masked_max<FR>(inv[a], live);
        const bool positive = lo > 0.0f;
        if (!positive && !(hi < 0.0f)) return f;  // mixed signs (or NaN): no bundle
        const float near_max = masked_max<FR>(positive ? lo_off[a] : hi_off[a], live);
        const float far_min = masked_min<FR>(positive ? hi_off[a] : lo_off[a], live);
        f.near[a] = positive ? mins[a] : maxs[a];
        f.far[a] = positive ? maxs[a] : mins[a];
        f.inv_lo[a] = F(lo), f.inv_hi[a] = F(hi);
        f.near_off[a] = F(near_max), f.far_off[a] = F(far_min);
    }
    f.valid = true;
    f.one_origin = masked_all_equal<FR>(p.ox, live) && masked_all_equal<FR>(p.oy, live) &&
                   masked_all_equal<FR>(p.oz, live);
    return f;
}

// The children of `n` that are not kBvhEmpty, as bits (they come first).
inline std::uint32_t used_children(const BvhNode8& n) {
    std::uint32_t count = 0;
    while (count < kBvhWidth && n.child[count] != kBvhEmpty) ++count;
    return (1u << count) - 1u;
}

// Children of `n` the bundle enters on [t_near, t_far]; entry[j]: where it enters child j.
template <class F>
[[gnu::always_inline]] inline std::uint32_t frustum_children(const BvhNode8& n,
                                                             const PacketFrustum<F>& f,
                                                             const F& t_near, const F& t_far,
                                                             float* entry) {
    constexpr std::uint32_t W = F::size;
    std::uint32_t bits = 0;
    for (std::uint32_t at = 0; at < kBvhWidth; at += W) {
        F tn = t_near, tf = t_far;
        for (int a = 0; a < 3; ++a) {
            const F near = F::load_aligned((n.*f.near[a]) + at);
            const F far = F::load_aligned((n.*f.far[a]) + at);
            tn = xsimd::max(tn, xsimd::min(xsimd::fms(near, f.inv_lo[a], f.near_off[a]),
                                           xsimd::fms(near, f.inv_hi[a], f.near_off[a])));
            tf = xsimd::min(tf, xsimd::max(xsimd::fms(far, f.inv_lo[a], f.far_off[a]),
                                           xsimd::fms(far, f.inv_hi[a], f.far_off[a])));
        }
        bits |= mask_bits<F>(tn <= tf) << at;
        tn.store_aligned(entry + at);
    }
    return bits;
}

}  // namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE
