#pragma once
// Small scenes built in code for the renderer tests (no loader involved).

#include "scene/scene.h"

namespace octray::testing {

inline Scene empty_scene(int width = 33, int height = 33) {
    Scene s;
    s.source = "test";
    s.image = {width, height, 1};
    s.camera.eye = {0, 0, 5};
    s.camera.lookat = {0, 0, 0};
    s.camera.up = {0, 1, 0};
    s.camera.fov = 60;
    s.background = {BackgroundType::constant, Rgb(0.0f), {}, {}};
    s.materials.push_back({"default", Material{}});
    return s;
}

inline std::uint32_t add_material(Scene& s, const Material& m) {
    s.materials.push_back({"", m});
    return static_cast<std::uint32_t>(s.materials.size() - 1);
}

inline void add_sphere(Scene& s, Vec3 center, float radius, std::uint32_t material = 0) {
    Object o;
    o.type = ObjectType::sphere;
    o.center = center;
    o.radius = radius;
    o.material = material;
    s.objects.push_back(o);
}

inline void add_plane(Scene& s, Vec3 point, Vec3 normal, std::uint32_t material = 0) {
    Object o;
    o.type = ObjectType::plane;
    o.point = point;
    o.normal = normalize(normal);
    o.material = material;
    s.objects.push_back(o);
}

inline void add_point_light(Scene& s, Vec3 position, Rgb color, bool inverse_square = false) {
    Light l;
    l.type = LightType::point;
    l.position = position;
    l.color = color;
    l.inverse_square = inverse_square;
    s.lights.push_back(l);
}

inline void add_directional_light(Scene& s, Vec3 direction, Rgb color) {
    Light l;
    l.type = LightType::directional;
    l.direction = direction;
    l.color = color;
    s.lights.push_back(l);
}

}  // namespace octray::testing
