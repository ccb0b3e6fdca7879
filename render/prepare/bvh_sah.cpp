// Binned SAH (Wald 2007, "On fast construction of SAH-based bounding volume hierarchies")
// on a binary tree built in parallel over subtrees: the first half of the sphere BVH
// builder (render/prepare/bvh_sah.h; the 8-wide collapse is render/prepare/bvh_build.cpp).
//
// Determinism: every decision depends only on the spheres of a subtree and its place in
// the tree. Binning reduces boxes with min/max and counts with integer sums (both exact,
// so any TBB split gives the same bins); a partition is one serial pass over its range; each
// binary subtree over primitives [b, e) writes the node slots [s, s + (e - b) - 1) of a
// preallocated array (inner nodes, and a leaf's box in its first slot; left child at s + 1,
// right child at s + mid - b),
// so no slot depends on which thread got there first. Partitions reorder a node's own range in
// place, which no other task touches meanwhile.

#include "render/prepare/bvh_sah.h"

#include <immintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <vector>

#include "core/cpu_features.h"

namespace octray::bvh_sah {
namespace {

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
        // Slightly fewer than `count` bins per extent, so the top center maps to the last
        // bin rather than past it (clamped anyway). 0 where the extent is 0 (or NaN), where
        // the quotient overflows (a denormal extent), and in w. All three axes at once:
        // each node makes one mapping, and lanes written one by one and read back as a
        // vector would wait on a failed store forwarding.
        const __m128 extent = _mm_sub_ps(centers.hi, centers.lo);
        const __m128 s = _mm_div_ps(_mm_set1_ps(static_cast<float>(count) * 0.99999f), extent);
        const __m128 xyz = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
        const __m128 valid = _mm_and_ps(xyz, _mm_and_ps(_mm_cmpgt_ps(extent, _mm_setzero_ps()),
                                                        _mm_cmplt_ps(s, _mm_set1_ps(kInf))));
        lo = centers.lo;
        scale = _mm_and_ps(valid, s);
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
// A bin's box: a Box without initialisers, so that a node's Bins clear only the bins it
// uses (8 + n/20 per axis; Box's initialisers would write all kBins of them every time).
struct BinBox {
    __m128 lo, hi;
    BinBox& operator=(const Box& b) {
        lo = b.lo, hi = b.hi;
        return *this;
    }
    operator Box() const { return Box{lo, hi}; }
    void grow(const Box& b) {
        lo = _mm_min_ps(lo, b.lo);
        hi = _mm_max_ps(hi, b.hi);
    }
};

struct Bins {
    BinBox box[3][kBins];
    alignas(16) std::int32_t count[kBins][4];

    Bins() = default;  // nothing written: BinsAvx::store_to() fills it
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

// The same binning with AVX where the CPU has it (this file is otherwise baseline SSE2):
// a bin's box is held as (lo, -hi) in one 8-wide register, so that growing it by a sphere
// is one min, one load and one store instead of two each (max(a, b) = -min(-a, -b), and
// on equal operands both minps and maxps return the second, so the boxes come out the
// same bit for bit, and so does the tree). Counts as in Bins.
struct BinsAvx {
    __m256 box[3][kBins];  // (lo, -hi)
    alignas(16) std::int32_t count[kBins][4];

