#pragma once
// Which acceleration structure the SIMD render path uses for spheres: `--accel`.

#include <cstdint>
#include <optional>
#include <string_view>

namespace octray {

// automatic: the BVH from kBvhAutoMinSpheres spheres on, brute force below; bvh: always
// the BVH; none: brute force (every ray against every sphere). The image is the same
// whichever is used (kernels/README.md, "The BVH").
enum class Accel { automatic, bvh, none };

// The sphere count from which Accel::automatic builds a BVH: the crossover measured by
// `octray bench` (docs/performance-log.md, "The `auto` crossover").
inline constexpr std::uint32_t kBvhAutoMinSpheres = 32;

// "auto", "bvh", "none".
const char* accel_name(Accel accel);
std::optional<Accel> parse_accel(std::string_view name);

// Whether `accel` means a BVH for a scene of `sphere_count` spheres (never for none).
bool accel_uses_bvh(Accel accel, std::uint32_t sphere_count);

}  // namespace octray
