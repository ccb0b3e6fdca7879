#pragma once
// The ray-sphere test shared by the brute-force kernels (brute_force.h) and the BVH leaves
// (bvh_single_ray.h, bvh_packet_traversal.h): one arithmetic, so both find the same t.
//
// Included ONLY by the per-ISA translation units, under their OCTRAY_KERNEL_NAMESPACE
// (packet_math.h; kernels/README.md, "the ODR rule").

#ifndef OCTRAY_KERNEL_NAMESPACE
#error "define OCTRAY_KERNEL_NAMESPACE (one per ISA translation unit) before including"
#endif

#include "kernels/packet_math.h"

namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE {

// Ray-sphere in the form that keeps its digits for small, distant spheres (reference:
// intersect_sphere, which derives it; Ray Tracing Gems ch. 7). Two steps, so that a loop
// can skip the roots when no lane has any: sphere_quadratic gives b = O'.V,
// c' = O'.O' - r^2 and disc = a (r^2 - l.l) with l = O' - (b/a) V; sphere_roots the two
// roots, sorted, from q = -b - sign(b) sqrt(disc): q/a and c'/q (q/a alone when q = 0).
// A negative or NaN discriminant gives NaN roots: every comparison with them fails.
// Forced inline: GCC kept them as calls in the leaf loops (4 % of a frame, perf).
template <class F>
struct SphereQuadratic {
    F b, c, disc;
};

template <class F>
[[gnu::always_inline]] inline SphereQuadratic<F> sphere_quadratic(const V3<F>& oc,
                                                                  const V3<F>& d, const F& a,
                                                                  const F& r2) {
    const F b = dot(oc, d);
    const V3<F> l = sub(oc, mul(d, b / a));
    return {b, dot(oc, oc) - r2, a * (r2 - dot(l, l))};
}

template <class F>
struct SphereRoots {
    F t_near, t_far;
};

template <class F>
[[gnu::always_inline]] inline SphereRoots<F> sphere_roots(const SphereQuadratic<F>& s,
                                                          const F& a) {
    const F zero(0.0f);
    const F root = xsimd::sqrt(s.disc);
    const F q = xsimd::select(s.b >= zero, -s.b - root, -s.b + root);
    const F t_q = q / a;
    const F t_c = xsimd::select(q != zero, s.c / q, t_q);
    const auto swap = t_c < t_q;
    return {xsimd::select(swap, t_c, t_q), xsimd::select(swap, t_q, t_c)};
}

}  // namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE
