// The sphere BVH builder (render/prepare/bvh_build.h): the binary tree by binned SAH
// (render/prepare/bvh_sah.cpp), then collapsed into 8-wide nodes (Wald et al. 2008, "Getting
// rid of packets"; embree's BVH8 collapse: open the child with the largest surface area until
// 8 children) and laid out.
//
// Determinism: the binary tree is the same for any thread count (render/prepare/bvh_sah.cpp);
// the 8-wide collapse hands large subtrees to tasks, and one pass then writes every node to its
// place in child order, whichever task finished first.

#include "render/prepare/bvh_build.h"

#include <emmintrin.h>
#include <math.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/prepare/bvh_sah.h"

namespace octray {

std::size_t SphereBvh::memory_bytes() const {
    return nodes.size() * sizeof(BvhNode8) +
           cx.size() * (sizeof(float) * 4 + sizeof(std::uint32_t));
}

double SphereBvh::bytes_per_sphere() const {
    return sphere_count > 0 ? static_cast<double>(memory_bytes()) / sphere_count : 0.0;
}

namespace {

using namespace bvh_sah;

// A sphere's box c ± sqrt(r2), rounded outwards: it holds every point of the sphere the
// kernels intersect (which knows only r2). In float: sqrtf is exact to half an ulp, and
// the factor and the relative and absolute steps cover every rounding after it.
void sphere_box(float cx, float cy, float cz, float r2, float lo[3], float hi[3]) {
    const __m128 grow_r = _mm_set1_ps(1.0f + 0x1.0p-21f);
    const __m128 rel = _mm_set1_ps(0x1.0p-21f);
    const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    const __m128 tiny = _mm_set1_ps(std::numeric_limits<float>::min());
    const __m128 c = _mm_setr_ps(cx, cy, cz, 0.0f);
    const __m128 radius = _mm_mul_ps(_mm_set1_ps(sqrtf(r2)), grow_r);
    __m128 l = _mm_sub_ps(c, radius), h = _mm_add_ps(c, radius);
    const auto step = [&](__m128 v) {
        return _mm_add_ps(_mm_mul_ps(_mm_and_ps(v, abs_mask), rel), tiny);
    };
    l = _mm_sub_ps(l, step(l));
    h = _mm_add_ps(h, step(h));
    alignas(16) float lv[4], hv[4];
    _mm_store_ps(lv, l);
    _mm_store_ps(hv, h);
    for (int a = 0; a < 3; ++a) lo[a] = lv[a], hi[a] = hv[a];
}

// The 8-wide collapse hands subtrees of this many spheres or more to tasks of their own.
constexpr std::uint32_t kParallelCollapse = 1024;

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
    Collapser(const BinaryNode* binary, const PrimRef* refs) : binary_(binary), refs_(refs) {}

    // Collapses the binary subtree at `slot` (spheres [b, e), at 8-wide level `depth`; a
    // leaf, without a node, where `leaf`) into `out`, its root at out.nodes[0]. Subtrees of
    // kParallelCollapse spheres or more are collapsed by tasks of their own into out.parts.
    void collapse(std::uint32_t slot, std::uint32_t b, std::uint32_t e, bool leaf,
                  std::uint32_t depth, Collapsed& out) const {
        std::vector<Deferred> deferred;
        emit(slot, b, e, leaf, depth, out, deferred);
        out.total = out.nodes.size();
        if (deferred.empty()) return;
        out.parts.resize(deferred.size());
        tbb::parallel_for(std::size_t{0}, deferred.size(), [&](std::size_t i) {
            const Deferred& d = deferred[i];
            collapse(d.slot, d.b, d.e, false, d.depth, out.parts[i]);
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

    std::uint32_t emit(std::uint32_t slot, std::uint32_t b, std::uint32_t e, bool leaf,
                       std::uint32_t depth, Collapsed& out,
                       std::vector<Deferred>& deferred) const {
        out.depth = std::max(out.depth, depth);
        // A binary subtree to become a child: its spheres, its split (0: a leaf) and which
        // of its children are leaves, its box and area.
        struct Child {
            std::uint32_t slot, b, e, mid, leaves;
            float lo[3], hi[3];
            float area;
            std::uint32_t right_slot() const { return slot + (mid - b); }
        };
        const auto child = [&](std::uint32_t s, std::uint32_t cb, std::uint32_t ce,
                               bool is_leaf) {
            Child c{s, cb, ce, 0, 0, {}, {}, 0.0f};
            if (is_leaf && ce - cb == 1) {
                // A leaf of one sphere: its box.
                const Box& box = refs_[cb].box;
                for (int a = 0; a < 3; ++a) c.lo[a] = box.lo_at(a), c.hi[a] = box.hi_at(a);
            } else if (is_leaf) {
                // A larger leaf's box, as the builder bounded its spheres, in the slot the
                // leaf leaves unused (bvh_sah.h): read in place of its spheres' boxes, which
                // lie elsewhere in memory (a quarter of the collapse's time went into
                // those reads).
                const BinaryNode& bn = binary_[s];
                for (int a = 0; a < 3; ++a) c.lo[a] = bn.lo[a], c.hi[a] = bn.hi[a];
            } else {
                const BinaryNode& bn = binary_[s];
                c.mid = bn.mid & kBinaryMidMask;
                c.leaves = bn.mid & (kBinaryLeftLeaf | kBinaryRightLeaf);
                for (int a = 0; a < 3; ++a) c.lo[a] = bn.lo[a], c.hi[a] = bn.hi[a];
                // An inner node's right child (its node, or a leaf's box) lies past its
                // left subtree, far away in memory for a large one: fetched now, it is
                // there when the node is opened.
                const bool single = (c.leaves & kBinaryRightLeaf) != 0 && ce - c.mid == 1;
                _mm_prefetch(single ? reinterpret_cast<const char*>(&refs_[c.mid])
                                    : reinterpret_cast<const char*>(&binary_[c.right_slot()]),
                             _MM_HINT_T0);
            }
            const float dx = c.hi[0] - c.lo[0], dy = c.hi[1] - c.lo[1], dz = c.hi[2] - c.lo[2];
            c.area = dx * dy + dy * dz + dz * dx;
            return c;
        };
        Child children[kBvhWidth];
        std::uint32_t count = 0;
        const auto open = [&](const Child& c, Child& first, Child& second) {
            first = child(c.slot + 1, c.b, c.mid, (c.leaves & kBinaryLeftLeaf) != 0);
            second = child(c.right_slot(), c.mid, c.e, (c.leaves & kBinaryRightLeaf) != 0);
        };
        children[count++] = child(slot, b, e, leaf);
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
                refs[i] = emit(c.slot, c.b, c.e, false, depth + 1, out, deferred);
            }
        }
        BvhNode8& node = out.nodes[index];  // after the recursion: emplace_back moves nodes
        for (std::uint32_t i = 0; i < kBvhWidth; ++i) {
            const bool used = i < count;
            const Child* c = used ? &children[i] : nullptr;
            node.min_x[i] = used ? c->lo[0] : kInf, node.max_x[i] = used ? c->hi[0] : -kInf;
            node.min_y[i] = used ? c->lo[1] : kInf, node.max_y[i] = used ? c->hi[1] : -kInf;
            node.min_z[i] = used ? c->lo[2] : kInf, node.max_z[i] = used ? c->hi[2] : -kInf;
            node.child[i] = used ? refs[i] : kBvhEmpty;
        }
        return index;
    }

    const BinaryNode* binary_;
    const PrimRef* refs_;
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

    // The builder's buffers (references, binary nodes) on huge pages: core/aligned.h.
    using PrimRefs = std::vector<PrimRef, UninitializedAllocator<PrimRef, Pages::huge>>;
    PrimRefs refs(n);
    // Each sphere's box c ± sqrt(r2), rounded outwards (sphere_box).
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, n, 4096),
                      [&](const tbb::blocked_range<std::uint32_t>& r) {
                          for (std::uint32_t i = r.begin(); i < r.end(); ++i) {
                              const auto index = static_cast<float>(i);
                              float l[3], h[3];
                              sphere_box(spheres.cx[i], spheres.cy[i], spheres.cz[i],
                                         spheres.r2[i], l, h);
                              refs[i].box.lo = _mm_setr_ps(l[0], l[1], l[2], index);
                              refs[i].box.hi = _mm_setr_ps(h[0], h[1], h[2], index);
                          }
                      });

    // The binary tree: n - 1 slots for its inner nodes (leaves have none).
    std::vector<BinaryNode, UninitializedAllocator<BinaryNode, Pages::huge>> binary(n - 1);
    const RangeBounds bounds = range_bounds(refs.data(), 0, n);
    const bool root_inner = build_binary_tree(refs.data(), binary.data(), bounds, n);
    const Box root = bounds.box;

