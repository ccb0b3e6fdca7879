// The sphere BVH's builder (render/prepare/bvh_build.h) and the traversal policy the scene
// view carries (render/prepare/scene_view.h). Every sphere in exactly one leaf, leaves of
// 1-8 spheres, every child box holds its spheres (the exact spheres, in double precision)
// and its children's boxes, empty slots last and never entered, the same bytes for any
// thread count, leaves that are small parts of the root on spread-out spheres; secondary
// rays ray by ray in large and in dense scenes. The traversal:
// tests/kernels/bvh/bvh_traversal_test.cpp.

#include "render/prepare/bvh_build.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "render/prepare/scene_view.h"
#include "scene/compile.h"
#include "tests/kernels/bvh/bvh_test_scenes.h"

namespace octray {
namespace {

using kernels::kPacketWidth;
using testing::large_scene;
using testing::NamedScene;
using testing::plane;
using testing::random_spheres;
using testing::scene_of;
using testing::sphere;
using testing::test_scenes;

// ---------------------------------------------------------------------------------------
// Builder invariants.

struct DBox {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
};

bool box_contains(const BvhNode8& n, int j, const double lo[3], const double hi[3]) {
    return n.min_x[j] <= lo[0] && n.min_y[j] <= lo[1] && n.min_z[j] <= lo[2] &&
           n.max_x[j] >= hi[0] && n.max_y[j] >= hi[1] && n.max_z[j] >= hi[2];
}

double half_area(double dx, double dy, double dz) { return dx * dy + dy * dz + dz * dx; }

// Half the surface area of child j's box.
double child_half_area(const BvhNode8& n, int j) {
    return half_area(n.max_x[j] - n.min_x[j], n.max_y[j] - n.min_y[j], n.max_z[j] - n.min_z[j]);
}

// Walks the tree; returns the subtree's exact box and counts each sphere's leaves.
DBox check_node(const SphereBvh& bvh, std::uint32_t index, std::vector<int>& seen,
                std::uint32_t depth, std::uint32_t& max_depth) {
    max_depth = std::max(max_depth, depth);
    const BvhNode8& n = bvh.nodes.at(index);
    DBox all;
    bool empty_seen = false;
    double previous_area = INFINITY;
    for (int j = 0; j < 8; ++j) {
        const std::uint32_t ref = n.child[j];
        if (ref == kBvhEmpty) {
            empty_seen = true;
            EXPECT_EQ(n.min_x[j], INFINITY);
            EXPECT_EQ(n.max_x[j], -INFINITY);
            EXPECT_EQ(n.min_y[j], INFINITY);
            EXPECT_EQ(n.max_z[j], -INFINITY);
            continue;
        }
        EXPECT_FALSE(empty_seen) << "empty slots come last";
        // Largest box first (the any-hit traversals visit children in node order).
        const double area = child_half_area(n, j);
        EXPECT_LE(area, previous_area * (1.0 + 1e-6)) << "node " << index << " child " << j;
        previous_area = area;
        DBox box;
        if (ref & kBvhLeafBit) {
            const std::uint32_t first = (ref & ~kBvhLeafBit) >> kBvhLeafCountBits;
            const std::uint32_t count = (ref & 7u) + 1;
            EXPECT_LE(first + count, bvh.sphere_count);
            for (std::uint32_t i = first; i < first + count && i < bvh.sphere_count; ++i) {
                ++seen.at(i);
                const double r = std::sqrt(static_cast<double>(bvh.r2[i]));
                const double c[3] = {bvh.cx[i], bvh.cy[i], bvh.cz[i]};
                for (int a = 0; a < 3; ++a) {
                    box.lo[a] = std::min(box.lo[a], c[a] - r);
                    box.hi[a] = std::max(box.hi[a], c[a] + r);
                }
            }
        } else if (ref <= index || ref >= bvh.nodes.size()) {
            // (Not walked: a cycle would recurse forever.)
            ADD_FAILURE() << "node " << index << " child " << j << " refers to node " << ref
                          << ": children come after their parent, within the tree";
            continue;
        } else {
            box = check_node(bvh, ref, seen, depth + 1, max_depth);
        }
        EXPECT_TRUE(box_contains(n, j, box.lo, box.hi)) << "node " << index << " child " << j;
        for (int a = 0; a < 3; ++a) {
            all.lo[a] = std::min(all.lo[a], box.lo[a]);
            all.hi[a] = std::max(all.hi[a], box.hi[a]);
        }
    }
    EXPECT_NE(n.child[0], kBvhEmpty) << "a node has at least one child";
    return all;
}

// Parents contain children: every child box of an inner child lies in the parent's slot.
void check_nesting(const SphereBvh& bvh, std::uint32_t index) {
    const BvhNode8& n = bvh.nodes[index];
    for (int j = 0; j < 8; ++j) {
        const std::uint32_t ref = n.child[j];
        if (ref == kBvhEmpty || (ref & kBvhLeafBit) || ref <= index || ref >= bvh.nodes.size())
            continue;  // (check_node reports a child before its parent)
        const BvhNode8& c = bvh.nodes[ref];
        for (int k = 0; k < 8 && c.child[k] != kBvhEmpty; ++k) {
            const double lo[3] = {c.min_x[k], c.min_y[k], c.min_z[k]};
            const double hi[3] = {c.max_x[k], c.max_y[k], c.max_z[k]};
            EXPECT_TRUE(box_contains(n, j, lo, hi)) << "node " << index << " child " << j;
        }
        check_nesting(bvh, ref);
    }
}

// Every sphere in exactly one leaf, boxes that contain their spheres and children, the
// leaf arrays a permutation of the scene's spheres.
void check_invariants(const NamedScene& ns) {
    SCOPED_TRACE(ns.name);
    const CompiledScene c = compile_scene(ns.scene);
    const SphereBvh bvh = build_sphere_bvh(c.spheres);
    ASSERT_EQ(bvh.sphere_count, c.spheres.count);
    ASSERT_FALSE(bvh.nodes.empty());
    std::vector<int> seen(bvh.sphere_count, 0);
    std::uint32_t depth = 0;
    check_node(bvh, 0, seen, 1, depth);
    check_nesting(bvh, 0);
    EXPECT_EQ(depth, bvh.depth);
    for (std::uint32_t i = 0; i < bvh.sphere_count; ++i)
        EXPECT_EQ(seen[i], 1) << "sphere slot " << i << " in exactly one leaf";
    // The leaf arrays are a permutation of the scene's spheres, objects once each.
    std::vector<int> object_seen(c.objects.count, 0);
    std::vector<float> r2_of_object(c.objects.count, -1.0f);
    for (std::uint32_t i = 0; i < c.spheres.count; ++i)
        r2_of_object[c.spheres.object[i]] = c.spheres.r2[i];
    for (std::uint32_t i = 0; i < bvh.sphere_count; ++i) {
        const std::uint32_t obj = bvh.object[i];
        ASSERT_LT(obj, c.objects.count);
        ++object_seen[obj];
        EXPECT_FALSE(c.objects.is_plane(obj));
        EXPECT_EQ(bvh.cx[i], c.objects.center(obj).x);
        EXPECT_EQ(bvh.r2[i], r2_of_object[obj]);
    }
    for (std::uint32_t k = 0; k < c.objects.count; ++k)
        EXPECT_EQ(object_seen[k], c.objects.is_plane(k) ? 0 : 1) << "object " << k;
    // Padding: a packet of never-hit entries.
    ASSERT_EQ(bvh.cx.size(), bvh.sphere_count + 8u);
    EXPECT_TRUE(std::isnan(bvh.r2[bvh.sphere_count]));
    EXPECT_GT(bvh.memory_bytes(), 0u);
}

TEST(SphereBvh, Invariants) {
    for (const NamedScene& ns : test_scenes()) check_invariants(ns);
}

TEST(SphereBvh, InvariantsOfALargeTree) {
    const NamedScene ns = large_scene();
    check_invariants(ns);
    const SphereBvh bvh = build_sphere_bvh(compile_scene(ns.scene).spheres);
    EXPECT_GT(bvh.nodes.size(), 256u);
}

// Every box is tight: exactly the union of the rounded boxes of the spheres under it, which
// is what refitting the tree to the same spheres computes (refit_sphere_bvh). The 8-wide
// collapse takes a leaf's box from where the binary build left it (the leaf's unused slot),
// not from its spheres: a box left stale or taken from the wrong slot differs here, where
// the containment checks above pass any box that is merely too large.
void check_tight_boxes(const NamedScene& ns) {
    SCOPED_TRACE(ns.name);
    const CompiledScene c = compile_scene(ns.scene);
    const SphereBvh built = build_sphere_bvh(c.spheres);
    std::vector<std::uint32_t> compiled_index(c.objects.count, 0);
    for (std::uint32_t s = 0; s < c.spheres.count; ++s) compiled_index[c.spheres.object[s]] = s;
    std::vector<std::uint32_t> leaf_sphere(built.sphere_count);
    for (std::uint32_t i = 0; i < built.sphere_count; ++i)
        leaf_sphere[i] = compiled_index[built.object[i]];
    SphereBvh refitted = built;
    refit_sphere_bvh(refitted, c.spheres, leaf_sphere);
    ASSERT_EQ(built.nodes.size(), refitted.nodes.size());
    for (std::size_t k = 0; k < built.nodes.size(); ++k)
        ASSERT_EQ(0, std::memcmp(&built.nodes[k], &refitted.nodes[k], sizeof(BvhNode8)))
            << "node " << k;
    for (int a = 0; a < 3; ++a) {
        EXPECT_EQ(built.lo[a], refitted.lo[a]);
        EXPECT_EQ(built.hi[a], refitted.hi[a]);
    }
}

TEST(SphereBvh, BoxesAreTheUnionsOfTheirSpheres) {
    for (const NamedScene& ns : test_scenes()) check_tight_boxes(ns);
    check_tight_boxes(large_scene());
}

// The tree splits space, not the input order: on spheres spread uniformly in a cube, a
// leaf's box is a small part of the root's. A leaf of about five neighbouring spheres
// spans a few thousandths of the root's surface area (0.15 % here); five spheres taken in
// input order, as a builder that no longer bins would group them, span most of the cube
// on each axis (44 % with the bins' scale forced to 0). The bound lies far from both. It
// catches a builder that stops splitting space, not a slightly worse tree.
TEST(SphereBvh, LeavesAreSmallPartsOfTheRoot) {
    const NamedScene ns = large_scene();
    const SphereBvh bvh = build_sphere_bvh(compile_scene(ns.scene).spheres);
    const double root =
        half_area(bvh.hi[0] - bvh.lo[0], bvh.hi[1] - bvh.lo[1], bvh.hi[2] - bvh.lo[2]);
    double leaf_areas = 0.0;
    std::uint32_t leaves = 0;
    for (const BvhNode8& n : bvh.nodes)
        for (int j = 0; j < 8; ++j)
            if (n.child[j] != kBvhEmpty && (n.child[j] & kBvhLeafBit) != 0) {
                leaf_areas += child_half_area(n, j);
                ++leaves;
            }
    ASSERT_EQ(leaves, bvh.leaf_count);
    EXPECT_LT(leaf_areas / leaves / root, 0.05);
}

// Secondary rays go ray by ray from kBvhSecondaryRayByRayMinSpheres spheres on, unless
// told otherwise; smaller scenes and the other rays follow packet_min_lanes.
TEST(SphereBvh, SecondaryRaysGoRayByRayInLargeScenes) {
    for (const std::uint32_t count :
         {kBvhSecondaryRayByRayMinSpheres - 1, kBvhSecondaryRayByRayMinSpheres}) {
        std::vector<Object> o;
        for (std::uint32_t i = 0; i < count; ++i)
            o.push_back(sphere({static_cast<float>(i % 64), static_cast<float>(i / 64 % 64),
                                static_cast<float>(i / 4096)},
                               0.25f));
        const CompiledScene c = compile_scene(scene_of(o));
        const SphereBvh bvh = build_sphere_bvh(c.spheres);
        const bool large = count >= kBvhSecondaryRayByRayMinSpheres;
        EXPECT_EQ(make_scene_view(c, bvh, 3).bvh_packet_min_lanes, 3u);
        EXPECT_EQ(make_scene_view(c, bvh, 3).bvh_secondary_min_lanes,
                  large ? kPacketWidth + 1 : 3u)
            << count << " spheres";
        EXPECT_EQ(make_scene_view(c, bvh, 3, 5).bvh_secondary_min_lanes, 5u);
    }
}

// ... and from kBvhSecondaryRayByRayDenseMinSpheres on where a line through the scene
// crosses kBvhSecondaryRayByRayMinCrossings spheres or more: 32768 spheres on a 64 x 64 x 8
// grid (box area ~10240) cross 2.5 of radius 1/4 and 8.1 of radius 0.45.
TEST(SphereBvh, SecondaryRaysGoRayByRayInDenseScenes) {
    for (const std::uint32_t count :
         {kBvhSecondaryRayByRayDenseMinSpheres - 1, kBvhSecondaryRayByRayDenseMinSpheres})
        for (const float radius : {0.25f, 0.45f}) {
            std::vector<Object> o;
            for (std::uint32_t i = 0; i < count; ++i)
                o.push_back(sphere({static_cast<float>(i % 64), static_cast<float>(i / 64 % 64),
                                    static_cast<float>(i / 4096)},
                                   radius));
            const CompiledScene c = compile_scene(scene_of(o));
            const SphereBvh bvh = build_sphere_bvh(c.spheres);
            const double crossings =
                sphere_crossings(c.spheres.r2.data(), count, bvh.lo, bvh.hi);
            EXPECT_NEAR(crossings, radius < 0.3f ? 2.5 : 8.1, 0.1);
            const bool dense = count >= kBvhSecondaryRayByRayDenseMinSpheres && radius > 0.3f;
            EXPECT_EQ(make_scene_view(c, bvh, 3).bvh_secondary_min_lanes,
                      dense ? kPacketWidth + 1 : 3u)
                << count << " spheres of radius " << radius;
        }
}

TEST(SphereBvh, NoSpheresNoTree) {
    const CompiledScene c = compile_scene(scene_of({plane({0, 0, 0}, {0, 1, 0})}));
    const SphereBvh bvh = build_sphere_bvh(c.spheres);
    EXPECT_TRUE(bvh.nodes.empty());
    EXPECT_EQ(make_scene_view(c, bvh).bvh_nodes, nullptr);
}

// The same bytes whatever the number of threads (binning and subtrees run in parallel
// above a few thousand spheres, so the scene is large enough for that).
TEST(SphereBvh, DeterministicAcrossThreadCounts) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    std::vector<Object> o;
    for (int i = 0; i < 40000; ++i)
        o.push_back(sphere({unit(rng), unit(rng), 4 * unit(rng)}, 0.01f));
    for (int i = 0; i < 3000; ++i) o.push_back(sphere({0.25f, 0.25f, 0.25f}, 0.02f));
    const CompiledScene c = compile_scene(scene_of(o));
    const auto build = [&](int threads) {
        tbb::task_arena arena(threads);
        SphereBvh bvh;
        arena.execute([&] { bvh = build_sphere_bvh(c.spheres); });
        return bvh;
    };
    const SphereBvh one = build(1);
    for (int threads : {2, 3, 4}) {
        SCOPED_TRACE(threads);
        const SphereBvh other = build(threads);
        ASSERT_EQ(one.nodes.size(), other.nodes.size());
        EXPECT_EQ(0, std::memcmp(one.nodes.data(), other.nodes.data(),
                                 one.nodes.size() * sizeof(BvhNode8)));
        EXPECT_EQ(one.object, other.object);
        EXPECT_EQ(one.depth, other.depth);
        EXPECT_EQ(one.leaf_count, other.leaf_count);
    }
}

}  // namespace
}  // namespace octray
