#pragma once
// Spheres as Embree user geometry, the way an expert Embree user renders them: one user
// primitive per sphere, whose intersect and occluded callbacks test one sphere against all
// N rays Embree hands over (N = 1, 4, 8 or 16) branch-free, lane-parallel, with the
// rendering model's robust sphere form (render/README.md). Embree then builds a BVH of
// objects (BVH8<object> on AVX2) and calls the callbacks from its packet traversal.
//
// The callbacks come in three builds, picked at run time like octray's kernels: AVX-512
// (16 lanes of xsimd at a time, embree_user_spheres_avx512.cpp), AVX2 + FMA (8 lanes,
// embree_user_spheres_avx2.cpp), both one body (embree_user_spheres_simd.h) compiled with
// their flags, and plain C++ one lane at a time for CPUs without AVX2. Only
// embree_baseline.cpp uses this header.

#include <embree3/rtcore.h>

#include <atomic>
#include <cstdint>

namespace octray::bench {

// What the callbacks read: the spheres in SoA, by primitive ID (the compiled scene's
// sphere order). Must outlive the Embree scene.
struct EmbreeSphereData {
    const float *cx, *cy, *cz, *r2;
    // Counts the builds that asked for the spheres' bounds (the bounds callback of primitive
    // 0, once per build): EmbreeScene::sphere_builds.
    std::atomic<std::uint64_t>* builds = nullptr;
};

struct EmbreeSphereCallbacks {
    RTCIntersectFunctionN intersect;
    RTCOccludedFunctionN occluded;
    const char* name;  // "avx512", "avx2" or "scalar"
};

// The best build this CPU runs.
const EmbreeSphereCallbacks& embree_sphere_callbacks();

// The builds: each hands packets narrower than its width to the next narrower one.
namespace scalar {
void intersect_spheres(const RTCIntersectFunctionNArguments* args);
void occlude_spheres(const RTCOccludedFunctionNArguments* args);
}  // namespace scalar
namespace avx2 {
void intersect_spheres(const RTCIntersectFunctionNArguments* args);
void occlude_spheres(const RTCOccludedFunctionNArguments* args);
}  // namespace avx2
namespace avx512 {
void intersect_spheres(const RTCIntersectFunctionNArguments* args);
void occlude_spheres(const RTCOccludedFunctionNArguments* args);
}  // namespace avx512

}  // namespace octray::bench
