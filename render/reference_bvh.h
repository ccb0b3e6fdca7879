#pragma once
// The scalar reference's own acceleration structure: a plain binary BVH over the scene's
// spheres, built by an object-median split and walked one ray at a time, nearest child
// first. It lives with the reference and shares nothing with kernels/ (not the wide BVH,
// not its builder, not its traversal), so the reference stays an independent check.
//
// The tree only decides which spheres a ray is tested against; the test itself and the
// closest-hit rule (smallest t, ties to the lower file index) are the reference's, so a
// ray finds the same hit as when it tests every sphere. For that, a box test must never
// skip a sphere that the sphere test would report, and the sphere test rounds. With
// u = 2^-24 and O' = O - c, the robust form computes l = O' - (b/a)V to within ~9u|O'|,
// so a ray whose discriminant comes out >= 0 passes within r + 10u|O'| of the center, and
// the roots put the hit point within a few u|O'| of that ray's chord (a root of a nearly
// tangent ray is off by up to ~sqrt(u r |O'|) along the ray, which moves the point only
// ~u|O'|/2 off the sphere). So every box is widened, per ray, by
//   margin = 32u D + 64u (D + max|O_i|)
// where D is the distance from the ray's origin to the farthest corner of the root box
// (a bound on |O'| for every sphere): the first term is the sphere test's rounding with
// room to spare, the second the rounding of O - c and of the boxes' own coordinates. The
// box test itself runs in double, where its rounding is far below the margin. A hit point
// then lies inside its sphere's widened box, so the box's entry distance is at most the
// hit's t, and a box is skipped only when it starts beyond the best hit found so far
// (boxes that start exactly there are still visited: a tie goes to the lower index).
// A ray whose margin is not finite (an origin past float range) tests every sphere.

#include <algorithm>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "core/ray.h"
#include "scene/scene.h"

namespace octray {

class ReferenceBvh {
  public:
    // Spheres per leaf, at most.
    static constexpr std::uint32_t kLeafSize = 4;
    // Levels at most: median splits halve the spheres, so 2^32 of them need 31.
    static constexpr int kMaxDepth = 64;

    // Builds the tree over the spheres of `objects` (planes are not in it).
    explicit ReferenceBvh(std::span<const Object> objects);

    // Calls visit(k) for the object index k of every sphere whose widened box the ray meets
    // on [ray.t_min, best_t], nearest box first; best_t is read again before each box, so
    // the caller narrows the search by lowering it inside visit.
    template <class Visit>
    void closest(const Ray& ray, const float& best_t, Visit&& visit) const;

    // Calls visit(k) for the spheres whose widened box the ray meets on
    // [ray.t_min, ray.t_max] until visit returns true (an occluder); returns whether it did.
    template <class Visit>
    bool any(const Ray& ray, Visit&& visit) const;

    std::size_t node_count() const { return nodes_.size(); }
    std::size_t sphere_count() const { return spheres_.size(); }
    // Levels from the root to the deepest leaf (1 for a lone leaf; 0 without spheres).
    int depth() const { return depth_; }

  private:
    // An inner node has count 0 and its children at first and first + 1; a leaf has its
    // spheres at spheres_[first, first + count).
    struct Node {
        float lo[3], hi[3];
        std::uint32_t first = 0, count = 0;
    };

    // A ray as the box tests read it: origin, reciprocal direction, and the margin.
    struct BoxRay {
        double o[3], inv[3];
        bool zero[3];  // direction component exactly 0: the slab is a yes/no on the origin
        double margin;
        bool usable;  // false: the margin is not finite, test every sphere
    };

    BoxRay box_ray(const Ray& ray) const;
    // The ray's interval [t0, t1] inside node n's widened box, empty when t0 > t1.
    void enter(const BoxRay& r, const Node& n, double& t0, double& t1) const;

