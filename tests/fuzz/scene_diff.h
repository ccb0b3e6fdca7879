#pragma once
// first_scene_difference(a, b): the first field in which two scenes differ, bit for bit
// ("" when they are the same), for the fuzzers' round-trip invariant and the hardening
// tests. Floats are compared as bit patterns: scene_to_json promises a scene that reads
// back identical, so that rendering it gives a bit-identical image (-0 and +0 differ).
// `source` is not compared (it names where a scene came from); the animation block is.

#include <bit>
#include <cstdint>
#include <optional>
#include <string>

#include "scene/scene.h"

namespace octray::fuzz {

namespace detail {

inline bool same(float a, float b) {
    return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b);
}
inline bool same(Vec3 a, Vec3 b) { return same(a.x, b.x) && same(a.y, b.y) && same(a.z, b.z); }
inline bool same(Rgb a, Rgb b) { return same(a.r, b.r) && same(a.g, b.g) && same(a.b, b.b); }

inline std::string material_difference(const Material& a, const Material& b) {
    if (!same(a.color, b.color)) return "color";
    if (!same(a.kd, b.kd)) return "kd";
    if (!same(a.ks, b.ks)) return "ks";
    if (!same(a.shininess, b.shininess)) return "shininess";
    if (!same(a.reflect, b.reflect)) return "reflect";
    if (!same(a.transmit, b.transmit)) return "transmit";
    if (!same(a.ior, b.ior)) return "ior";
    if (a.checker.has_value() != b.checker.has_value()) return "checker (present)";
    if (a.checker && !same(a.checker->color, b.checker->color)) return "checker.color";
    if (a.checker && !same(a.checker->size, b.checker->size)) return "checker.size";
    return "";
}

template <typename T>
bool same_optional(const std::optional<T>& a, const std::optional<T>& b) {
    if (a.has_value() != b.has_value()) return false;
    return !a || same(*a, *b);
}

inline std::string animation_difference(const Animation& a, const Animation& b) {
    if (a.frames != b.frames) return "frames";
    if (std::bit_cast<std::uint64_t>(a.fps) != std::bit_cast<std::uint64_t>(b.fps))
        return "fps";
    if (a.camera.size() != b.camera.size()) return "camera (count)";
    for (std::size_t i = 0; i < a.camera.size(); ++i) {
        const std::string at = "camera[" + std::to_string(i) + "]";
        const CameraKey &p = a.camera[i], &q = b.camera[i];
        if (p.frame != q.frame) return at + ".frame";
        if (!same_optional(p.eye, q.eye)) return at + ".eye";
        if (!same_optional(p.lookat, q.lookat)) return at + ".lookat";
        if (!same_optional(p.up, q.up)) return at + ".up";
        if (!same_optional(p.fov, q.fov)) return at + ".fov";
    }
    if (a.objects.size() != b.objects.size()) return "objects (count)";
    for (std::size_t i = 0; i < a.objects.size(); ++i) {
        const std::string at = "objects[" + std::to_string(i) + "]";
        const ObjectTrack &p = a.objects[i], &q = b.objects[i];
        if (p.name != q.name) return at + ".name";
        if (p.object != q.object) return at + ".object";
        if (p.keys.size() != q.keys.size()) return at + " (key count)";
        for (std::size_t k = 0; k < p.keys.size(); ++k) {
            const std::string kat = at + "[" + std::to_string(k) + "]";
            if (p.keys[k].frame != q.keys[k].frame) return kat + ".frame";
            if (!same_optional(p.keys[k].center, q.keys[k].center)) return kat + ".center";
            if (!same_optional(p.keys[k].radius, q.keys[k].radius)) return kat + ".radius";
        }
    }
    return "";
}

}  // namespace detail

inline std::string first_scene_difference(const Scene& a, const Scene& b) {
    using detail::same;
    if (a.image.width != b.image.width) return "image.width";
    if (a.image.height != b.image.height) return "image.height";
    if (a.image.spp != b.image.spp) return "image.spp";

    const Camera &ca = a.camera, &cb = b.camera;
    if (ca.type != cb.type) return "camera.type";
    if (!same(ca.eye, cb.eye)) return "camera.eye";
    if (!same(ca.lookat, cb.lookat)) return "camera.lookat";
    if (!same(ca.up, cb.up)) return "camera.up";
    if (!same(ca.fov, cb.fov)) return "camera.fov";
    if (!same(ca.width, cb.width)) return "camera.width";
    if (!same(ca.aperture, cb.aperture)) return "camera.aperture";
    if (!same(ca.focus_distance, cb.focus_distance)) return "camera.focus_distance";
    if (ca.fov_units_stated != cb.fov_units_stated) return "camera.fov_units";

    if (a.background.type != b.background.type) return "background.type";
    if (a.background.type == BackgroundType::constant) {
        if (!same(a.background.color, b.background.color)) return "background.color";
    } else {
        if (!same(a.background.bottom, b.background.bottom)) return "background.bottom";
        if (!same(a.background.top, b.background.top)) return "background.top";
    }
    if (!same(a.ambient, b.ambient)) return "ambient";

    if (a.render.max_depth != b.render.max_depth) return "render.max_depth";
    if (a.render.seed != b.render.seed) return "render.seed";
    if (a.render.epsilon.has_value() != b.render.epsilon.has_value()) return "render.epsilon";
    if (a.render.epsilon && !same(*a.render.epsilon, *b.render.epsilon))
        return "render.epsilon";

    if (a.materials.size() != b.materials.size()) return "materials (count)";
    for (std::size_t i = 0; i < a.materials.size(); ++i) {
        const std::string at = "materials[" + std::to_string(i) + "]";
        if (a.materials[i].name != b.materials[i].name) return at + ".name";
        const std::string d =
            detail::material_difference(a.materials[i].material, b.materials[i].material);
        if (!d.empty()) return at + "." + d;
    }

    if (a.objects.size() != b.objects.size()) return "objects (count)";
    for (std::size_t i = 0; i < a.objects.size(); ++i) {
        const std::string at = "objects[" + std::to_string(i) + "]";
        const Object &p = a.objects[i], &q = b.objects[i];
        if (p.type != q.type) return at + ".type";
        if (p.name != q.name) return at + ".name";
        if (p.material != q.material) return at + ".material";
        if (p.type == ObjectType::sphere) {
            if (!same(p.center, q.center)) return at + ".center";
            if (!same(p.radius, q.radius)) return at + ".radius";
        } else {
            if (!same(p.point, q.point)) return at + ".point";
            if (!same(p.normal, q.normal)) return at + ".normal";
        }
    }

    if (a.lights.size() != b.lights.size()) return "lights (count)";
    for (std::size_t i = 0; i < a.lights.size(); ++i) {
        const std::string at = "lights[" + std::to_string(i) + "]";
        const Light &p = a.lights[i], &q = b.lights[i];
        if (p.type != q.type) return at + ".type";
        if (p.type == LightType::point) {
            if (!same(p.position, q.position)) return at + ".position";
            if (p.inverse_square != q.inverse_square) return at + ".falloff";
        } else {
            if (!same(p.direction, q.direction)) return at + ".direction";
        }
        if (!same(p.color, q.color)) return at + ".color";
    }

    if (a.animation.has_value() != b.animation.has_value()) return "animation (present)";
    if (a.animation) {
        const std::string d = detail::animation_difference(*a.animation, *b.animation);
        if (!d.empty()) return "animation." + d;
    }
    return "";
}

}  // namespace octray::fuzz
