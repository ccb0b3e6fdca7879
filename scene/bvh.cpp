// The sphere BVH builder: binned SAH (Wald 2007, "On fast construction of SAH-based
// bounding volume hierarchies") on a binary tree built in parallel over subtrees, then
// collapsed into 8-wide nodes (Wald et al. 2008, "Getting rid of packets"; embree's
// BVH8 collapse: open the child with the largest surface area until 8 children).
//
// Determinism: every decision depends only on the spheres of a subtree and its place in
// the tree. Binning reduces boxes with min/max and counts with integer sums (both exact,
// so any TBB split gives the same bins); a partition is one serial pass over its range; each
// binary subtree over primitives [b, e) writes the node slots [s, s + 2(e - b) - 1) of a
// preallocated array (left child at s + 1, right child at s + 2(mid - b)), so no slot
// depends on which thread got there first; the 8-wide collapse hands large subtrees to
// tasks, and one pass then writes every node to its place in child order, whichever task
// finished first.

#include "scene/bvh.h"

#include <emmintrin.h>
#include <math.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <stdexcept>
#include <vector>

namespace octray {

const char* accel_name(Accel accel) {
    switch (accel) {
        case Accel::automatic:
            return "auto";
        case Accel::bvh:
            return "bvh";
        case Accel::none:
            return "none";
    }
    return "?";
}

std::optional<Accel> parse_accel(std::string_view name) {
    for (Accel a : {Accel::automatic, Accel::bvh, Accel::none})
        if (name == accel_name(a)) return a;
    return std::nullopt;
}

bool accel_uses_bvh(Accel accel, std::uint32_t sphere_count) {
    switch (accel) {
        case Accel::automatic:
            return sphere_count >= kBvhAutoMinSpheres;
        case Accel::bvh:
            return sphere_count > 0;
        case Accel::none:
            return false;
    }
    return false;
}

std::size_t SphereBvh::memory_bytes() const {
    return nodes.size() * sizeof(BvhNode8) +
           cx.size() * (sizeof(float) * 4 + sizeof(std::uint32_t));
}

double SphereBvh::bytes_per_sphere() const {
    return sphere_count > 0 ? static_cast<double>(memory_bytes()) / sphere_count : 0.0;
}

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Binned SAH: at most 16 bins per axis (Wald 2007 found 16-32 as good as a full sweep;
// 32 traced no faster here), fewer for small ranges (BinMapping).
constexpr int kBins = 16;
// A binary subtree becomes a leaf when the SAH prefers it and it holds at most this many
// spheres (a leaf is one 8-wide test against one ray).
constexpr std::uint32_t kMaxLeafSize = kBvhWidth;
// SAH costs of a node visit and of one sphere test.
constexpr float kTraversalCost = 1.0f;
constexpr float kIntersectionCost = 0.25f;
// Below this many spheres a subtree (or a binning pass) runs in one task.
constexpr std::uint32_t kParallelSubtree = 4096;
constexpr std::uint32_t kParallelBinning = 1u << 15;
// The 8-wide collapse hands subtrees of this many spheres or more to tasks of their own.
constexpr std::uint32_t kParallelCollapse = 1024;
// Beyond this binary depth, subtrees are split at the middle index: the depth (and so the
// kernels' traversal stack) stays bounded whatever the spheres' layout.
constexpr std::uint32_t kMaxSahDepth = 48;

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

// A binary node. mid == 0 marks a leaf (an inner node's mid lies above its begin >= 0).
// No initialisers: the slot array is allocated untouched and filled by the build tasks.
struct BinaryNode {
    float lo[3], hi[3];
    std::uint32_t mid;
};

RangeBounds range_bounds(const PrimRef* refs, std::uint32_t b, std::uint32_t e) {
    const auto serial = [refs](std::uint32_t first, std::uint32_t last, RangeBounds r) {
        for (std::uint32_t i = first; i < last; ++i) r.grow(refs[i]);
        return r;
    };
    if (e - b < kParallelBinning) return serial(b, e, RangeBounds{});
    return tbb::parallel_reduce(
        tbb::blocked_range<std::uint32_t>(b, e, kParallelBinning / 4), RangeBounds{},
        [&](const tbb::blocked_range<std::uint32_t>& r, RangeBounds init) {
            return serial(r.begin(), r.end(), init);
        },
        [](RangeBounds x, const RangeBounds& y) {
            x.grow(y);
            return x;
        });
}

// The bins of a range: 8 + n/20 per axis up to kBins (n spheres). Most nodes are small,
// and a node's bins are cleared, filled and swept whatever its size. Maps a center to its
// bin along each axis; the partition uses the same function, so it agrees with the bins'
// counts exactly.
struct BinMapping {
    __m128 lo;
    __m128 scale;        // 0 on an axis without extent (and in w)
    int count;           // bins per axis, 8 ... kBins
    __m128 extent_mask;  // all ones in the lanes of axes with extent

    BinMapping(const Box& centers, std::uint32_t n) {
        count = static_cast<int>(std::min<std::uint32_t>(8 + n / 20, kBins));
        alignas(16) float s[4] = {0, 0, 0, 0};
        for (int a = 0; a < 3; ++a) {
            const float extent = centers.hi_at(a) - centers.lo_at(a);
            // Slightly fewer than `count` bins per extent, so the top center maps to the
            // last bin rather than past it (clamped anyway).
            s[a] = extent > 0.0f ? (static_cast<float>(count) * 0.99999f) / extent : 0.0f;
            if (!(s[a] < kInf)) s[a] = 0.0f;  // denormal extent
        }
        lo = centers.lo;
        scale = _mm_load_ps(s);
        extent_mask = _mm_cmpgt_ps(scale, _mm_setzero_ps());
    }
    __m128i bins(__m128 center) const {
        __m128 k = _mm_mul_ps(_mm_sub_ps(center, lo), scale);
        k = _mm_min_ps(_mm_max_ps(k, _mm_setzero_ps()),
                       _mm_set1_ps(static_cast<float>(count - 1)));
        return _mm_cvttps_epi32(k);
    }
};

// Lanes of `a` where `mask` is set, else lanes of `b`.
__m128 select(__m128 mask, __m128 a, __m128 b) {
    return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b));
}
__m128i select(__m128 mask, __m128i a, __m128i b) {
    const __m128i m = _mm_castps_si128(mask);
    return _mm_or_si128(_mm_and_si128(m, a), _mm_andnot_si128(m, b));
}

// Per axis and bin: the spheres' boxes and their count (the children's center bounds come
// out of the partition, which visits every sphere anyway). Counts are kept per bin with
// the three axes in lanes, as the sweep reads them.
struct Bins {
    Box box[3][kBins];
    alignas(16) std::int32_t count[kBins][4];

    explicit Bins(int bins) {
        for (int k = 0; k < bins; ++k) {
            for (int a = 0; a < 3; ++a) box[a][k] = Box{};
            _mm_store_si128(counts_at(k), _mm_setzero_si128());
        }
    }
    __m128i* counts_at(int k) { return reinterpret_cast<__m128i*>(count[k]); }
    __m128i counts(int k) const {
        return _mm_load_si128(reinterpret_cast<const __m128i*>(count[k]));
    }
    void add(const PrimRef& p, const BinMapping& m) {
        // The three bins out of their lanes by shuffles (a store and three loads would
        // make each update wait on store forwarding).
        const __m128i k = m.bins(p.center());
        const int kx = _mm_cvtsi128_si32(k);
        const int ky = _mm_cvtsi128_si32(_mm_shuffle_epi32(k, 0x55));
        const int kz = _mm_cvtsi128_si32(_mm_shuffle_epi32(k, 0xaa));
        box[0][kx].grow(p.box), ++count[kx][0];
        box[1][ky].grow(p.box), ++count[ky][1];
        box[2][kz].grow(p.box), ++count[kz][2];
    }
    void merge(const Bins& o, int bins) {
        for (int k = 0; k < bins; ++k) {
            for (int a = 0; a < 3; ++a) box[a][k].grow(o.box[a][k]);
            _mm_store_si128(counts_at(k), _mm_add_epi32(counts(k), o.counts(k)));
        }
    }
};

// Ranges from this many spheres on are binned into two sets of bins, even and odd
// spheres apart, merged at the end.
constexpr std::uint32_t kTwoWayBinning = 32;

// Bins spheres [b, e) one after the other. Neighbouring spheres tend to fall into the same
// bins (sphereflakes are generated child by child), and then each update waits for the
// previous one's store; two sets of bins, merged at the end (exactly: min, max and integer
// sums), make two independent chains.
void bin_serial(const PrimRef* refs, std::uint32_t b, std::uint32_t e, const BinMapping& m,
                Bins& bins) {
    std::uint32_t i = b;
    if (e - b >= kTwoWayBinning) {
        Bins odd(m.count);
        for (; i + 1 < e; i += 2) {
            bins.add(refs[i], m);
            odd.add(refs[i + 1], m);
        }
        bins.merge(odd, m.count);
    }
    for (; i < e; ++i) bins.add(refs[i], m);
}

void bin_range(const PrimRef* refs, std::uint32_t b, std::uint32_t e, const BinMapping& m,
               Bins& bins) {
    if (e - b < kParallelBinning) {
        bin_serial(refs, b, e, m, bins);
        return;
    }
    bins = tbb::parallel_reduce(
        tbb::blocked_range<std::uint32_t>(b, e, kParallelBinning / 4), Bins(m.count),
        [&](const tbb::blocked_range<std::uint32_t>& r, Bins part) {
            bin_serial(refs, r.begin(), r.end(), m, part);
            return part;
        },
        [&](Bins x, const Bins& y) {
            x.merge(y, m.count);
            return x;
        });
}

// Half the surface areas of three boxes, one per lane (w: 0). Empty boxes come out
// infinite (never used: a split with an empty side is skipped).
__m128 half_areas(const Box (&boxes)[3]) {
    __m128 x = _mm_sub_ps(boxes[0].hi, boxes[0].lo), y = _mm_sub_ps(boxes[1].hi, boxes[1].lo);
    __m128 z = _mm_sub_ps(boxes[2].hi, boxes[2].lo), w = _mm_setzero_ps();
    _MM_TRANSPOSE4_PS(x, y, z, w);  // now x holds the three boxes' x extents, and so on
    return _mm_add_ps(_mm_add_ps(_mm_mul_ps(x, y), _mm_mul_ps(y, z)), _mm_mul_ps(z, x));
}

struct Split {
    int axis = -1;
    int bin = 0;  // the left side holds bins [0, bin]
    float cost = kInf;
    Box left, right;
};

// The cheapest SAH split over every axis and bin boundary (ties: the lower axis, then
// the lower bin). The three axes are swept at once, one per lane.
Split best_split(const Bins& bins, const BinMapping& m) {
    const int nb = m.count;
    // Bins [k, nb): their boxes' areas and their counts.
    alignas(16) float right_area[kBins][4];
    alignas(16) std::int32_t right_count[kBins][4];
    Box acc[3];
    __m128i n = _mm_setzero_si128();
    for (int k = nb - 1; k > 0; --k) {
        for (int a = 0; a < 3; ++a) acc[a].grow(bins.box[a][k]);
        n = _mm_add_epi32(n, bins.counts(k));
        _mm_store_ps(right_area[k], half_areas(acc));
        _mm_store_si128(reinterpret_cast<__m128i*>(right_count[k]), n);
    }
    // Bins [0, k] against bins [k + 1, nb): the cheapest k per axis.
    Box left[3];
    __m128i nl = _mm_setzero_si128();
    __m128 best_cost = _mm_set1_ps(kInf);
    __m128i best_bin = _mm_setzero_si128();
    const __m128i zero = _mm_setzero_si128();
    for (int k = 0; k < nb - 1; ++k) {
        for (int a = 0; a < 3; ++a) left[a].grow(bins.box[a][k]);
        nl = _mm_add_epi32(nl, bins.counts(k));
        const __m128i nr = _mm_load_si128(reinterpret_cast<const __m128i*>(right_count[k + 1]));
        const __m128 cost =
            _mm_add_ps(_mm_mul_ps(half_areas(left), _mm_cvtepi32_ps(nl)),
                       _mm_mul_ps(_mm_load_ps(right_area[k + 1]), _mm_cvtepi32_ps(nr)));
        const __m128 empty_side = _mm_castsi128_ps(
            _mm_or_si128(_mm_cmpeq_epi32(nl, zero), _mm_cmpeq_epi32(nr, zero)));
        const __m128 better =
            _mm_andnot_ps(empty_side, _mm_and_ps(m.extent_mask, _mm_cmplt_ps(cost, best_cost)));
        best_cost = select(better, cost, best_cost);
        best_bin = select(better, _mm_set1_epi32(k), best_bin);
    }
    alignas(16) float costs[4];
    alignas(16) std::int32_t bins_at[4];
    _mm_store_ps(costs, best_cost);
    _mm_store_si128(reinterpret_cast<__m128i*>(bins_at), best_bin);
    Split best;
    for (int a = 0; a < 3; ++a)
        if (costs[a] < best.cost) best.axis = a, best.bin = bins_at[a], best.cost = costs[a];
    if (best.axis >= 0)
        for (int k = 0; k < nb; ++k)
            (k <= best.bin ? best.left : best.right).grow(bins.box[best.axis][k]);
    return best;
}

// Copies the spheres of [b, e) from `src` to `dst`, those whose center lies in bins
// [0, bin] of `Axis` first, and returns where the rest begin; the two sides' center
// bounds come out on the way. Branch-free (which side a sphere goes to is a coin toss
// the CPU cannot predict): each sphere goes to the next free slot at the front or at the
// back of [b, e) (the right side comes out reversed). The axis is a template argument so
// that its lane is picked by a shuffle, not by a round trip through memory.
template <int Axis>
std::uint32_t partition_on(const PrimRef* src, PrimRef* dst, std::uint32_t b, std::uint32_t e,
                           const BinMapping& m, int bin, Box& left_centers,
                           Box& right_centers) {
    constexpr int kBroadcast = Axis * 0x55;  // _MM_SHUFFLE(Axis, Axis, Axis, Axis)
    const __m128i last_left = _mm_set1_epi32(bin);
    const __m128 all_ones = _mm_castsi128_ps(_mm_set1_epi32(-1));
    Box lc, rc;
    PrimRef* front = dst + b;
    PrimRef* back = dst + e;
    for (std::uint32_t i = b; i < e; ++i) {
        const PrimRef p = src[i];
        const __m128 c = p.center();
        // All ones in every lane where the bin on `Axis` lies right of `bin`.
        const __m128i right_mask =
            _mm_shuffle_epi32(_mm_cmpgt_epi32(m.bins(c), last_left), kBroadcast);
        const std::int32_t right = _mm_cvtsi128_si32(right_mask);  // 0 or -1
        *(right ? back - 1 : front) = p;
        front += 1 + right;
        back += right;
        // The side's bounds grow by the center, the other side's by NaN, which min and
        // max pass over: minps and maxps return their second operand where either is
        // NaN, and all ones (the mask) is a NaN.
        const __m128 to_right = _mm_castsi128_ps(right_mask);
        const __m128 left_c = _mm_or_ps(c, to_right);
        const __m128 right_c = _mm_or_ps(c, _mm_xor_ps(to_right, all_ones));
        lc.lo = _mm_min_ps(left_c, lc.lo), lc.hi = _mm_max_ps(left_c, lc.hi);
        rc.lo = _mm_min_ps(right_c, rc.lo), rc.hi = _mm_max_ps(right_c, rc.hi);
    }
    left_centers = lc;
    right_centers = rc;
    return static_cast<std::uint32_t>(front - dst);
}

std::uint32_t partition(const PrimRef* src, PrimRef* dst, std::uint32_t b, std::uint32_t e,
                        const BinMapping& m, int axis, int bin, Box& left_centers,
                        Box& right_centers) {
    switch (axis) {
        case 0:
            return partition_on<0>(src, dst, b, e, m, bin, left_centers, right_centers);
        case 1:
            return partition_on<1>(src, dst, b, e, m, bin, left_centers, right_centers);
        default:
            return partition_on<2>(src, dst, b, e, m, bin, left_centers, right_centers);
    }
}

class Builder {
  public:
    // The spheres start in `refs` and end there in leaf order; the partitions move them
    // back and forth between `refs` and `scratch` (as many spheres), level by level.
    Builder(PrimRef* refs, PrimRef* scratch, BinaryNode* nodes)
        : refs_(refs), scratch_(scratch), nodes_(nodes) {}

    void build(const RangeBounds& rb, std::uint32_t n) { build(0, 0, n, rb, 0, refs_); }

  private:
    // Builds the subtree of spheres [b, e), which lie in `src` (refs_ or scratch_), into
    // slots [slot, slot + 2(e - b) - 1).
    void build(std::uint32_t slot, std::uint32_t b, std::uint32_t e, const RangeBounds& rb,
               std::uint32_t depth, PrimRef* src) {
        BinaryNode& node = nodes_[slot];
        for (int a = 0; a < 3; ++a) node.lo[a] = rb.box.lo_at(a), node.hi[a] = rb.box.hi_at(a);
        node.mid = 0;
        const std::uint32_t n = e - b;
        const auto leaf = [&] {
            if (src != refs_) std::copy(src + b, src + e, refs_ + b);
        };
        // A split costs at least one traversal step, more than testing this many spheres:
        // the SAH would choose the leaf, so the binning is skipped.
        if (static_cast<float>(n) * kIntersectionCost <= kTraversalCost) return leaf();

        PrimRef* const other = src == refs_ ? scratch_ : refs_;
        PrimRef* children_src = src;
        std::uint32_t mid = 0;
        RangeBounds left, right;
        if (depth < kMaxSahDepth) {
            const BinMapping m(rb.centers, n);
            Bins bins(m.count);
            bin_range(src, b, e, m, bins);
            const Split split = best_split(bins, m);
            const float area = rb.box.half_area();
            const float leaf_cost = kIntersectionCost * static_cast<float>(n);
            const float split_cost =
                split.axis < 0 ? kInf
                : area > 0.0f  ? kTraversalCost + kIntersectionCost * split.cost / area
                               : kTraversalCost + kIntersectionCost * static_cast<float>(n);
            if (n <= kMaxLeafSize && leaf_cost <= split_cost) return leaf();
            if (split.axis >= 0) {
                mid = partition(src, other, b, e, m, split.axis, split.bin, left.centers,
                                right.centers);
                children_src = other;
                left.box = split.left;
                right.box = split.right;
            }
        } else if (n <= kMaxLeafSize) {
            return leaf();
        }
        // Every center in one bin (coincident spheres) or too deep: the middle index.
        if (mid <= b || mid >= e) {
            mid = b + n / 2;
            left = range_bounds(src, b, mid);
            right = range_bounds(src, mid, e);
        }
        node.mid = mid;
        const std::uint32_t left_slot = slot + 1, right_slot = slot + 2 * (mid - b);
        if (n >= kParallelSubtree) {
            tbb::parallel_invoke(
                [&] { build(left_slot, b, mid, left, depth + 1, children_src); },
                [&] { build(right_slot, mid, e, right, depth + 1, children_src); });
        } else {
            build(left_slot, b, mid, left, depth + 1, children_src);
            build(right_slot, mid, e, right, depth + 1, children_src);
        }
    }

    PrimRef* refs_;
    PrimRef* scratch_;
    BinaryNode* nodes_;
};

// The 8-wide nodes of a subtree, its root first, inner child references relative to its
// own first node; the subtrees collapsed by tasks of their own (`parts`) are not in
// `nodes`, and the child slots that will point at them (`links`) hold kBvhEmpty.
struct Collapsed {
    struct Link {
        std::uint32_t node, child;
    };
    UninitializedVector<BvhNode8, Pages::huge> nodes;  // emit() writes every field
    std::vector<Collapsed> parts;
    std::vector<Link> links;  // where parts[i]'s root goes
    std::size_t total = 0;    // nodes with all the parts'
    std::uint32_t leaf_count = 0;
    std::uint32_t depth = 0;

    // Writes the subtree's nodes to dst[offset, offset + total): its own nodes, then each
    // part's after them, in order (so the same bytes for any number of threads), with
    // their references made absolute. Each node is copied once.
    void flatten(BvhNode8* dst, std::uint32_t offset) const {
        std::vector<std::uint32_t> part_offset(parts.size());
        auto next = static_cast<std::uint32_t>(offset + nodes.size());
        for (std::size_t i = 0; i < parts.size(); ++i) {
            part_offset[i] = next;
            next += static_cast<std::uint32_t>(parts[i].total);
        }
        tbb::parallel_invoke(
            [&] {
                for (std::size_t k = 0; k < nodes.size(); ++k) {
                    BvhNode8 node = nodes[k];
                    for (std::uint32_t& child : node.child)
                        if ((child & kBvhLeafBit) == 0) child += offset;  // kBvhEmpty: leaf bit
                    dst[offset + k] = node;
                }
                for (std::size_t i = 0; i < parts.size(); ++i)
                    dst[offset + links[i].node].child[links[i].child] = part_offset[i];
            },
            [&] {
                tbb::parallel_for(std::size_t{0}, parts.size(), [&](std::size_t i) {
                    parts[i].flatten(dst, part_offset[i]);
                });
            });
    }
};

class Collapser {
  public:
    explicit Collapser(const BinaryNode* binary) : binary_(binary) {}

    // Collapses the binary subtree at `slot` (spheres [b, e), at 8-wide level `depth`) into
    // `out`, its root at out.nodes[0]. Subtrees of kParallelCollapse spheres or more are
    // collapsed by tasks of their own into out.parts.
    void collapse(std::uint32_t slot, std::uint32_t b, std::uint32_t e, std::uint32_t depth,
                  Collapsed& out) const {
        std::vector<Deferred> deferred;
        emit(slot, b, e, depth, out, deferred);
        out.total = out.nodes.size();
        if (deferred.empty()) return;
        out.parts.resize(deferred.size());
        tbb::parallel_for(std::size_t{0}, deferred.size(), [&](std::size_t i) {
            const Deferred& d = deferred[i];
            collapse(d.slot, d.b, d.e, d.depth, out.parts[i]);
        });
        for (const Collapsed& part : out.parts) {
            out.total += part.total;
            out.leaf_count += part.leaf_count;
            out.depth = std::max(out.depth, part.depth);
        }
    }

  private:
    // A subtree left for a task of its own (its child slot: the matching Collapsed::links).
    struct Deferred {
        std::uint32_t slot, b, e, depth;
    };

    std::uint32_t emit(std::uint32_t slot, std::uint32_t b, std::uint32_t e,
                       std::uint32_t depth, Collapsed& out,
                       std::vector<Deferred>& deferred) const {
        out.depth = std::max(out.depth, depth);
        // A binary node to become a child: its spheres, its split (0: a leaf), its area.
        struct Child {
            std::uint32_t slot, b, e, mid;
            float area;
            std::uint32_t right_slot() const { return slot + 2 * (mid - b); }
        };
        const auto child = [&](std::uint32_t s, std::uint32_t cb, std::uint32_t ce) {
            const Child c{s, cb, ce, binary_[s].mid, half_area(s)};
            // An inner node's right child lies past its left subtree, far away in memory
            // for a large one: fetched now, it is there when the node is opened.
            if (c.mid != 0)
                _mm_prefetch(reinterpret_cast<const char*>(&binary_[c.right_slot()]),
                             _MM_HINT_T0);
            return c;
        };
        Child children[kBvhWidth];
        std::uint32_t count = 0;
        const auto open = [&](const Child& c, Child& first, Child& second) {
            first = child(c.slot + 1, c.b, c.mid);
            second = child(c.right_slot(), c.mid, c.e);
        };
        children[count++] = child(slot, b, e);
        // Open the inner child with the largest surface area (the root first) until there
        // are 8.
        while (count < kBvhWidth) {
            int pick = -1;
            float pick_area = -1.0f;
            for (std::uint32_t i = 0; i < count; ++i)
                if (children[i].mid != 0 && children[i].area > pick_area)
                    pick = static_cast<int>(i), pick_area = children[i].area;
            if (pick < 0) break;
            Child first, second;
            open(children[pick], first, second);
            for (std::uint32_t i = count; i > static_cast<std::uint32_t>(pick) + 1; --i)
                children[i] = children[i - 1];
            children[pick] = first;
            children[pick + 1] = second;
            ++count;
        }

        // Largest box first: the any-hit traversals take children in node order, and a ray
        // that meets a node meets its larger children more often (the SAH's odds), so an
        // occluder tends to be found sooner. Closest-hit orders children by distance.
        // (A stable insertion sort: at most 8 children.)
        for (std::uint32_t i = 1; i < count; ++i) {
            const Child c = children[i];
            std::uint32_t j = i;
            for (; j > 0 && children[j - 1].area < c.area; --j) children[j] = children[j - 1];
            children[j] = c;
        }
        const auto index = static_cast<std::uint32_t>(out.nodes.size());
        out.nodes.emplace_back();
        std::uint32_t refs[kBvhWidth];
        for (std::uint32_t i = 0; i < count; ++i) {
            const Child& c = children[i];
            if (c.mid == 0) {
                ++out.leaf_count;
                refs[i] = kBvhLeafBit | (c.b << kBvhLeafCountBits) | (c.e - c.b - 1);
            } else if (c.e - c.b >= kParallelCollapse) {
                deferred.push_back({c.slot, c.b, c.e, depth + 1});
                out.links.push_back({index, i});
                refs[i] = kBvhEmpty;  // set by Collapsed::flatten()
            } else {
                refs[i] = emit(c.slot, c.b, c.e, depth + 1, out, deferred);
            }
        }
        BvhNode8& node = out.nodes[index];  // after the recursion: emplace_back moves nodes
        for (std::uint32_t i = 0; i < kBvhWidth; ++i) {
            const bool used = i < count;
            const BinaryNode* bn = used ? &binary_[children[i].slot] : nullptr;
            node.min_x[i] = used ? bn->lo[0] : kInf, node.max_x[i] = used ? bn->hi[0] : -kInf;
            node.min_y[i] = used ? bn->lo[1] : kInf, node.max_y[i] = used ? bn->hi[1] : -kInf;
            node.min_z[i] = used ? bn->lo[2] : kInf, node.max_z[i] = used ? bn->hi[2] : -kInf;
            node.child[i] = used ? refs[i] : kBvhEmpty;
        }
        return index;
    }

    float half_area(std::uint32_t slot) const {
        const BinaryNode& b = binary_[slot];
        const float dx = b.hi[0] - b.lo[0], dy = b.hi[1] - b.lo[1], dz = b.hi[2] - b.lo[2];
        return dx * dy + dy * dz + dz * dx;
    }

    const BinaryNode* binary_;
};

}  // namespace