    // A sphere as the builder sorts it: its box, its center, its object index.
    struct Prim {
        float lo[3], hi[3], c[3];
        std::uint32_t object;
    };
    // Subtrees of at least this many spheres build their two halves on two threads.
    static constexpr std::uint32_t kParallelSpheres = 1u << 14;
    // Fills node `node` with prims[first, first + count) at depth `level` (the root's 1),
    // its descendants from node `below` on; returns the depth of its deepest leaf.
    int build_node(std::uint32_t node, std::uint32_t below, std::vector<Prim>& prims,
                   std::uint32_t first, std::uint32_t count, int level);
    // Nodes of a subtree over `count` spheres, itself included (memoised in
    // subtree_sizes_ while building).
    std::uint32_t subtree_nodes(std::uint32_t count);
    std::uint32_t known_subtree_nodes(std::uint32_t count) const;  // 0: not memoised
    std::vector<std::pair<std::uint32_t, std::uint32_t>> subtree_sizes_;

    std::vector<Node> nodes_;
    std::vector<std::uint32_t> spheres_;  // object indices in leaf order
    int depth_ = 0;
};

// ---- Traversal ----------------------------------------------------------------------------

template <class Visit>
void ReferenceBvh::closest(const Ray& ray, const float& best_t, Visit&& visit) const {
    if (nodes_.empty()) return;
    const BoxRay r = box_ray(ray);
    if (!r.usable) {
        for (const std::uint32_t k : spheres_) visit(k);
        return;
    }
    // Nodes to visit with the distance at which the ray enters them; the nearer child is
    // pushed last so that it is popped first. Each inner node pops one entry and pushes at
    // most two, so the stack never holds more than depth + 1 entries.
    struct Entry {
        std::uint32_t node;
        double t0;
    };
    Entry stack[kMaxDepth + 1];
    int top = 0;
    double t0 = 0.0, t1 = 0.0;
    enter(r, nodes_[0], t0, t1);
    if (!(std::max(t0, double{ray.t_min}) <= std::min(t1, double{best_t}))) return;
    stack[top++] = {0, t0};
    while (top > 0) {
        const Entry e = stack[--top];
        if (e.t0 > best_t) continue;  // a nearer hit was found since it was pushed
        const Node& n = nodes_[e.node];
        if (n.count > 0) {
            for (std::uint32_t s = n.first; s < n.first + n.count; ++s) visit(spheres_[s]);
            continue;
        }
        double a0 = 0.0, a1 = 0.0, b0 = 0.0, b1 = 0.0;
        enter(r, nodes_[n.first], a0, a1);
        enter(r, nodes_[n.first + 1], b0, b1);
        const double lo = ray.t_min, hi = best_t;
        const bool hit_a = std::max(a0, lo) <= std::min(a1, hi);
        const bool hit_b = std::max(b0, lo) <= std::min(b1, hi);
        if (hit_a && hit_b) {
            const bool a_first = a0 <= b0;
            stack[top++] = a_first ? Entry{n.first + 1, b0} : Entry{n.first, a0};
            stack[top++] = a_first ? Entry{n.first, a0} : Entry{n.first + 1, b0};
        } else if (hit_a) {
            stack[top++] = {n.first, a0};
        } else if (hit_b) {
            stack[top++] = {n.first + 1, b0};
        }
    }
}

template <class Visit>
bool ReferenceBvh::any(const Ray& ray, Visit&& visit) const {
    if (nodes_.empty()) return false;
    const BoxRay r = box_ray(ray);
    if (!r.usable) {
        for (const std::uint32_t k : spheres_)
            if (visit(k)) return true;
        return false;
    }
    const double lo = ray.t_min, hi = ray.t_max;
    std::uint32_t stack[kMaxDepth + 1];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& n = nodes_[stack[--top]];
        double t0 = 0.0, t1 = 0.0;
        enter(r, n, t0, t1);
        if (!(std::max(t0, lo) <= std::min(t1, hi))) continue;
        if (n.count > 0) {
            for (std::uint32_t s = n.first; s < n.first + n.count; ++s)
                if (visit(spheres_[s])) return true;
            continue;
        }
        stack[top++] = n.first + 1;
        stack[top++] = n.first;
    }
    return false;
}

}  // namespace octray
