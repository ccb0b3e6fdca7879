#pragma once
// What every BVH traversal shares: a packet's rays as the traversal reads them (BvhPacket,
// loaded with the margin that widens every box), the traversal stacks, leaf references.
//
// Included ONLY by the per-ISA translation units, under their OCTRAY_KERNEL_NAMESPACE
// (packet_math.h; kernels/README.md, "the ODR rule").
//
// The tree is render/prepare/bvh_build.h's: 8-wide nodes with their children's boxes in SoA
// (kernels/bvh/bvh_node.h), leaves of up to 8 spheres in SoA. Two traversals share it:
// - packet traversal (Wald et al. 2001, "Interactive rendering with coherent ray
//   tracing", widened to 8-wide nodes): the packet as a whole (a frustum, where its
//   directions' signs agree) is tested against all 8 children at once; the 8-ray packet is
//   then tested against each child box the frustum enters, lanes whose current closest hit
//   lies before the box are culled, and children are visited nearest first;
// - single-ray traversal (Wald et al. 2008, "Getting rid of packets"; embree's BVH8): one
//   ray against all 8 child boxes in one operation, near/far planes picked by the ray's
//   direction signs (Williams et al. 2005), children visited nearest first.
// A packet whose live lanes drop below SceneView::bvh_packet_min_lanes goes on ray by ray
// from that node (embree's hybrid traversal).
//
// Bit-exactness. Leaves test spheres with the brute-force kernels' exact arithmetic (same
// operands, same order), and a hit replaces the current one when it is nearer or equally
// near with a lower file index: the brute-force result (the first listed object wins a
// tie) whatever the visiting order. Box tests only decide which spheres are tested, so
// they must never cull a sphere the brute-force test would report. That test rounds. With
// u = 2^-24, the robust form (sphere_quadratic) computes l = O' - (b/a)V to within ~9u|O'|,
// so a lane with disc >= 0 has its ray pass within r + 10u|O'| of the center, and the
// roots q/a, c'/q put the point within a few u|O'| of that ray's chord (c'/q loses digits
// only for an origin within ~1e-4 r of the surface moving tangentially, where both true
// roots are ~0 and the origin lies in the box anyway). So every box is widened, per ray, by
//   32u D + 64u(D + max|O|)
// where D is the distance from the ray origin to the farthest corner of the root box
// (bounding |O'| for every sphere): the first term the sphere test's rounding, with room
// to spare, the second the rounding of the slab test itself (FMA: it decides visits, not
// values) and of O - c. (The textbook form used before was far worse: a fuzzy sphere of
// radius ~sqrt(19u)|O'| around a tiny sphere far away, and a widening of
// sqrt(r_min^2 + 32u(D^2 + r_max^2)) - r_min, up to half a radius on random:1048576.)
// The tests (tests/kernels/bvh/bvh_traversal_test.cpp) check hit for hit against brute force
// on degenerate scenes (radii from 1e-6 to 1e3, coincident spheres, spheres far apart).

#ifndef OCTRAY_KERNEL_NAMESPACE
#error "define OCTRAY_KERNEL_NAMESPACE (one per ISA translation unit) before including"
#endif

#include <immintrin.h>

#include <cstdint>

#include "kernels/packet_math.h"

namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE {

// Rays per traversal packet. A translation unit that defines OCTRAY_TRAVERSAL_ARCH (the
// AVX-512 one: xsimd::avx512f) traverses 16 rays at a time, one register per packet: two
// of the stream's 8-ray packets, adjacent pixels, share every node visit and leaf load,
// as embree's 16-wide packets do. Its node tests stay 8 lanes wide (the node's 8
// children, in the kernel's Arch). Without it a traversal packet is the stream's packet,
// in registers of the kernel's Arch.
#ifdef OCTRAY_TRAVERSAL_ARCH
template <class Arch>
using RayArch = OCTRAY_TRAVERSAL_ARCH;
constexpr std::uint32_t kTraversalWidth = 16;
#else
template <class Arch>
using RayArch = Arch;
constexpr std::uint32_t kTraversalWidth = kPacketWidth;
#endif
static_assert(kTraversalWidth % kPacketWidth == 0 && kTraversalWidth <= 16);

// Entries of a traversal stack: a node pushes at most 8 children (the single-ray
// traversal writes all 8 slots above the top at once), and the builder keeps the tree
// below 48 + 28 levels (render/prepare/bvh_sah.cpp, kMaxSahDepth).
constexpr std::uint32_t kBvhStackSize = 1024;
// 32u and 64u of the margin above.
constexpr float kBvhFuzz = 0x1.0p-19f;
constexpr float kBvhSlack = 0x1.0p-18f;
// Direction components smaller than this are replaced by it (with their sign) before the
// reciprocal, so that box tests never compute 0 * inf.
constexpr float kBvhTinyDirection = 1e-18f;

// One packet's rays as the traversal reads them, lane by lane in memory: the single-ray
// traversal picks its lane's scalars from here.
struct BvhPacket {
    static constexpr std::uint32_t N = kTraversalWidth;
    alignas(64) float ox[N], oy[N], oz[N];
    alignas(64) float dx[N], dy[N], dz[N];
    alignas(64) float a[N];  // V·V, as the sphere test computes it
    alignas(64) float inv_x[N], inv_y[N], inv_z[N];
    // (O + margin) * inv and (O - margin) * inv: a widened slab [min - m, max + m] is
    // entered at min * inv - lo_off (positive direction) or max * inv - hi_off (negative).
    alignas(64) float lo_off_x[N], lo_off_y[N], lo_off_z[N];
    alignas(64) float hi_off_x[N], hi_off_y[N], hi_off_z[N];
    // Closest hit: the nearest hit so far (t, file index). Any hit: t_max.
    alignas(64) float best_t[N], best_id[N];
};

struct BvhStacks {
    std::uint32_t packet_node[kBvhStackSize];
    std::uint16_t packet_mask[kBvhStackSize];  // lanes, one bit each
    std::uint32_t ray_node[kBvhStackSize];
    std::uint32_t ray_node_b[kBvhStackSize];  // a second ray's (bvh_closest_rays)
    // Where the closest-hit walks' ray enters each stacked node, at most (push_children):
    // a node entered beyond the hit found since is dropped without a visit.
    float ray_entry[kBvhStackSize];
    float ray_entry_b[kBvhStackSize];
    // The sphere (BVH index) that last occluded a lane of a packet, or kBvhEmpty: the
    // next packet of shadow rays tests it first (bvh_occluded_packet). Valid for the
    // SceneView of the stacks' caller only.
    std::uint32_t occluder = kBvhEmpty;
};

// The widening of every box for rays from `o` (the margin derived above).
template <class F>
F bvh_margin(const SceneView& s, const V3<F>& o) {
    const auto far_extent = [](const F& x, float lo, float hi) {
        return xsimd::max(xsimd::abs(x - F(lo)), xsimd::abs(x - F(hi)));
    };
    const F ex = far_extent(o.x, s.bvh_lo[0], s.bvh_hi[0]);
    const F ey = far_extent(o.y, s.bvh_lo[1], s.bvh_hi[1]);
    const F ez = far_extent(o.z, s.bvh_lo[2], s.bvh_hi[2]);
    const F d = xsimd::sqrt(ex * ex + ey * ey + ez * ez);
    const F o_max = xsimd::max(xsimd::max(xsimd::abs(o.x), xsimd::abs(o.y)), xsimd::abs(o.z));
    const F m = F(kBvhFuzz) * d + F(kBvhSlack) * (d + o_max);
    return m * F(1.0f + 0x1.0p-10f);  // the rounding of this very computation
}

template <class F>
F safe_reciprocal(const F& d) {
    const F tiny(kBvhTinyDirection);
    return F(1.0f) / xsimd::select(xsimd::abs(d) < tiny, xsimd::copysign(tiny, d), d);
}

// Box tests stay finite while (|O| + margin + |box|) * |1/V| does; beyond this (scenes with
// coordinates past ~1e19, or an overflowing margin) a packet falls back to brute force.
constexpr float kBvhFiniteLimit = 1e37f;

// v[at ... at + size) of a stream `left` values long from v. Streams hold whole 8-ray
// packets (kernel_types.h), so a 16-lane register whose upper half lies past them repeats
// its lower half: finite rays, never read back.
template <class F>
F load_stream(const float* v, std::uint32_t at, std::uint32_t left) {
    if constexpr (F::size == 16) {
        if (left <= at + kPacketWidth) return _mm512_broadcast_f32x8(_mm256_load_ps(v + at));
    }
    (void)left;
    return F::load_aligned(v + at);
}

// Loads a packet's rays [base, base + kTraversalWidth) of a stream holding `count` into
// `p`: origins, directions, V·V; best_t starts at `t_far` (+inf where null), best_id at
// -1. What a beam packet reads (bvh_beam.h); the box tests need packet_box_offsets too.
template <class F>
void load_packet_rays(const float* ox, const float* oy, const float* oz, const float* dx,
                      const float* dy, const float* dz, const float* t_far, std::uint32_t base,
                      std::uint32_t count, BvhPacket& p) {
    constexpr std::uint32_t W = F::size;
    const std::uint32_t left = count - base;
    const auto load = [&](const float* v, std::uint32_t at) {
        return load_stream<F>(v + base, at, left);
    };
    for (std::uint32_t at = 0; at < kTraversalWidth; at += W) {
        store3(V3<F>{load(ox, at), load(oy, at), load(oz, at)}, p.ox, p.oy, p.oz, at);
        const V3<F> d{load(dx, at), load(dy, at), load(dz, at)};
        store3(d, p.dx, p.dy, p.dz, at);
        dot(d, d).store_aligned(p.a + at);
        (t_far ? load(t_far, at) : F(kInf)).store_aligned(p.best_t + at);
        F(-1.0f).store_aligned(p.best_id + at);
    }
}

// The box tests' fields of the rays in `p` (reciprocal directions and the widened slab
// offsets); leaves its hits alone. Returns the lanes whose box tests stay finite
// (kBvhFiniteLimit).
template <class F>
std::uint32_t packet_box_offsets(const SceneView& s, BvhPacket& p) {
    constexpr std::uint32_t W = F::size;
    float box_max = 0.0f;  // no fmaxf: it is a libm call, not an instruction
    for (int a = 0; a < 3; ++a) {
        const float lo = fabsf(s.bvh_lo[a]), hi = fabsf(s.bvh_hi[a]);
        box_max = box_max > lo ? box_max : lo;
        box_max = box_max > hi ? box_max : hi;
    }
    std::uint32_t finite = 0;
    for (std::uint32_t at = 0; at < kTraversalWidth; at += W) {
        const V3<F> o = load3<F>(p.ox, p.oy, p.oz, at), d = load3<F>(p.dx, p.dy, p.dz, at);
        const V3<F> inv{safe_reciprocal(d.x), safe_reciprocal(d.y), safe_reciprocal(d.z)};
        store3(inv, p.inv_x, p.inv_y, p.inv_z, at);
        const F m = bvh_margin(s, o);
        const F o_max =
            xsimd::max(xsimd::max(xsimd::abs(o.x), xsimd::abs(o.y)), xsimd::abs(o.z));
        const F inv_max =
            xsimd::max(xsimd::max(xsimd::abs(inv.x), xsimd::abs(inv.y)), xsimd::abs(inv.z));
        finite |= mask_bits<F>((o_max + m + F(box_max)) * inv_max < F(kBvhFiniteLimit)) << at;
        const V3<F> lo{o.x + m, o.y + m, o.z + m}, hi{o.x - m, o.y - m, o.z - m};
        store3(hadamard(lo, inv), p.lo_off_x, p.lo_off_y, p.lo_off_z, at);
        store3(hadamard(hi, inv), p.hi_off_x, p.hi_off_y, p.hi_off_z, at);
    }
    return finite;
}

// Both: a packet ready for the BVH traversal. Returns packet_box_offsets's lanes.
template <class F>
std::uint32_t load_bvh_packet(const SceneView& s, const float* ox, const float* oy,
                              const float* oz, const float* dx, const float* dy,
                              const float* dz, const float* t_far, std::uint32_t base,
                              std::uint32_t count, BvhPacket& p) {
    load_packet_rays<F>(ox, oy, oz, dx, dy, dz, t_far, base, count, p);
    return packet_box_offsets<F>(s, p);
}

inline std::uint32_t leaf_first(std::uint32_t ref) {
    return (ref & ~kBvhLeafBit) >> kBvhLeafCountBits;
}
inline std::uint32_t leaf_count(std::uint32_t ref) {
    return (ref & ((1u << kBvhLeafCountBits) - 1u)) + 1u;
}

// Starts loading a leaf's spheres (the first cache line of each of the four arrays). A
// packet pops the leaves it pushes soon after; without this, in a large scene, the first
// load of each array waits for memory (docs/performance-log.md, "Packets from one origin; leaf
// prefetches").
inline void prefetch_leaf(const SceneView& s, std::uint32_t ref) {
    const std::uint32_t first = leaf_first(ref);
    for (const float* a : {s.bvh_cx, s.bvh_cy, s.bvh_cz, s.bvh_r2})
        _mm_prefetch(reinterpret_cast<const char*>(a + first), _MM_HINT_T0);
}

}  // namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE
