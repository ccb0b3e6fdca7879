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
// Forced inline: GCC kept them as calls in the leaf loops (docs/performance-log.md,
// "Figures from source comments").
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

// A cheaper test first, in the BVH's leaves. Most spheres a packet meets in a leaf it
// misses with every lane, and sphere_quadratic pays a division (b/a) per sphere: on
// AVX-512, a divide of 16 floats takes about as long as the rest of the test. So
// sphere_may_hit computes l' = O' - (b * inv_a) V with inv_a = 1/a rounded once per ray,
// and sphere_quadratic runs only where some lane may have disc >= 0; the roots come from
// sphere_quadratic alone, so the hits stay bit for bit what they were. Brute force (scenes
// of a few, mostly large spheres, where many packets hit) does without it: there it cost
// a third of whitted's primary rays (docs/performance-log.md).
//
// Why no lane with disc >= 0 is rejected (u = 2^-24, O' = oc): disc = a (r2 - l.l) >= 0,
// rounded, means fl(l.l) <= r2, so |l|^2 <= (1 + 4u) r2 for the rounded l. Both l and l'
// lie within 20u|O'| of the exact perpendicular (b's rounding, then the quotient's or the
// product's, then V q and the difference: about 10u|O'| per component), so
// |l'| <= |l| + 40u|O'| and, with (x + y)^2 <= (1 + 2^-8) x^2 + 257 y^2,
//   |l'|^2 <= (1 + 2^-8)(1 + 4u) r2 + 257 (40u)^2 |O'|^2 < (1 + 2^-8 + 8u) r2 + 2^-29 |O'|^2.
// The bound below is twice that, and more, on each term (the rounding of the bound and of
// the dot products, a few u, fits many times in that room); 1e-30 covers underflow in
// the dot products of tiny spheres. A NaN anywhere keeps its lane (the comparison fails).
// Near misses (a ray passing within about r (1 + 2^-8) + 2^-13.5 |O'| of the center)
// still pay for sphere_quadratic.
template <class F>
[[gnu::always_inline]] inline auto sphere_may_hit(const V3<F>& oc, const V3<F>& d,
                                                  const F& inv_a, const F& r2) {
    const F b = dot(oc, d);
    const V3<F> l = sub(oc, mul(d, b * inv_a));
    const F bound = F(1.0f + 0x1.0p-7f) * r2 + F(0x1.0p-27f) * dot(oc, oc) + F(1e-30f);
    return !(dot(l, l) > bound);
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