    __attribute__((target("avx2"))) explicit BinsAvx(int bins) {
        for (int k = 0; k < bins; ++k) {
            for (int a = 0; a < 3; ++a) box[a][k] = _mm256_set1_ps(kInf);
            _mm_store_si128(reinterpret_cast<__m128i*>(count[k]), _mm_setzero_si128());
        }
    }
    __attribute__((target("avx2"))) void add(const PrimRef& p, const BinMapping& m) {
        const __m256 v = _mm256_loadu_ps(reinterpret_cast<const float*>(&p));
        const __m256 g =
            _mm256_xor_ps(v, _mm256_setr_ps(0, 0, 0, 0, -0.0f, -0.0f, -0.0f, -0.0f));
        const __m128i k = m.bins(p.center());
        const int kx = _mm_cvtsi128_si32(k);
        const int ky = _mm_cvtsi128_si32(_mm_shuffle_epi32(k, 0x55));
        const int kz = _mm_cvtsi128_si32(_mm_shuffle_epi32(k, 0xaa));
        box[0][kx] = _mm256_min_ps(box[0][kx], g), ++count[kx][0];
        box[1][ky] = _mm256_min_ps(box[1][ky], g), ++count[ky][1];
        box[2][kz] = _mm256_min_ps(box[2][kz], g), ++count[kz][2];
    }
    __attribute__((target("avx2"))) void merge(const BinsAvx& o, int bins) {
        for (int k = 0; k < bins; ++k) {
            for (int a = 0; a < 3; ++a) box[a][k] = _mm256_min_ps(box[a][k], o.box[a][k]);
            for (int a = 0; a < 3; ++a) count[k][a] += o.count[k][a];
        }
    }
    __attribute__((target("avx2"))) Box at(int a, int k) const {
        return Box{_mm256_castps256_ps128(box[a][k]),
                   _mm_xor_ps(_mm256_extractf128_ps(box[a][k], 1), _mm_set1_ps(-0.0f))};
    }
    // Into `bins` (grown: as Bins::merge).
    __attribute__((target("avx2"))) void merge_into(Bins& bins, int nb) const {
        for (int k = 0; k < nb; ++k) {
            for (int a = 0; a < 3; ++a) bins.box[a][k].grow(at(a, k));
            for (int a = 0; a < 3; ++a) bins.count[k][a] += count[k][a];
        }
    }
    // Into `bins`, whatever it held (the same as merge_into() on cleared bins).
    __attribute__((target("avx2"))) void store_to(Bins& bins, int nb) const {
        for (int k = 0; k < nb; ++k) {
            for (int a = 0; a < 3; ++a) bins.box[a][k] = at(a, k);
            _mm_store_si128(bins.counts_at(k),
                            _mm_load_si128(reinterpret_cast<const __m128i*>(count[k])));
        }
    }
};

// Whether this CPU bins with AVX (core/cpu_features.h: the one reading behind octray's
// hand-written intrinsics outside the kernels).
bool avx_binning() { return cpu_features().avx2; }

__attribute__((target("avx2"))) void bin_serial_avx(const PrimRef* refs, std::uint32_t b,
                                                    std::uint32_t e, const BinMapping& m,
                                                    Bins& bins, bool fresh) {
    BinsAvx even(m.count);
    std::uint32_t i = b;
    if (e - b >= kTwoWayBinning) {
        BinsAvx odd(m.count);
        for (; i + 1 < e; i += 2) {
            even.add(refs[i], m);
            odd.add(refs[i + 1], m);
        }
        even.merge(odd, m.count);
    }
    for (; i < e; ++i) even.add(refs[i], m);
    if (fresh)
        even.store_to(bins, m.count);
    else
        even.merge_into(bins, m.count);
}

// Bins spheres [b, e) one after the other. Neighbouring spheres tend to fall into the same
// bins (sphereflakes are generated child by child), and then each update waits for the
// previous one's store; two sets of bins, merged at the end (exactly: min, max and integer
// sums), make two independent chains. With AVX: bin_serial_avx, for every range.
void bin_serial(const PrimRef* refs, std::uint32_t b, std::uint32_t e, const BinMapping& m,
                Bins& bins) {
    if (avx_binning()) return bin_serial_avx(refs, b, e, m, bins, false);
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

// Into `bins`, whatever they held.
void bin_range(const PrimRef* refs, std::uint32_t b, std::uint32_t e, const BinMapping& m,
               Bins& bins) {
    if (e - b < kParallelBinning) {
        if (avx_binning()) return bin_serial_avx(refs, b, e, m, bins, true);
        bins = Bins(m.count);
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

// Reorders the spheres of [b, e) in place, those whose center lies in bins [0, bin] of
// `Axis` first, and returns where the rest begin; the two sides' center bounds come out on
// the way. In place, so the build needs no second array of references (its pages cost a
// fault each, the time to clear them, and cache space). Branch-free (which side a sphere
// goes to is a coin toss the CPU cannot predict): [b, l) holds the left spheres found so
// far and [l, i) the right ones; each sphere is swapped with the first right one at l, and
// l moves on only past a left one (a right sphere swaps with a right one: the right side
// comes out permuted, the same way for any thread count). The axis is a template argument
// so that its lane is picked by a shuffle, not by a round trip through memory.
template <int Axis>
std::uint32_t partition_on(PrimRef* refs, std::uint32_t b, std::uint32_t e, const BinMapping& m,
                           int bin, Box& left_centers, Box& right_centers) {
    constexpr int kBroadcast = Axis * 0x55;  // _MM_SHUFFLE(Axis, Axis, Axis, Axis)
    const __m128i last_left = _mm_set1_epi32(bin);
    const __m128 all_ones = _mm_castsi128_ps(_mm_set1_epi32(-1));
    Box lc, rc;
    PrimRef* l = refs + b;
    for (PrimRef *i = refs + b, *end = refs + e; i < end; ++i) {
        const PrimRef p = *i;
        const __m128 c = p.center();
        // All ones in every lane where the bin on `Axis` lies right of `bin`.
        const __m128i right_mask =
            _mm_shuffle_epi32(_mm_cmpgt_epi32(m.bins(c), last_left), kBroadcast);
        const std::int32_t right = _mm_cvtsi128_si32(right_mask);  // 0 or -1
        const PrimRef q = *l;
        *i = q;
        *l = p;
        l += 1 + right;
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
    return static_cast<std::uint32_t>(l - refs);
}

std::uint32_t partition(PrimRef* refs, std::uint32_t b, std::uint32_t e, const BinMapping& m,
                        int axis, int bin, Box& left_centers, Box& right_centers) {
    switch (axis) {
        case 0:
            return partition_on<0>(refs, b, e, m, bin, left_centers, right_centers);
        case 1:
            return partition_on<1>(refs, b, e, m, bin, left_centers, right_centers);
        default:
            return partition_on<2>(refs, b, e, m, bin, left_centers, right_centers);
    }
}

class Builder {
  public:
    // The spheres are reordered in `refs`, node by node, into leaf order.
    Builder(PrimRef* refs, BinaryNode* nodes) : refs_(refs), nodes_(nodes) {}

    bool build(const RangeBounds& rb, std::uint32_t n) { return !build(0, 0, n, rb, 0); }

  private:
    // A leaf of n spheres with this box. It has no node, but a leaf of two or more
    // spheres owns at least one unused slot: its box goes there, as the collapse's
    // (render/prepare/bvh_build.cpp) to read in place of the spheres' boxes. Returns true.
    bool leaf(std::uint32_t slot, std::uint32_t n, const Box& box) {
        if (n >= 2) {
            BinaryNode& node = nodes_[slot];
            for (int a = 0; a < 3; ++a) node.lo[a] = box.lo_at(a), node.hi[a] = box.hi_at(a);
            node.mid = 0;
        }
        return true;
    }

    // Builds the subtree of spheres [b, e) into slots [slot, slot + (e - b) - 1); returns
    // whether it is a leaf (and then writes no node, only its box: leaf()).
    bool build(std::uint32_t slot, std::uint32_t b, std::uint32_t e, const RangeBounds& rb,
               std::uint32_t depth) {
        const std::uint32_t n = e - b;
        // A split costs at least one traversal step, more than testing this many spheres:
        // the SAH would choose the leaf, so the binning is skipped.
        if (static_cast<float>(n) * kIntersectionCost <= kTraversalCost)
            return leaf(slot, n, rb.box);

        std::uint32_t mid = 0;
        RangeBounds left, right;
        if (depth < kMaxSahDepth) {
            const BinMapping m(rb.centers, n);
            Bins bins;
            bin_range(refs_, b, e, m, bins);
            const Split split = best_split(bins, m);
            const float area = rb.box.half_area();
            const float leaf_cost = kIntersectionCost * static_cast<float>(n);
            const float split_cost =
                split.axis < 0 ? kInf
                : area > 0.0f  ? kTraversalCost + kIntersectionCost * split.cost / area
                               : kTraversalCost + kIntersectionCost * static_cast<float>(n);
            if (n <= kMaxLeafSize && leaf_cost <= split_cost) return leaf(slot, n, rb.box);
            if (split.axis >= 0) {
                mid = partition(refs_, b, e, m, split.axis, split.bin, left.centers,
                                right.centers);
                left.box = split.left;
                right.box = split.right;
            }
        } else if (n <= kMaxLeafSize) {
            return leaf(slot, n, rb.box);
        }
        // Every center in one bin (coincident spheres) or too deep: the middle index.
        if (mid <= b || mid >= e) {
            mid = b + n / 2;
            left = range_bounds(refs_, b, mid);
            right = range_bounds(refs_, mid, e);
        }
        const std::uint32_t left_slot = slot + 1, right_slot = slot + (mid - b);
        bool left_leaf, right_leaf;
        if (n >= kParallelSubtree) {
            tbb::parallel_invoke(
                [&] { left_leaf = build(left_slot, b, mid, left, depth + 1); },
                [&] { right_leaf = build(right_slot, mid, e, right, depth + 1); });
        } else {
            left_leaf = build(left_slot, b, mid, left, depth + 1);
            right_leaf = build(right_slot, mid, e, right, depth + 1);
        }
        BinaryNode& node = nodes_[slot];
        for (int a = 0; a < 3; ++a) node.lo[a] = rb.box.lo_at(a), node.hi[a] = rb.box.hi_at(a);
        node.mid =
            mid | (left_leaf ? kBinaryLeftLeaf : 0u) | (right_leaf ? kBinaryRightLeaf : 0u);
        return false;
    }

    PrimRef* refs_;
    BinaryNode* nodes_;
};

}  // namespace

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

bool build_binary_tree(PrimRef* refs, BinaryNode* nodes, const RangeBounds& rb,
                       std::uint32_t n) {
    return Builder(refs, nodes).build(rb, n);
}

}  // namespace octray::bvh_sah
