// The reference's binary BVH: an object-median builder and the per-ray box test
// (reference_bvh.h derives the margin that keeps it exact).

#include "render/reference_bvh.h"

#include <oneapi/tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace octray {
namespace {

// Every point of the sphere lies in [lo, hi]: c -+ r rounded to nearest can be half an ulp
// inside the true bound, and one step outwards puts it outside.
float box_lo(float c, float r) {
    return std::nextafter(c - r, -std::numeric_limits<float>::infinity());
}
float box_hi(float c, float r) {
    return std::nextafter(c + r, std::numeric_limits<float>::infinity());
}

}  // namespace

// Nodes of the subtree over `count` spheres (the node itself included). Median splits
// give every subtree a shape fixed by its count, so each subtree's nodes can be placed
// before it is built, and subtrees build in parallel into their own places: the tree is
// the same whatever the threads do.
std::uint32_t ReferenceBvh::subtree_nodes(std::uint32_t count) {
    if (count <= kLeafSize) return 1;
    // At most two distinct counts per level (floor and ceiling halves): memoised.
    if (const std::uint32_t known = known_subtree_nodes(count); known > 0) return known;
    const std::uint32_t n = 1 + subtree_nodes(count / 2) + subtree_nodes(count - count / 2);
    subtree_sizes_.emplace_back(count, n);
    return n;
}

std::uint32_t ReferenceBvh::known_subtree_nodes(std::uint32_t count) const {
    if (count <= kLeafSize) return 1;
    for (const auto& [c, n] : subtree_sizes_)
        if (c == count) return n;
    return 0;
}

// The builder works on a copy of the spheres (boxes, centers, object indices), so that its
// passes read contiguous memory; the tree keeps only the object indices in leaf order.
ReferenceBvh::ReferenceBvh(std::span<const Object> objects) {
    std::vector<Prim> prims;
    for (std::uint32_t k = 0; k < objects.size(); ++k) {
        const Object& o = objects[k];
        if (o.type != ObjectType::sphere) continue;
        Prim p;
        const float c[3] = {o.center.x, o.center.y, o.center.z};
        for (int a = 0; a < 3; ++a) {
            p.c[a] = c[a];
            p.lo[a] = box_lo(c[a], o.radius);
            p.hi[a] = box_hi(c[a], o.radius);
        }
        p.object = k;
        prims.push_back(p);
    }
    if (prims.empty()) return;
    const auto n = static_cast<std::uint32_t>(prims.size());
    nodes_.resize(subtree_nodes(n));
    depth_ = build_node(0, 1, prims, 0, n, 1);
    spheres_.reserve(prims.size());
    for (const Prim& p : prims) spheres_.push_back(p.object);
}

int ReferenceBvh::build_node(std::uint32_t node, std::uint32_t below, std::vector<Prim>& prims,
                             std::uint32_t first, std::uint32_t count, int level) {
    if (level > kMaxDepth) throw std::logic_error("ReferenceBvh: tree deeper than kMaxDepth");

    // The node's box (the spheres' boxes) and the box of their centers (the split's).
    float lo[3], hi[3], clo[3], chi[3];
    for (int a = 0; a < 3; ++a) {
        lo[a] = clo[a] = std::numeric_limits<float>::infinity();
        hi[a] = chi[a] = -std::numeric_limits<float>::infinity();
    }
    for (std::uint32_t i = first; i < first + count; ++i) {
        const Prim& p = prims[i];
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], p.lo[a]);
            hi[a] = std::max(hi[a], p.hi[a]);
            clo[a] = std::min(clo[a], p.c[a]);
            chi[a] = std::max(chi[a], p.c[a]);
        }
    }
    Node& n = nodes_[node];
    for (int a = 0; a < 3; ++a) n.lo[a] = lo[a], n.hi[a] = hi[a];

    if (count <= kLeafSize) {
        n.first = first;
        n.count = count;
        return level;
    }

    // Object median along the widest extent of the centers: half the spheres (by center,
    // ties by object index, so the tree does not depend on the sort's implementation) to
    // each side. Coincident centers still split by count, so every leaf holds kLeafSize
    // spheres at most and the depth stays log2(n).
    int axis = 0;
    for (int a = 1; a < 3; ++a)
        if (chi[a] - clo[a] > chi[axis] - clo[axis]) axis = a;
    const std::uint32_t half = count / 2;
    const auto begin = prims.begin() + first;
    std::nth_element(begin, begin + half, begin + count, [axis](const Prim& x, const Prim& y) {
        return x.c[axis] < y.c[axis] || (x.c[axis] == y.c[axis] && x.object < y.object);
    });

    // The children sit side by side at `below`; the left child's subtree comes after them,
    // then the right child's.
    n.first = below;
    n.count = 0;
    const std::uint32_t left_below = below + 2;
    // (Every count of this tree was memoised by the constructor's subtree_nodes: the
    // parallel builds only read the table.)
    const std::uint32_t right_below = left_below + known_subtree_nodes(half) - 1;
    int left = 0, right = 0;
    const auto build_left = [&] {
        left = build_node(below, left_below, prims, first, half, level + 1);
    };
    const auto build_right = [&] {
        right =
            build_node(below + 1, right_below, prims, first + half, count - half, level + 1);
    };
    // Large subtrees on two threads; small ones are not worth a task.
    if (count >= kParallelSpheres)
        tbb::parallel_invoke(build_left, build_right);
    else
        build_left(), build_right();
    return std::max(left, right);
}

ReferenceBvh::BoxRay ReferenceBvh::box_ray(const Ray& ray) const {
    BoxRay r{};
    const Vec3 o = ray.origin, d = ray.direction;
    const double od[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
    const Node& root = nodes_[0];
    double far2 = 0.0, o_max = 0.0;
    bool finite = true;
    for (int a = 0; a < 3; ++a) {
        finite = finite && std::isfinite(od[a]) && std::isfinite(dd[a]);
        r.o[a] = od[a];
        r.zero[a] = dd[a] == 0.0;
        r.inv[a] = r.zero[a] ? 0.0 : 1.0 / dd[a];
        const double far =
            std::max(std::fabs(od[a] - root.lo[a]), std::fabs(od[a] - root.hi[a]));
        far2 += far * far;
        o_max = std::max(o_max, std::fabs(od[a]));
    }
    // The margin of reference_bvh.h: 32u D + 64u (D + max|O_i|), u = 2^-24.
    const double D = std::sqrt(far2);
    r.margin = 0x1.0p-19 * D + 0x1.0p-18 * (D + o_max);
    r.usable = finite && std::isfinite(r.margin);
    return r;
}

void ReferenceBvh::enter(const BoxRay& r, const Node& n, double& t0, double& t1) const {
    t0 = -std::numeric_limits<double>::infinity();
    t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        const double lo = n.lo[a] - r.margin, hi = n.hi[a] + r.margin;
        if (r.zero[a]) {
            // Parallel to the slab: inside it for every t, or never.
            if (r.o[a] < lo || r.o[a] > hi) {
                t0 = std::numeric_limits<double>::infinity();
                t1 = -std::numeric_limits<double>::infinity();
                return;
            }
            continue;
        }
        double ta = (lo - r.o[a]) * r.inv[a], tb = (hi - r.o[a]) * r.inv[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
}

}  // namespace octray
