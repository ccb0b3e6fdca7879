#pragma once
// The binary half of the sphere BVH builder (render/prepare/bvh_build.h): the builder's boxes
// and sphere references in SSE registers, and the binned SAH build of a binary tree over them
// (render/prepare/bvh_sah.cpp). render/prepare/bvh_build.cpp makes the references, collapses
// the binary tree into 8-wide nodes and lays them out. Internal to those two files.

#include <emmintrin.h>

#include <cstdint>
#include <limits>

#include "kernels/bvh/bvh_node.h"

namespace octray::bvh_sah {

inline constexpr float kInf = std::numeric_limits<float>::infinity();

// Binned SAH: at most 16 bins per axis (Wald 2007 found 16-32 as good as a full sweep;
// 32 traced no faster here), fewer for small ranges (BinMapping).
inline constexpr int kBins = 16;
// A binary subtree becomes a leaf when the SAH prefers it and it holds at most this many
// spheres (a leaf is one 8-wide test against one ray).
inline constexpr std::uint32_t kMaxLeafSize = kBvhWidth;
// SAH costs of a node visit and of one sphere test.
inline constexpr float kTraversalCost = 1.0f;
inline constexpr float kIntersectionCost = 0.25f;
// Below this many spheres a subtree (or a binning pass) runs in one task.
inline constexpr std::uint32_t kParallelSubtree = 4096;
inline constexpr std::uint32_t kParallelBinning = 1u << 15;
// Beyond this binary depth, subtrees are split at the middle index: the depth (and so the
// kernels' traversal stack) stays bounded whatever the spheres' layout.
inline constexpr std::uint32_t kMaxSahDepth = 48;

// Boxes and primitive references in SSE registers (SSE2 is baseline x86-64; this file gets
// no ISA flags): growing a box is one min and one max, binning one center three ways is a
// handful of instructions (embree's binned builder does the same).
struct Box {
    __m128 lo = _mm_set1_ps(kInf);
    __m128 hi = _mm_set1_ps(-kInf);

    void grow(const Box& b) {
        lo = _mm_min_ps(lo, b.lo);
        hi = _mm_max_ps(hi, b.hi);
    }
    void grow(__m128 p) {
        lo = _mm_min_ps(lo, p);
        hi = _mm_max_ps(hi, p);
    }
    float lo_at(int a) const { return lane(lo, a); }
    float hi_at(int a) const { return lane(hi, a); }
    // Half the surface area; 0 for an empty box.
    float half_area() const {
        alignas(16) float d[4];
        _mm_store_ps(d, _mm_sub_ps(hi, lo));
        if (!(d[0] >= 0.0f)) return 0.0f;
        return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
    }
    static float lane(__m128 v, int a) {
        alignas(16) float f[4];
        _mm_store_ps(f, v);
        return f[a];
    }
};

// A sphere as the builder sees it: its conservative box; the w lanes hold the sphere's
// index as a float (exact: at most 2^24 spheres), which min/max carry along harmlessly.
struct PrimRef {
    Box box;
    __m128 center() const { return _mm_mul_ps(_mm_add_ps(box.lo, box.hi), _mm_set1_ps(0.5f)); }
    std::uint32_t sphere() const { return static_cast<std::uint32_t>(Box::lane(box.lo, 3)); }
};

// Bounds of a range: the spheres' boxes and their centers.
struct RangeBounds {
    Box box, centers;
    void grow(const PrimRef& p) {
        box.grow(p.box);
        centers.grow(p.center());
    }
    void grow(const RangeBounds& r) {
        box.grow(r.box);
        centers.grow(r.centers);
    }
};

// An inner node of the binary tree: its box and where its right child's spheres begin
// (mid, in the low bits), with a bit for each child that is a leaf. Leaves have no node of
// their own, so a subtree of n spheres needs n - 1 slots, not 2n - 1 (half the memory to
// fault in and clear). A leaf of k >= 2 spheres still owns k - 1 slots it does not use: its
// box goes in the first (mid 0), where the collapse reads it next to its parent's node
// instead of from its spheres' references elsewhere in memory; a leaf of one sphere has no
// slot, and its box is its sphere's.
// No initialisers: the slot array is allocated untouched and filled by the build tasks.
struct BinaryNode {
    float lo[3], hi[3];
    std::uint32_t mid;
};
inline constexpr std::uint32_t kBinaryLeftLeaf = 1u << 31;
inline constexpr std::uint32_t kBinaryRightLeaf = 1u << 30;
inline constexpr std::uint32_t kBinaryMidMask = kBinaryRightLeaf - 1;  // 2^24 spheres at most

// Bounds of spheres [b, e) of `refs`.
RangeBounds range_bounds(const PrimRef* refs, std::uint32_t b, std::uint32_t e);

// Builds the binary tree over the n spheres of `refs` (bounds `rb`) into nodes[0, n - 1):
// node 0 the root, a left child right after its parent, the right child of a node over
// spheres [b, e) split at mid at mid - b slots after it. Returns false where the root is a
// leaf (no node written). The spheres end in `refs` in leaf order (the partitions reorder
// them in place). In parallel with TBB over subtrees; every node and every byte of `refs`
// the same for any thread count.
bool build_binary_tree(PrimRef* refs, BinaryNode* nodes, const RangeBounds& rb,
                       std::uint32_t n);

}  // namespace octray::bvh_sah
