// scene_to_json: what it writes reads back through parse_scene_json as the identical
// Scene, field by field and float by float (bit patterns, so -0 and 0 differ too).

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <limits>
#include <string>

#include "scene/builtin.h"
#include "scene/load.h"

namespace octray {
namespace {

#define EXPECT_SAME_FLOAT(a, b)                                                               \
    EXPECT_EQ(std::bit_cast<std::uint32_t>(float(a)), std::bit_cast<std::uint32_t>(float(b))) \
        << #a << " = " << (a) << " vs " << (b)

void expect_same(Vec3 a, Vec3 b, const std::string& what) {
    SCOPED_TRACE(what);
    EXPECT_SAME_FLOAT(a.x, b.x);
    EXPECT_SAME_FLOAT(a.y, b.y);
    EXPECT_SAME_FLOAT(a.z, b.z);
}

void expect_same(Rgb a, Rgb b, const std::string& what) {
    SCOPED_TRACE(what);
    EXPECT_SAME_FLOAT(a.r, b.r);
    EXPECT_SAME_FLOAT(a.g, b.g);
    EXPECT_SAME_FLOAT(a.b, b.b);
}

void expect_same_material(const Material& a, const Material& b, const std::string& what) {
    SCOPED_TRACE(what);
    expect_same(a.color, b.color, "color");
    EXPECT_SAME_FLOAT(a.kd, b.kd);
    EXPECT_SAME_FLOAT(a.ks, b.ks);
    EXPECT_SAME_FLOAT(a.shininess, b.shininess);
    expect_same(a.reflect, b.reflect, "reflect");
    EXPECT_SAME_FLOAT(a.transmit, b.transmit);
    EXPECT_SAME_FLOAT(a.ior, b.ior);
    ASSERT_EQ(a.checker.has_value(), b.checker.has_value());
    if (a.checker) {
        expect_same(a.checker->color, b.checker->color, "checker.color");
        EXPECT_SAME_FLOAT(a.checker->size, b.checker->size);
    }
}

// Every field but `source` (which names where a scene came from).
void expect_same_scene(const Scene& a, const Scene& b) {
    EXPECT_EQ(a.image.width, b.image.width);
    EXPECT_EQ(a.image.height, b.image.height);
    EXPECT_EQ(a.image.spp, b.image.spp);

    EXPECT_EQ(a.camera.type, b.camera.type);
    expect_same(a.camera.eye, b.camera.eye, "camera.eye");
    expect_same(a.camera.lookat, b.camera.lookat, "camera.lookat");
    expect_same(a.camera.up, b.camera.up, "camera.up");
    EXPECT_SAME_FLOAT(a.camera.fov, b.camera.fov);
    EXPECT_SAME_FLOAT(a.camera.width, b.camera.width);
    EXPECT_SAME_FLOAT(a.camera.aperture, b.camera.aperture);
    EXPECT_SAME_FLOAT(a.camera.focus_distance, b.camera.focus_distance);

    EXPECT_EQ(a.background.type, b.background.type);
    if (a.background.type == BackgroundType::constant) {
        expect_same(a.background.color, b.background.color, "background.color");
    } else {
        expect_same(a.background.bottom, b.background.bottom, "background.bottom");
        expect_same(a.background.top, b.background.top, "background.top");
    }
    expect_same(a.ambient, b.ambient, "ambient");

    EXPECT_EQ(a.render.max_depth, b.render.max_depth);
    EXPECT_EQ(a.render.seed, b.render.seed);
    ASSERT_EQ(a.render.epsilon.has_value(), b.render.epsilon.has_value());
    if (a.render.epsilon) {
        EXPECT_SAME_FLOAT(*a.render.epsilon, *b.render.epsilon);
    }

    ASSERT_EQ(a.materials.size(), b.materials.size());
    for (std::size_t i = 0; i < a.materials.size(); ++i) {
        EXPECT_EQ(a.materials[i].name, b.materials[i].name);
        expect_same_material(a.materials[i].material, b.materials[i].material,
                             "materials[" + std::to_string(i) + "]");
    }

    ASSERT_EQ(a.objects.size(), b.objects.size());
    for (std::size_t i = 0; i < a.objects.size(); ++i) {
        SCOPED_TRACE("objects[" + std::to_string(i) + "]");
        const Object& p = a.objects[i];
        const Object& q = b.objects[i];
        ASSERT_EQ(p.type, q.type);
        EXPECT_EQ(p.name, q.name);
        EXPECT_EQ(p.material, q.material);
        if (p.type == ObjectType::sphere) {
            expect_same(p.center, q.center, "center");
            EXPECT_SAME_FLOAT(p.radius, q.radius);
        } else {
            expect_same(p.point, q.point, "point");
            expect_same(p.normal, q.normal, "normal");
        }
    }

    ASSERT_EQ(a.lights.size(), b.lights.size());
    for (std::size_t i = 0; i < a.lights.size(); ++i) {
        SCOPED_TRACE("lights[" + std::to_string(i) + "]");
        const Light& p = a.lights[i];
        const Light& q = b.lights[i];
        ASSERT_EQ(p.type, q.type);
        if (p.type == LightType::point) {
            expect_same(p.position, q.position, "position");
            EXPECT_EQ(p.inverse_square, q.inverse_square);
        } else {
            expect_same(p.direction, q.direction, "direction");
        }
        expect_same(p.color, q.color, "color");
    }
}

void expect_round_trip(const Scene& scene) {
    const std::string text = scene_to_json(scene);
    const Scene back = parse_scene_json(text, "written.json");
    expect_same_scene(scene, back);
    // Writing is a fixed point: the second pass prints the same text.
    EXPECT_EQ(scene_to_json(back), text);
}

TEST(SceneWrite, RoundTripWhitted) { expect_round_trip(make_builtin_scene("whitted")); }

TEST(SceneWrite, RoundTripRandom16) { expect_round_trip(make_builtin_scene("random:16")); }

TEST(SceneWrite, RoundTripSphereflake2) {
    expect_round_trip(make_builtin_scene("sphereflake:2"));
}

TEST(SceneWrite, RoundTripOverriddenBuiltin) {
    expect_round_trip(
        make_builtin_scene("random:5,width=33,height=17,spp=5,seed=9,max_depth=2"));
}

// A scene that uses every feature of the format.
const char* const kEveryFeature = R"json({
  "image":  { "width": 321, "height": 123, "spp": 16 },
  "camera": { "type": "thinlens", "eye": [0.1, 1.3, 5.7], "lookat": [0, 0.5, -0.3],
              "up": [0.01, 1, 0], "fov": 47.5, "aperture": 0.05, "focus_distance": 5.3 },
  "background": { "type": "gradient", "bottom": [1, 0.9, 0.8], "top": [0.5, 0.7, 1.0] },
  "ambient": [0.05, 0.06, 0.07],
  "render": { "max_depth": 9, "seed": 18446744073709551615, "epsilon": 3e-05 },
  "materials": {
    "zeta":   { "color": [0.9, 0.8, 0.7], "kd": 0.1, "ks": 0.5, "shininess": 64, "reflect": 0.8 },
    "glass":  { "color": 1, "kd": 0, "ks": 0.5, "shininess": 128,
                "reflect": [0.1, 0.2, 0.3], "transmit": 0.9, "ior": 1.33 },
    "floor":  { "color": [0.9, 0.9, 0.9], "checker": { "color": [0.1, 0.2, 0.1], "size": 0.7 } }
  },
  "objects": [
    { "type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "zeta", "name": "ball" },
    { "type": "sphere", "center": [-0.0, 1e-30, 3.4e38], "radius": 1e-3 },
    { "type": "plane", "point": [0, -0.25, 0], "normal": [0.3, 1, 0.2], "material": "floor",
      "name": "ground" },
    { "type": "sphere", "center": [2, 1, 0], "radius": 0.5, "material": "glass" },
    { "type": "sphere", "center": [-2, 1, 0.1], "radius": 0.25,
      "material": { "color": [1, 0, 0], "ks": 0.25, "checker": { "color": 0.5 } } },
    { "type": "sphere", "center": [3, 1, 0], "radius": 0.125 },
    { "type": "sphere", "center": [4, 1, 0], "radius": 0.125, "material": {} }
  ],
  "lights": [
    { "type": "point", "position": [5, 8, 5], "color": [1, 0.9, 0.8], "falloff": "inverse-square" },
    { "type": "point", "position": [-5, 8, 5], "color": 0.7 },
    { "type": "directional", "direction": [-1, -1, -0.5], "color": 0.3 }
  ]
})json";

TEST(SceneWrite, RoundTripEveryFeature) {
    const Scene s = parse_scene_json(kEveryFeature, "every.json");
    // Two objects without a material share the default one; an inline {} has its own.
    ASSERT_EQ(s.materials.size(), 6u);
    EXPECT_EQ(s.objects[1].material, 3u);
    EXPECT_EQ(s.objects[5].material, 3u);
    EXPECT_EQ(s.objects[4].material, 4u);
    EXPECT_EQ(s.objects[6].material, 5u);
    expect_round_trip(s);

    // Every other camera and background type.
    for (
        const char* camera :
        {R"({"type": "pinhole", "eye": [0, 1, 5], "lookat": [0, 0, 0], "fov": 33.3})",
         R"({"type": "orthographic", "eye": [0, 1, 5], "lookat": [0, 0, 0], "width": 7.1})",
         R"({"type": "fisheye", "eye": [0, 1, 5], "lookat": [0, 0, 0], "up": [0, 0, 1], "fov": 360})"}) {
        std::string text = kEveryFeature;
        const std::size_t start = text.find("{ \"type\": \"thinlens\"");
        const std::size_t end = text.find('}', start) + 1;
        text.replace(start, end - start, camera);
        const std::size_t bg = text.find("{ \"type\": \"gradient\"");
        text.replace(bg, text.find('}', bg) + 1 - bg,
                     R"({"type": "constant", "color": [0.2, 0.1, 0.3]})");
        SCOPED_TRACE(camera);
        expect_round_trip(parse_scene_json(text, "variant.json"));
    }
}

TEST(SceneWrite, FloatsAreExact) {
    // Many float bit patterns, including ones whose shortest decimal lies close to the
    // middle between two floats: each must come back bit for bit.
    Scene s = make_builtin_scene("random:1");
    s.objects.clear();
    SplitMix64 rng(2024);
    const auto any_finite = [&rng] {
        for (;;) {
            const auto bits = static_cast<std::uint32_t>(rng.next() >> 32);
            const float f = std::bit_cast<float>(bits);
            if (std::isfinite(f)) return f;
        }
    };
    for (int i = 0; i < 10000; ++i) {
        Object o;
        o.center = {any_finite(), any_finite(), any_finite()};
        o.radius = std::fabs(any_finite());
        if (o.radius == 0.0f) o.radius = std::numeric_limits<float>::denorm_min();
        o.material = 0;
        s.objects.push_back(o);
    }
    // Extremes written exactly too.
    Object extreme;
    extreme.center = {std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(),
                      std::numeric_limits<float>::denorm_min()};
    extreme.radius = std::numeric_limits<float>::min();
    s.objects.push_back(extreme);
    // Such spheres' bounding box overflows float; with render.epsilon given, the
    // self-intersection rule does not need the box, so the scene is valid.
    EXPECT_THROW(parse_scene_json(scene_to_json(s), "floats.json"), SceneError);
    s.render.epsilon = 1e-4f;
    expect_round_trip(s);
}

TEST(SceneWrite, WritesTheSeedAsAnIntegerAndNoAnimation) {
    Scene s = make_builtin_scene("whitted,seed=18446744073709551615");
    const std::string text = scene_to_json(s);
    EXPECT_NE(text.find("\"seed\":18446744073709551615"), std::string::npos) << text;
    EXPECT_EQ(text.find("animation"), std::string::npos);
    // Short decimals, not the float's 17-digit double expansion.
    EXPECT_NE(text.find("\"fov\":50"), std::string::npos) << text;
    EXPECT_NE(text.find("0.85"), std::string::npos) << text;
    EXPECT_EQ(text.find("0.850000"), std::string::npos) << text;
}

}  // namespace
}  // namespace octray
