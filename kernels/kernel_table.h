#pragma once
// One table of kernel entry points per ISA, each defined in its own translation unit
// (kernels_avx512.cpp, kernels_avx2.cpp, kernels_sse41.cpp, kernels_sse2.cpp) and picked at run
// time by kernels/dispatch.h. Plain data only (see kernels/README.md, "the ODR rule").

#include <cstdint>

#include "kernels/isa.h"
#include "kernels/kernel_types.h"

namespace octray::kernels {

struct KernelTable {
    Isa isa;
    const char* name;
    // 8 (AVX2, AVX-512) or 4 (SSE): registers per packet = 8 / this.
    std::uint32_t lanes_per_register;
    // Rays per BVH traversal packet: 8, or 16 with AVX-512 (kernels/bvh/bvh_packet.h).
    std::uint32_t traversal_width;

    // Primary rays for `count` camera samples; returns how many rays it wrote (the
    // fisheye drops samples outside its image circle). Weights are 1.
    std::uint32_t (*camera_rays)(const SceneView& scene, const CameraSamples& samples,
                                 std::uint32_t count, const RayStream& out);

    // Closest hit on (t_min, inf) for `count` rays: primary rays with t_min = ε_s,
    // secondary rays with t_min = 0 (SceneView::bvh_secondary_min_lanes).
    void (*closest_hit)(const SceneView& scene, const RayStream& rays, std::uint32_t count,
                        float t_min, const HitStream& hits);

    // occluded[i] = 1 when shadow ray i hits anything on (0, t_max), else 0.
    void (*any_hit)(const SceneView& scene, const ShadowStream& rays, std::uint32_t count,
                    std::uint32_t* occluded);

    // Shades a generation: per-ray colors, shadow rays, the next generation.
    ShadeCounts (*shade)(const SceneView& scene, const ShadeInput& in, const ShadeOutput& out);
};

// Defined in the per-ISA translation units.
extern const KernelTable kKernelsSse2;
extern const KernelTable kKernelsSse41;
extern const KernelTable kKernelsAvx2;
extern const KernelTable kKernelsAvx512;

}  // namespace octray::kernels