    // 8-wide nodes: preorder, but for the subtrees collapsed by tasks of their own.
    Collapsed collapsed;
    Collapser(binary.data(), refs.data()).collapse(0, 0, n, !root_inner, 1, collapsed);
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

void refit_sphere_bvh(SphereBvh& bvh, const CompiledSpheres& spheres,
                      std::span<const std::uint32_t> leaf_sphere) {
    const auto start = std::chrono::steady_clock::now();
    const std::uint32_t n = bvh.sphere_count;
    if (spheres.count != n || leaf_sphere.size() != n)
        throw std::invalid_argument("refit_sphere_bvh: the tree holds " + std::to_string(n) +
                                    " spheres, the scene " + std::to_string(spheres.count));
    if (n == 0) return;
    // The tree's copy of the spheres, in leaf order.
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, n, 4096),
                      [&](const tbb::blocked_range<std::uint32_t>& r) {
                          for (std::uint32_t i = r.begin(); i < r.end(); ++i) {
                              const std::uint32_t s = leaf_sphere[i];
                              bvh.cx[i] = spheres.cx[s], bvh.cy[i] = spheres.cy[s];
                              bvh.cz[i] = spheres.cz[s], bvh.r2[i] = spheres.r2[s];
                          }
                      });
    // Leaf boxes (independent of each other) in parallel, then the inner children's boxes
    // from the last node to the first: a node's children come after it, so each inner
    // child's box is the union of a node already refitted.
    const auto count = static_cast<std::uint32_t>(bvh.nodes.size());
    tbb::parallel_for(
        tbb::blocked_range<std::uint32_t>(0, count, 64),
        [&](const tbb::blocked_range<std::uint32_t>& r) {
            for (std::uint32_t k = r.begin(); k < r.end(); ++k) {
                BvhNode8& node = bvh.nodes[k];
                for (std::uint32_t j = 0; j < kBvhWidth; ++j) {
                    const std::uint32_t child = node.child[j];
                    if (child == kBvhEmpty || (child & kBvhLeafBit) == 0) continue;
                    const std::uint32_t first = (child & ~kBvhLeafBit) >> kBvhLeafCountBits;
                    const std::uint32_t leaf_count =
                        (child & ((1u << kBvhLeafCountBits) - 1)) + 1;
                    float lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf};
                    for (std::uint32_t i = first; i < first + leaf_count; ++i) {
                        float l[3], h[3];
                        sphere_box(bvh.cx[i], bvh.cy[i], bvh.cz[i], bvh.r2[i], l, h);
                        for (int a = 0; a < 3; ++a)
                            lo[a] = std::min(lo[a], l[a]), hi[a] = std::max(hi[a], h[a]);
                    }
                    node.min_x[j] = lo[0], node.min_y[j] = lo[1], node.min_z[j] = lo[2];
                    node.max_x[j] = hi[0], node.max_y[j] = hi[1], node.max_z[j] = hi[2];
                }
            }
        });
    const auto node_box = [&](const BvhNode8& node, float lo[3], float hi[3]) {
        for (int a = 0; a < 3; ++a) lo[a] = kInf, hi[a] = -kInf;
        for (std::uint32_t j = 0; j < kBvhWidth; ++j) {
            if (node.child[j] == kBvhEmpty) continue;
            lo[0] = std::min(lo[0], node.min_x[j]), hi[0] = std::max(hi[0], node.max_x[j]);
            lo[1] = std::min(lo[1], node.min_y[j]), hi[1] = std::max(hi[1], node.max_y[j]);
            lo[2] = std::min(lo[2], node.min_z[j]), hi[2] = std::max(hi[2], node.max_z[j]);
        }
    };
    for (std::uint32_t k = count; k-- > 0;) {
        BvhNode8& node = bvh.nodes[k];
        for (std::uint32_t j = 0; j < kBvhWidth; ++j) {
            const std::uint32_t child = node.child[j];
            if (child == kBvhEmpty || (child & kBvhLeafBit) != 0) continue;
            float lo[3], hi[3];
            node_box(bvh.nodes[child], lo, hi);
            node.min_x[j] = lo[0], node.min_y[j] = lo[1], node.min_z[j] = lo[2];
            node.max_x[j] = hi[0], node.max_y[j] = hi[1], node.max_z[j] = hi[2];
        }
    }
    node_box(bvh.nodes[0], bvh.lo, bvh.hi);
    bvh.build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double sphere_bvh_cost(const SphereBvh& bvh) {
    const auto half_area = [](float dx, float dy, float dz) {
        return static_cast<double>(dx) * dy + static_cast<double>(dy) * dz +
               static_cast<double>(dz) * dx;
    };
    const double root =
        half_area(bvh.hi[0] - bvh.lo[0], bvh.hi[1] - bvh.lo[1], bvh.hi[2] - bvh.lo[2]);
    if (!(root > 0.0)) return 0.0;
    double sum = 0.0;
    for (const BvhNode8& node : bvh.nodes)
        for (std::uint32_t j = 0; j < kBvhWidth; ++j)
            if (node.child[j] != kBvhEmpty)
                sum += half_area(node.max_x[j] - node.min_x[j], node.max_y[j] - node.min_y[j],
                                 node.max_z[j] - node.min_z[j]);
    return sum / root;
}

}  // namespace octray
