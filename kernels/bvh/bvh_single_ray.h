#pragma once
// BVH traversal one ray at a time (closest hit and occlusion), the hybrid traversal's
// second half (bvh_packet.h). Closest-hit rays walk two at a time (bvh_closest_rays), and
// with AVX2 a node's children are ordered without a branch per child (push_children).
//
// Included ONLY by the per-ISA translation units, under their OCTRAY_KERNEL_NAMESPACE
// (packet_math.h; kernels/README.md, "the ODR rule").

#ifndef OCTRAY_KERNEL_NAMESPACE
#error "define OCTRAY_KERNEL_NAMESPACE (one per ISA translation unit) before including"
#endif

#include <cstdint>

#include "kernels/bvh/bvh_frustum.h"
#include "kernels/bvh/bvh_packet.h"
#include "kernels/geometry/sphere_test.h"

namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE {

// Single ray: one ray against the 8 children of a node at once.

// The ray of one lane, with its near and far planes chosen by its direction's signs.
template <class F>
struct BvhRay {
    using Plane = const float (BvhNode8::*)[kBvhWidth];
    Plane near_x, near_y, near_z, far_x, far_y, far_z;
    F inv_x, inv_y, inv_z;
    F near_off_x, near_off_y, near_off_z, far_off_x, far_off_y, far_off_z;
    V3<F> o, d;
    F a, inv_a;  // inv_a: sphere_may_hit's

    BvhRay() = default;
    BvhRay(const BvhPacket& p, std::uint32_t lane) {
        const auto axis = [&](float inv, float lo_off, float hi_off, Plane& near, Plane& far,
                              F& near_off, F& far_off, Plane min, Plane max) {
            // Positive direction: enter through min - m, leave through max + m.
            const bool positive = inv >= 0.0f;
            near = positive ? min : max;
            far = positive ? max : min;
            near_off = F(positive ? lo_off : hi_off);
            far_off = F(positive ? hi_off : lo_off);
        };
        axis(p.inv_x[lane], p.lo_off_x[lane], p.hi_off_x[lane], near_x, far_x, near_off_x,
             far_off_x, &BvhNode8::min_x, &BvhNode8::max_x);
        axis(p.inv_y[lane], p.lo_off_y[lane], p.hi_off_y[lane], near_y, far_y, near_off_y,
             far_off_y, &BvhNode8::min_y, &BvhNode8::max_y);
        axis(p.inv_z[lane], p.lo_off_z[lane], p.hi_off_z[lane], near_z, far_z, near_off_z,
             far_off_z, &BvhNode8::min_z, &BvhNode8::max_z);
        inv_x = F(p.inv_x[lane]), inv_y = F(p.inv_y[lane]), inv_z = F(p.inv_z[lane]);
        o = {F(p.ox[lane]), F(p.oy[lane]), F(p.oz[lane])};
        d = {F(p.dx[lane]), F(p.dy[lane]), F(p.dz[lane])};
        a = F(p.a[lane]);
        inv_a = F(1.0f / p.a[lane]);
    }

    // Bit i set when child i's widened box meets the ray on [t_near, t_far]; entry[i] is
    // where the ray enters it (unless entry is null: any hit needs no order).
    std::uint32_t test(const BvhNode8& n, const F& t_near, const F& t_far, float* entry) const {
        constexpr std::uint32_t W = F::size;
        std::uint32_t bits = 0;
        for (std::uint32_t at = 0; at < kBvhWidth; at += W) {
            const F tnx = xsimd::fms(F::load_aligned((n.*near_x) + at), inv_x, near_off_x);
            const F tny = xsimd::fms(F::load_aligned((n.*near_y) + at), inv_y, near_off_y);
            const F tnz = xsimd::fms(F::load_aligned((n.*near_z) + at), inv_z, near_off_z);
            const F tfx = xsimd::fms(F::load_aligned((n.*far_x) + at), inv_x, far_off_x);
            const F tfy = xsimd::fms(F::load_aligned((n.*far_y) + at), inv_y, far_off_y);
            const F tfz = xsimd::fms(F::load_aligned((n.*far_z) + at), inv_z, far_off_z);
            const F tn = xsimd::max(xsimd::max(tnx, tny), xsimd::max(tnz, t_near));
            const F tf = xsimd::min(xsimd::min(tfx, tfy), xsimd::min(tfz, t_far));
            bits |= mask_bits<F>(tn <= tf) << at;
            if (entry != nullptr) tn.store_aligned(entry + at);
        }
        return bits;
    }
};

// A ray against spheres i ... i + W - 1 of a leaf (lanes at ... of its `count`): the
// brute-force arithmetic of sphere_test.h (sphere_quadratic, sphere_roots), so the BVH
// finds the same t as brute force. `live`: lanes holding a sphere with real roots.
template <class F>
struct LeafRoots {
    typename F::batch_bool_type live;
    F t_near, t_far;
};

template <class F>
[[gnu::always_inline]] inline LeafRoots<F> leaf_roots(const SceneView& s, const BvhRay<F>& ray,
                                                      std::uint32_t i, std::uint32_t at,
                                                      std::uint32_t count) {
    const F zero(0.0f);
    const V3<F> c{F::load_unaligned(s.bvh_cx + i), F::load_unaligned(s.bvh_cy + i),
                  F::load_unaligned(s.bvh_cz + i)};
    const F r2 = F::load_unaligned(s.bvh_r2 + i);
    const V3<F> oc = sub(ray.o, c);
    if (xsimd::none(live_lanes<F>(at, count) && sphere_may_hit(oc, ray.d, ray.inv_a, r2)))
        return {zero != zero, zero, zero};
    const SphereQuadratic<F> quad = sphere_quadratic(oc, ray.d, ray.a, r2);
    const auto live = live_lanes<F>(at, count) && quad.disc >= zero;
    if (xsimd::none(live)) return {live, zero, zero};
    const SphereRoots<F> roots = sphere_roots(quad, ray.a);
    return {live, roots.t_near, roots.t_far};
}

#if defined(__AVX2__)
// Eight keys sorted into descending order (unsigned) by a bitonic network: six rounds of
// a permutation, a min, a max and a blend, and no branch.
inline __m256i sort8_descending(__m256i v) {
    const auto round = [&](__m256i partner, int upper) {
        const __m256i lo = _mm256_min_epu32(v, partner), hi = _mm256_max_epu32(v, partner);
        // The lanes of `upper` take the smaller key, the others the larger.
        switch (upper) {
            case 0xAA:
                return _mm256_blend_epi32(hi, lo, 0xAA);
            case 0xCC:
                return _mm256_blend_epi32(hi, lo, 0xCC);
            default:
                return _mm256_blend_epi32(hi, lo, 0xF0);
        }
    };
    v = round(_mm256_shuffle_epi32(v, _MM_SHUFFLE(2, 3, 0, 1)), 0xAA);
    v = round(_mm256_shuffle_epi32(v, _MM_SHUFFLE(0, 1, 2, 3)), 0xCC);
    v = round(_mm256_shuffle_epi32(v, _MM_SHUFFLE(2, 3, 0, 1)), 0xAA);
    v = round(_mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(7, 6, 5, 4, 3, 2, 1, 0)), 0xF0);
    v = round(_mm256_shuffle_epi32(v, _MM_SHUFFLE(1, 0, 3, 2)), 0xCC);
    v = round(_mm256_shuffle_epi32(v, _MM_SHUFFLE(2, 3, 0, 1)), 0xAA);
    return v;
}

