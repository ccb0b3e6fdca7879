// The scalar build of the user-geometry sphere callbacks (bench/embree_user_spheres.h),
// and the run-time choice between it and the AVX2 and AVX-512 builds.

#include "bench/embree_user_spheres.h"

#include <cmath>
#include <limits>

#include "kernels/dispatch.h"

namespace octray::bench {
namespace scalar {
namespace {

// The robust form (render/README.md) for one lane: the root Embree reports, the nearer one
// in (tnear, tfar) (a ray starting inside hits the far side), or NaN for none.
float sphere_root(const EmbreeSphereData& s, unsigned prim, RTCRayN* ray, unsigned n,
                  unsigned i) {
    const float ox = RTCRayN_org_x(ray, n, i) - s.cx[prim];
    const float oy = RTCRayN_org_y(ray, n, i) - s.cy[prim];
    const float oz = RTCRayN_org_z(ray, n, i) - s.cz[prim];
    const float dx = RTCRayN_dir_x(ray, n, i), dy = RTCRayN_dir_y(ray, n, i),
                dz = RTCRayN_dir_z(ray, n, i);
    const float a = dx * dx + dy * dy + dz * dz;
    const float b = ox * dx + oy * dy + oz * dz;
    const float bt = b / a;
    const float lx = ox - bt * dx, ly = oy - bt * dy, lz = oz - bt * dz;
    const float r2 = s.r2[prim];
    const float disc = a * (r2 - (lx * lx + ly * ly + lz * lz));
    if (!(disc >= 0.0f)) return std::numeric_limits<float>::quiet_NaN();
    const float root = std::sqrt(disc);
    const float q = b >= 0.0f ? -b - root : -b + root;
    const float t_q = q / a;
    const float t_c = q != 0.0f ? (ox * ox + oy * oy + oz * oz - r2) / q : t_q;
    const float t_near = t_c < t_q ? t_c : t_q, t_far = t_c < t_q ? t_q : t_c;
    const float tnear = RTCRayN_tnear(ray, n, i), tfar = RTCRayN_tfar(ray, n, i);
    if (t_near > tnear && t_near < tfar) return t_near;
    if (t_far > tnear && t_far < tfar) return t_far;
    return std::numeric_limits<float>::quiet_NaN();
}

}  // namespace

void intersect_spheres(const RTCIntersectFunctionNArguments* args) {
    const auto& s = *static_cast<const EmbreeSphereData*>(args->geometryUserPtr);
    const unsigned n = args->N, prim = args->primID;
    RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, n);
    RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, n);
    for (unsigned i = 0; i < n; ++i) {
        if (args->valid[i] != -1) continue;
        const float t = sphere_root(s, prim, ray, n, i);
        if (!(t == t)) continue;
        RTCRayN_tfar(ray, n, i) = t;  // and the IDs: all the bench reads (no Ng, u, v)
        RTCHitN_primID(hit, n, i) = prim;
        RTCHitN_geomID(hit, n, i) = args->geomID;
        RTCHitN_instID(hit, n, i, 0) = args->context->instID[0];
    }
}

void occlude_spheres(const RTCOccludedFunctionNArguments* args) {
    const auto& s = *static_cast<const EmbreeSphereData*>(args->geometryUserPtr);
    const unsigned n = args->N, prim = args->primID;
    for (unsigned i = 0; i < n; ++i) {
        if (args->valid[i] != -1) continue;
        const float t = sphere_root(s, prim, args->ray, n, i);
        if (t == t) RTCRayN_tfar(args->ray, n, i) = -std::numeric_limits<float>::infinity();
    }
}

}  // namespace scalar

const EmbreeSphereCallbacks& embree_sphere_callbacks() {
    static const EmbreeSphereCallbacks scalar_build{scalar::intersect_spheres,
                                                    scalar::occlude_spheres, "scalar"};
    static const EmbreeSphereCallbacks avx2_build{avx2::intersect_spheres,
                                                  avx2::occlude_spheres, "avx2"};
    static const EmbreeSphereCallbacks avx512_build{avx512::intersect_spheres,
                                                    avx512::occlude_spheres, "avx512"};
    // The builds' flags are the kernels' (F, VL, BW and DQ), so is the check.
    return isa_supported(Isa::avx512) ? avx512_build
           : isa_supported(Isa::avx2) ? avx2_build
                                      : scalar_build;
}

}  // namespace octray::bench
