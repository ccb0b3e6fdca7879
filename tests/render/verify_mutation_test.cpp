// The reference stays an independent check: a deliberate bug in the kernels' BVH (a child
// skipped, boxes shrunk) changes the packet path's image of a large scene, and the
// comparison `octray verify` makes (every pixel against the reference, which finds its
// spheres through a BVH of its own) catches it. The broken trees are fed to the real
// kernels through a kernel table whose closest_hit and any_hit swap the tree in the scene
// view for a mutated copy; the same harness with an unmutated copy matches to the bit.

#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <vector>

#include "kernels/dispatch.h"
#include "render/packet_renderer.h"
#include "render/prepare/bvh_build.h"
#include "render/reference.h"
#include "scene/compile.h"
#include "scene/load.h"

namespace octray {
namespace {

// The tree the kernels walk while a test runs (the kernel table holds plain functions).
struct BrokenTree {
    SphereBvh bvh;  // its spheres in leaf order
    std::vector<BvhNode8> nodes;
    const kernels::KernelTable* real = nullptr;
};
BrokenTree* g_tree = nullptr;

kernels::SceneView with_broken_tree(const kernels::SceneView& s) {
    kernels::SceneView v = s;
    v.bvh_nodes = g_tree->nodes.data();
    v.bvh_cx = g_tree->bvh.cx.data(), v.bvh_cy = g_tree->bvh.cy.data();
    v.bvh_cz = g_tree->bvh.cz.data(), v.bvh_r2 = g_tree->bvh.r2.data();
    v.bvh_object = g_tree->bvh.object.data();
    return v;
}

void broken_closest_hit(const kernels::SceneView& s, const kernels::RayStream& rays,
                        std::uint32_t count, float t_min, const kernels::HitStream& hits) {
    g_tree->real->closest_hit(with_broken_tree(s), rays, count, t_min, hits);
}

void broken_any_hit(const kernels::SceneView& s, const kernels::ShadowStream& rays,
                    std::uint32_t count, std::uint32_t* occluded) {
    g_tree->real->any_hit(with_broken_tree(s), rays, count, occluded);
}

// Pixels of the packet path's image, with the kernels' tree changed by `mutate`, that
// differ from the reference's image of the same scene.
std::size_t pixels_caught(const Scene& scene, const std::function<void(BrokenTree&)>& mutate) {
    const CompiledScene compiled = compile_scene(scene);
    BrokenTree tree;
    tree.bvh = build_sphere_bvh(compiled.spheres);
    tree.nodes.assign(tree.bvh.nodes.begin(), tree.bvh.nodes.end());
    tree.real = &kernel_table(resolve_isa(Isa::automatic));
    mutate(tree);
    kernels::KernelTable table = *tree.real;
    table.closest_hit = broken_closest_hit;
    table.any_hit = broken_any_hit;

    g_tree = &tree;
    RenderOptions options;
    options.accel = Accel::bvh;
    const RenderResult simd = render_packet(compiled, options, table);
    g_tree = nullptr;
    const RenderResult ref = render_reference(scene, {});
    EXPECT_EQ(simd.image.pixel_count(), ref.image.pixel_count());
    std::size_t differ = 0;
    for (std::size_t k = 0; k < ref.image.pixel_count(); ++k)
        differ += rgb_at(ref.image, k) == rgb_at(simd.image, k) ? 0 : 1;
    return differ;
}

bool is_leaf(std::uint32_t child) { return child != kBvhEmpty && (child & kBvhLeafBit) != 0; }

class VerifyMutation : public ::testing::Test {
  protected:
    void SetUp() override { scene = load_scene("random:16384,width=160,height=90"); }
    Scene scene;
};

TEST_F(VerifyMutation, TheHarnessWithAnIntactTreeMatchesTheReference) {
    EXPECT_EQ(pixels_caught(scene, [](BrokenTree&) {}), 0u);
}

TEST_F(VerifyMutation, ASkippedChildIsCaught) {
    // The root's second child and everything under it are never visited.
    const std::size_t caught = pixels_caught(scene, [](BrokenTree& t) {
        BvhNode8& root = t.nodes[0];
        ASSERT_NE(root.child[1], kBvhEmpty);
        root.child[1] = kBvhEmpty;
        root.min_x[1] = root.min_y[1] = root.min_z[1] = kInfinity;
        root.max_x[1] = root.max_y[1] = root.max_z[1] = -kInfinity;
    });
    EXPECT_GT(caught, 0u);
}

TEST_F(VerifyMutation, LeafBoxesShrunkByAFewPercentAreCaught) {
    // Every leaf's box loses 5 % of its width on its +x side: spheres still lie mostly
    // inside, and only rays entering through the lost sliver miss them.
    std::size_t shrunk = 0;
    const std::size_t caught = pixels_caught(scene, [&](BrokenTree& t) {
        for (BvhNode8& n : t.nodes)
            for (std::uint32_t i = 0; i < kBvhWidth; ++i)
                if (is_leaf(n.child[i])) {
                    n.max_x[i] -= 0.05f * (n.max_x[i] - n.min_x[i]);
                    ++shrunk;
                }
    });
    EXPECT_GT(shrunk, 0u);
    EXPECT_GT(caught, 0u);
}

}  // namespace
}  // namespace octray
