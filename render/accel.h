#pragma once
// Which acceleration structure the SIMD render path uses for spheres (`--accel`), and where
// `auto` is resolved: the packet renderer (render/packet_renderer.cpp), the memory estimate
// (render/batch/memory_estimate.cpp), `octray bench` and `octray info` ask accel_uses_bvh().
// Plain declarations: the scalar reference sees Accel through render/render_options.h but never
// calls these (it links no kernels and no BVH).

#include <cstdint>
#include <optional>
#include <string_view>

namespace octray {

// automatic: the BVH (render/prepare/bvh_build.h) from kBvhAutoMinSpheres spheres on, brute
// force below; bvh: always the BVH; none: brute force (every ray against every sphere). The
// image is the same whichever is used (kernels/README.md, section "The BVH").
enum class Accel { automatic, bvh, none };

// The sphere count from which Accel::automatic builds a BVH: the crossover measured by
// `octray bench` (docs/performance-log.md, the paragraph "The `auto` crossover").
inline constexpr std::uint32_t kBvhAutoMinSpheres = 16;

// "auto", "bvh", "none".
const char* accel_name(Accel accel);
std::optional<Accel> parse_accel(std::string_view name);

// Whether `accel` means a BVH for a scene of `sphere_count` spheres (never for none).
bool accel_uses_bvh(Accel accel, std::uint32_t sphere_count);

}  // namespace octray
