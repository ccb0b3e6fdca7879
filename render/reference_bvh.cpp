// The reference's binary BVH: an object-median builder and the per-ray box test
// (reference_bvh.h derives the margin that keeps it exact).

#include "render/reference_bvh.h"

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

// The builder works on a copy of the spheres (centers, radii, object indices), so that its
// passes read contiguous memory; the tree keeps only the object indices in leaf order.
ReferenceBvh::ReferenceBvh(std::span<const Object> objects) {
    std::vector<Prim> prims;
    for (std::uint32_t k = 0; k < objects.size(); ++k) {
        const Object& o = objects[k];
        if (o.type != ObjectType::sphere) continue;
        prims.push_back({{o.center.x, o.center.y, o.center.z}, o.radius, k});
    }
    if (prims.empty()) return;
    // A median split leaves ceil(n / 2) spheres on the larger side: about n / 2 leaves
    // below n / kLeafSize nodes each level, 2n / kLeafSize nodes at most in all.
    nodes_.reserve(2 * (prims.size() / kLeafSize + 1));
    nodes_.emplace_back();
    build_node(0, prims, 0, static_cast<std::uint32_t>(prims.size()), 1);
    spheres_.reserve(prims.size());
    for (const Prim& p : prims) spheres_.push_back(p.object);
}

void ReferenceBvh::build_node(std::uint32_t node, std::vector<Prim>& prims, std::uint32_t first,
                              std::uint32_t count, int level) {
    if (level > kMaxDepth) throw std::logic_error("ReferenceBvh: tree deeper than kMaxDepth");
    depth_ = std::max(depth_, level);

    // The node's box (the spheres' boxes) and the box of their centers (the split's).
    float lo[3], hi[3], clo[3], chi[3];
    for (int a = 0; a < 3; ++a) {
        lo[a] = clo[a] = std::numeric_limits<float>::infinity();
        hi[a] = chi[a] = -std::numeric_limits<float>::infinity();
    }
    for (std::uint32_t i = first; i < first + count; ++i) {
        const Prim& p = prims[i];
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], box_lo(p.c[a], p.r));
            hi[a] = std::max(hi[a], box_hi(p.c[a], p.r));
            clo[a] = std::min(clo[a], p.c[a]);
            chi[a] = std::max(chi[a], p.c[a]);
        }
    }
    for (int a = 0; a < 3; ++a) nodes_[node].lo[a] = lo[a], nodes_[node].hi[a] = hi[a];

    if (count <= kLeafSize) {
        nodes_[node].first = first;
        nodes_[node].count = count;
        return;
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

    const auto children = static_cast<std::uint32_t>(nodes_.size());
    nodes_.emplace_back();
    nodes_.emplace_back();
    nodes_[node].first = children;
    nodes_[node].count = 0;
    build_node(children, prims, first, half, level + 1);
    build_node(children + 1, prims, first + half, count - half, level + 1);
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