// push_children without a branch per child: each child's key is its entry distance (a
// non-negative float, so its bits order as integers) with its slot in the low 3 bits, and
// 0 for a child the ray misses. Sorted in descending order, the hit children come first,
// farthest first; all eight references are stored, and beside them in `entries` the keys
// with their slot bits cleared (never above the entry), the stack grows by the hits less
// the nearest, which is returned. Ties (entries equal but for their 3 low bits) fall in
// any order, which changes no hit (the closest-hit rule does not depend on the order).
inline std::uint32_t push_children(const BvhNode8& n, std::uint32_t bits, const float* entry,
                                   std::uint32_t* stack, float* entries, std::uint32_t& sp) {
    const __m256i slot = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256i hit = _mm256_castps_si256(lane_mask8<__m256>(bits));
    const __m256i bits_of_entry = _mm256_castps_si256(_mm256_load_ps(entry));
    const __m256i key = _mm256_and_si256(
        hit, _mm256_or_si256(_mm256_andnot_si256(_mm256_set1_epi32(7), bits_of_entry), slot));
    // The nearest by a horizontal minimum (misses as the largest key): the next node's
    // address waits on three rounds, not on the network's six.
    __m256i m = _mm256_or_si256(key, _mm256_xor_si256(hit, _mm256_set1_epi32(-1)));
    m = _mm256_min_epu32(m, _mm256_permute2x128_si256(m, m, 1));
    m = _mm256_min_epu32(m, _mm256_shuffle_epi32(m, _MM_SHUFFLE(1, 0, 3, 2)));
    m = _mm256_min_epu32(m, _mm256_shuffle_epi32(m, _MM_SHUFFLE(2, 3, 0, 1)));
    const std::uint32_t nearest = n.child[_mm256_cvtsi256_si32(m) & 7];
    const __m256i order = sort8_descending(key);
    const __m256i child = _mm256_permutevar8x32_epi32(
        _mm256_load_si256(reinterpret_cast<const __m256i*>(n.child)), order);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(stack + sp), child);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(entries + sp),
                        _mm256_andnot_si256(_mm256_set1_epi32(7), order));
    sp += static_cast<std::uint32_t>(__builtin_popcount(bits)) - 1;
    return nearest;
}
#else
// Children of `n` in `bits`, nearest first by `entry`: the nearest is returned, the rest
// pushed farthest first, each with its entry in `entries`.
inline std::uint32_t push_children(const BvhNode8& n, std::uint32_t bits, const float* entry,
                                   std::uint32_t* stack, float* entries, std::uint32_t& sp) {
    std::uint32_t order[kBvhWidth];
    std::uint32_t count = 0;
    while (bits != 0) {
        const auto j = static_cast<std::uint32_t>(__builtin_ctz(bits));
        bits &= bits - 1;
        std::uint32_t k = count++;
        for (; k > 0 && entry[order[k - 1]] < entry[j]; --k) order[k] = order[k - 1];
        order[k] = j;  // descending entry
    }
    for (std::uint32_t k = 0; k + 1 < count; ++k)
        entries[sp] = entry[order[k]], stack[sp++] = n.child[order[k]];
    return n.child[order[count - 1]];
}

#endif

// Children of `n` in `bits` in the node's order (the builder's: largest box first, the
// likeliest to occlude): the first is returned, the rest pushed last first.
inline std::uint32_t push_children_in_order(const BvhNode8& n, std::uint32_t bits,
                                            std::uint32_t* stack, std::uint32_t& sp) {
    const auto first = static_cast<std::uint32_t>(__builtin_ctz(bits));
    for (bits &= bits - 1; bits != 0; bits &= ~(1u << (31 - __builtin_clz(bits))))
        stack[sp++] = n.child[31 - __builtin_clz(bits)];
    return n.child[first];
}

// Starts loading the children of `n` in `bits`: the ray visits them next, and in a large
// tree each one is a wait for memory (L3 or beyond) without this. An inner node is 224
// bytes (four cache lines), a leaf's spheres a line of each array (prefetch_leaf).
inline void prefetch_children(const SceneView& s, const BvhNode8& n, std::uint32_t bits) {
    for (; bits != 0; bits &= bits - 1) {
        const std::uint32_t child = n.child[__builtin_ctz(bits)];
        if ((child & kBvhLeafBit) != 0) {
            prefetch_leaf(s, child);
        } else {
            const char* node = reinterpret_cast<const char*>(s.bvh_nodes + child);
            for (int line = 0; line < 4; ++line) _mm_prefetch(node + 64 * line, _MM_HINT_T0);
        }
    }
}

// One ray's closest-hit walk, a node at a time (bvh_closest_rays interleaves two).
template <class F>
struct ClosestWalk {
    BvhRay<F> ray;
    float best_t, best_id;
    std::uint32_t node, sp;
    std::uint32_t* stack;
    float* entries;  // beside stack: where the ray enters each node, at most

    void begin(const BvhPacket& p, std::uint32_t lane, std::uint32_t start,
               std::uint32_t* stack_, float* entries_) {
        ray = BvhRay<F>(p, lane);
        best_t = p.best_t[lane], best_id = p.best_id[lane];
        node = start, sp = 0, stack = stack_, entries = entries_;
    }

    // Visits `node`; false once the walk is over.
    [[gnu::always_inline]] bool step(const SceneView& s, const F& tmin) {
        constexpr std::uint32_t W = F::size;
        if ((node & kBvhLeafBit) == 0) {
            alignas(64) float entry[kBvhWidth];
            const BvhNode8& n = s.bvh_nodes[node];
            const std::uint32_t bits = ray.test(n, tmin, F(best_t), entry);
            if (bits != 0) {
                prefetch_children(s, n, bits);
                node = push_children(n, bits, entry, stack, entries, sp);
                return true;
            }
        } else {
            // Up to 8 spheres against the ray, the brute-force arithmetic per lane.
            const std::uint32_t first = leaf_first(node), count = leaf_count(node);
            for (std::uint32_t at = 0; at < count; at += W) {
                const std::uint32_t i = first + at;
                const LeafRoots<F> r = leaf_roots(s, ray, i, at, count);
                if (xsimd::none(r.live)) continue;
                // The sphere's candidate is its first root above t_min.
                const F t = xsimd::select(r.t_near > tmin, r.t_near, r.t_far);
                std::uint32_t bits = mask_bits<F>(r.live && t > tmin && t <= F(best_t));
                if (bits == 0) continue;
                alignas(64) float ts[W];
                t.store_aligned(ts);
                for (; bits != 0; bits &= bits - 1) {
                    const auto l = static_cast<std::uint32_t>(__builtin_ctz(bits));
                    const auto id = static_cast<float>(s.bvh_object[i + l]);
                    if (ts[l] < best_t || (ts[l] == best_t && id < best_id))
                        best_t = ts[l], best_id = id;
                }
            }
        }
        // The next node the ray enters no farther than its hit so far (entered exactly at
        // best_t, it may hold a tie of a lower index): the box test would drop the others.
        do {
            if (sp == 0) return false;
            --sp;
        } while (entries[sp] > best_t);
        node = stack[sp];
        return true;
    }
};

