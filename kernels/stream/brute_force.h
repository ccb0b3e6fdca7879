#pragma once
// Closest hit and any hit against every sphere and plane, without a BVH.
//
// Included ONLY by the per-ISA translation units, under their OCTRAY_KERNEL_NAMESPACE
// (packet_math.h; kernels/README.md, "the ODR rule").

#ifndef OCTRAY_KERNEL_NAMESPACE
#error "define OCTRAY_KERNEL_NAMESPACE (one per ISA translation unit) before including"
#endif

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "kernels/bvh/bvh_packet.h"
#include "kernels/geometry/plane_test.h"
#include "kernels/geometry/sphere_test.h"
#include "kernels/packet_math.h"

namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE {

// Brute force takes kTraversalWidth rays at a time, in registers of RayArch (bvh_packet.h):
// 16 rays in one AVX-512 register in the avx512 translation unit, where a sphere's test
// then costs one 16-lane operation per step instead of two 8-lane ones (the packet is two
// of the stream's 8-ray packets, neighbouring pixels or neighbouring secondary rays), and
// the stream's 8-ray packets elsewhere. A stream's last packet may hold 8 rays or fewer:
// load_stream repeats its lower half above, and store_stream writes back the lower half
// alone, never past the stream's whole 8-ray packets (kernel_types.h).
template <class B, class T>
[[gnu::always_inline]] inline void store_stream(const B& x, T* out, std::uint32_t at,
                                                std::uint32_t left) {
    if constexpr (B::size == 16) {
        if (left <= at + kPacketWidth) {
            if constexpr (std::is_same_v<T, float>)
                _mm256_store_ps(out + at, _mm512_castps512_ps256(x));
            else
                _mm256_store_si256(reinterpret_cast<__m256i*>(out + at),
                                   _mm512_castsi512_si256(x));
            return;
        }
    }
    (void)left;
    x.store_aligned(out + at);
}

// Closest hit over all spheres and planes, brute force (reference:
// ReferenceTracer::intersect); closest_hit() in kernels/stream/hit_kernels.h calls it when the
// scene has no BVH.
// Spheres are broadcast one at a time against the packet. An object's candidate is its
// first root above t_min; the hit is the smallest candidate, ties to the lower file index
// (the reference walks objects in file order and keeps a hit only when strictly nearer).
template <class Arch>
void closest_hit_all(const SceneView& s, const RayStream& rays, std::uint32_t count,
                     float t_min, const HitStream& hits) {
    using F = xsimd::batch<float, RayArch<Arch>>;
    using M = xsimd::batch_bool<float, RayArch<Arch>>;
    constexpr std::uint32_t W = F::size;
    constexpr std::uint32_t K = kTraversalWidth / W;
    const F tmin(t_min);
    for (std::uint32_t base = 0; base < count; base += kTraversalWidth) {
        const std::uint32_t left = count - base;
        const auto load = [&](const float* v, std::uint32_t at) {
            return load_stream<F>(v + base, at, left);
        };
        V3<F> o[K], d[K];
        F a[K], best_t[K], best_id[K];
        for (std::uint32_t k = 0; k < K; ++k) {
            const std::uint32_t at = k * W;
            o[k] = {load(rays.ox, at), load(rays.oy, at), load(rays.oz, at)};
            d[k] = {load(rays.dx, at), load(rays.dy, at), load(rays.dz, at)};
            a[k] = dot(d[k], d[k]);
            best_t[k] = F(kInf);
            best_id[k] = F(-1.0f);
        }
        for (std::uint32_t i = 0; i < s.sphere_count; ++i) {
            const V3<F> c{F(s.sphere_cx[i]), F(s.sphere_cy[i]), F(s.sphere_cz[i])};
            const F r2(s.sphere_r2[i]);
            SphereQuadratic<F> quad[K];
            M any_root = F(0.0f) != F(0.0f);  // all false
            for (std::uint32_t k = 0; k < K; ++k) {
                quad[k] = sphere_quadratic(sub(o[k], c), d[k], a[k], r2);
                any_root = any_root || quad[k].disc >= F(0.0f);
            }
            if (xsimd::none(any_root)) continue;
            const F id(static_cast<float>(s.sphere_object[i]));
            for (std::uint32_t k = 0; k < K; ++k) {
                const auto [t_near, t_far] = sphere_roots(quad[k], a[k]);
                const M near_ok = t_near > tmin && t_near < best_t[k];
                const M far_ok = t_far > tmin && t_far < best_t[k];
                const M hit = near_ok || far_ok;
                best_t[k] =
                    xsimd::select(hit, xsimd::select(near_ok, t_near, t_far), best_t[k]);
                best_id[k] = xsimd::select(hit, id, best_id[k]);
            }
        }
        for (std::uint32_t k = 0; k < K; ++k)
            closest_planes(s, o[k], d[k], tmin, best_t[k], best_id[k]);
        for (std::uint32_t k = 0; k < K; ++k) {  // ids < 2^24: exact
            store_stream(best_t[k], hits.t + base, k * W, left);
            store_stream(xsimd::to_int(best_id[k]), hits.object + base, k * W, left);
        }
    }
}

// ---------------------------------------------------------------------------------------
// The cull of brute-force shadow rays. A shadow ray occludes only through a root t of
// (0, t_max), whose point O + t V lies on the segment [O, O + t_max V]; the packet's
// segments lie in one box (of each segment's ends). A sphere occludes only if it comes
// within about r of that point, so one whose box, widened, misses the segments' box is
// skipped. The widening covers the sphere test's rounding many times over: a computed
// root lies within a few ulps (near a tangent, within sqrt(disc)'s rounding, some 2^-11 r)
// of the exact point, and the near misses it may count as hits pass within 40u |O - C| of
// the surface (sphere_test.h, u = 2^-24), where the margin here is 2^-10 (r + |C| + the
// box's largest coordinate). Unbounded segments (directional lights) cull nothing.
struct SegmentBox {
    bool bounded = false;
    float lo[3], hi[3];
    float scale;  // the largest |coordinate| of the box
};

template <class F, class M, std::uint32_t K>
SegmentBox segment_box(const V3<F> (&o)[K], const V3<F> (&d)[K], const F (&t_max)[K],
                       const M (&done)[K]) {
    SegmentBox box;
    float scale = 0.0f;
    for (int axis = 0; axis < 3; ++axis) {
        F lo(kInf), hi(-kInf);
        for (std::uint32_t k = 0; k < K; ++k) {
            const F from = axis == 0 ? o[k].x : axis == 1 ? o[k].y : o[k].z;
            const F step = axis == 0 ? d[k].x : axis == 1 ? d[k].y : d[k].z;
            const F to = xsimd::fma(step, t_max[k], from);
            lo = xsimd::select(done[k], lo, xsimd::min(lo, xsimd::min(from, to)));
            hi = xsimd::select(done[k], hi, xsimd::max(hi, xsimd::max(from, to)));
        }
        alignas(64) float lanes[F::size];
        lo.store_aligned(lanes);
        box.lo[axis] = masked_min<F>(lanes, (1u << F::size) - 1u);
        hi.store_aligned(lanes);
        box.hi[axis] = masked_max<F>(lanes, (1u << F::size) - 1u);
        // An unbounded segment: no cull. (No lane left makes the scale infinite: none
        // either. A lane with NaN drops out of the box, and a NaN ray hits nothing.)
        if (!(box.hi[axis] - box.lo[axis] < kInf)) return box;
        scale = std::max(scale, std::max(std::fabs(box.lo[axis]), std::fabs(box.hi[axis])));
    }
    box.bounded = scale < kInf;
    box.scale = scale;
    return box;
}

// Spheres [block, block + FS::size) that may occlude a segment of `box`, as bits (all of
// them when the box is unbounded). The arrays' padding (NaN) fails every comparison.
template <class FS>
std::uint32_t spheres_near(const SceneView& s, std::uint32_t block, const SegmentBox& box) {
    if (!box.bounded) return (1u << FS::size) - 1u;
    const FS cx = FS::load_aligned(s.sphere_cx + block),
             cy = FS::load_aligned(s.sphere_cy + block),
             cz = FS::load_aligned(s.sphere_cz + block);
    const FS r = xsimd::sqrt(FS::load_aligned(s.sphere_r2 + block));
    const FS pad =
        xsimd::fma(FS(0x1.0p-10f),
                   r + xsimd::abs(cx) + xsimd::abs(cy) + xsimd::abs(cz) + FS(box.scale), r);
    const auto near = [&](const FS& c, int axis) {
        return c + pad >= FS(box.lo[axis]) && c - pad <= FS(box.hi[axis]);
    };
    return mask_bits<FS>(near(cx, 0) && near(cy, 1) && near(cz, 2));
}

// ---------------------------------------------------------------------------------------
// Any hit for shadow rays on (0, t_max), brute force (reference: ReferenceTracer::occluded);
// any_hit() in kernels/stream/hit_kernels.h calls it when the scene has no BVH. A packet
// stops testing objects once every live lane is occluded. occluded[i] is 1 or 0.
template <class Arch>
void any_hit_all(const SceneView& s, const ShadowStream& rays, std::uint32_t count,
                 std::uint32_t* occluded) {
    using F = xsimd::batch<float, RayArch<Arch>>;
    using M = xsimd::batch_bool<float, RayArch<Arch>>;
    using FS = xsimd::batch<float, Arch>;  // spheres, a block at a time, for the cull
    constexpr std::uint32_t W = F::size;
    constexpr std::uint32_t K = kTraversalWidth / W;
    constexpr std::uint32_t WS = FS::size;
    static_assert(kSceneArrayPadding % WS == 0);
    const F zero(0.0f);
    for (std::uint32_t base = 0; base < count; base += kTraversalWidth) {
        const std::uint32_t left = count - base;
        const auto load = [&](const float* v, std::uint32_t at) {
            return load_stream<F>(v + base, at, left);
        };
        V3<F> o[K], d[K];
        F a[K], t_max[K];
        M done[K];  // occluded, or a dead lane
        for (std::uint32_t k = 0; k < K; ++k) {
            const std::uint32_t at = k * W;
            o[k] = {load(rays.ox, at), load(rays.oy, at), load(rays.oz, at)};
            d[k] = {load(rays.dx, at), load(rays.dy, at), load(rays.dz, at)};
            t_max[k] = load(rays.t_max, at);
            a[k] = dot(d[k], d[k]);
            done[k] = at < left ? !live_lanes<F>(at, left) : (zero == zero);
        }
        const auto all_done = [&] {
            for (std::uint32_t k = 0; k < K; ++k)
                if (!xsimd::all(done[k])) return false;
            return true;
        };
        const SegmentBox box = s.sphere_count >= s.shadow_cull_min_spheres
                                   ? segment_box(o, d, t_max, done)
                                   : SegmentBox{};
        for (std::uint32_t block = 0; block < s.sphere_count && !all_done(); block += WS) {
            std::uint32_t keep = spheres_near<FS>(s, block, box);
            if (s.sphere_count - block < WS) keep &= (1u << (s.sphere_count - block)) - 1u;
            for (; keep != 0 && !all_done(); keep &= keep - 1) {
                const std::uint32_t i = block + static_cast<std::uint32_t>(__builtin_ctz(keep));
                const V3<F> c{F(s.sphere_cx[i]), F(s.sphere_cy[i]), F(s.sphere_cz[i])};
                const F r2(s.sphere_r2[i]);
                SphereQuadratic<F> quad[K];
                M any_root = zero != zero;
                for (std::uint32_t k = 0; k < K; ++k) {
                    quad[k] = sphere_quadratic(sub(o[k], c), d[k], a[k], r2);
                    any_root = any_root || (quad[k].disc >= zero && !done[k]);
                }
                if (xsimd::none(any_root)) continue;
                for (std::uint32_t k = 0; k < K; ++k) {
                    const auto [t_near, t_far] = sphere_roots(quad[k], a[k]);
                    done[k] = done[k] || (t_near > zero && t_near < t_max[k]) ||
                              (t_far > zero && t_far < t_max[k]);
                }
            }
        }
        if (!all_done())
            for (std::uint32_t k = 0; k < K; ++k)
                done[k] = done[k] || any_plane(s, o[k], d[k], t_max[k]);
        // Dead lanes come out as 1; nobody reads them.
        for (std::uint32_t k = 0; k < K; ++k)
            store_stream(xsimd::to_int(xsimd::select(done[k], F(1.0f), zero)),
                         reinterpret_cast<std::int32_t*>(occluded + base), k * W, left);
    }
}

}  // namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE
