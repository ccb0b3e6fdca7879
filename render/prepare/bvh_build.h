#pragma once
// An 8-wide bounding volume hierarchy over a compiled scene's spheres (planes stay outside
// it: they are unbounded and tested directly). Built by binned SAH on a binary tree, in
// parallel with TBB over subtrees, then collapsed into 8-wide nodes whose children's boxes
// are stored in SoA (kernels/bvh/bvh_node.h). Leaves hold up to 8 spheres, copied into SoA
// arrays in leaf order (cx, cy, cz, r2, object: the layout the brute-force kernels read).
//
// Deterministic: the tree (every byte of it) does not depend on the number of threads.
// Boxes are conservative: every sphere's box is rounded outwards, so that the box holds
// the sphere exactly as the kernels' float arithmetic sees it (kernels/README.md,
// "The BVH").

#include <cstddef>
#include <cstdint>
#include <span>

#include "core/aligned.h"
#include "kernels/bvh/bvh_node.h"
#include "scene/compile.h"

namespace octray {

struct SphereBvh {
    // Node 0 is the root; children come after their parent. Empty when the scene has no
    // spheres. (Large arrays on huge pages, and sized without being written, so that the
    // build's threads fill them in parallel: core/aligned.h.)
    UninitializedVector<BvhNode8, Pages::huge> nodes;
    // Spheres in leaf order, padded with kBvhWidth entries that never hit (NaN), so that
    // a kernel may load 8 entries from any leaf's first sphere.
    std::uint32_t sphere_count = 0;
    UninitializedVector<float, Pages::huge> cx, cy, cz, r2;
    UninitializedVector<std::uint32_t, Pages::huge> object;  // the file index, as in
                                                             // CompiledSpheres

    // The root's box (of the spheres, not their centers): the kernels derive their
    // rounding margin from it.
    float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};

    std::uint32_t leaf_count = 0;
    std::uint32_t depth = 0;  // levels of 8-wide nodes (root alone: 1)
    double build_seconds = 0.0;

    // Bytes the BVH holds (nodes and its copy of the spheres), and per sphere.
    std::size_t memory_bytes() const;
    double bytes_per_sphere() const;
};

// Builds the BVH of `spheres` in the calling thread's TBB arena (a tbb::task_arena of N
// threads limits it to N). Throws std::invalid_argument beyond 2^24 spheres (the most a
// compiled scene holds).
SphereBvh build_sphere_bvh(const CompiledSpheres& spheres);

// Refits `bvh` (built over spheres of the same count) to spheres that moved or changed
// size: the tree's copy of the spheres from `spheres`, where leaf slot i holds compiled
// sphere leaf_sphere[i], and every box again the union of what it holds, rounded outwards
// as the build does. The tree's shape stays, so its cost (sphere_bvh_cost) may grow;
// build_seconds becomes the refit's time. Any tree that bounds its spheres finds the same
// hits (kernels/README.md, "The BVH"). Throws std::invalid_argument when counts differ.
void refit_sphere_bvh(SphereBvh& bvh, const CompiledSpheres& spheres,
                      std::span<const std::uint32_t> leaf_sphere);

// The tree's surface-area cost: the sum of every child box's surface area over the root
// box's, which is the expected number of child boxes a random ray through the root box
// enters. A refit tree whose spheres spread apart grows it.
double sphere_bvh_cost(const SphereBvh& bvh);

}  // namespace octray
