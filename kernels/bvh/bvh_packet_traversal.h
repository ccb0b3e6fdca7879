#pragma once
// BVH traversal by packets (closest hit and occlusion), going on ray by ray
// (bvh_single_ray.h) where a packet's live lanes drop below
// SceneView::bvh_packet_min_lanes.
//
// Included ONLY by the per-ISA translation units, under their OCTRAY_KERNEL_NAMESPACE
// (packet_math.h; kernels/README.md, "the ODR rule").

#ifndef OCTRAY_KERNEL_NAMESPACE
#error "define OCTRAY_KERNEL_NAMESPACE (one per ISA translation unit) before including"
#endif

#include <cstdint>

#include "kernels/bvh/bvh_frustum.h"
#include "kernels/bvh/bvh_packet.h"
#include "kernels/bvh/bvh_single_ray.h"
#include "kernels/geometry/sphere_test.h"

namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE {

// Packets: the packet's rays (kTraversalWidth) against one child box at a time.

// Lanes of the packet whose widened box of child j meets the ray on [t_near, t_far[lane]].
// F: the packet's registers.
// Always inlined: a node runs it for each of its 8 children, and as a call (which GCC
// chose) each one also paid for the call and a vzeroupper.
template <class F>
[[gnu::always_inline]] inline std::uint32_t packet_child_lanes(const BvhNode8& n,
                                                               std::uint32_t j,
                                                               const BvhPacket& p,
                                                               const F& t_near,
                                                               const float* t_far) {
    constexpr std::uint32_t W = F::size;
    const F min_x(n.min_x[j]), max_x(n.max_x[j]), min_y(n.min_y[j]), max_y(n.max_y[j]);
    const F min_z(n.min_z[j]), max_z(n.max_z[j]);
    std::uint32_t bits = 0;
    for (std::uint32_t at = 0; at < kTraversalWidth; at += W) {
        const F ix = F::load_aligned(p.inv_x + at), iy = F::load_aligned(p.inv_y + at),
                iz = F::load_aligned(p.inv_z + at);
        // Either slab plane may be the near one (lanes differ in sign): sort per lane.
        const F ax = fused_ms(min_x, ix, F::load_aligned(p.lo_off_x + at));
        const F bx = fused_ms(max_x, ix, F::load_aligned(p.hi_off_x + at));
        const F ay = fused_ms(min_y, iy, F::load_aligned(p.lo_off_y + at));
        const F by = fused_ms(max_y, iy, F::load_aligned(p.hi_off_y + at));
        const F az = fused_ms(min_z, iz, F::load_aligned(p.lo_off_z + at));
        const F bz = fused_ms(max_z, iz, F::load_aligned(p.hi_off_z + at));
        const F tn = xsimd::max(xsimd::max(xsimd::min(ax, bx), xsimd::min(ay, by)),
                                xsimd::max(xsimd::min(az, bz), t_near));
        const F tf = xsimd::min(xsimd::min(xsimd::max(ax, bx), xsimd::max(ay, by)),
                                xsimd::min(xsimd::max(az, bz), F::load_aligned(t_far + at)));
        bits |= mask_bits<F>(tn <= tf) << at;
    }
    return bits;
}

// Where lane `rep` of the packet enters each of the 8 children (children in lanes): the
// order in which the packet visits them. Only an order: it decides no hit.
template <class F>
void packet_child_keys(const BvhNode8& n, const BvhPacket& p, std::uint32_t rep, float* key) {
    constexpr std::uint32_t W = F::size;
    const F ix(p.inv_x[rep]), iy(p.inv_y[rep]), iz(p.inv_z[rep]);
    const F lo_x(p.lo_off_x[rep]), lo_y(p.lo_off_y[rep]), lo_z(p.lo_off_z[rep]);
    const F hi_x(p.hi_off_x[rep]), hi_y(p.hi_off_y[rep]), hi_z(p.hi_off_z[rep]);
    for (std::uint32_t at = 0; at < kBvhWidth; at += W) {
        const F ax = xsimd::fms(F::load_aligned(n.min_x + at), ix, lo_x);
        const F bx = xsimd::fms(F::load_aligned(n.max_x + at), ix, hi_x);
        const F ay = xsimd::fms(F::load_aligned(n.min_y + at), iy, lo_y);
        const F by = xsimd::fms(F::load_aligned(n.max_y + at), iy, hi_y);
        const F az = xsimd::fms(F::load_aligned(n.min_z + at), iz, lo_z);
        const F bz = xsimd::fms(F::load_aligned(n.max_z + at), iz, hi_z);
        const F entry =
            xsimd::max(xsimd::max(xsimd::min(ax, bx), xsimd::min(ay, by)), xsimd::min(az, bz));
        // Ranks need a total order: a NaN (never expected) sorts as the farthest.
        xsimd::select(entry == entry, entry, F(kInf)).store_aligned(key + at);
    }
}

// Pushes the children of `n` that some lane of `mask` enters, nearest on top: nearest
// where the bundle enters them, or, without a bundle, along the representative lane. Only
// the children the bundle enters get the per-lane tests (none, for a bundle from one
// origin: each child takes all of `mask`); these are independent (no branch between them,
// so the CPU overlaps them), and the entered children are then placed by rank, without a
// data-dependent branch: child j goes below every entered child nearer than it (ties: the
// lower index nearer). The leaves among them start loading (prefetch_leaf). F: the node
// tests' registers; the packet's are FR.
template <class F, bool kNearestFirst = true>
void push_packet_children(const SceneView& s, const BvhNode8& n, const BvhPacket& p,
                          const PacketFrustum<F>& fr, std::uint32_t mask, float t_near,
                          const float* t_far, BvhStacks& st, std::uint32_t& sp) {
    using FR = xsimd::batch<float, RayArch<typename F::arch_type>>;
    constexpr std::uint32_t W = F::size;
    std::uint32_t lanes[kBvhWidth] = {}, entered = 0;
    alignas(64) float key[kBvhWidth];
    const std::uint32_t candidates =
        fr.valid ? frustum_children<F>(n, fr, F(t_near), F(masked_max<FR>(t_far, mask)), key)
                 : used_children(n);
    if (fr.one_origin) {
        for (std::uint32_t j = 0; j < kBvhWidth; ++j) lanes[j] = mask;
        entered = candidates;
    } else {
        for (std::uint32_t bits = candidates; bits != 0; bits &= bits - 1) {
            const auto j = static_cast<std::uint32_t>(__builtin_ctz(bits));
            lanes[j] = packet_child_lanes(n, j, p, FR(t_near), t_far) & mask;
            entered |= static_cast<std::uint32_t>(lanes[j] != 0) << j;
        }
    }
    if (entered == 0) return;
    for (std::uint32_t bits = entered; bits != 0; bits &= bits - 1) {
        const std::uint32_t child = n.child[__builtin_ctz(bits)];
        if ((child & kBvhLeafBit) != 0) prefetch_leaf(s, child);
    }
    const auto count = static_cast<std::uint32_t>(__builtin_popcount(entered));
    if (count == 1 || !kNearestFirst) {
        // One child, or any hit (which needs no order): node order (largest box first, the
        // likeliest occluder), the first on top.
        for (std::uint32_t bits = entered, slot = sp + count; bits != 0; bits &= bits - 1) {
            const auto j = static_cast<std::uint32_t>(__builtin_ctz(bits));
            st.packet_node[--slot] = n.child[j];
            st.packet_mask[slot] = static_cast<std::uint16_t>(lanes[j]);
        }
        sp += count;
        return;
    }
    if (!fr.valid)
        packet_child_keys<F>(n, p, static_cast<std::uint32_t>(__builtin_ctz(mask)), key);
    alignas(64) static constexpr float kIndex[kBvhWidth] = {0, 1, 2, 3, 4, 5, 6, 7};
    for (std::uint32_t bits = entered; bits != 0; bits &= bits - 1) {
        const auto j = static_cast<std::uint32_t>(__builtin_ctz(bits));
        const F kj(key[j]), index_j(static_cast<float>(j));
        std::uint32_t nearer = 0;  // entered children that must be pushed after j
        for (std::uint32_t at = 0; at < kBvhWidth; at += W) {
            const F k = F::load_aligned(key + at), index = F::load_aligned(kIndex + at);
            nearer |= mask_bits<F>(k < kj || (k == kj && index < index_j)) << at;
        }
        const std::uint32_t slot =
            sp + count - 1 - static_cast<std::uint32_t>(__builtin_popcount(nearer & entered));
        st.packet_node[slot] = n.child[j];
        st.packet_mask[slot] = static_cast<std::uint16_t>(lanes[j]);
    }
    sp += count;
}

// A packet's rays in registers (K of them) for the sphere tests of a leaf or a beam
// (bvh_beam.h), with its closest hits so far.
template <class F, std::uint32_t K>
struct PacketRays {
    V3<F> o[K], d[K];
    F a[K], inv_a[K], best_t[K], best_id[K];

    explicit PacketRays(const BvhPacket& p) {
        for (std::uint32_t k = 0; k < K; ++k) {
            const std::uint32_t at = k * F::size;
            o[k] = load3<F>(p.ox, p.oy, p.oz, at);
            d[k] = load3<F>(p.dx, p.dy, p.dz, at);
            a[k] = F::load_aligned(p.a + at);
            inv_a[k] = F(1.0f) / a[k];
            best_t[k] = F::load_aligned(p.best_t + at);
            best_id[k] = F::load_aligned(p.best_id + at);
        }
    }
    void store(BvhPacket& p) const {
        for (std::uint32_t k = 0; k < K; ++k) {
            best_t[k].store_aligned(p.best_t + k * F::size);
            best_id[k].store_aligned(p.best_id + k * F::size);
        }
    }
};

// Sphere i of the BVH's arrays against every lane of `r` (hits on (tmin, inf)): the
// division-free test first (sphere_may_hit), then the exact one where some lane may hit.
// kPreTest: whether sphere_may_hit runs first (in the leaves, where most spheres miss
// every lane; not in a beam, whose spheres lie in the packet's pyramid).
template <class F, std::uint32_t K, bool kPreTest = true>
[[gnu::always_inline]] inline void packet_closest_sphere(const SceneView& s, std::uint32_t i,
                                                         PacketRays<F, K>& r, const F& tmin) {
    const F zero(0.0f);
    const V3<F> c{F(s.bvh_cx[i]), F(s.bvh_cy[i]), F(s.bvh_cz[i])};
    const F r2(s.bvh_r2[i]);
    V3<F> oc[K];
    auto may_hit = zero != zero;
    for (std::uint32_t k = 0; k < K; ++k) {
        oc[k] = sub(r.o[k], c);
        if constexpr (kPreTest)
            may_hit = may_hit || sphere_may_hit(oc[k], r.d[k], r.inv_a[k], r2);
    }
    if (kPreTest && xsimd::none(may_hit)) return;
    SphereQuadratic<F> quad[K];
    auto any_root = zero != zero;
    for (std::uint32_t k = 0; k < K; ++k) {
        quad[k] = sphere_quadratic(oc[k], r.d[k], r.a[k], r2);
        any_root = any_root || quad[k].disc >= zero;
    }
    if (xsimd::none(any_root)) return;
    const F id(static_cast<float>(s.bvh_object[i]));
    for (std::uint32_t k = 0; k < K; ++k) {
        const auto [t_near, t_far] = sphere_roots(quad[k], r.a[k]);
        const F t = xsimd::select(t_near > tmin, t_near, t_far);
        const auto hit =
            t > tmin && (t < r.best_t[k] || (t == r.best_t[k] && id < r.best_id[k]));
        r.best_t[k] = xsimd::select(hit, t, r.best_t[k]);
        r.best_id[k] = xsimd::select(hit, id, r.best_id[k]);
    }
}

// The lanes of `r` that sphere i occludes on (0, t_max), t_max in r.best_t, as bits.
template <class F, std::uint32_t K, bool kPreTest = true>
[[gnu::always_inline]] inline std::uint32_t packet_occluding_sphere(const SceneView& s,
                                                                    std::uint32_t i,
                                                                    const PacketRays<F, K>& r) {
    const F zero(0.0f);
    const V3<F> c{F(s.bvh_cx[i]), F(s.bvh_cy[i]), F(s.bvh_cz[i])};
    const F r2(s.bvh_r2[i]);
    std::uint32_t bits = 0;
    for (std::uint32_t k = 0; k < K; ++k) {
        const V3<F> oc = sub(r.o[k], c);
        if (kPreTest && xsimd::none(sphere_may_hit(oc, r.d[k], r.inv_a[k], r2))) continue;
        const SphereQuadratic<F> quad = sphere_quadratic(oc, r.d[k], r.a[k], r2);
        if (xsimd::none(quad.disc >= zero)) continue;
        const auto [t_near, t_far] = sphere_roots(quad, r.a[k]);
        const F t_max = r.best_t[k];
        const auto hit = (t_near > zero && t_near < t_max) || (t_far > zero && t_far < t_max);
        bits |= mask_bits<F>(hit) << (k * F::size);
    }
    return bits;
}

// Closest hits of the packet `p` (lanes `live`, not empty: packet_frustum) among the BVH's
// spheres.
template <class Arch>
void bvh_closest_packet(const SceneView& s, BvhPacket& p, std::uint32_t live, float t_min,
                        BvhStacks& st) {
    using FN = xsimd::batch<float, Arch>;          // a node's children
    using F = xsimd::batch<float, RayArch<Arch>>;  // the packet's rays
    constexpr std::uint32_t W = F::size;
    constexpr std::uint32_t K = kTraversalWidth / W;
    const F tmin(t_min), zero(0.0f);
    // Too few lanes for a packet from the root (or single rays only): no frustum needed.
    if (static_cast<std::uint32_t>(__builtin_popcount(live)) < s.bvh_packet_min_lanes)
        return bvh_closest_rays<Arch>(s, p, live, 0, t_min, st);
    const PacketFrustum<FN> fr = packet_frustum<FN, F>(p, live);
    std::uint32_t sp = 0;
    st.packet_node[sp] = 0, st.packet_mask[sp++] = static_cast<std::uint16_t>(live);
    while (sp > 0) {
        --sp;
        const std::uint32_t node = st.packet_node[sp], mask = st.packet_mask[sp];
        if (static_cast<std::uint32_t>(__builtin_popcount(mask)) < s.bvh_packet_min_lanes) {
            bvh_closest_rays<Arch>(s, p, mask, node, t_min, st);
            continue;
        }
        if ((node & kBvhLeafBit) == 0) {
            push_packet_children(s, s.bvh_nodes[node], p, fr, mask, t_min, p.best_t, st, sp);
            continue;
        }
        // A leaf: each sphere broadcast against the packet, as the brute-force kernel does,
        // with ties to the lower file index.
        PacketRays<F, K> r(p);
        const std::uint32_t first = leaf_first(node), end = first + leaf_count(node);
        for (std::uint32_t i = first; i < end; ++i) packet_closest_sphere(s, i, r, tmin);
        r.store(p);
    }
}

// Sets bit i of the result for each lane of `live` (not empty: packet_frustum) that a sphere
// occludes on (0, t_max).
template <class Arch>
std::uint32_t bvh_occluded_packet(const SceneView& s, const BvhPacket& p, std::uint32_t live,
                                  BvhStacks& st) {
    using FN = xsimd::batch<float, Arch>;          // a node's children
    using F = xsimd::batch<float, RayArch<Arch>>;  // the packet's rays
    constexpr std::uint32_t K = kTraversalWidth / F::size;
    std::uint32_t done = 0, sp = 0;
    const PacketRays<F, K> r(p);  // best_t: each lane's t_max
    // The sphere that occluded the packet before first: neighbouring shadow rays are
    // often blocked by the same sphere, and a lane it occludes needs no traversal. Any
    // occluder answers a lane, so the answer is the same whichever is found.
    if (st.occluder != kBvhEmpty) {
        done = packet_occluding_sphere(s, st.occluder, r) & live;
        if (done == live) return done;
        if (done == 0) st.occluder = kBvhEmpty;
    }
    const PacketFrustum<FN> fr = packet_frustum<FN, F>(p, live & ~done);
    st.packet_node[sp] = 0, st.packet_mask[sp++] = static_cast<std::uint16_t>(live & ~done);
    while (sp > 0 && done != live) {
        --sp;
        const std::uint32_t node = st.packet_node[sp], mask = st.packet_mask[sp] & ~done;
        if (mask == 0) continue;
        if (static_cast<std::uint32_t>(__builtin_popcount(mask)) < s.bvh_packet_min_lanes) {
            for (std::uint32_t bits = mask; bits != 0; bits &= bits - 1) {
                const auto lane = static_cast<std::uint32_t>(__builtin_ctz(bits));
                if (bvh_occluded_ray<Arch>(s, p, lane, node, st.ray_node)) done |= 1u << lane;
            }
            continue;
        }
        if ((node & kBvhLeafBit) == 0) {
            push_packet_children<FN, false>(s, s.bvh_nodes[node], p, fr, mask, 0.0f, p.best_t,
                                            st, sp);
            continue;
        }
        const std::uint32_t first = leaf_first(node), end = first + leaf_count(node);
        for (std::uint32_t i = first; i < end && (done & mask) != mask; ++i) {
            const std::uint32_t bits = packet_occluding_sphere(s, i, r) & mask;
            done |= bits;
            if (__builtin_popcount(bits) >= 4) st.occluder = i;
        }
    }
    return done;
}

}  // namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE
