#pragma once
// The scenes the sphere BVH's tests share: the builder's
// (tests/render/prepare/bvh_build_test.cpp) and the traversal's
// (tests/kernels/bvh/bvh_traversal_test.cpp). Random and degenerate sphere sets: one sphere,
// all at one point, radii from 1e-6 to 1e3, spheres far apart along one axis, duplicates that
// tie, planes.

#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/vec3.h"
#include "scene/scene.h"

namespace octray::testing {

inline Object sphere(Vec3 c, float r) {
    Object o;
    o.type = ObjectType::sphere;
    o.center = c;
    o.radius = r;
    return o;
}

inline Object plane(Vec3 p, Vec3 n) {
    Object o;
    o.type = ObjectType::plane;
    o.point = p;
    o.normal = normalize(n);
    return o;
}

inline Scene scene_of(std::vector<Object> objects) {
    Scene s;
    s.image = {64, 48, 1};
    s.materials.push_back({"m", Material{}});
    s.objects = std::move(objects);
    return s;
}

// `count` spheres, centers uniform in [-spread, spread)^3, radii in [r_min, r_min + r_span).
inline std::vector<Object> random_spheres(std::mt19937& rng, int count, float spread,
                                          float r_min, float r_span) {
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f), u01(0.0f, 1.0f);
    std::vector<Object> o;
    for (int i = 0; i < count; ++i)
        o.push_back(sphere({spread * unit(rng), spread * unit(rng), spread * unit(rng)},
                           r_min + r_span * u01(rng)));
    return o;
}

// The scenes every test runs on: name and objects.
struct NamedScene {
    std::string name;
    Scene scene;
};

inline std::vector<NamedScene> test_scenes() {
    std::vector<NamedScene> out;
    std::mt19937 rng(12345);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f), u01(0.0f, 1.0f);
    out.push_back({"random", scene_of(random_spheres(rng, 700, 2.0f, 0.02f, 0.2f))});
    out.push_back({"one sphere", scene_of({sphere({0.3f, -0.2f, 0.1f}, 0.7f)})});
    {
        std::vector<Object> o;
        for (int i = 0; i < 40; ++i) o.push_back(sphere({0.5f, 0.5f, 0.5f}, 0.4f));
        out.push_back({"coincident", scene_of(o)});
    }
    {
        // Radii from 1e-6 to 1e3 (log-uniform), centers spread over a scale to match.
        std::vector<Object> o;
        for (int i = 0; i < 400; ++i) {
            const float r = std::pow(10.0f, -6.0f + 9.0f * u01(rng));
            o.push_back(sphere({3 * unit(rng), 3 * unit(rng), 3 * unit(rng)}, r));
        }
        for (int i = 0; i < 200; ++i)
            o.push_back(sphere({2 * unit(rng), 2 * unit(rng), 2 * unit(rng)},
                               std::pow(10.0f, -6.0f + 5.0f * u01(rng))));
        out.push_back({"radii 1e-6 to 1e3", scene_of(o)});
    }
    {
        // Far apart along x (exponentially), tiny along y and z.
        std::vector<Object> o;
        for (int i = 0; i < 300; ++i) {
            const float x = (i % 2 ? 1.0f : -1.0f) * std::pow(2.0f, 0.1f * i);
            o.push_back(sphere({x, 1e-3f * unit(rng), 1e-3f * unit(rng)}, 0.5f + u01(rng)));
        }
        out.push_back({"far apart along x", scene_of(o)});
    }
    {
        // Duplicates (exact ties between different objects) among planes, in mixed order.
        std::vector<Object> o;
        for (int i = 0; i < 150; ++i) {
            const Object s = sphere({unit(rng), unit(rng), unit(rng)}, 0.1f + 0.3f * u01(rng));
            o.push_back(s);
            if (i % 3 == 0) o.push_back(s);
            if (i % 50 == 0) o.push_back(plane({0, unit(rng), 0}, {unit(rng), 1, unit(rng)}));
        }
        out.push_back({"duplicates and planes", scene_of(o)});
    }
    {
        // Coordinates near the float range's end: box tests would overflow, so packets
        // fall back to brute force; ordinary spheres beside them still go through the tree.
        std::vector<Object> o;
        for (int i = 0; i < 60; ++i)
            o.push_back(sphere({unit(rng), unit(rng), unit(rng)}, 0.1f + 0.2f * u01(rng)));
        o.push_back(sphere({1e30f, -1e30f, 3e29f}, 1e18f));
        o.push_back(sphere({-2e30f, 1e29f, 0.0f}, 5e17f));
        out.push_back({"huge coordinates", scene_of(o)});
    }
    {
        // Tiny spheres far from the rays' origins: the brute force's quadratic rounds
        // heavily there (its hits are fuzzy).
        std::vector<Object> o;
        for (int i = 0; i < 500; ++i)
            o.push_back(sphere({0.01f * unit(rng), 0.01f * unit(rng), 0.01f * unit(rng)},
                               1e-6f + 1e-4f * u01(rng)));
        out.push_back({"tiny cluster", scene_of(o)});
    }
    return out;
}

// Large enough that the builder's tasks collapse subtrees of their own
// (render/prepare/bvh_build.cpp: 1024 spheres or more), whose nodes are appended and relocated.
inline NamedScene large_scene() {
    std::mt19937 rng(2026);
    return {"20000 spheres", scene_of(random_spheres(rng, 20000, 3.0f, 0.005f, 0.03f))};
}

}  // namespace octray::testing
