#pragma once
// The kernels' view of a prepared scene and the traversal policy it carries: the plain
// pointers of kernels::SceneView into a compiled scene and its sphere BVH, and the
// thresholds that pick brute force, packets, single rays or sorted shadow rays by the
// scene's size and density (kernels/README.md, "The BVH"). Baseline code, no ISA flags.

#include <cstdint>

#include "kernels/kernel_types.h"
#include "render/prepare/bvh_build.h"
#include "scene/compile.h"

namespace octray {

// The plain-pointer view the kernels read; valid while `scene` lives and is not changed.
kernels::SceneView make_scene_view(const CompiledScene& scene);

// Packets with fewer live lanes than this continue ray by ray in the BVH (measured:
// docs/performance-log.md, "The packet → single-ray switch").
inline constexpr std::uint32_t kBvhPacketMinLanes = 2;

// From this many spheres on, the BVH's any-hit regroups shadow rays into packets of
// neighbouring origins and one direction octant: below, the sort costs more than it saves
// and shadow beams win (measured: docs/performance-log.md, "BVH: millions of spheres
// against Embree"; since the sort's four quarters, session 32, sorted against beams:
// random:4096 level, random:8192 20-30 % and random:16384 40-60 % faster, sphereflake:4
// level, random:2048 and random:1024 15-40 % slower).
inline constexpr std::uint32_t kBvhShadowSortMinSpheres = 8192;

// In BVHs of at most this many spheres, shadow rays, and closest-hit rays that form no beam
// (kernels/bvh/bvh_beam.h: primary rays from one origin do), test every sphere as without a
// BVH: 16 spheres against a 16-ray register cost less than the packet traversal's and the
// shadow beams' bookkeeping, while primary rays' beams beat brute force from about 16
// spheres on (measured: docs/performance-log.md, "Small scenes: brute force 16 rays
// wide, beams for their primary rays").
inline constexpr std::uint32_t kBvhBruteForceMaxSpheres = 16;

// From this many spheres on, brute-force shadow rays skip the spheres whose widened box
// misses the box of their packet's segments. Below, every sphere is tested: the box costs a
// packet about as much as three or four sphere tests. Measured (docs/performance-log.md,
// session 32): random:16's shadow rays 15-25 % faster with the cull, random:12 level,
// random:8 10 % and random:4 45 % slower.
inline constexpr std::uint32_t kShadowCullMinSpheres = 12;

// From this many spheres on, secondary rays go ray by ray through the BVH from the root:
// their packets hold rays from different tiny spheres heading anywhere, and single rays
// are faster (measured: docs/performance-log.md, "Secondary rays ray by ray").
inline constexpr std::uint32_t kBvhSecondaryRayByRayMinSpheres = 131072;

// ... and from this many on where the spheres are dense: where a line through the BVH's
// root box crosses kBvhSecondaryRayByRayMinCrossings spheres or more on average
// (sphere_crossings), secondary rays end a few spheres from where they start and their
// packets part at once. The sphere count alone does not tell the scenes where single rays
// win from those where packets do; the crossings do (measured: docs/performance-log.md,
// "Single rays two at a time", the paragraph "Which secondary rays go ray by ray").
inline constexpr std::uint32_t kBvhSecondaryRayByRayDenseMinSpheres = 32768;
inline constexpr double kBvhSecondaryRayByRayMinCrossings = 7.0;

// The mean number of spheres that a random line through the box [lo, hi] crosses, for
// spheres of squared radii r2[0 .. count): by Cauchy's formula a convex body inside a
// convex box meets a uniformly random line through the box with the probability of
// their surface areas' ratio, so the mean is sum(4 pi r^2) / area(box).
double sphere_crossings(const float* r2, std::uint32_t count, const float lo[3],
                        const float hi[3]);

// secondary_min_lanes: pick by the scene's size and density (kBvhSecondaryRayByRayMinSpheres,
// kBvhSecondaryRayByRayDenseMinSpheres).
inline constexpr std::uint32_t kBvhSecondaryLanesAuto = ~0u;

// The same with the spheres' BVH built from `scene` (render/prepare/bvh_build.h); both must
// outlive the view. An empty BVH (no spheres) leaves the view brute force. `packet_min_lanes`
// for primary and shadow rays, `secondary_min_lanes` for secondary rays (SceneView).
kernels::SceneView make_scene_view(const CompiledScene& scene, const SphereBvh& bvh,
                                   std::uint32_t packet_min_lanes = kBvhPacketMinLanes,
                                   std::uint32_t secondary_min_lanes = kBvhSecondaryLanesAuto);

}  // namespace octray
