// Prepare once, render many (PreparedScene::update, render/prepare/bvh_build.h
// refit_sphere_bvh): frames whose spheres move and change size, rendered from one prepared
// scene updated in place and refitted, are bit for bit the frames rendered from a fresh compile
// and build; a refit tree's boxes still hold their spheres and children; a pose that spreads
// the spheres far apart grows the tree's cost past the limit and rebuilds it.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "render/packet_renderer.h"
#include "render/prepare/bvh_build.h"
#include "scene/builtin.h"

namespace octray {
namespace {

// Every sphere moved by up to `step` along each axis and its radius scaled by 0.9 ... 1.1
// (a pose the animation could give: same objects, same order).
Scene moved(const Scene& scene, std::mt19937& rng, float step) {
    Scene s = scene;
    std::uniform_real_distribution<float> offset(-step, step), scale(0.9f, 1.1f);
    for (Object& o : s.objects) {
        if (o.type != ObjectType::sphere) continue;
        o.center = o.center + Vec3{offset(rng), offset(rng), offset(rng)};
        o.radius *= scale(rng);
    }
    return s;
}

bool same_bits(const Image& a, const Image& b) {
    return a.width() == b.width() && a.height() == b.height() && rgb_pixels(a) == rgb_pixels(b);
}

// Boxes that hold what they bound: each leaf's spheres (c -+ r), each inner child's boxes.
void expect_boxes_hold(const SphereBvh& bvh) {
    for (std::size_t k = 0; k < bvh.nodes.size(); ++k) {
        const BvhNode8& n = bvh.nodes[k];
        for (std::uint32_t j = 0; j < kBvhWidth; ++j) {
            const std::uint32_t child = n.child[j];
            if (child == kBvhEmpty) continue;
            const auto holds = [&](double lx, double ly, double lz, double hx, double hy,
                                   double hz) {
                return n.min_x[j] <= lx && n.min_y[j] <= ly && n.min_z[j] <= lz &&
                       n.max_x[j] >= hx && n.max_y[j] >= hy && n.max_z[j] >= hz;
            };
            if (child & kBvhLeafBit) {
                const std::uint32_t first = (child & ~kBvhLeafBit) >> kBvhLeafCountBits;
                const std::uint32_t count = (child & 7u) + 1;
                for (std::uint32_t i = first; i < first + count; ++i) {
                    const double r = std::sqrt(double(bvh.r2[i]));
                    EXPECT_TRUE(holds(bvh.cx[i] - r, bvh.cy[i] - r, bvh.cz[i] - r,
                                      bvh.cx[i] + r, bvh.cy[i] + r, bvh.cz[i] + r))
                        << "node " << k << " leaf " << j << " sphere " << i;
                }
            } else {
                const BvhNode8& c = bvh.nodes[child];
                for (std::uint32_t i = 0; i < kBvhWidth && c.child[i] != kBvhEmpty; ++i)
                    EXPECT_TRUE(holds(c.min_x[i], c.min_y[i], c.min_z[i], c.max_x[i],
                                      c.max_y[i], c.max_z[i]))
                        << "node " << k << " child " << j;
            }
        }
    }
}

TEST(Refit, MovingAndResizingSpheresRenderTheSameBitsAsAFreshBuild) {
    const Scene scene = make_builtin_scene("random:3000,width=64,height=36");
    PreparedScene prepared(scene, Accel::bvh, 2);
    ASSERT_NE(prepared.bvh(), nullptr);
    std::mt19937 rng(11);
    RenderOptions options;
    options.accel = Accel::bvh;
    Scene posed = scene;
    for (int frame = 1; frame <= 4; ++frame) {
        posed = moved(posed, rng, 0.02f);
        posed.camera.eye = posed.camera.eye + Vec3{0.5f, 0.2f, 0.0f};
        const PreparedScene::Update u = prepared.update(posed);
        EXPECT_FALSE(u.rebuilt) << "frame " << frame << ": cost grew " << u.cost_growth;
        expect_boxes_hold(*prepared.bvh());
        options.frame = static_cast<std::uint32_t>(frame);
        EXPECT_TRUE(same_bits(render_packet(prepared, options).image,
                              render_packet(posed, options).image))
            << "frame " << frame;
    }
}

TEST(Refit, APoseThatSpreadsTheSpheresRebuildsTheTree) {
    const Scene scene = make_builtin_scene("random:3000,width=64,height=36");
    PreparedScene prepared(scene, Accel::bvh, 2);
    // Every sphere swapped with a random other one's place: the leaves' spheres lie all
    // over the scene, and the refit boxes overlap everywhere.
    Scene posed = scene;
    std::mt19937 rng(3);
    std::vector<Vec3> centers;
    for (const Object& o : posed.objects)
        if (o.type == ObjectType::sphere) centers.push_back(o.center);
    std::shuffle(centers.begin(), centers.end(), rng);
    std::size_t k = 0;
    for (Object& o : posed.objects)
        if (o.type == ObjectType::sphere) o.center = centers[k++];
    const PreparedScene::Update u = prepared.update(posed);
    EXPECT_TRUE(u.rebuilt) << "cost grew only " << u.cost_growth;
    EXPECT_GT(u.cost_growth, PreparedScene::kRefitCostLimit);
    expect_boxes_hold(*prepared.bvh());
    EXPECT_TRUE(same_bits(render_packet(prepared, {}).image, render_packet(posed, {}).image));
    // Brute force (no tree) updates only the arrays.
    PreparedScene brute(scene, Accel::none);
    EXPECT_FALSE(brute.update(posed).rebuilt);
    EXPECT_TRUE(same_bits(render_packet(brute, {}).image, render_packet(posed, {}).image));
}

}  // namespace
}  // namespace octray
