// JSON scene files (docs/scene-format.md) into the authored Scene: the diagnosing reader
// (scene/load.h, parse_scene_json_diagnosing). Defaults and the rules are in
// docs/scene-format.md, what the code decides where it is silent in scene/README.md; every
// message names the file, the JSON path and what was expected.

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "scene/camera.h"
#include "scene/json_dom.h"
#include "scene/json_positions.h"
#include "scene/json_reader.h"
#include "scene/json_rules.h"
#include "scene/load.h"
#include "scene/read_animation.h"

namespace octray {
namespace {

using namespace scene_json;
using scene_json::kMaxDepthLimit;
using scene_json::kMaxIntValue;

constexpr std::array<std::string_view, 9> kTopKeys = {"image",   "camera", "background",
                                                      "ambient", "render", "materials",
                                                      "objects", "lights", "animation"};

void read_image(const Reader& r, const Json& j, ImageSettings& image) {
    static constexpr std::array<std::string_view, 3> keys = {"width", "height", "spp"};
    r.require_object(j, "image", "width, height, spp");
    r.check_keys(j, "image", keys);
    if (j.contains("width"))
        image.width = static_cast<int>(r.integer(j["width"], "image.width", 1, kMaxIntValue));
    if (j.contains("height"))
        image.height =
            static_cast<int>(r.integer(j["height"], "image.height", 1, kMaxIntValue));
    if (j.contains("spp"))
        image.spp = static_cast<int>(r.integer(j["spp"], "image.spp", 1, scene_json::kMaxSpp));
}

void read_camera(const Reader& r, const Json& j, Camera& camera) {
    const std::string path = "camera";
    r.require_object(j, path, "type, eye, lookat, up, ...");
    static constexpr std::array<std::string_view, 4> types = {"pinhole", "orthographic",
                                                              "thinlens", "fisheye"};
    if (j.contains("type")) {
        camera.type = static_cast<CameraType>(r.choice(j["type"], "camera.type", types));
    }
    static constexpr std::array<ForeignKey, 5> foreign = {
        ForeignKey{"fov", "pinhole, thinlens and fisheye cameras"},
        ForeignKey{"fov_units", "pinhole, thinlens and fisheye cameras"},
        ForeignKey{"width", "orthographic cameras"}, ForeignKey{"aperture", "thinlens cameras"},
        ForeignKey{"focus_distance", "thinlens cameras"}};
    std::vector<std::string_view> allowed = {"type", "eye", "lookat", "up"};
    switch (camera.type) {
        case CameraType::pinhole:
        case CameraType::fisheye:
            allowed.insert(allowed.end(), {"fov", "fov_units"});
            break;
        case CameraType::orthographic:
            allowed.push_back("width");
            break;
        case CameraType::thinlens:
            allowed.insert(allowed.end(), {"fov", "fov_units", "aperture", "focus_distance"});
            break;
    }
    const std::string kind =
        "a " + std::string(types[static_cast<std::size_t>(camera.type)]) + " camera";
    r.check_keys(j, path, allowed, foreign, kind);

    camera.eye =
        r.vec3(r.require_key(j, path, "eye", "the eye position [x, y, z]"), "camera.eye");
    camera.lookat = r.vec3(r.require_key(j, path, "lookat", "the look-at point [x, y, z]"),
                           "camera.lookat");
    if (j.contains("up")) camera.up = r.vec3(j["up"], "camera.up");
    if (j.contains("fov")) camera.fov = r.number(j["fov"], "camera.fov");
    if (j.contains("fov_units")) {
        // Always degrees: the key states that a small fov (scene_warnings) is meant.
        static constexpr std::array<std::string_view, 1> units = {"degrees"};
        static_cast<void>(r.choice(j["fov_units"], "camera.fov_units", units));
        camera.fov_units_stated = true;
    }
    if (j.contains("width")) camera.width = r.number(j["width"], "camera.width");
    if (camera.type == CameraType::thinlens) {
        camera.aperture =
            r.number(r.require_key(j, path, "aperture", "the lens radius (a number >= 0)"),
                     "camera.aperture");
        if (j.contains("focus_distance")) {
            camera.focus_distance = r.number(j["focus_distance"], "camera.focus_distance");
        } else {
            camera.focus_distance =
                scene_json::default_focus_distance(camera.eye, camera.lookat);
        }
    }
}

void read_background(const Reader& r, const Json& j, Background& bg) {
    const std::string path = "background";
    r.require_object(j, path, "type constant with color, or type gradient with bottom and top");
    static constexpr std::array<std::string_view, 2> types = {"constant", "gradient"};
    bg.type = static_cast<BackgroundType>(
        r.choice(r.require_key(j, path, "type", "\"constant\" or \"gradient\""),
                 "background.type", types));
    static constexpr std::array<ForeignKey, 3> foreign = {
        ForeignKey{"color", "constant backgrounds"},
        ForeignKey{"bottom", "gradient backgrounds"},
        ForeignKey{"top", "gradient backgrounds"}};
    if (bg.type == BackgroundType::constant) {
        static constexpr std::array<std::string_view, 2> keys = {"type", "color"};
        r.check_keys(j, path, keys, foreign, "a constant background");
        bg.color = r.color(r.require_key(j, path, "color", "a color [r, g, b] or a number"),
                           "background.color");
    } else {
        static constexpr std::array<std::string_view, 3> keys = {"type", "bottom", "top"};
        r.check_keys(j, path, keys, foreign, "a gradient background");
        bg.bottom = r.color(r.require_key(j, path, "bottom", "a color [r, g, b] or a number"),
                            "background.bottom");
        bg.top = r.color(r.require_key(j, path, "top", "a color [r, g, b] or a number"),
                         "background.top");
    }
}

void read_render(const Reader& r, const Json& j, RenderSettings& render) {
    static constexpr std::array<std::string_view, 3> keys = {"max_depth", "seed", "epsilon"};
    r.require_object(j, "render", "max_depth, seed, epsilon");
    r.check_keys(j, "render", keys);
    if (j.contains("max_depth")) {
        render.max_depth =
            static_cast<int>(r.integer(j["max_depth"], "render.max_depth", 0, kMaxDepthLimit));
    }
    if (j.contains("seed")) render.seed = r.unsigned64(j["seed"], "render.seed");
    if (j.contains("epsilon")) render.epsilon = r.number(j["epsilon"], "render.epsilon");
}

Material read_material(const Reader& r, const Json& j, const std::string& path) {
    static constexpr std::array<std::string_view, 8> keys = {
        "color", "kd", "ks", "shininess", "reflect", "transmit", "ior", "checker"};
    r.require_object(j, path,
                     "a material: color, kd, ks, shininess, reflect, transmit, ior, checker");
    r.check_keys(j, path, keys);
    Material m;
    if (j.contains("color")) m.color = r.color(j["color"], child_path(path, "color"));
    if (j.contains("kd")) m.kd = r.number(j["kd"], child_path(path, "kd"));
    if (j.contains("ks")) m.ks = r.number(j["ks"], child_path(path, "ks"));
    if (j.contains("shininess"))
        m.shininess = r.number(j["shininess"], child_path(path, "shininess"));
    if (j.contains("reflect")) m.reflect = r.color(j["reflect"], child_path(path, "reflect"));
    if (j.contains("transmit"))
        m.transmit = r.number(j["transmit"], child_path(path, "transmit"));
    if (j.contains("ior")) m.ior = r.number(j["ior"], child_path(path, "ior"));
    if (j.contains("checker")) {
        const std::string cpath = child_path(path, "checker");
        const Json& c = j["checker"];
        r.require_object(c, cpath, "color and size");
        static constexpr std::array<std::string_view, 2> ckeys = {"color", "size"};
        r.check_keys(c, cpath, ckeys);
        Checker checker;
        checker.color =
            r.color(r.require_key(c, cpath, "color", "the second color of the checker"),
                    child_path(cpath, "color"));
        if (c.contains("size")) checker.size = r.number(c["size"], child_path(cpath, "size"));
        m.checker = checker;
    }
    return m;
}

// A plane normal made unit length (scene_json::unit_plane_normal), or the error for zero.
Vec3 normalized_normal(const Reader& r, Vec3 n, const std::string& path) {
    const std::optional<Vec3> unit = scene_json::unit_plane_normal(n);
    if (!unit) r.fail(path, "expected a non-zero normal vector, found " + format_vec(n));
    return *unit;
}

struct MaterialTable {
    std::unordered_map<std::string, std::uint32_t> by_name;
    std::vector<std::string_view> names;  // file order, for messages
    std::optional<std::uint32_t> default_slot;
};

std::uint32_t read_object_material(const Reader& r, const Json& j, const std::string& path,
                                   Scene& scene, MaterialTable& table) {
    const auto it = j.find("material");
    if (it == j.end()) {
        // Objects without a material share one default material, added on first use.
        if (!table.default_slot) {
            table.default_slot = static_cast<std::uint32_t>(scene.materials.size());
            scene.materials.push_back(NamedMaterial{"", Material{}});
        }
        return *table.default_slot;
    }
    const std::string mpath = child_path(path, "material");
    if (it->is_string()) {
        const std::string& name = it->get_ref<const std::string&>();
        const auto found = table.by_name.find(name);
        if (found == table.by_name.end()) {
            const std::string known = table.names.empty()
                                          ? "the scene defines no named materials"
                                          : "the scene defines " + join_quoted(table.names);
            r.fail(mpath, "unknown material " + quote_text(name) +
                              suggestion(name, table.names) +
                              "; expected the name of a material in \"materials\" (" + known +
                              ") or an inline material object");
        }
        return found->second;
    }
    if (!it->is_object()) {
        r.fail(mpath,
               "expected a material name or an inline material object, found " + describe(*it));
    }
    scene.materials.push_back(NamedMaterial{"", read_material(r, *it, mpath)});
    return static_cast<std::uint32_t>(scene.materials.size() - 1);
}

void read_objects(const Reader& r, const Json& j, Scene& scene, MaterialTable& table) {
    if (!j.is_array()) r.fail("objects", "expected an array of objects, found " + describe(j));
    static constexpr std::array<std::string_view, 2> types = {"sphere", "plane"};
    static constexpr std::array<ForeignKey, 4> foreign = {
        ForeignKey{"center", "spheres"}, ForeignKey{"radius", "spheres"},
        ForeignKey{"point", "planes"}, ForeignKey{"normal", "planes"}};
    static constexpr std::array<std::string_view, 5> sphere_keys = {"type", "name", "material",
                                                                    "center", "radius"};
    static constexpr std::array<std::string_view, 5> plane_keys = {"type", "name", "material",
                                                                   "point", "normal"};
    scene.objects.reserve(j.size());
    for (std::size_t i = 0; i < j.size(); ++i) {
        const std::string path = index_path("objects", i);
        const Json& o = j[i];
        r.require_object(o, path, "an object with type sphere or plane");
        Object obj;
        obj.type = static_cast<ObjectType>(
            r.choice(r.require_key(o, path, "type", "\"sphere\" or \"plane\""),
                     child_path(path, "type"), types));
        if (obj.type == ObjectType::sphere) {
            r.check_keys(o, path, sphere_keys, foreign, "a sphere");
            obj.center =
                r.vec3(r.require_key(o, path, "center", "the sphere's center [x, y, z]"),
                       child_path(path, "center"));
            obj.radius = r.number(r.require_key(o, path, "radius", "the sphere's radius (> 0)"),
                                  child_path(path, "radius"));
        } else {
            r.check_keys(o, path, plane_keys, foreign, "a plane");
            obj.point =
                r.vec3(r.require_key(o, path, "point", "a point on the plane [x, y, z]"),
                       child_path(path, "point"));
            const std::string npath = child_path(path, "normal");
            obj.normal = normalized_normal(
                r,
                r.vec3(r.require_key(o, path, "normal", "the plane's normal [x, y, z]"), npath),
                npath);
        }
        if (o.contains("name")) {
            obj.name = r.string(o["name"], child_path(path, "name"));
            if (obj.name.empty()) {
                r.fail(child_path(path, "name"), "expected a non-empty name, found \"\"");
            }
        }
        obj.material = read_object_material(r, o, path, scene, table);
        scene.objects.push_back(std::move(obj));
    }
}

void read_lights(const Reader& r, const Json& j, Scene& scene) {
    if (!j.is_array()) r.fail("lights", "expected an array of lights, found " + describe(j));
    static constexpr std::array<std::string_view, 2> types = {"point", "directional"};
    static constexpr std::array<ForeignKey, 3> foreign = {
        ForeignKey{"position", "point lights"}, ForeignKey{"falloff", "point lights"},
        ForeignKey{"direction", "directional lights"}};
    static constexpr std::array<std::string_view, 4> point_keys = {"type", "position", "color",
                                                                   "falloff"};
    static constexpr std::array<std::string_view, 3> directional_keys = {"type", "direction",
                                                                         "color"};
    static constexpr std::array<std::string_view, 2> falloffs = {"none", "inverse-square"};
    scene.lights.reserve(j.size());
    for (std::size_t i = 0; i < j.size(); ++i) {
        const std::string path = index_path("lights", i);
        const Json& l = j[i];
        r.require_object(l, path, "a light with type point or directional");
        Light light;
        light.type = static_cast<LightType>(
            r.choice(r.require_key(l, path, "type", "\"point\" or \"directional\""),
                     child_path(path, "type"), types));
        if (light.type == LightType::point) {
            r.check_keys(l, path, point_keys, foreign, "a point light");
            light.position =
                r.vec3(r.require_key(l, path, "position", "the light's position [x, y, z]"),
                       child_path(path, "position"));
            if (l.contains("falloff")) {
                light.inverse_square =
                    r.choice(l["falloff"], child_path(path, "falloff"), falloffs) == 1;
            }
        } else {
            r.check_keys(l, path, directional_keys, foreign, "a directional light");
            light.direction = r.vec3(r.require_key(l, path, "direction",
                                                   "the direction the light travels [x, y, z]"),
                                     child_path(path, "direction"));
        }
        if (l.contains("color")) light.color = r.color(l["color"], child_path(path, "color"));
        scene.lights.push_back(light);
    }
}

Scene read_scene_text(std::string_view json_text, const std::string& source) {
    const Json root = parse_json_dom(json_text, source);
    const Reader r(source);
    if (!root.is_object()) {
        r.fail("", "expected a JSON object at the top level, found " + describe(root));
    }
    r.check_keys(root, "", kTopKeys);

    Scene scene;
    scene.source = source;
    if (root.contains("image")) read_image(r, root["image"], scene.image);
    read_camera(
        r, r.require_key(root, "", "camera", "an object with at least \"eye\" and \"lookat\""),
        scene.camera);
    if (root.contains("background")) read_background(r, root["background"], scene.background);
    if (root.contains("ambient")) scene.ambient = r.color(root["ambient"], "ambient");
    if (root.contains("render")) read_render(r, root["render"], scene.render);

    MaterialTable table;
    if (root.contains("materials")) {
        const Json& mats = root["materials"];
        if (!mats.is_object()) {
            r.fail("materials",
                   "expected an object mapping names to materials, found " + describe(mats));
        }
        for (const auto& [name, value] : mats.items()) {
            const std::string path = child_path("materials", name);
            if (name.empty()) r.fail(path, "expected a non-empty material name");
            table.by_name.emplace(name, static_cast<std::uint32_t>(scene.materials.size()));
            scene.materials.push_back(NamedMaterial{name, read_material(r, value, path)});
        }
        for (const NamedMaterial& nm : scene.materials) table.names.push_back(nm.name);
    }
    if (root.contains("objects")) read_objects(r, root["objects"], scene, table);
    if (root.contains("lights")) read_lights(r, root["lights"], scene);
    if (root.contains("animation"))
        scene.animation = read_animation(r, root["animation"], scene);

    validate_scene(scene);
    return scene;
}

}  // namespace

Scene parse_scene_json_diagnosing(std::string_view json_text, const std::string& source) {
    try {
        return read_scene_text(json_text, source);
    } catch (const SceneError& e) {
        // Every error in the file points at where its path is written, as a compiler's
        // "file:line:column:" does, so an editor jumps there.
        if (e.position().line > 0 || e.file() != source) throw;
        const std::optional<SourcePosition> at = json_path_position(json_text, e.json_path());
        if (!at) throw;
        throw SceneError(e.file(), *at, e.json_path(), e.message());
    }
}

}  // namespace octray
