// The built-in scenes of docs/scene-format.md: splitmix64 and random:N to the
// letter, sphereflake geometry, the whitted scene's framing, and the ",key=value" options.

#include "scene/builtin.h"

#include <gtest/gtest.h>
#include <oneapi/tbb/global_control.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <string>
#include <vector>

#include "scene/camera.h"
#include "scene/load.h"
#include "scene_diff.h"

namespace octray {
namespace {

void expect_error(const std::string& spec, const std::string& path,
                  std::initializer_list<std::string> needles) {
    try {
        make_builtin_scene(spec);
        ADD_FAILURE() << "expected a SceneError for " << spec;
    } catch (const SceneError& e) {
        const std::string what = e.what();
        EXPECT_EQ(e.file(), spec) << what;
        EXPECT_EQ(e.json_path(), path) << what;
        EXPECT_EQ(what.rfind(spec + ": ", 0), 0u) << what;
        if (!path.empty()) {
            EXPECT_NE(what.find(": " + path + ": "), std::string::npos) << what;
        }
        for (const std::string& n : needles) {
            EXPECT_NE(what.find(n), std::string::npos)
                << "missing \"" << n << "\" in: " << what;
        }
    }
}

// splitmix64 written out once more, straight from the spec's wording.
struct HandSplitMix {
    std::uint64_t state;
    std::uint64_t next() {
        state += 0x9E3779B97F4A7C15ull;
        std::uint64_t z = state;
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    float next_float() { return static_cast<float>(next() >> 40) / 16777216.0f; }
};

TEST(SceneBuiltin, SplitMix64KnownValues) {
    // From an independent implementation (Python integers), state starting at 1.
    SplitMix64 rng(1);
    EXPECT_EQ(rng.next(), 0x910A2DEC89025CC1ull);
    EXPECT_EQ(rng.next(), 0xBEEB8DA1658EEC67ull);
    EXPECT_EQ(rng.next(), 0xF893A2EEFB32555Eull);
    SplitMix64 f(1);
    EXPECT_EQ(f.next_float(), 9505325.0f / 16777216.0f);  // 0x910A2D = top 24 bits
    EXPECT_EQ(f.next_float(), 12512141.0f / 16777216.0f);

    SplitMix64 a(12345);
    HandSplitMix b{12345};
    for (int i = 0; i < 1000; ++i) ASSERT_EQ(a.next(), b.next());
}

TEST(SceneBuiltin, IsBuiltinScene) {
    EXPECT_TRUE(is_builtin_scene("whitted"));
    EXPECT_TRUE(is_builtin_scene("whitted,spp=4"));
    EXPECT_TRUE(is_builtin_scene("random:5"));
    EXPECT_TRUE(is_builtin_scene("random"));
    EXPECT_TRUE(is_builtin_scene("sphereflake:2,width=3"));
    EXPECT_FALSE(is_builtin_scene("scene.json"));
    EXPECT_FALSE(is_builtin_scene("randomx:5"));
    EXPECT_FALSE(is_builtin_scene("scenes/random:4.json"));
    EXPECT_FALSE(is_builtin_scene(""));
}

TEST(SceneBuiltin, RandomFollowsTheSpec) {
    const Scene s = make_builtin_scene("random:16");
    EXPECT_EQ(s.source, "random:16");
    ASSERT_EQ(s.objects.size(), 16u);

    // First sphere by hand: the first three outputs of splitmix64 from state 1, top 24
    // bits each, x = 2 * f - 1.
    EXPECT_EQ(s.objects[0].center.x, 2.0f * (9505325.0f / 16777216.0f) - 1.0f);
    EXPECT_EQ(s.objects[0].center.y, 2.0f * (12512141.0f / 16777216.0f) - 1.0f);
    EXPECT_EQ(s.objects[0].center.z, 2.0f * (16290722.0f / 16777216.0f) - 1.0f);
    EXPECT_NEAR(s.objects[0].center.x, 0.13312304, 1e-7);

    HandSplitMix rng{1};
    const float radius = static_cast<float>(0.6 * std::pow(16.0, -1.0 / 3.0));
    EXPECT_NEAR(radius, 0.6 / 2.5198421, 1e-6);
    for (const Object& o : s.objects) {
        EXPECT_EQ(o.type, ObjectType::sphere);
        const float x = 2.0f * rng.next_float() - 1.0f;
        const float y = 2.0f * rng.next_float() - 1.0f;
        const float z = 2.0f * rng.next_float() - 1.0f;
        EXPECT_EQ(o.center, (Vec3{x, y, z}));
        EXPECT_EQ(o.radius, radius);
        EXPECT_EQ(o.material, 0u);
    }
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].material.color, Rgb(0.8f));  // grey diffuse
    EXPECT_EQ(s.materials[0].material.kd, 1.0f);
    EXPECT_EQ(s.materials[0].material.ks, 0.0f);
    EXPECT_EQ(s.materials[0].material.reflect, Rgb(0.0f));

    EXPECT_EQ(s.camera.type, CameraType::pinhole);
    EXPECT_EQ(s.camera.eye, (Vec3{0, 0, 4}));
    EXPECT_EQ(s.camera.lookat, (Vec3{0, 0, 0}));
    EXPECT_EQ(s.camera.up, (Vec3{0, 1, 0}));
    EXPECT_EQ(s.camera.fov, 60.0f);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].type, LightType::point);
    EXPECT_EQ(s.lights[0].position, (Vec3{4, 6, 5}));
    EXPECT_EQ(s.lights[0].color, Rgb(1.0f));
    EXPECT_EQ(s.image.width, 1920);
    EXPECT_EQ(s.image.height, 1080);
    EXPECT_EQ(s.image.spp, 1);
    EXPECT_EQ(s.render.seed, 1u);
}

TEST(SceneBuiltin, RandomSeedStartsTheGenerator) {
    const Scene s = make_builtin_scene("random:1000,seed=77");
    EXPECT_EQ(s.render.seed, 77u);
    HandSplitMix rng{77};
    for (const Object& o : s.objects) {
        const float x = 2.0f * rng.next_float() - 1.0f;
        const float y = 2.0f * rng.next_float() - 1.0f;
        const float z = 2.0f * rng.next_float() - 1.0f;
        ASSERT_EQ(o.center, (Vec3{x, y, z}));
        ASSERT_GE(o.center.x, -1.0f);
        ASSERT_LT(o.center.x, 1.0f);
    }
    EXPECT_EQ(s.objects[0].radius, static_cast<float>(0.6 * std::pow(1000.0, -1.0 / 3.0)));
    // Seed 1 is the default: the same scene, bit for bit.
    const Scene a = make_builtin_scene("random:50");
    const Scene b = make_builtin_scene("random:50,seed=1");
    ASSERT_EQ(a.objects.size(), b.objects.size());
    for (std::size_t i = 0; i < a.objects.size(); ++i) {
        EXPECT_EQ(a.objects[i].center, b.objects[i].center);
    }
    EXPECT_EQ(a.render.seed, b.render.seed);
}

// Visits the sphereflake's spheres in the order the generator writes them (parent, then
// its 9 subtrees) and calls `edge` for every parent-child pair.
std::size_t walk_flake(std::size_t& next, int levels,
                       const std::function<void(std::size_t, std::size_t)>& edge) {
    const std::size_t me = next++;
    if (levels == 0) return me;
    for (int c = 0; c < 9; ++c) edge(me, walk_flake(next, levels - 1, edge));
    return me;
}

double distance(Vec3 a, Vec3 b) {
    const double dx = double(a.x) - b.x, dy = double(a.y) - b.y, dz = double(a.z) - b.z;
    return std::sqrt(dx * dx + dy * dy + dz * dz);
}

TEST(SceneBuiltin, SphereflakeFourHas7381TouchingSpheres) {
    const Scene s = make_builtin_scene("sphereflake:4");
    ASSERT_EQ(s.objects.size(), 7382u);
    EXPECT_EQ(s.objects[0].type, ObjectType::plane);
    EXPECT_EQ(s.objects[0].normal, (Vec3{0, 0, 1}));
    EXPECT_EQ(s.objects[0].point, (Vec3{0, 0, -0.5f}));
    std::size_t spheres = 0;
    for (const Object& o : s.objects) spheres += o.type == ObjectType::sphere;
    EXPECT_EQ(spheres, 7381u);

    // Spheres start at index 1, after the floor.
    const Object& root = s.objects[1];
    EXPECT_EQ(root.center, (Vec3{0, 0, 0}));
    EXPECT_EQ(root.radius, 0.5f);

    std::size_t next = 1, edges = 0;
    std::vector<std::vector<std::size_t>> children(s.objects.size());
    walk_flake(next, 4, [&](std::size_t parent, std::size_t child) {
        const Object& p = s.objects[parent];
        const Object& c = s.objects[child];
        const double touching = double(p.radius) + c.radius;
        EXPECT_NEAR(distance(p.center, c.center), touching, 1e-5 * touching)
            << "parent " << parent << " child " << child;
        EXPECT_NEAR(c.radius, p.radius / 3.0, 1e-7 * p.radius);
        children[parent].push_back(child);
        ++edges;
    });
    EXPECT_EQ(next, 7382u);
    EXPECT_EQ(edges, 7380u);

    // Siblings do not overlap, and none of them sits below its parent's equator.
    for (std::size_t parent = 1; parent < children.size(); ++parent) {
        const auto& kids = children[parent];
        for (std::size_t a = 0; a < kids.size(); ++a) {
            for (std::size_t b = a + 1; b < kids.size(); ++b) {
                const Object& ka = s.objects[kids[a]];
                const Object& kb = s.objects[kids[b]];
                EXPECT_GE(distance(ka.center, kb.center), 2.0 * ka.radius * (1.0 - 1e-5));
            }
        }
    }
    // The root's children: 6 on its equator (z = 0), 3 above it.
    int equator = 0, above = 0;
    for (std::size_t k : children[1]) {
        const float z = s.objects[k].center.z;
        if (std::fabs(z) < 1e-6f) ++equator;
        if (z > 0.1f) ++above;
    }
    EXPECT_EQ(equator, 6);
    EXPECT_EQ(above, 3);

    EXPECT_EQ(s.lights.size(), 3u);
    EXPECT_EQ(s.camera.up, (Vec3{0, 0, 1}));
    EXPECT_EQ(s.source, "sphereflake:4");
}

TEST(SceneBuiltin, SphereflakeLevels) {
    EXPECT_EQ(make_builtin_scene("sphereflake:0").objects.size(), 2u);
    EXPECT_EQ(make_builtin_scene("sphereflake:1").objects.size(), 11u);
    EXPECT_EQ(make_builtin_scene("sphereflake:2").objects.size(), 92u);
    EXPECT_EQ(make_builtin_scene("sphereflake:3").objects.size(), 821u);
}

// The film position of a point, by the pinhole formulas of the rendering model.
struct Film {
    double x, y, depth;
};
Film project(const Scene& s, Vec3 p) {
    const CameraFrame f = make_camera_frame(s.camera, s.image.width, s.image.height);
    const Vec3 d = p - s.camera.eye;
    const double depth = dot(d, f.ln);
    const double t = std::tan(s.camera.fov * 3.14159265358979 / 360.0);
    return {dot(d, f.u_hat) / depth / t, dot(d, f.v_hat) / depth / (t / f.aspect), depth};
}

TEST(SceneBuiltin, WhittedScene) {
    const Scene s = make_builtin_scene("whitted");
    EXPECT_EQ(s.image.width, 1280);
    EXPECT_EQ(s.image.height, 720);
    EXPECT_EQ(s.image.spp, 1);
    EXPECT_EQ(s.render.max_depth, 5);
    EXPECT_EQ(s.background.type, BackgroundType::gradient);
    EXPECT_EQ(s.lights.size(), 2u);
    for (const Light& l : s.lights) EXPECT_EQ(l.type, LightType::point);

    int planes = 0, mirrors = 0, glasses = 0, diffuse = 0;
    for (const Object& o : s.objects) {
        const Material& m = s.materials.at(o.material).material;
        if (o.type == ObjectType::plane) {
            ++planes;
            EXPECT_TRUE(m.checker.has_value());
            EXPECT_EQ(o.normal, (Vec3{0, 1, 0}));
            continue;
        }
        // Every sphere rests on the floor and is in the picture, in front of the camera.
        EXPECT_EQ(o.center.y, o.radius);
        const Film film = project(s, o.center);
        EXPECT_GT(film.depth, 0.0);
        EXPECT_LT(std::fabs(film.x), 0.9) << o.name;
        EXPECT_LT(std::fabs(film.y), 0.9) << o.name;
        if (m.transmit > 0.0f) {
            ++glasses;
            EXPECT_NEAR(m.transmit, 0.9f, 1e-6);
            EXPECT_EQ(m.ior, 1.5f);
            EXPECT_GT(max_component(m.reflect), 0.0f);
        } else if (max_component(m.reflect) >= 0.5f) {
            ++mirrors;
        } else {
            ++diffuse;
            EXPECT_GT(m.kd, 0.5f);
            EXPECT_NE(m.color.r, m.color.b);  // colored, not grey
        }
    }
    EXPECT_EQ(planes, 1);
    EXPECT_EQ(mirrors, 1);
    EXPECT_EQ(glasses, 1);
    EXPECT_EQ(diffuse, 1);
    // Looking down at the spheres from slightly above them.
    EXPECT_GT(s.camera.eye.y, s.camera.lookat.y);
}

TEST(SceneBuiltin, OverridesReplaceImageAndRenderSettings) {
    const Scene s = make_builtin_scene("random:16,width=640,height=360,spp=4,max_depth=3");
    EXPECT_EQ(s.image.width, 640);
    EXPECT_EQ(s.image.height, 360);
    EXPECT_EQ(s.image.spp, 4);
    EXPECT_EQ(s.render.max_depth, 3);
    EXPECT_EQ(s.objects.size(), 16u);
    const Scene w = make_builtin_scene("whitted,spp=9,seed=5,max_depth=0");
    EXPECT_EQ(w.image.width, 1280);
    EXPECT_EQ(w.image.spp, 9);
    EXPECT_EQ(w.render.seed, 5u);
    EXPECT_EQ(w.render.max_depth, 0);
    EXPECT_EQ(w.source, "whitted,spp=9,seed=5,max_depth=0");
    const Scene f =
        make_builtin_scene("sphereflake:1,width=64,height=48,seed=18446744073709551615");
    EXPECT_EQ(f.image.width, 64);
    EXPECT_EQ(f.render.seed, 18446744073709551615ull);
}

TEST(SceneBuiltinError, BadCountsAndLevels) {
    expect_error(
        "random", "",
        {"expected random:N with N a sphere count from 1 to 16777216", "found no count"});
    expect_error("random:0", "", {"from 1 to 16777216", "found \"0\""});
    expect_error("random:abc", "", {"from 1 to 16777216", "found \"abc\""});
    expect_error("random:16777217", "", {"found \"16777217\""});
    expect_error("random:99999999999999999999999", "", {"found \"99999999999999999999999\""});
    expect_error("random:-4", "", {"found \"-4\""});
    expect_error("sphereflake", "",
                 {"expected sphereflake:L with L a recursion level from 0 to 7"});
    expect_error("sphereflake:8", "", {"from 0 to 7", "found \"8\""});
    expect_error("sphereflake:-1", "", {"found \"-1\""});
    expect_error("whitted:3", "", {"whitted takes no argument"});
    expect_error("teapot", "",
                 {"unknown built-in scene \"teapot\"", "whitted, random:N or sphereflake:L"});
}

TEST(SceneBuiltinError, BadOptions) {
    expect_error(
        "random:16,depth=3", "depth",
        {"unknown option \"depth\"", "valid options: width, height, spp, seed, max_depth"});
    expect_error("whitted,width=0", "width",
                 {"expected an integer from 1 to 2147483647, found \"0\""});
    expect_error("whitted,width=12px", "width", {"expected an integer", "found \"12px\""});
    expect_error("whitted,height=-2", "height", {"found \"-2\""});
    expect_error("whitted,spp=", "spp", {"expected an integer from 1", "found \"\""});
    // Issue 38: one spp limit everywhere (a scene file's, `--spp`'s): 2^20.
    expect_error("whitted,spp=1048577", "spp", {"from 1 to 1048576", "found \"1048577\""});
    expect_error("whitted,max_depth=65", "max_depth", {"expected an integer from 0 to 64"});
    expect_error("whitted,seed=-1", "seed",
                 {"expected a non-negative integer", "found \"-1\""});
    expect_error("whitted,width=64,width=32", "width", {"option given twice"});
    expect_error("whitted,width", "width", {"expected key=value", "found \"width\""});
    expect_error("random:4,", "", {"empty option", "key=value"});
    // Each option is valid alone; together they make an image too large to allocate.
    expect_error("whitted,width=100000,height=100000", "image", {"10000000000 pixels"});
}

TEST(SceneBuiltin, LoadSceneDispatchesToGenerators) {
    const Scene s = load_scene("sphereflake:1,width=32,height=32");
    EXPECT_EQ(s.objects.size(), 11u);
    EXPECT_EQ(s.image.width, 32);
    EXPECT_EQ(s.source, "sphereflake:1,width=32,height=32");
}

// The big built-ins are generated in parallel (oneTBB); the scene must not depend on the
// thread count, and must be the serial definition's.

Scene built_with_threads(const std::string& spec, std::size_t threads) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    return make_builtin_scene(spec);
}

TEST(SceneBuiltin, ParallelGenerationIsTheSameForOneAndTwoThreads) {
    for (const char* spec : {"random:100000,seed=5", "sphereflake:5"}) {
        const Scene one = built_with_threads(spec, 1);
        const Scene two = built_with_threads(spec, 2);
        EXPECT_EQ(fuzz::first_scene_difference(one, two), "") << spec;
    }
}

TEST(SceneBuiltin, ParallelRandomIsTheSerialSequence) {
    const Scene s = built_with_threads("random:100000,seed=5", 2);
    ASSERT_EQ(s.objects.size(), 100000u);
    HandSplitMix rng{5};
    for (const Object& o : s.objects) {
        const float x = 2.0f * rng.next_float() - 1.0f;
        const float y = 2.0f * rng.next_float() - 1.0f;
        const float z = 2.0f * rng.next_float() - 1.0f;
        ASSERT_EQ(o.center, (Vec3{x, y, z}));
    }
}

TEST(SceneBuiltin, SplitMix64DiscardSkipsOutputs) {
    SplitMix64 skipped(99);
    skipped.discard(1000);
    HandSplitMix rng{99};
    for (int i = 0; i < 1000; ++i) (void)rng.next();
    for (int i = 0; i < 10; ++i) EXPECT_EQ(skipped.next(), rng.next());
}

// In depth-first order the children of the sphere at p (with `left` levels below it) are
// at p + 1 + c * size(left - 1): each touches its parent at a third of its radius. Level 5
// is generated in parallel from the root's children down.
TEST(SceneBuiltin, ParallelSphereflakeKeepsTheDepthFirstOrder) {
    const Scene s = built_with_threads("sphereflake:5", 2);
    const auto size = [](int levels) {
        std::size_t n = 0, k = 1;
        for (int l = 0; l <= levels; ++l, k *= 9) n += k;
        return n;
    };
    ASSERT_EQ(s.objects.size(), 1 + size(5));
    std::size_t checked = 0;
    const std::function<void(std::size_t, int)> visit = [&](std::size_t p, int left) {
        const Object& parent = s.objects[p];
        if (left == 0) return;
        for (std::size_t c = 0; c < 9; ++c) {
            const std::size_t at = p + 1 + c * size(left - 1);
            const Object& child = s.objects[at];
            EXPECT_FLOAT_EQ(child.radius, parent.radius / 3.0f) << at;
            const Vec3 d = child.center - parent.center;
            // Centers are rounded to float once: a few ulps of coordinates near 1.
            EXPECT_NEAR(std::sqrt(dot(d, d)), parent.radius * 4.0f / 3.0f,
                        4e-7f + 1e-5f * parent.radius)
                << at;
            ++checked;
            visit(at, left - 1);
        }
    };
    visit(1, 5);
    EXPECT_EQ(checked, size(5) - 1);
}

}  // namespace
}  // namespace octray
