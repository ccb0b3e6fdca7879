#pragma once
// The arithmetic every packet kernel is written in, templated on the xsimd architecture:
// V3 (three registers: x, y, z of a packet's lanes) and its operations in core/vec3.h's
// order, live lanes, masks as flags, and the per-lane gather of object and material fields.
//
// Every kernel header in this folder is included ONLY by the per-ISA translation units
// (kernels_avx2.cpp, kernels_sse41.cpp, kernels_sse2.cpp), each of which defines
// OCTRAY_KERNEL_NAMESPACE first so that every function lands in a namespace of its own:
// nothing compiled with -mavx2 can be merged by the linker into code that runs on an
// SSE2-only CPU (kernels/README.md, "the ODR rule"). For the same reason the kernels call
// no non-template inline code from shared headers: only xsimd (templated on the
// architecture), C library functions (<math.h>: sqrtf, powf, sinf, cosf, atan2f) and the
// plain-data structs of kernels/kernel_types.h.
//
// Every formula mirrors render/reference.cpp operation by operation (same operands, same
// order; -ffp-contract=off keeps the compiler from fusing), so a ray traced here has the
// same bits as the reference's. Comments name the reference's expression where the order
// matters. Transcendental functions (pow, sin, cos, atan2) are the C library's, per lane,
// as in the reference: xsimd's own versions differ by ulps.
//
// Packets are 8 rays (kPacketWidth). A kernel walks a stream in packets; a packet is
// K = 8 / batch::size registers (one on AVX2, two on SSE). The AVX-512 translation unit
// runs these kernels 8 lanes wide too, and only its BVH traversal 16 rays at a time
// (bvh/bvh_packet.h, kTraversalWidth).

#ifndef OCTRAY_KERNEL_NAMESPACE
#error "define OCTRAY_KERNEL_NAMESPACE (one per ISA translation unit) before including"
#endif

#include <immintrin.h>

#include <cstdint>
#include <type_traits>
#include <xsimd/xsimd.hpp>

#include "kernels/kernel_types.h"

namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE {

constexpr float kInf = __builtin_inff();

template <class F>
struct V3 {
    F x, y, z;
};

// Vec3 arithmetic, component by component (core/vec3.h's order).
template <class F>
V3<F> add(const V3<F>& a, const V3<F>& b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class F>
V3<F> sub(const V3<F>& a, const V3<F>& b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class F>
V3<F> neg(const V3<F>& a) {
    return {-a.x, -a.y, -a.z};
}
template <class F>
V3<F> mul(const V3<F>& a, const F& s) {
    return {a.x * s, a.y * s, a.z * s};
}
template <class F>
V3<F> div(const V3<F>& a, const F& s) {
    return {a.x / s, a.y / s, a.z / s};
}
// Component-wise product (Rgb * Rgb).
template <class F>
V3<F> hadamard(const V3<F>& a, const V3<F>& b) {
    return {a.x * b.x, a.y * b.y, a.z * b.z};
}
// Summed left to right: (x*x + y*y) + z*z.
template <class F>
F dot(const V3<F>& a, const V3<F>& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
// Divides by the length, as core/vec3.h's normalize does.
template <class F>
V3<F> normalize(const V3<F>& a) {
    const F len = xsimd::sqrt(dot(a, a));
    return div(a, len);
}
template <class F, class M>
V3<F> select(const M& m, const V3<F>& a, const V3<F>& b) {
    return {xsimd::select(m, a.x, b.x), xsimd::select(m, a.y, b.y), xsimd::select(m, a.z, b.z)};
}
// core/color.h's max_component: (r > g ? r : g), then (m > b ? m : b).
template <class F>
F max_component(const V3<F>& c) {
    const F m = xsimd::select(c.x > c.y, c.x, c.y);
    return xsimd::select(m > c.z, m, c.z);
}
template <class F>
V3<F> broadcast(const float v[3]) {
    return {F(v[0]), F(v[1]), F(v[2])};
}
template <class F>
V3<F> load3(const float* x, const float* y, const float* z, std::uint32_t i) {
    return {F::load_aligned(x + i), F::load_aligned(y + i), F::load_aligned(z + i)};
}
template <class F>
void store3(const V3<F>& v, float* x, float* y, float* z, std::uint32_t i) {
    v.x.store_aligned(x + i);
    v.y.store_aligned(y + i);
    v.z.store_aligned(z + i);
}

// a * b - c, fused. xsimd 8.1 fuses only on its FMA3 architectures; AVX-512 has the
// instruction too.
template <class F>
F fused_ms(const F& a, const F& b, const F& c) {
    if constexpr (F::size == 16)
        return _mm512_fmsub_ps(a, b, c);
    else
        return xsimd::fms(a, b, c);
}

// Lanes [base, base + size) that lie below `count`.
template <class F>
auto live_lanes(std::uint32_t base, std::uint32_t count) {
    alignas(64) static constexpr float kIota[16] = {0, 1, 2,  3,  4,  5,  6,  7,
                                                    8, 9, 10, 11, 12, 13, 14, 15};
    const std::uint32_t left = count - base;
    const float limit = static_cast<float>(left < F::size ? left : F::size);
    return F::load_aligned(kIota) < F(limit);
}

// The lanes of a mask as 0/1 flags in memory, for the per-lane loops (compaction, libm).
template <class F, class M>
void mask_to_flags(const M& m, float* flags) {
    xsimd::select(m, F(1.0f), F(0.0f)).store_aligned(flags);
}

// The object (or material) each lane reads, and whether they are all the same: coherent
// packets (a 4x2 pixel block on one sphere) then load each field once and broadcast it.
struct LaneIndex {
    alignas(64) std::int32_t index[16];  // a packet's lanes: 4, 8, or 16 (AVX-512 shading)
    bool uniform;
};

// base[index[i]] per lane, as float (T: float, or a small unsigned count or flag). AVX2
// and AVX-512 gather in one instruction; SSE builds the register from four scalar loads.
// Neither writes lanes to memory to load them back as a whole register (a store-forwarding
// stall).
template <class F, class T>
F gather(const T* base, const LaneIndex& ix) {
    if (ix.uniform) return F(static_cast<float>(base[ix.index[0]]));
    if constexpr (F::size == 16) {
        const __m512i index = _mm512_load_si512(ix.index);
        if constexpr (std::is_same_v<T, float>)
            return _mm512_i32gather_ps(index, base, 4);
        else
            return _mm512_cvtepi32_ps(_mm512_i32gather_epi32(index, base, 4));
    } else if constexpr (F::size == 8) {
        const __m256i index = _mm256_load_si256(reinterpret_cast<const __m256i*>(ix.index));
        if constexpr (std::is_same_v<T, float>)
            return _mm256_i32gather_ps(base, index, 4);
        else
            return _mm256_cvtepi32_ps(
                _mm256_i32gather_epi32(reinterpret_cast<const int*>(base), index, 4));
    } else {
        static_assert(F::size == 4);
        return _mm_setr_ps(
            static_cast<float>(base[ix.index[0]]), static_cast<float>(base[ix.index[1]]),
            static_cast<float>(base[ix.index[2]]), static_cast<float>(base[ix.index[3]]));
    }
}

// Bit i set when lane i of the mask is (movmskps; AVX-512 masks are bits already).
template <class F, class M>
std::uint32_t mask_bits(const M& m) {
    if constexpr (F::size == 16) {
        return static_cast<std::uint32_t>(static_cast<__mmask16>(m));
    } else if constexpr (F::size == 8) {
        return static_cast<std::uint32_t>(_mm256_movemask_ps(static_cast<__m256>(m)));
    } else {
        return static_cast<std::uint32_t>(_mm_movemask_ps(static_cast<__m128>(m)));
    }
}

}  // namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE
