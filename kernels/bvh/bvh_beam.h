#pragma once
// Beams: the rays of a camera tile, from one origin (or its shadow rays, towards one point
// light), traced against the few spheres their pyramid holds, gathered from the BVH once
// for all the tile's packets.
//
// Included ONLY by the per-ISA translation units, under their OCTRAY_KERNEL_NAMESPACE
// (packet_math.h; kernels/README.md, "the ODR rule").
//
// A pinhole camera's tile of 16 x 16 pixels sees a narrow pyramid of the scene: each of
// its 16-ray packets visits a few BVH nodes and tests a few spheres, of which hardly any
// comes near any of its rays (counted: docs/performance-log.md, "Beams"). The node visits,
// the packet frustum and the box offsets of every ray cost more than the sphere tests that
// decide the hits. So closest_hit takes a group of up to kBeamRays rays that share their
// origin O (Reshetov et al. 2005, "Multi-level ray tracing algorithm", finds entry points
// the same way):
// 1. beam_rays: every direction has one sign on a main axis m; per ray, its slopes
//    u = d_a / d_m and v = d_b / d_m on the two other axes. The rays lie in the pyramid
//    u_lo <= p_a / w <= u_hi, v_lo <= p_b / w <= v_hi, w >= 0, in coordinates about O with
//    the main axis's sign folded in (p = sign (X - O) on a and b, w = sign (X - O)_m).
// 2. beam_gather: one walk of the BVH with that pyramid, nearest boxes first, collects the
//    spheres it may hold, up to kBeamMaxSpheres; the spheres left out then lie beyond a
//    depth, the beam's horizon.
// 3. beam_closest_packet: each packet bounds its own rays' slopes, keeps the gathered
//    spheres inside its own pyramid (16 spheres per test), and tests those with the leaves'
//    exact arithmetic (packet_closest_sphere). A lane whose hit lies beyond the horizon
//    goes on through the BVH (hit_kernels.h, closest_hit).
// Shadow rays that end near one point (a point light) are a beam seen from that point,
// each segment reaching out to its origin (beam_rays for a ShadowStream, then
// beam_occluded_packet); any_hit forms them where it keeps the stream's order.
//
// Bit-exactness. The pyramid tests only decide which spheres are tested; the exact test
// and its tie rule (the lower file index wins) decide the hits, in any order. So a sphere
// may be dropped only where no ray of the pyramid could report it. A lane reports a
// sphere only when its ray passes within r + 10u|O'| of the center (u = 2^-24; the bound
// of kernels/bvh/bvh_packet.h), at a point in front of O, or when O lies within that distance
// of the center (a root in front of an origin behind the sphere's center). Both put the
// sphere's center within that distance of the pyramid, so within it of each of the
// pyramid's planes: the sphere is kept while every plane's signed distance to the center
// is at least -reach, with
//   reach = r (1 + 2^-8) + 2^-13 |q|_1,   q = sign (c - O),
// where 2^-13 |q|_1 (>= 512u|O'|) holds the test's 10u|O'|, the slopes' rounding (half an
// ulp of each) and the rounding of the plane distances themselves many times over. A
// plane with normal (1, -u) in (p, w) has distance (p - u w) / sqrt(1 + u^2); the tests
// multiply instead of dividing. The walk drops a node's child box only where each sphere
// inside it would be dropped: the box holds the sphere's ball (render/prepare/bvh_build.cpp
// rounds it outwards), so with the box's largest value F of a plane function, f(c) <= F - r|n|,
// and a box is dropped where F < -delta |n| with
//   delta = 2^-9 min_extent + 2^-12 E,   E = max over the box of |X - O|_1,
// which exceeds 2^-8 r + 2^-13 |q|_1 (2r <= the box's smallest extent) with 2^-13 E to
// spare for the rounding. Coordinates are bounded (kBeamLimit) so that nothing overflows,
// and slopes (kBeamMaxSlope) so that the planes stay well defined; a NaN direction, mixed
// signs or mixed origins leave the group to the packet traversal.

#ifndef OCTRAY_KERNEL_NAMESPACE
#error "define OCTRAY_KERNEL_NAMESPACE (one per ISA translation unit) before including"
#endif

#include <cmath>
#include <cstdint>

#include "kernels/bvh/bvh_frustum.h"
#include "kernels/bvh/bvh_packet.h"
#include "kernels/bvh/bvh_packet_traversal.h"

namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE {

// Rays per beam: a 16 x 16 tile of one sample per pixel, or a 32 x 8 strip of the default
// 32 x 32 tile.
constexpr std::uint32_t kBeamRays = 256;
// The most spheres a beam gathers; a beam that meets more is left to the packet traversal.
constexpr std::uint32_t kBeamMaxSpheres = 256;
// Origins and the scene's box beyond this, or slopes beyond kBeamMaxSlope: no beam.
constexpr float kBeamLimit = 1e18f;
constexpr float kBeamMaxSlope = 1e6f;
constexpr float kBeamRadiusGrow = 1.0f + 0x1.0p-8f;
constexpr float kBeamReachSlack = 0x1.0p-13f;
// Room for the rounding of a depth (a product, a difference) compared against another.
constexpr float kBeamDepthGrow = 1.0f + 0x1.0p-10f;

struct Beam {
    float o[3];             // the apex: the rays' origin, or the point shadow rays meet
    std::uint32_t m, a, b;  // the main axis, then the two others
    float sign;             // of every ray's main direction component (seen from the apex)
    float u_lo, u_hi, v_lo, v_hi;
    float n_ulo, n_uhi, n_vlo, n_vhi;  // sqrt(1 + slope^2) of the four planes
    // Shadow beams: the farthest depth of a segment (else +inf), and what every reach
    // adds for segments that end near, not at, the apex (else 0).
    float w_far, reach_extra;
    std::uint32_t count;  // spheres gathered
    // No sphere left out (beyond kBeamMaxSpheres) lies nearer than this depth w: a packet
    // whose every hit lies nearer is done, others go on through the BVH. +inf: none left out.
    float horizon;
    alignas(64) float u[kBeamRays], v[kBeamRays];
    alignas(64) float w[kBeamRays];  // shadow beams: each segment's far depth (its origin's)
    // The gathered spheres: q = sign (c - O) on a, b, m; reach as above; the BVH index.
    alignas(64) float qa[kBeamMaxSpheres], qb[kBeamMaxSpheres], qw[kBeamMaxSpheres];
    alignas(64) float reach[kBeamMaxSpheres];
    alignas(64) std::uint32_t sphere[kBeamMaxSpheres];
    // The least near depth (q_w - reach) of the spheres from block k (16 spheres) on.
    float block_near[kBeamMaxSpheres / 16];
};

// The rays' slopes, stored per ray in the beam and bounded lane by lane as they come;
// set() reduces the lanes into the beam's bounds and its planes' norms.
template <class F>
struct SlopeBounds {
    F u_lo = F(kInf), u_hi = F(-kInf), v_lo = F(kInf), v_hi = F(-kInf);

    template <class M>
    void add(Beam& beam, std::uint32_t at, const M& live, const F& u, const F& v) {
        u.store_aligned(beam.u + at);
        v.store_aligned(beam.v + at);
        u_lo = xsimd::min(u_lo, xsimd::select(live, u, F(kInf)));
        u_hi = xsimd::max(u_hi, xsimd::select(live, u, F(-kInf)));
        v_lo = xsimd::min(v_lo, xsimd::select(live, v, F(kInf)));
        v_hi = xsimd::max(v_hi, xsimd::select(live, v, F(-kInf)));
    }
    void set(Beam& beam) const {
        constexpr std::uint32_t W = F::size;
        alignas(64) float lanes[4][W];
        u_lo.store_aligned(lanes[0]), u_hi.store_aligned(lanes[1]);
        v_lo.store_aligned(lanes[2]), v_hi.store_aligned(lanes[3]);
        beam.u_lo = beam.v_lo = kInf, beam.u_hi = beam.v_hi = -kInf;
        for (std::uint32_t i = 0; i < W; ++i) {
            beam.u_lo = lanes[0][i] < beam.u_lo ? lanes[0][i] : beam.u_lo;
            beam.u_hi = lanes[1][i] > beam.u_hi ? lanes[1][i] : beam.u_hi;
            beam.v_lo = lanes[2][i] < beam.v_lo ? lanes[2][i] : beam.v_lo;
            beam.v_hi = lanes[3][i] > beam.v_hi ? lanes[3][i] : beam.v_hi;
        }
        beam.n_ulo = sqrtf(1.0f + beam.u_lo * beam.u_lo);
        beam.n_uhi = sqrtf(1.0f + beam.u_hi * beam.u_hi);
        beam.n_vlo = sqrtf(1.0f + beam.v_lo * beam.v_lo);
        beam.n_vhi = sqrtf(1.0f + beam.v_hi * beam.v_hi);
    }
};

// Whether the apex and the scene's box lie within kBeamLimit.
inline bool beam_in_range(const SceneView& s, const float apex[3]) {
    for (int k = 0; k < 3; ++k)
        if (!(fabsf(apex[k]) < kBeamLimit && fabsf(s.bvh_lo[k]) < kBeamLimit &&
              fabsf(s.bvh_hi[k]) < kBeamLimit))
            return false;
    return true;
}

// The main axis (the largest component of v) and the others, and v's sign on it.
inline void set_beam_axes(Beam& beam, const float v[3]) {
    std::uint32_t m = 0;
    if (fabsf(v[1]) > fabsf(v[m])) m = 1;
    if (fabsf(v[2]) > fabsf(v[m])) m = 2;
    beam.m = m, beam.a = (m + 1) % 3, beam.b = (m + 2) % 3;
    beam.sign = v[m] < 0.0f ? -1.0f : 1.0f;
}

// Step 1 for rays [base, base + n) of a stream holding `count`: whether they form a beam,
// and if so its axes, origin, slopes and bounds. F: the stream's registers.
template <class F>
bool beam_rays(const SceneView& s, const RayStream& rays, std::uint32_t base, std::uint32_t n,
               std::uint32_t count, Beam& beam) {
    constexpr std::uint32_t W = F::size;
    const float* const o[3] = {rays.ox + base, rays.oy + base, rays.oz + base};
    const float* const d[3] = {rays.dx + base, rays.dy + base, rays.dz + base};
    for (int k = 0; k < 3; ++k) beam.o[k] = o[k][0];
    if (!beam_in_range(s, beam.o)) return false;
    const float d0[3] = {d[0][0], d[1][0], d[2][0]};
    set_beam_axes(beam, d0);
    const std::uint32_t m = beam.m;
    const F ox(beam.o[0]), oy(beam.o[1]), oz(beam.o[2]), sign(beam.sign);
    const F max_slope(kBeamMaxSlope);
    SlopeBounds<F> slopes;
    const std::uint32_t left = count - base;
    for (std::uint32_t at = 0; at < n; at += W) {
        const auto load = [&](const float* v) { return load_stream<F>(v, at, left); };
        const F dm = load(d[m]), u = load(d[beam.a]) / dm, v = load(d[beam.b]) / dm;
        const auto good = load(o[0]) == ox && load(o[1]) == oy && load(o[2]) == oz &&
                          sign * dm > F(0.0f) && xsimd::abs(u) < max_slope &&
                          xsimd::abs(v) < max_slope;
        const auto live = live_lanes<F>(at, n);
        if (xsimd::any(live && !good)) return false;
        slopes.add(beam, at, live, u, v);
    }
    slopes.set(beam);
    beam.w_far = kInf, beam.reach_extra = 0.0f;
    return true;
}

// Step 1 for shadow rays (the same name: beam_for_group takes either stream): segments O_i + t
// V_i, 0 < t < t_max_i, that all end near one point (towards a point light V = L - P and t_max
// = 1 from O = P + eps N: they end at L + eps N). The apex A is where the first one ends; seen
// from A, each segment runs from (near) A out to its origin, at depth w_i. Reaches grow by how
// far the segments' ends lie from A (one more rounding: 2^-20 |A|), and by 2^-13 of the longest
// segment (the exact test's 10u|O'| with |O'| <= |O - A| + |q|, and the rounding of O - A).
template <class F>
bool beam_rays(const SceneView& s, const ShadowStream& rays, std::uint32_t base,
               std::uint32_t n, std::uint32_t count, Beam& beam) {
    constexpr std::uint32_t W = F::size;
    const float* const o[3] = {rays.ox + base, rays.oy + base, rays.oz + base};
    const float* const d[3] = {rays.dx + base, rays.dy + base, rays.dz + base};
    const float* const t_max = rays.t_max + base;
    if (!(t_max[0] > 0.0f && t_max[0] < kInf)) return false;
    float out[3];
    for (int k = 0; k < 3; ++k) {
        beam.o[k] = fmaf(t_max[0], d[k][0], o[k][0]);
        out[k] = o[k][0] - beam.o[k];
    }
    if (!beam_in_range(s, beam.o)) return false;
    set_beam_axes(beam, out);
    const F apex[3] = {F(beam.o[0]), F(beam.o[1]), F(beam.o[2])};
    const F sign(beam.sign), max_slope(kBeamMaxSlope), inf(kInf), zero(0.0f);
    SlopeBounds<F> slopes;
    F w_max = zero, dev_max = zero, length_max = zero;
    const std::uint32_t left = count - base;
    for (std::uint32_t at = 0; at < n; at += W) {
        const auto load = [&](const float* v) { return load_stream<F>(v, at, left); };
        const F t = load(t_max);
        F r[3], dev = zero, length = zero;
        for (int k = 0; k < 3; ++k) {
            const F origin = load(o[k]);
            r[k] = origin - apex[k];
            dev += xsimd::abs(xsimd::fma(t, load(d[k]), origin) - apex[k]);
            length += xsimd::abs(r[k]);
        }
        const F u = r[beam.a] / r[beam.m], v = r[beam.b] / r[beam.m], w = sign * r[beam.m];
        const auto good = t > zero && t < inf && w > zero && xsimd::abs(u) < max_slope &&
                          xsimd::abs(v) < max_slope && dev <= F(0x1.0p-8f) * length;
        const auto live = live_lanes<F>(at, n);
        if (xsimd::any(live && !good)) return false;
        slopes.add(beam, at, live, u, v);
        w.store_aligned(beam.w + at);
        w_max = xsimd::max(w_max, xsimd::select(live, w, zero));
        dev_max = xsimd::max(dev_max, xsimd::select(live, dev, zero));
        length_max = xsimd::max(length_max, xsimd::select(live, length, zero));
    }
    slopes.set(beam);
    alignas(64) float lanes[3][W];
    w_max.store_aligned(lanes[0]), dev_max.store_aligned(lanes[1]);
    length_max.store_aligned(lanes[2]);
    float far = 0.0f, deviation = 0.0f, length = 0.0f;
    for (std::uint32_t i = 0; i < W; ++i) {
        far = lanes[0][i] > far ? lanes[0][i] : far;
        deviation = lanes[1][i] > deviation ? lanes[1][i] : deviation;
        length = lanes[2][i] > length ? lanes[2][i] : length;
    }
    const float apex_norm = fabsf(beam.o[0]) + fabsf(beam.o[1]) + fabsf(beam.o[2]);
    beam.w_far = far * kBeamDepthGrow;
    beam.reach_extra = deviation * kBeamDepthGrow + 0x1.0p-20f * (apex_norm + deviation) +
                       kBeamReachSlack * length;
    return true;
}

// The children of `n` whose boxes may hold a sphere the beam keeps (step 2's box test).
// F: the node tests' registers.
template <class F>
std::uint32_t beam_children(const BvhNode8& n, const Beam& beam, float* near) {
    using Plane = const float(BvhNode8::*)[kBvhWidth];
    static constexpr Plane kMin[3] = {&BvhNode8::min_x, &BvhNode8::min_y, &BvhNode8::min_z};
    static constexpr Plane kMax[3] = {&BvhNode8::max_x, &BvhNode8::max_y, &BvhNode8::max_z};
    constexpr std::uint32_t W = F::size;
    const F sign(beam.sign), zero(0.0f);
    const F u_lo(beam.u_lo), u_hi(beam.u_hi), v_lo(beam.v_lo), v_hi(beam.v_hi);
    std::uint32_t bits = 0;
    for (std::uint32_t at = 0; at < kBvhWidth; at += W) {
        // The box's corners in beam coordinates, per axis: the two values of p_a, p_b, w.
        const auto side = [&](std::uint32_t axis, F& lo, F& hi) {
            const F o(beam.o[axis]);
            lo = sign * (F::load_aligned((n.*kMin[axis]) + at) - o);
            hi = sign * (F::load_aligned((n.*kMax[axis]) + at) - o);
        };
        F a0, a1, b0, b1, w0, w1;
        side(beam.a, a0, a1), side(beam.b, b0, b1), side(beam.m, w0, w1);
        const F extent = xsimd::min(xsimd::min(xsimd::abs(a1 - a0), xsimd::abs(b1 - b0)),
                                    xsimd::abs(w1 - w0));
        const F e = xsimd::max(xsimd::abs(a0), xsimd::abs(a1)) +
                    xsimd::max(xsimd::abs(b0), xsimd::abs(b1)) +
                    xsimd::max(xsimd::abs(w0), xsimd::abs(w1));
        const F delta =
            F(0x1.0p-9f) * extent + F(0x1.0p-12f) * e + F(beam.reach_extra) + F(1e-30f);
        // The largest value over the box of each plane's function (p - u w or u w - p).
        const auto lower = [&](const F& p0, const F& p1, const F& slope) {
            return xsimd::max(p0, p1) + xsimd::max(-slope * w0, -slope * w1);
        };
        const auto upper = [&](const F& p0, const F& p1, const F& slope) {
            return xsimd::max(slope * w0, slope * w1) - xsimd::min(p0, p1);
        };
        const F near_w = xsimd::min(w0, w1) - delta;
        const auto keep = xsimd::max(w0, w1) >= -delta && near_w <= F(beam.w_far) &&
                          lower(a0, a1, u_lo) >= -delta * F(beam.n_ulo) &&
                          upper(a0, a1, u_hi) >= -delta * F(beam.n_uhi) &&
                          lower(b0, b1, v_lo) >= -delta * F(beam.n_vlo) &&
                          upper(b0, b1, v_hi) >= -delta * F(beam.n_vhi) && delta > zero;
        bits |= mask_bits<F>(keep) << at;
        // No sphere inside lies nearer than this (its near depth q_w - reach, the box's
        // least w less 2^-8 r + 2^-13 |q|_1 + reach_extra).
        near_w.store_aligned(near + at);
    }
    return bits;
}

// Step 2: gathers the spheres the beam may hold, nearest boxes first (by their least
// depth w), up to kBeamMaxSpheres; the spheres left out lie beyond beam.horizon.
// `stack`: room for kBvhStackSize node references.
template <class F>
void beam_gather(const SceneView& s, Beam& beam, std::uint32_t* stack) {
    constexpr std::uint32_t W = F::size;
    constexpr std::uint32_t kFull = ~0u;  // sp once the beam holds kBeamMaxSpheres
    const float* const c[3] = {s.bvh_cx, s.bvh_cy, s.bvh_cz};
    const F sign(beam.sign), o_a(beam.o[beam.a]), o_b(beam.o[beam.b]), o_w(beam.o[beam.m]);
    const F u_lo(beam.u_lo), u_hi(beam.u_hi), v_lo(beam.v_lo), v_hi(beam.v_hi);
    const F n_ulo(beam.n_ulo), n_uhi(beam.n_uhi), n_vlo(beam.n_vlo), n_vhi(beam.n_vhi);
    const F w_far(beam.w_far), extra(beam.reach_extra);
    float stack_near[kBvhStackSize];
    std::uint32_t count = 0, sp = 0;
    stack[sp] = 0, stack_near[sp++] = -kInf;
    beam.horizon = kInf;
    while (sp > 0) {
        --sp;
        const std::uint32_t ref = stack[sp];
        if ((ref & kBvhLeafBit) == 0) {
            // Children pushed farthest first, so that the nearest comes off the stack next.
            const BvhNode8& n = s.bvh_nodes[ref];
            alignas(64) float near[kBvhWidth];
            const std::uint32_t keep = beam_children<F>(n, beam, near) & used_children(n);
            std::uint32_t order[kBvhWidth], kept = 0;
            for (std::uint32_t bits = keep; bits != 0; bits &= bits - 1) {
                auto j = static_cast<std::uint32_t>(__builtin_ctz(bits)), at = kept++;
                for (; at > 0 && near[order[at - 1]] < near[j]; --at) order[at] = order[at - 1];
                order[at] = j;
            }
            for (std::uint32_t k = 0; k < kept; ++k)
                stack[sp] = n.child[order[k]], stack_near[sp++] = near[order[k]];
            continue;
        }
        // A leaf's spheres a register at a time (the arrays are padded:
        // render/prepare/bvh_build.h).
        const std::uint32_t first = leaf_first(ref), leaf = leaf_count(ref);
        for (std::uint32_t at = 0; at < leaf && sp != kFull; at += W) {
            const std::uint32_t i = first + at;
            const F qa = sign * (F::load_unaligned(c[beam.a] + i) - o_a);
            const F qb = sign * (F::load_unaligned(c[beam.b] + i) - o_b);
            const F qw = sign * (F::load_unaligned(c[beam.m] + i) - o_w);
            const F reach =
                xsimd::sqrt(F::load_unaligned(s.bvh_r2 + i)) * F(kBeamRadiusGrow) +
                F(kBeamReachSlack) * (xsimd::abs(qa) + xsimd::abs(qb) + xsimd::abs(qw)) + extra;
            const auto keep = qw >= -reach && qw - reach <= w_far &&
                              xsimd::fnma(u_lo, qw, qa) >= -reach * n_ulo &&
                              xsimd::fms(u_hi, qw, qa) >= -reach * n_uhi &&
                              xsimd::fnma(v_lo, qw, qb) >= -reach * n_vlo &&
                              xsimd::fms(v_hi, qw, qb) >= -reach * n_vhi;
            std::uint32_t bits = mask_bits<F>(keep);
            if (leaf - at < W) bits &= (1u << (leaf - at)) - 1u;
            if (bits == 0) continue;
            alignas(64) float lane[4][W];
            qa.store_aligned(lane[0]), qb.store_aligned(lane[1]), qw.store_aligned(lane[2]);
            reach.store_aligned(lane[3]);
            for (; bits != 0; bits &= bits - 1) {
                const auto j = static_cast<std::uint32_t>(__builtin_ctz(bits));
                if (count == kBeamMaxSpheres) {
                    // Full: what is left lies beyond this leaf's box and every pending box.
                    float horizon = stack_near[sp];
                    for (std::uint32_t k = 0; k < sp; ++k)
                        horizon = stack_near[k] < horizon ? stack_near[k] : horizon;
                    beam.horizon = horizon;
                    sp = kFull;
                    break;
                }
                beam.qa[count] = lane[0][j], beam.qb[count] = lane[1][j];
                beam.qw[count] = lane[2][j], beam.reach[count] = lane[3][j];
                beam.sphere[count++] = i + j;
            }
        }
        if (sp == kFull) break;
    }
    beam.count = count;
    float near = kInf;
    for (std::uint32_t k = count; k > 0; --k) {
        const float at = beam.qw[k - 1] - beam.reach[k - 1];
        near = at < near ? at : near;
        if ((k - 1) % 16 == 0) beam.block_near[(k - 1) / 16] = near;
    }
    // The last block's unused entries fail every packet's test (0 >= +|n| is false).
    for (; count % 16 != 0; ++count) {
        beam.qa[count] = beam.qb[count] = beam.qw[count] = 0.0f;
        beam.reach[count] = -1.0f, beam.sphere[count] = 0;
    }
}

// Whether rays [group, group + n) of a stream of `count` (RayStream or ShadowStream) form a
// beam; if so, its spheres are gathered. A group of one packet or less is left to the
// packet traversal (nothing to share). FR: the rays' registers (16 lanes with AVX-512:
// the slopes of 256 rays, two divisions each, in half the steps); FN: the node tests'.
template <class FR, class FN, class Stream>
bool beam_for_group(const SceneView& s, const Stream& rays, std::uint32_t group,
                    std::uint32_t n, std::uint32_t count, Beam& beam, BvhStacks& st) {
    if (n <= kTraversalWidth || !beam_rays<FR>(s, rays, group, n, count, beam)) return false;
    beam_gather<FN>(s, beam, st.ray_node);
    return true;
}

// A packet's own pyramid (the slopes of lanes `live` of the beam's rays [at, ...)), tested
// against the beam's spheres a register at a time.
template <class F>
struct PacketPyramid {
    F u_lo, u_hi, v_lo, v_hi, n_ulo, n_uhi, n_vlo, n_vhi, w_far;

    PacketPyramid(const Beam& beam, std::uint32_t at, std::uint32_t live) {
        const float ul = masked_min<F>(beam.u + at, live),
                    uh = masked_max<F>(beam.u + at, live);
        const float vl = masked_min<F>(beam.v + at, live),
                    vh = masked_max<F>(beam.v + at, live);
        u_lo = F(ul), u_hi = F(uh), v_lo = F(vl), v_hi = F(vh);
        n_ulo = F(sqrtf(1.0f + ul * ul)), n_uhi = F(sqrtf(1.0f + uh * uh));
        n_vlo = F(sqrtf(1.0f + vl * vl)), n_vhi = F(sqrtf(1.0f + vh * vh));
        w_far =
            F(beam.w_far == kInf ? kInf : masked_max<F>(beam.w + at, live) * kBeamDepthGrow);
    }
    // Which of the beam's spheres [first, first + F::size) the pyramid may hold, as bits.
    std::uint32_t keeps(const Beam& beam, std::uint32_t first) const {
        const F qa = F::load_aligned(beam.qa + first), qb = F::load_aligned(beam.qb + first);
        const F qw = F::load_aligned(beam.qw + first);
        const F reach = F::load_aligned(beam.reach + first);
        return mask_bits<F>(xsimd::fnma(u_lo, qw, qa) >= -reach * n_ulo &&
                            xsimd::fms(u_hi, qw, qa) >= -reach * n_uhi &&
                            xsimd::fnma(v_lo, qw, qb) >= -reach * n_vlo &&
                            xsimd::fms(v_hi, qw, qb) >= -reach * n_vhi && qw - reach <= w_far);
    }
};

// Step 3: the closest hits of packet `p` (lanes `live`, not empty; rays [at, at +
// kTraversalWidth) of the beam) among the beam's spheres. Blocks of spheres that all lie
// beyond every lane's hit so far are skipped. Returns the live lanes whose hit (or miss)
// does not lie nearer than the beam's horizon: the BVH must finish those.
template <class Arch>
std::uint32_t beam_closest_packet(const SceneView& s, const Beam& beam, std::uint32_t at,
                                  BvhPacket& p, std::uint32_t live, float t_min) {
    using F = xsimd::batch<float, RayArch<Arch>>;
    constexpr std::uint32_t W = F::size;
    constexpr std::uint32_t K = kTraversalWidth / W;
    const PacketPyramid<F> pyramid(beam, at, live);
    const float* const d_main = beam.m == 0 ? p.dx : beam.m == 1 ? p.dy : p.dz;
    const F tmin(t_min);
    PacketRays<F, K> r(p);
    // The live lanes whose hit so far lies nearer than depth `w` (in w = t |V_m|, with
    // room for the rounding of the product and of the spheres' near depths).
    const auto nearer_lanes = [&](float w) {
        std::uint32_t bits = 0;
        for (std::uint32_t k = 0; k < K; ++k) {
            const F depth = r.best_t[k] * xsimd::abs(F::load_aligned(d_main + k * W));
            bits |= mask_bits<F>(depth * F(kBeamDepthGrow) < F(w)) << (k * W);
        }
        return bits & live;
    };
    for (std::uint32_t first = 0; first < beam.count; first += 16) {
        if (first != 0 && nearer_lanes(beam.block_near[first / 16]) == live) break;
        for (std::uint32_t block = first; block < first + 16; block += W)
            for (std::uint32_t bits = pyramid.keeps(beam, block); bits != 0; bits &= bits - 1)
                packet_closest_sphere<F, K, false>(s, beam.sphere[block + __builtin_ctz(bits)],
                                                   r, tmin);
    }
    r.store(p);
    return beam.horizon == kInf ? 0 : live & ~nearer_lanes(beam.horizon);
}

// Step 3 for shadow rays: the lanes of `live` (not empty) that a sphere of the beam
// occludes, as bits. Blocks of spheres beyond every unoccluded lane's origin end the
// search. `unfinished`: the unoccluded lanes whose origin lies beyond the beam's horizon,
// which the BVH must finish.
template <class Arch>
std::uint32_t beam_occluded_packet(const SceneView& s, const Beam& beam, std::uint32_t at,
                                   const BvhPacket& p, std::uint32_t live,
                                   std::uint32_t& unfinished) {
    using F = xsimd::batch<float, RayArch<Arch>>;
    constexpr std::uint32_t W = F::size;
    constexpr std::uint32_t K = kTraversalWidth / W;
    const PacketPyramid<F> pyramid(beam, at, live);
    const PacketRays<F, K> r(p);  // best_t: each lane's t_max
    std::uint32_t done = 0;
    for (std::uint32_t first = 0; first < beam.count && done != live; first += 16) {
        if (first != 0 && beam.block_near[first / 16] >
                              masked_max<F>(beam.w + at, live & ~done) * kBeamDepthGrow)
            break;
        for (std::uint32_t block = first; block < first + 16; block += W)
            for (std::uint32_t bits = pyramid.keeps(beam, block); bits != 0 && done != live;
                 bits &= bits - 1)
                done |=
                    packet_occluding_sphere(s, beam.sphere[block + __builtin_ctz(bits)], r) &
                    live;
    }
    unfinished = 0;
    if (beam.horizon != kInf) {
        for (std::uint32_t k = 0; k < K; ++k) {
            const F w = F::load_aligned(beam.w + at + k * W);
            unfinished |= mask_bits<F>(w * F(kBeamDepthGrow) >= F(beam.horizon)) << (k * W);
        }
        unfinished &= live & ~done;
    }
    return done;
}

}  // namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE
