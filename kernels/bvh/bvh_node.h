#pragma once
// The node layout of the sphere BVH (render/prepare/bvh_build.h), shared by the builder and the
// packet kernels. Plain data and constants only: the per-ISA kernel translation units include
// it (kernels/README.md, "the ODR rule").

#include <cstdint>

namespace octray {

// Children per node; also the most spheres a leaf holds.
inline constexpr std::uint32_t kBvhWidth = 8;

// A child reference: an inner node's index, or a leaf
//   kBvhLeafBit | first << kBvhLeafCountBits | (count - 1)
// whose spheres are [first, first + count) of the BVH's sphere arrays (count 1 ... 8).
// Used children come in order of decreasing box surface area; unused child slots come
// last and hold kBvhEmpty with an empty box (min = +inf, max = -inf), which no ray enters.
inline constexpr std::uint32_t kBvhLeafBit = 0x80000000u;
inline constexpr std::uint32_t kBvhLeafCountBits = 3;
inline constexpr std::uint32_t kBvhEmpty = 0xFFFFFFFFu;
// Leaves address spheres with 28 bits: more than the 2^24 objects a scene may have.

// An 8-wide node: its children's boxes in SoA, so that one 8-wide operation tests a ray
// against all eight (224 bytes, 7 cache-line halves).
struct alignas(32) BvhNode8 {
    float min_x[kBvhWidth], max_x[kBvhWidth];
    float min_y[kBvhWidth], max_y[kBvhWidth];
    float min_z[kBvhWidth], max_z[kBvhWidth];
    std::uint32_t child[kBvhWidth];
};
static_assert(sizeof(BvhNode8) == 224);

}  // namespace octray