SphereBvh build_sphere_bvh(const CompiledSpheres& spheres) {
    const auto start = std::chrono::steady_clock::now();
    const std::uint32_t n = spheres.count;
    // Sphere indices travel as exact floats through the build (as hit ids do in the
    // kernels): at most 2^24, the most objects a compiled scene has.
    if (n > (1u << 24)) throw std::invalid_argument("a sphere BVH holds at most 2^24 spheres");
    SphereBvh bvh;
    bvh.sphere_count = n;
    if (n == 0) {
        bvh.build_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return bvh;
    }

    // The builder's buffers (references twice, binary nodes) on huge pages: core/aligned.h.
    using PrimRefs = std::vector<PrimRef, UninitializedAllocator<PrimRef, Pages::huge>>;
    PrimRefs refs(n);
    // Each sphere's box c ± sqrt(r2), rounded outwards: it holds every point of the sphere
    // the kernels intersect (which knows only r2).
    tbb::parallel_for(
        tbb::blocked_range<std::uint32_t>(0, n, 4096),
        [&](const tbb::blocked_range<std::uint32_t>& r) {
            // c -+ r rounded outwards in float: sqrtf is exact to half an
            // ulp, the factor and the relative and absolute steps cover
            // every rounding after it.
            const __m128 grow_r = _mm_set1_ps(1.0f + 0x1.0p-21f);
            const __m128 rel = _mm_set1_ps(0x1.0p-21f);
            const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
            const __m128 tiny = _mm_set1_ps(std::numeric_limits<float>::min());
            for (std::uint32_t i = r.begin(); i < r.end(); ++i) {
                const auto index = static_cast<float>(i);
                const __m128 c = _mm_setr_ps(spheres.cx[i], spheres.cy[i], spheres.cz[i], 0.0f);
                const __m128 radius = _mm_mul_ps(_mm_set1_ps(sqrtf(spheres.r2[i])), grow_r);
                __m128 lo = _mm_sub_ps(c, radius), hi = _mm_add_ps(c, radius);
                const auto step = [&](__m128 v) {
                    return _mm_add_ps(_mm_mul_ps(_mm_and_ps(v, abs_mask), rel), tiny);
                };
                lo = _mm_sub_ps(lo, step(lo));
                hi = _mm_add_ps(hi, step(hi));
                alignas(16) float l[4], h[4];
                _mm_store_ps(l, lo);
                _mm_store_ps(h, hi);
                refs[i].box.lo = _mm_setr_ps(l[0], l[1], l[2], index);
                refs[i].box.hi = _mm_setr_ps(h[0], h[1], h[2], index);
            }
        });

    // The binary tree: 2n - 1 slots (a leaf holds at least one sphere).
    std::vector<BinaryNode, UninitializedAllocator<BinaryNode, Pages::huge>> binary(
        2 * static_cast<std::size_t>(n) - 1);
    {
        PrimRefs scratch(n);
        Builder(refs.data(), scratch.data(), binary.data())
            .build(range_bounds(refs.data(), 0, n), n);
    }
    const Box root{_mm_setr_ps(binary[0].lo[0], binary[0].lo[1], binary[0].lo[2], 0.0f),
                   _mm_setr_ps(binary[0].hi[0], binary[0].hi[1], binary[0].hi[2], 0.0f)};

    // 8-wide nodes: preorder, but for the subtrees collapsed by tasks of their own.
    Collapsed collapsed;
    Collapser(binary.data()).collapse(0, 0, n, 1, collapsed);
    bvh.nodes.resize(collapsed.total);
    collapsed.flatten(bvh.nodes.data(), 0);
    bvh.leaf_count = collapsed.leaf_count;
    bvh.depth = collapsed.depth;
    binary = {};

    // The spheres in leaf order, padded with a packet of never-hit entries.
    const std::uint32_t padded = n + kBvhWidth;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    bvh.cx.resize(padded), bvh.cy.resize(padded), bvh.cz.resize(padded);
    bvh.r2.resize(padded), bvh.object.resize(padded);
    for (std::uint32_t i = n; i < padded; ++i)
        bvh.cx[i] = bvh.cy[i] = bvh.cz[i] = bvh.r2[i] = nan, bvh.object[i] = 0u;
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, n, 4096),
                      [&](const tbb::blocked_range<std::uint32_t>& r) {
                          for (std::uint32_t i = r.begin(); i < r.end(); ++i) {
                              const std::uint32_t s = refs[i].sphere();
                              bvh.cx[i] = spheres.cx[s], bvh.cy[i] = spheres.cy[s];
                              bvh.cz[i] = spheres.cz[s], bvh.r2[i] = spheres.r2[s];
                              bvh.object[i] = spheres.object[s];
                          }
                      });

    for (int a = 0; a < 3; ++a) bvh.lo[a] = root.lo_at(a), bvh.hi[a] = root.hi_at(a);
    bvh.build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return bvh;
}

}  // namespace octray