// Closest hit of lane `lane` of `p` in the subtree `start`, on (t_min, best_t].
template <class Arch>
void bvh_closest_ray(const SceneView& s, BvhPacket& p, std::uint32_t lane, std::uint32_t start,
                     float t_min, BvhStacks& st) {
    using F = xsimd::batch<float, Arch>;
    const F tmin(t_min);
    ClosestWalk<F> w;
    w.begin(p, lane, start, st.ray_node, st.ray_entry);
    while (w.step(s, tmin)) {
    }
    p.best_t[lane] = w.best_t, p.best_id[lane] = w.best_id;
}

// bvh_closest_ray for each lane of `lanes`, two walks at a time: each node visit waits on
// its parent's (the node's load, the box test, the choice of the nearest child), and the
// other ray's visits fill that wait.
template <class Arch>
void bvh_closest_rays(const SceneView& s, BvhPacket& p, std::uint32_t lanes,
                      std::uint32_t start, float t_min, BvhStacks& st) {
    using F = xsimd::batch<float, Arch>;
    if (__builtin_popcount(lanes) < 2) {
        if (lanes != 0)
            bvh_closest_ray<Arch>(s, p, static_cast<std::uint32_t>(__builtin_ctz(lanes)), start,
                                  t_min, st);
        return;
    }
    const F tmin(t_min);
    const auto next = [&] {
        const auto lane = static_cast<std::uint32_t>(__builtin_ctz(lanes));
        lanes &= lanes - 1;
        return lane;
    };
    std::uint32_t la = next(), lb = next();
    ClosestWalk<F> a, b;
    a.begin(p, la, start, st.ray_node, st.ray_entry);
    b.begin(p, lb, start, st.ray_node_b, st.ray_entry_b);
    bool live_a = true, live_b = true;
    // A walk that ends hands in its hit and takes the next lane, if any.
    const auto end = [&](ClosestWalk<F>& w, std::uint32_t& lane) {
        p.best_t[lane] = w.best_t, p.best_id[lane] = w.best_id;
        if (lanes == 0) return false;
        lane = next();
        w.begin(p, lane, start, w.stack, w.entries);
        return true;
    };
    while (live_a || live_b) {
        if (live_a && !a.step(s, tmin)) live_a = end(a, la);
        if (live_b && !b.step(s, tmin)) live_b = end(b, lb);
    }
}

// Whether lane `lane` of `p` hits a sphere of the subtree `start` on (0, t_max).
template <class Arch>
bool bvh_occluded_ray(const SceneView& s, const BvhPacket& p, std::uint32_t lane,
                      std::uint32_t start, std::uint32_t* stack) {
    using F = xsimd::batch<float, Arch>;
    constexpr std::uint32_t W = F::size;
    const BvhRay<F> ray(p, lane);
    const F zero(0.0f), t_max(p.best_t[lane]);
    std::uint32_t sp = 0, node = start;
    for (;;) {
        if ((node & kBvhLeafBit) == 0) {
            const BvhNode8& n = s.bvh_nodes[node];
            const std::uint32_t bits = ray.test(n, zero, t_max, nullptr);
            if (bits != 0) {
                prefetch_children(s, n, bits);
                node = push_children_in_order(n, bits, stack, sp);
                continue;
            }
        } else {
            const std::uint32_t first = leaf_first(node), count = leaf_count(node);
            for (std::uint32_t at = 0; at < count; at += W) {
                const std::uint32_t i = first + at;
                const LeafRoots<F> r = leaf_roots(s, ray, i, at, count);
                if (xsimd::none(r.live)) continue;
                const auto& live = r.live;
                const F& t_near = r.t_near;
                const F& t_far = r.t_far;
                if (xsimd::any(live && ((t_near > zero && t_near < t_max) ||
                                        (t_far > zero && t_far < t_max))))
                    return true;
            }
        }
        if (sp == 0) return false;
        node = stack[--sp];
    }
}

}  // namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE
