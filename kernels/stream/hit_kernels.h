#pragma once
// The closest_hit and any_hit entry points of the kernel table: the BVH when the scene
// view has one (bvh_packet_traversal.h), else brute force (brute_force.h); planes stay
// outside the tree. Shadow rays are sorted into coherent packets first in large BVHs.
//
// Included ONLY by the per-ISA translation units, under their OCTRAY_KERNEL_NAMESPACE
// (packet_math.h; kernels/README.md, "the ODR rule").

#ifndef OCTRAY_KERNEL_NAMESPACE
#error "define OCTRAY_KERNEL_NAMESPACE (one per ISA translation unit) before including"
#endif

#include <cstdint>
#include <utility>

#include "kernels/bvh/bvh_beam.h"
#include "kernels/bvh/bvh_packet.h"
#include "kernels/bvh/bvh_packet_traversal.h"
#include "kernels/geometry/plane_test.h"
#include "kernels/stream/brute_force.h"

namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE {

// Lanes [base, base + kTraversalWidth) below count, as bits.
inline std::uint32_t live_bits(std::uint32_t base, std::uint32_t count) {
    const std::uint32_t left = count - base;
    return left >= kTraversalWidth ? (1u << kTraversalWidth) - 1u : (1u << left) - 1u;
}

// The packet-lane thresholds of a scene view in a traversal of kTraversalWidth rays: a
// threshold above kPacketWidth means "single rays only" (SceneView) whatever the width.
inline std::uint32_t traversal_min_lanes(std::uint32_t min_lanes) {
    return min_lanes > kPacketWidth ? kTraversalWidth + 1 : min_lanes;
}

// Rays [base, ...) of a stream, as a stream (base a multiple of kTraversalWidth, so that
// its arrays stay 64-byte aligned).
inline RayStream stream_from(const RayStream& r, std::uint32_t base) {
    return {r.ox + base, r.oy + base, r.oz + base, r.dx + base, r.dy + base,
            r.dz + base, r.wr + base, r.wg + base, r.wb + base, r.pixel + base};
}
inline ShadowStream stream_from(const ShadowStream& r, std::uint32_t base) {
    return {r.ox + base,     r.oy + base,     r.oz + base,    r.dx + base,
            r.dy + base,     r.dz + base,     r.t_max + base, r.term_r + base,
            r.term_g + base, r.term_b + base, r.parent + base};
}

template <class Arch>
void closest_hit(const SceneView& scene, const RayStream& rays, std::uint32_t count,
                 float t_min, const HitStream& hits) {
    if (scene.bvh_nodes == nullptr)
        return closest_hit_all<Arch>(scene, rays, count, t_min, hits);
    // Secondary rays switch to single rays by their own rule (SceneView).
    SceneView s = scene;
    s.bvh_packet_min_lanes =
        traversal_min_lanes(t_min == 0.0f ? s.bvh_secondary_min_lanes : s.bvh_packet_min_lanes);
    using F = xsimd::batch<float, RayArch<Arch>>;  // the packet's rays
    using FN = xsimd::batch<float, Arch>;          // the stream's
    constexpr std::uint32_t W = F::size;
    BvhPacket p;
    BvhStacks st;
    Beam beam;
    const F tmin(t_min);
    for (std::uint32_t group = 0; group < count; group += kBeamRays) {
        // A group of rays from one origin is a beam (bvh_beam.h).
        const std::uint32_t n = count - group < kBeamRays ? count - group : kBeamRays;
        const bool in_beam = beam_for_group<F, FN>(s, rays, group, n, count, beam, st);
        if (!in_beam && s.sphere_count <= s.bvh_brute_force_max_spheres) {
            // A small BVH: rays that form no beam test every sphere (SceneView).
            closest_hit_all<Arch>(s, stream_from(rays, group), n, t_min,
                                  HitStream{hits.t + group, hits.object + group});
            continue;
        }
        for (std::uint32_t base = group; base < group + n; base += kTraversalWidth) {
            const std::uint32_t live = live_bits(base, count);
            // Lanes the BVH traverses: all of them, or those a beam leaves unfinished,
            // which go on from the beam's hits (the tie rule makes the result the same
            // as from none).
            std::uint32_t traverse = live, finite;
            if (in_beam) {
                load_packet_rays<F>(rays.ox, rays.oy, rays.oz, rays.dx, rays.dy, rays.dz,
                                    nullptr, base, count, p);
                traverse = beam_closest_packet<Arch>(s, beam, base - group, p, live, t_min);
                finite = traverse != 0 ? packet_box_offsets<F>(s, p) : live;
            } else {
                finite = load_bvh_packet<F>(s, rays.ox, rays.oy, rays.oz, rays.dx, rays.dy,
                                            rays.dz, nullptr, base, count, p);
            }
            if ((finite & live) != live) {
                // Box tests would overflow: this packet against every sphere.
                closest_hit_all<Arch>(
                    s, stream_from(rays, base),
                    count - base < kTraversalWidth ? count - base : kTraversalWidth, t_min,
                    HitStream{hits.t + base, hits.object + base});
                continue;
            }
            if (traverse != 0) bvh_closest_packet<Arch>(s, p, traverse, t_min, st);
            // Planes stay outside the tree.
            for (std::uint32_t at = 0; at < kTraversalWidth; at += W) {
                F best_t = F::load_aligned(p.best_t + at),
                  best_id = F::load_aligned(p.best_id + at);
                closest_planes(s, load3<F>(p.ox, p.oy, p.oz, at),
                               load3<F>(p.dx, p.dy, p.dz, at), tmin, best_t, best_id);
                best_t.store_aligned(p.best_t + at);
                best_id.store_aligned(p.best_id + at);
            }
            // Back to the stream by its own packets, none past its end.
            for (std::uint32_t at = 0; at < kTraversalWidth && base + at < count;
                 at += FN::size) {
                FN::load_aligned(p.best_t + at).store_aligned(hits.t + base + at);
                xsimd::to_int(FN::load_aligned(p.best_id + at))  // ids < 2^24
                    .store_aligned(hits.object + base + at);
            }
        }
    }
}

// The lanes of `live` in packet `p` (its t_max in best_t) that a plane occludes, as bits.
template <class Arch>
std::uint32_t plane_occluded(const SceneView& s, const BvhPacket& p, std::uint32_t live) {
    using F = xsimd::batch<float, RayArch<Arch>>;
    std::uint32_t done = 0;
    for (std::uint32_t at = 0; at < kTraversalWidth; at += F::size)
        done |= mask_bits<F>(any_plane(s, load3<F>(p.ox, p.oy, p.oz, at),
                                       load3<F>(p.dx, p.dy, p.dz, at),
                                       F::load_aligned(p.best_t + at)))
                << at;
    return done & live;
}

// Whether each live lane of the kTraversalWidth rays from `base` of `rays` (a stream of
// `count`) is occluded, as bits.
template <class Arch>
std::uint32_t occluded_packet(const SceneView& s, const ShadowStream& rays, std::uint32_t base,
                              std::uint32_t count, std::uint32_t live, BvhPacket& p,
                              BvhStacks& st) {
    using F = xsimd::batch<float, RayArch<Arch>>;
    if ((load_bvh_packet<F>(s, rays.ox, rays.oy, rays.oz, rays.dx, rays.dy, rays.dz, rays.t_max,
                            base, count, p) &
         live) != live) {
        // Box tests would overflow: this packet against every sphere.
        alignas(64) std::uint32_t flags[kTraversalWidth] = {};
        any_hit_all<Arch>(s, stream_from(rays, base),
                          static_cast<std::uint32_t>(32 - __builtin_clz(live)), flags);
        std::uint32_t bits = 0;
        for (std::uint32_t i = 0; i < kTraversalWidth; ++i) bits |= (flags[i] & 1u) << i;
        return bits & live;
    }
    // Planes first: a lane they occlude needs no traversal.
    const std::uint32_t done = plane_occluded<Arch>(s, p, live);
    if (done == live) return done;  // no lane left to trace
    return done | bvh_occluded_packet<Arch>(s, p, live & ~done, st);
}

// occluded_packet for rays of a shadow beam (bvh_beam.h): planes, then the beam's spheres,
// then the BVH for the lanes the beam leaves unfinished.
template <class Arch>
std::uint32_t beam_occluded(const SceneView& s, const ShadowStream& rays, const Beam& beam,
                            std::uint32_t group, std::uint32_t base, std::uint32_t count,
                            std::uint32_t live, BvhPacket& p, BvhStacks& st) {
    using F = xsimd::batch<float, RayArch<Arch>>;
    load_packet_rays<F>(rays.ox, rays.oy, rays.oz, rays.dx, rays.dy, rays.dz, rays.t_max, base,
                        count, p);
    std::uint32_t done = plane_occluded<Arch>(s, p, live);
    if (done == live) return done;
    std::uint32_t unfinished = 0;
    done |= beam_occluded_packet<Arch>(s, beam, base - group, p, live & ~done, unfinished);
    if (unfinished == 0) return done;
    return done | occluded_packet<Arch>(s, rays, base, count, unfinished, p, st);
}

// Shadow rays are traced in batches of up to this many, regrouped into packets of rays
// whose origins lie close together (in BVHs of SceneView::bvh_shadow_sort_min_spheres
// spheres or more); smaller calls are traced in the order given.
constexpr std::uint32_t kShadowBatch = 4096;
constexpr std::uint32_t kShadowSortMin = 64;

// The sort keys of shadow rays [at, at + W) (lanes past the stream's end read its
// padding, and their keys go unused): each ray's direction octant (3 sign bits: rays of
// one packet then mostly share their signs, so the packet's frustum test applies), then
// the cell of the BVH's root box (32 per axis, clamped) that holds its origin, as a
// 15-bit Morton code (neighbouring cells get neighbouring codes).
template <class F>
void shadow_keys(const SceneView& s, const ShadowStream& rays, std::uint32_t at,
                 std::uint32_t* key) {
    using I = xsimd::batch<std::int32_t, typename F::arch_type>;
    const float* const o[3] = {rays.ox + at, rays.oy + at, rays.oz + at};
    const float* const d[3] = {rays.dx + at, rays.dy + at, rays.dz + at};
    I code(0);
    for (int a = 0; a < 3; ++a) {
        const float extent = s.bvh_hi[a] - s.bvh_lo[a];
        const F scale(extent > 0.0f && 32.0f / extent < kInf ? 32.0f / extent : 0.0f);
        // max(NaN, 0) is 0 (the second operand): below the box or NaN, cell 0.
        const F f = xsimd::max((F::load_unaligned(o[a]) - F(s.bvh_lo[a])) * scale, F(0.0f));
        I q = xsimd::to_int(xsimd::min(f, F(31.0f)));
        q = (q | (q << 8)) & I(0x0300F);  // 5 bits spread to every third bit
        q = (q | (q << 4)) & I(0x030C3);
        q = (q | (q << 2)) & I(0x09249);
        // The direction's sign bit.
        const I sign = (xsimd::bitwise_cast<I>(F::load_unaligned(d[a])) >> 31) & I(1);
        code = code | (q << a) | (sign << (15 + a));
    }
    code.store_unaligned(reinterpret_cast<std::int32_t*>(key));
}

// One stable pass of a counting sort of `n` words by the digit (word >> shift) & 511, from
// `from` into `to`. The four quarters of `from` are counted and scattered in turn, each
// with counters of its own: neighbouring rays often share a digit, and one counter's
// increments (a load, an add, a store) would wait on each other through memory, where four
// quarters make four independent chains. Quarter by quarter in order within each digit,
// so the pass stays stable.
inline void sort_pass(const std::uint32_t* from, std::uint32_t* to, std::uint32_t n,
                      std::uint32_t shift) {
    const std::uint32_t q = (n + 3) / 4;
    // Quarter k is [k q, (k + 1) q) clipped to n; the last is the shortest.
    const std::uint32_t* const f1 = from + (q < n ? q : n);
    const std::uint32_t* const f2 = from + (2 * q < n ? 2 * q : n);
    const std::uint32_t* const f3 = from + (3 * q < n ? 3 * q : n);
    const std::uint32_t common = static_cast<std::uint32_t>(from + n - f3);
    alignas(64) std::uint32_t at[4][512] = {};
    const auto digit = [shift](std::uint32_t w) { return (w >> shift) & 511u; };
    const auto tails = [&](auto&& f) {
        for (std::uint32_t j = common; j < q; ++j) {
            if (from + j < f1) f(0, from[j]);
            if (f1 + j < f2) f(1, f1[j]);
            if (f2 + j < f3) f(2, f2[j]);
        }
    };
    for (std::uint32_t j = 0; j < common; ++j) {
        ++at[0][digit(from[j])];
        ++at[1][digit(f1[j])];
        ++at[2][digit(f2[j])];
        ++at[3][digit(f3[j])];
    }
    tails([&](std::uint32_t k, std::uint32_t w) { ++at[k][digit(w)]; });
    std::uint32_t sum = 0;
    for (std::uint32_t d = 0; d < 512; ++d) {
        const std::uint32_t c0 = at[0][d], c1 = at[1][d], c2 = at[2][d], c3 = at[3][d];
        at[0][d] = sum;
        at[1][d] = sum + c0;
        at[2][d] = sum + c0 + c1;
        at[3][d] = sum + c0 + c1 + c2;
        sum += c0 + c1 + c2 + c3;
    }
    for (std::uint32_t j = 0; j < common; ++j) {
        const std::uint32_t w0 = from[j], w1 = f1[j], w2 = f2[j], w3 = f3[j];
        to[at[0][digit(w0)]++] = w0;
        to[at[1][digit(w1)]++] = w1;
        to[at[2][digit(w2)]++] = w2;
        to[at[3][digit(w3)]++] = w3;
    }
    tails([&](std::uint32_t k, std::uint32_t w) { to[at[k][digit(w)]++] = w; });
}

template <class Arch>
void any_hit(const SceneView& scene, const ShadowStream& rays, std::uint32_t count,
             std::uint32_t* occluded) {
    // Small BVHs too: brute force beats their shadow beams (SceneView).
    if (scene.bvh_nodes == nullptr || scene.sphere_count <= scene.bvh_brute_force_max_spheres)
        return any_hit_all<Arch>(scene, rays, count, occluded);
    SceneView s = scene;
    s.bvh_packet_min_lanes = traversal_min_lanes(s.bvh_packet_min_lanes);
    BvhPacket p;
    BvhStacks st;
    if (count < kShadowSortMin || s.sphere_count < s.bvh_shadow_sort_min_spheres) {
        using F = xsimd::batch<float, RayArch<Arch>>;  // the rays'
        using FN = xsimd::batch<float, Arch>;          // the node tests'
        Beam beam;
        for (std::uint32_t group = 0; group < count; group += kBeamRays) {
            // Rays towards one point light from one tile are a beam (bvh_beam.h).
            const std::uint32_t n = count - group < kBeamRays ? count - group : kBeamRays;
            const bool in_beam = beam_for_group<F, FN>(s, rays, group, n, count, beam, st);
            for (std::uint32_t base = group; base < group + n; base += kTraversalWidth) {
                const std::uint32_t live = live_bits(base, count);
                const std::uint32_t bits =
                    in_beam
                        ? beam_occluded<Arch>(s, rays, beam, group, base, count, live, p, st)
                        : occluded_packet<Arch>(s, rays, base, count, live, p, st);
                // Whole stream packets (kernel_types.h), none past the stream's end.
                for (std::uint32_t i = 0; i < kTraversalWidth && base + i < count; ++i)
                    occluded[base + i] = (bits >> i) & 1u;
            }
        }
        return;
    }
    // Packets of neighbouring pixels' shadow rays start on surfaces at any depth and may
    // head for different lights, and their traversals share little. Sorted by direction
    // octant and origin cell, rays from one neighbourhood towards one light travel
    // together (measured, with the threshold kBvhShadowSortMinSpheres:
    // docs/performance-log.md, "BVH: millions of spheres against Embree"). Each ray's
    // answer is exact whatever its packet, so the order changes no result. The sort is a
    // counting sort of words holding the key (18 bits) above the ray's index in the batch
    // (12 bits), two passes of 9 bits.
    static_assert(kShadowBatch <= 4096);
    alignas(64) std::uint32_t order[kShadowBatch], sorted[kShadowBatch];
    constexpr std::uint32_t N = kTraversalWidth;
    struct Gathered {
        alignas(64) float ox[N], oy[N], oz[N];
        alignas(64) float dx[N], dy[N], dz[N];
        alignas(64) float t_max[N], term[N];
        std::uint32_t parent[N];
    } g;
    // Only the arrays occluded_packet reads are gathered: the rest stay as set here.
    for (std::uint32_t l = 0; l < N; ++l) g.term[l] = 0.0f, g.parent[l] = 0;
    const ShadowStream packet{g.ox,    g.oy,   g.oz,   g.dx,   g.dy,    g.dz,
                              g.t_max, g.term, g.term, g.term, g.parent};
    for (std::uint32_t first = 0; first < count; first += kShadowBatch) {
        const std::uint32_t n = count - first < kShadowBatch ? count - first : kShadowBatch;
        // The keys a traversal register's lanes at a time (16 with AVX-512: shadow_keys
        // was 6 % of random:65536's shadow rays at 8), over the stream's whole packets of
        // kPacketWidth (its padding is readable), then the rest.
        using F = xsimd::batch<float, Arch>;
        using FW = xsimd::batch<float, RayArch<Arch>>;
        const std::uint32_t packets = (n + kPacketWidth - 1) / kPacketWidth * kPacketWidth;
        std::uint32_t at = 0;
        for (; at + FW::size <= packets; at += FW::size)
            shadow_keys<FW>(s, rays, first + at, order + at);
        for (; at < n; at += F::size) shadow_keys<F>(s, rays, first + at, order + at);
        for (std::uint32_t i = 0; i < n; ++i) order[i] = order[i] << 12 | i;
        sort_pass(order, sorted, n, 12);
        sort_pass(sorted, order, n, 21);
        for (std::uint32_t i = 0; i < n; ++i) order[i] &= 4095u;
        for (std::uint32_t k = 0; k < n; k += N) {
            const std::uint32_t live = live_bits(k, n);
            // The sorted rays into the packet, a traversal register at a time (gather:
            // AVX2 and AVX-512 in one instruction). Dead lanes repeat the first ray:
            // finite values, never read back.
            LaneIndex ix[N / FW::size];
            if (live == live_bits(0, N)) {
                // Whole registers (a store the gather's load can take as it is).
                using I = xsimd::batch<std::int32_t, RayArch<Arch>>;
                for (std::uint32_t at = 0; at < N; at += I::size)
                    (I::load_unaligned(reinterpret_cast<const std::int32_t*>(order) + k + at) +
                     I(static_cast<std::int32_t>(first)))
                        .store_aligned(ix[at / I::size].index);
            } else {
                for (std::uint32_t l = 0; l < N; ++l)
                    ix[l / FW::size].index[l % FW::size] = static_cast<std::int32_t>(
                        first + order[(live >> l & 1u) != 0 ? k + l : k]);
            }
            for (std::uint32_t r = 0; r < N / FW::size; ++r) {
                ix[r].uniform = false;
                const std::uint32_t at = r * FW::size;
                for (const auto& [from, to] :
                     {std::pair{rays.ox, g.ox}, std::pair{rays.oy, g.oy},
                      std::pair{rays.oz, g.oz}, std::pair{rays.dx, g.dx},
                      std::pair{rays.dy, g.dy}, std::pair{rays.dz, g.dz},
                      std::pair{rays.t_max, g.t_max}})
                    gather<FW>(from, ix[r]).store_aligned(to + at);
            }
            const std::uint32_t bits = occluded_packet<Arch>(s, packet, 0, N, live, p, st);
            for (std::uint32_t l = 0; l < N && k + l < n; ++l)
                occluded[first + order[k + l]] = (bits >> l) & 1u;
        }
    }
}

}  // namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE
