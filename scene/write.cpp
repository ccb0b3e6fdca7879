// A Scene back to the JSON of docs/scene-format.md, such that parse_scene_json
// returns the identical Scene: every field written, floats exact, materials in order.

#include <array>
#include <bit>
#include <charconv>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <system_error>
#include <vector>

#include "scene/load.h"

namespace octray {
namespace {

using Json = nlohmann::ordered_json;

// The shortest decimal that reads back as this float, stored as the double that decimal
// parses to: nlohmann prints that double as the same short text ("0.8", not
// "0.800000011920929"), and the loader's double-to-float conversion gives `f` back.
// Should the double's rounding to float ever land elsewhere (double rounding), fall back
// to the float's exact value, which always survives the trip.
Json number(float f) {
    std::array<char, 32> buf{};
    const auto printed = std::to_chars(buf.data(), buf.data() + buf.size(), f);
    double d = 0.0;
    const auto parsed = std::from_chars(buf.data(), printed.ptr, d);
    if (printed.ec == std::errc{} && parsed.ec == std::errc{} &&
        std::bit_cast<std::uint32_t>(static_cast<float>(d)) ==
            std::bit_cast<std::uint32_t>(f)) {
        return Json(d);
    }
    return Json(static_cast<double>(f));
}

Json vector(Vec3 v) { return Json::array({number(v.x), number(v.y), number(v.z)}); }

bool same_bits(float a, float b) {
    return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b);
}

// Grey colors are written as a bare number, as a person would write them.
Json color(Rgb c) {
    if (same_bits(c.r, c.g) && same_bits(c.g, c.b)) return number(c.r);
    return Json::array({number(c.r), number(c.g), number(c.b)});
}

bool same_material(const Material& a, const Material& b) {
    const auto same_rgb = [](Rgb x, Rgb y) {
        return same_bits(x.r, y.r) && same_bits(x.g, y.g) && same_bits(x.b, y.b);
    };
    if (a.checker.has_value() != b.checker.has_value()) return false;
    if (a.checker && !(same_rgb(a.checker->color, b.checker->color) &&
                       same_bits(a.checker->size, b.checker->size))) {
        return false;
    }
    return same_rgb(a.color, b.color) && same_bits(a.kd, b.kd) && same_bits(a.ks, b.ks) &&
           same_bits(a.shininess, b.shininess) && same_rgb(a.reflect, b.reflect) &&
           same_bits(a.transmit, b.transmit) && same_bits(a.ior, b.ior);
}

Json material(const Material& m) {
    Json j = Json::object();
    j["color"] = color(m.color);
    j["kd"] = number(m.kd);
    j["ks"] = number(m.ks);
    j["shininess"] = number(m.shininess);
    j["reflect"] = color(m.reflect);
    j["transmit"] = number(m.transmit);
    j["ior"] = number(m.ior);
    if (m.checker) {
        j["checker"] =
            Json{{"color", color(m.checker->color)}, {"size", number(m.checker->size)}};
    }
    return j;
}

Json camera(const Camera& c) {
    static constexpr std::array<const char*, 4> types = {"pinhole", "orthographic", "thinlens",
                                                         "fisheye"};
    Json j = Json::object();
    j["type"] = types[static_cast<std::size_t>(c.type)];
    j["eye"] = vector(c.eye);
    j["lookat"] = vector(c.lookat);
    j["up"] = vector(c.up);
    switch (c.type) {
        case CameraType::pinhole:
        case CameraType::fisheye:
            j["fov"] = number(c.fov);
            break;
        case CameraType::orthographic:
            j["width"] = number(c.width);
            break;
        case CameraType::thinlens:
            j["fov"] = number(c.fov);
            j["aperture"] = number(c.aperture);
            j["focus_distance"] = number(c.focus_distance);
            break;
    }
    if (c.fov_units_stated && c.type != CameraType::orthographic) j["fov_units"] = "degrees";
    return j;
}

Json background(const Background& b) {
    if (b.type == BackgroundType::constant) {
        return Json{{"type", "constant"}, {"color", color(b.color)}};
    }
    return Json{{"type", "gradient"}, {"bottom", color(b.bottom)}, {"top", color(b.top)}};
}

Json light(const Light& l) {
    Json j = Json::object();
    if (l.type == LightType::point) {
        j["type"] = "point";
        j["position"] = vector(l.position);
        j["color"] = color(l.color);
        j["falloff"] = l.inverse_square ? "inverse-square" : "none";
    } else {
        j["type"] = "directional";
        j["direction"] = vector(l.direction);
        j["color"] = color(l.color);
    }
    return j;
}

std::string dump(const Json& j) {
    return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

// Only the properties a key sets, so that the scene's values still show through the others.
Json camera_key(const CameraKey& k) {
    Json j = Json::object();
    j["frame"] = k.frame;
    if (k.eye) j["eye"] = vector(*k.eye);
    if (k.lookat) j["lookat"] = vector(*k.lookat);
    if (k.up) j["up"] = vector(*k.up);
    if (k.fov) j["fov"] = number(*k.fov);
    return j;
}

Json object_key(const ObjectKey& k) {
    Json j = Json::object();
    j["frame"] = k.frame;
    if (k.center) j["center"] = vector(*k.center);
    if (k.radius) j["radius"] = number(*k.radius);
    return j;
}

// One key per line. fps is a double: nlohmann prints the shortest text that reads back
// as the same double.
std::string animation(const Animation& a) {
    std::string out = "  \"animation\": {\n";
    out += "    \"frames\": " + std::to_string(a.frames) + ",\n";
    out += "    \"fps\": " + dump(Json(a.fps));
    if (!a.camera.empty()) {
        out += ",\n    \"camera\": [";
        for (std::size_t i = 0; i < a.camera.size(); ++i) {
            out += i ? ",\n      " : "\n      ";
            out += dump(camera_key(a.camera[i]));
        }
        out += "\n    ]";
    }
    if (!a.objects.empty()) {
        out += ",\n    \"objects\": {";
        for (std::size_t t = 0; t < a.objects.size(); ++t) {
            const ObjectTrack& track = a.objects[t];
            out += t ? ",\n      " : "\n      ";
            out += dump(Json(track.name)) + ": [";
            for (std::size_t i = 0; i < track.keys.size(); ++i) {
                out += i ? ",\n        " : "\n        ";
                out += dump(object_key(track.keys[i]));
            }
            out += track.keys.empty() ? "]" : "\n      ]";
        }
        out += "\n    }";
    }
    out += "\n  }\n";
    return out;
}

}  // namespace

std::string scene_to_json(const Scene& scene) {
    // How many objects use each material: an unnamed (inline) material shared by several
    // objects is the loader's default material, which is written by leaving "material" out.
    std::vector<std::size_t> uses(scene.materials.size(), 0);
    for (const Object& o : scene.objects) {
        if (o.material < uses.size()) ++uses[o.material];
    }

    std::string out = "{\n";
    const auto field = [&out](const char* key, const Json& value, bool last = false) {
        out += "  \"" + std::string(key) + "\": " + dump(value) + (last ? "\n" : ",\n");
    };
    field("image", Json{{"width", scene.image.width},
                        {"height", scene.image.height},
                        {"spp", scene.image.spp}});
    field("camera", camera(scene.camera));
    field("background", background(scene.background));
    field("ambient", color(scene.ambient));
    Json render{{"max_depth", scene.render.max_depth}, {"seed", scene.render.seed}};
    if (scene.render.epsilon) render["epsilon"] = number(*scene.render.epsilon);
    field("render", render);

    // One material, object and light per line: large generated scenes stay diffable.
    out += "  \"materials\": {";
    bool first = true;
    for (const NamedMaterial& nm : scene.materials) {
        if (nm.name.empty()) continue;
        out += first ? "\n" : ",\n";
        out += "    " + dump(Json(nm.name)) + ": " + dump(material(nm.material));
        first = false;
    }
    out += first ? "},\n" : "\n  },\n";

    out += "  \"objects\": [";
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        const Object& o = scene.objects[i];
        Json j = Json::object();
        j["type"] = o.type == ObjectType::sphere ? "sphere" : "plane";
        if (!o.name.empty()) j["name"] = o.name;
        if (o.type == ObjectType::sphere) {
            j["center"] = vector(o.center);
            j["radius"] = number(o.radius);
        } else {
            j["point"] = vector(o.point);
            j["normal"] = vector(o.normal);
        }
        if (o.material < scene.materials.size()) {
            const NamedMaterial& nm = scene.materials[o.material];
            if (!nm.name.empty()) {
                j["material"] = nm.name;
            } else if (!(uses[o.material] > 1 && same_material(nm.material, Material{}))) {
                j["material"] = material(nm.material);
            }
        }
        out += (i ? ",\n    " : "\n    ") + dump(j);
    }
    out += scene.objects.empty() ? "],\n" : "\n  ],\n";

    out += "  \"lights\": [";
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        out += (i ? ",\n    " : "\n    ") + dump(light(scene.lights[i]));
    }
    out += scene.lights.empty() ? "]" : "\n  ]";
    if (scene.animation) {
        out += ",\n";
        out += animation(*scene.animation);
    } else {
        out += "\n";
    }
    out += "}\n";
    return out;
}

}  // namespace octray
