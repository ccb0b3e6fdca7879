#pragma once
// The SIMD builds of the user-geometry sphere callbacks (bench/embree_user_spheres.h), one
// body for every width: each build's translation unit defines
//   OCTRAY_EMBREE_CALLBACK_NAMESPACE  its namespace (avx2, avx512),
//   OCTRAY_EMBREE_CALLBACK_ARCH       the xsimd architecture (W lanes of it at a time),
//   OCTRAY_EMBREE_CALLBACK_NARROWER   the build that takes packets narrower than W,
// is compiled with that architecture's flags (bench/CMakeLists.txt), and is reached only
// through embree_sphere_callbacks() on a CPU that has them. One sphere against W rays at a
// time, branch-free: every lane computes the robust form (render/README.md), and the lanes
// that hit are merged into the ray/hit arrays with selects. Everything is in the build's
// namespace and calls no inline code shared with baseline translation units but xsimd's
// (templated on the architecture), so nothing built with these flags can be linked into
// code that runs on a CPU without them.

#if !defined(OCTRAY_EMBREE_CALLBACK_NAMESPACE) || !defined(OCTRAY_EMBREE_CALLBACK_ARCH) || \
    !defined(OCTRAY_EMBREE_CALLBACK_NARROWER)
#error "define the build's namespace, architecture and narrower build before including"
#endif

#include <cstdint>
#include <limits>
#include <xsimd/xsimd.hpp>

#include "bench/embree_user_spheres.h"

namespace octray::bench::OCTRAY_EMBREE_CALLBACK_NAMESPACE {
namespace {

using F = xsimd::batch<float, OCTRAY_EMBREE_CALLBACK_ARCH>;
using I = xsimd::batch<std::int32_t, OCTRAY_EMBREE_CALLBACK_ARCH>;
constexpr unsigned W = F::size;

struct Lanes {
    F t;                     // the reported root (where `hit`)
    F::batch_bool_type hit;  // valid lanes with a root in (tnear, tfar)
};

// Lanes [i, i + W) of the N-ray packet against sphere `prim`.
Lanes sphere_lanes(const EmbreeSphereData& s, unsigned prim, const int* valid, float* ray,
                   unsigned n, unsigned i) {
    const F cx(s.cx[prim]), cy(s.cy[prim]), cz(s.cz[prim]), r2(s.r2[prim]);
    const F ox = F::load_unaligned(ray + 0 * n + i) - cx;
    const F oy = F::load_unaligned(ray + 1 * n + i) - cy;
    const F oz = F::load_unaligned(ray + 2 * n + i) - cz;
    const F tnear = F::load_unaligned(ray + 3 * n + i);
    const F dx = F::load_unaligned(ray + 4 * n + i);
    const F dy = F::load_unaligned(ray + 5 * n + i);
    const F dz = F::load_unaligned(ray + 6 * n + i);
    const F tfar = F::load_unaligned(ray + 8 * n + i);
    // octray's operations in octray's order (kernels/geometry/sphere_test.h, sphere_quadratic
    // and sphere_roots), without FMA: the same t bit for bit. With FMA the roots moved by an
    // ulp or two, enough to flip shadow rays at sphereflake's touching spheres and fail the
    // Embree frame's validation (docs/performance-log.md, "Figures from source comments").
    const F a = dx * dx + dy * dy + dz * dz;
    const F b = ox * dx + oy * dy + oz * dz;
    const F bt = b / a;
    const F lx = ox - dx * bt, ly = oy - dy * bt, lz = oz - dz * bt;
    const F disc = a * (r2 - (lx * lx + ly * ly + lz * lz));
    const F root = xsimd::sqrt(disc);  // NaN where disc < 0: every test below fails
    const F q = xsimd::select(b >= F(0.0f), -b - root, -b + root);
    const F t_q = q / a;
    const F c = (ox * ox + oy * oy + oz * oz) - r2;
    const F t_c = xsimd::select(q != F(0.0f), c / q, t_q);
    const auto swap = t_c < t_q;
    const F t_near = xsimd::select(swap, t_c, t_q), t_far = xsimd::select(swap, t_q, t_c);
    const auto near_ok = t_near > tnear && t_near < tfar;
    const auto far_ok = t_far > tnear && t_far < tfar;
    // valid[] is -1 for an active lane, 0 otherwise.
    const auto active = xsimd::bool_cast(I::load_unaligned(valid + i) != I(0));
    return {xsimd::select(near_ok, t_near, t_far), active && (near_ok || far_ok)};
}

// Stores `value` into lanes [i, i + W) of a column where `hit`, keeping the rest.
template <class B, class M>
void merge(void* column, unsigned i, const M& hit, const B& value) {
    auto* p = static_cast<typename B::value_type*>(column) + i;
    xsimd::select(hit, value, B::load_unaligned(p)).store_unaligned(p);
}

}  // namespace

void intersect_spheres(const RTCIntersectFunctionNArguments* args) {
    const unsigned n = args->N;
    if (n < W) return OCTRAY_EMBREE_CALLBACK_NARROWER::intersect_spheres(args);
    const auto& s = *static_cast<const EmbreeSphereData*>(args->geometryUserPtr);
    const unsigned prim = args->primID;
    auto* ray = reinterpret_cast<float*>(RTCRayHitN_RayN(args->rayhit, n));
    auto* hit = reinterpret_cast<float*>(RTCRayHitN_HitN(args->rayhit, n));
    for (unsigned i = 0; i < n; i += W) {
        const Lanes l = sphere_lanes(s, prim, args->valid, ray, n, i);
        if (xsimd::none(l.hit)) continue;
        const auto ihit = xsimd::bool_cast(l.hit);
        // tfar and the IDs: all the bench reads of a hit (EmbreeScene::intersect), so all
        // an expert's callback writes; the geometric normal and u, v are left alone.
        merge(ray + 8 * n, i, l.hit, l.t);
        merge(hit + 5 * n, i, ihit, I(static_cast<std::int32_t>(prim)));
        merge(hit + 6 * n, i, ihit, I(static_cast<std::int32_t>(args->geomID)));
        merge(hit + 7 * n, i, ihit, I(static_cast<std::int32_t>(args->context->instID[0])));
    }
}

void occlude_spheres(const RTCOccludedFunctionNArguments* args) {
    const unsigned n = args->N;
    if (n < W) return OCTRAY_EMBREE_CALLBACK_NARROWER::occlude_spheres(args);
    const auto& s = *static_cast<const EmbreeSphereData*>(args->geometryUserPtr);
    auto* ray = reinterpret_cast<float*>(args->ray);
    for (unsigned i = 0; i < n; i += W) {
        const Lanes l = sphere_lanes(s, args->primID, args->valid, ray, n, i);
        if (xsimd::any(l.hit))
            merge(ray + 8 * n, i, l.hit, F(-std::numeric_limits<float>::infinity()));
    }
}

}  // namespace octray::bench::OCTRAY_EMBREE_CALLBACK_NAMESPACE
