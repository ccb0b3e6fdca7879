#pragma once
// Ray-plane tests: closest hit and occlusion against every plane of the scene.
//
// Included ONLY by the per-ISA translation units, under their OCTRAY_KERNEL_NAMESPACE
// (packet_math.h; kernels/README.md, "the ODR rule").

#ifndef OCTRAY_KERNEL_NAMESPACE
#error "define OCTRAY_KERNEL_NAMESPACE (one per ISA translation unit) before including"
#endif

#include <cstdint>

#include "kernels/packet_math.h"

namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE {

// |V.N| below this is a plane miss (reference: kPlaneParallelEpsilon).
constexpr float kPlaneParallelEpsilon = 1e-12f;

// Planes, for one register of rays: closest hit with ties to the lower file index, and
// occlusion on (0, t_max). Shared by the brute-force kernels and the BVH traversal
// (kernels/stream/hit_kernels.h): planes stay outside the BVH.
template <class F>
void closest_planes(const SceneView& s, const V3<F>& o, const V3<F>& d, const F& tmin,
                    F& best_t, F& best_id) {
    for (std::uint32_t i = 0; i < s.plane_count; ++i) {
        // t = (d - O.N) / (V.N), d = P0.N; |V.N| < 1e-12 misses.
        const V3<F> n{F(s.plane_nx[i]), F(s.plane_ny[i]), F(s.plane_nz[i])};
        const F pd(s.plane_d[i]);
        const F id(static_cast<float>(s.plane_object[i]));
        const F denom = dot(d, n);
        const F t = (pd - dot(o, n)) / denom;
        const auto nearer = t < best_t || (t == best_t && id < best_id);
        const auto hit = xsimd::abs(denom) >= F(kPlaneParallelEpsilon) && t > tmin && nearer;
        best_t = xsimd::select(hit, t, best_t);
        best_id = xsimd::select(hit, id, best_id);
    }
}

template <class F>
auto any_plane(const SceneView& s, const V3<F>& o, const V3<F>& d, const F& t_max) {
    auto occluded = F(0.0f) != F(0.0f);  // all false
    for (std::uint32_t i = 0; i < s.plane_count; ++i) {
        const V3<F> n{F(s.plane_nx[i]), F(s.plane_ny[i]), F(s.plane_nz[i])};
        const F pd(s.plane_d[i]);
        const F denom = dot(d, n);
        const F t = (pd - dot(o, n)) / denom;
        occluded = occluded ||
                   (xsimd::abs(denom) >= F(kPlaneParallelEpsilon) && t > F(0.0f) && t < t_max);
    }
    return occluded;
}

}  // namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE
