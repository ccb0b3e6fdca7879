// The fast reader of JSON scene files: simdjson's On-Demand API straight into a Scene, in
// one forward pass, without a DOM. It only ever accepts: at the first thing it would have
// to report (invalid JSON, a wrong type, an unknown or duplicate key, a value out of range,
// a scene that validate_scene refuses) it declines, and parse_scene_json reads the text
// again with the diagnosing reader (read_scene.cpp), which writes the message. So every message
// stays the diagnosing reader's, and for every file both readers accept they must build
// the same scene, bit for bit: tests/scene/json_readers_test.cpp and the scene fuzzer
// check that they do. scene/README.md ("Two readers") lists the rules mirrored here.
// The value readers are scene/fast_values.h; this file reads the sections.
//
// Why a second reader at all: it earns its place by speed alone, 7 to 11 times the
// diagnosing reader's on the same text (random:1048576, 114 MB: 0.55 s against 4.0 s on a
// shared 2 vCPU Xeon; bench/scene_read_bench.cpp, figures in scene/README.md, "Two
// readers"). Were it ever not clearly faster, it should go: the diagnosing reader alone
// reads every valid file the same. The rule: it may only accept what the other accepts,
// and build the same scene.

#include <simdjson.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "core/aligned.h"
#include "scene/fast_values.h"
#include "scene/json_rules.h"
#include "scene/load.h"

namespace octray {
namespace {

static_assert(kJsonPadding >= simdjson::SIMDJSON_PADDING,
              "read_scene_file must leave the padding simdjson reads past the end");

using namespace scene_json::fast;
using scene_json::kMaxIntValue;

// ---------------------------------------------------------------------------------------
// The sections. Keys arrive in file order; each reader collects them, then applies the
// rules that depend on several (a type's own keys, required keys) at the end.

void read_image(od::value& v, ImageSettings& image) {
    static constexpr std::array<std::string_view, 3> keys = {"width", "height", "spp"};
    KeySet seen(keys);
    for (auto f : take(v.get_object())) {
        od::field field = take(std::move(f));
        const std::size_t key = seen.see(key_of(field));
        const int n = static_cast<int>(
            integer_of(field.value(), 1, key == 2 ? scene_json::kMaxSpp : kMaxIntValue));
        switch (key) {
            case 0:
                image.width = n;
                break;
            case 1:
                image.height = n;
                break;
            default:
                image.spp = n;
        }
    }
}

void read_camera(od::value& v, Camera& camera) {
    enum { kType, kEye, kLookat, kUp, kFov, kWidth, kAperture, kFocus, kFovUnits };
    static constexpr std::array<std::string_view, 9> keys = {
        "type",  "eye",      "lookat",         "up",       "fov",
        "width", "aperture", "focus_distance", "fov_units"};
    static constexpr std::array<std::string_view, 1> units = {"degrees"};
    static constexpr std::array<std::string_view, 4> types = {"pinhole", "orthographic",
                                                              "thinlens", "fisheye"};
    KeySet seen(keys);
    read_fields(v, seen, [&](std::size_t which, od::value& value) {
        switch (which) {
            case kType:
                camera.type = static_cast<CameraType>(choice_of(value, types));
                break;
            case kEye:
                camera.eye = vec3_of(value);
                break;
            case kLookat:
                camera.lookat = vec3_of(value);
                break;
            case kUp:
                camera.up = vec3_of(value);
                break;
            case kFov:
                camera.fov = float_of(value);
                break;
            case kWidth:
                camera.width = float_of(value);
                break;
            case kAperture:
                camera.aperture = float_of(value);
                break;
            case kFovUnits:
                // Always degrees: the key states that a small fov (scene_warnings) is meant.
                static_cast<void>(choice_of(value, units));
                camera.fov_units_stated = true;
                break;
            default:
                camera.focus_distance = float_of(value);
        }
    });
    if (!seen.has(kEye) || !seen.has(kLookat)) throw Decline{};
    const bool thinlens = camera.type == CameraType::thinlens;
    const bool has_fov = camera.type != CameraType::orthographic;
    if (((seen.has(kFov) || seen.has(kFovUnits)) && !has_fov) ||
        (seen.has(kWidth) && camera.type != CameraType::orthographic) ||
        (seen.has(kAperture) && !thinlens) || (seen.has(kFocus) && !thinlens)) {
        throw Decline{};
    }
    if (thinlens) {
        if (!seen.has(kAperture)) throw Decline{};
        if (!seen.has(kFocus)) {
            camera.focus_distance =
                scene_json::default_focus_distance(camera.eye, camera.lookat);
        }
    }
}

void read_background(od::value& v, Background& bg) {
    enum { kType, kColor, kBottom, kTop };
    static constexpr std::array<std::string_view, 4> keys = {"type", "color", "bottom", "top"};
    static constexpr std::array<std::string_view, 2> types = {"constant", "gradient"};
    KeySet seen(keys);
    read_fields(v, seen, [&](std::size_t which, od::value& value) {
        switch (which) {
            case kType:
                bg.type = static_cast<BackgroundType>(choice_of(value, types));
                break;
            case kColor:
                bg.color = color_of(value);
                break;
            case kBottom:
                bg.bottom = color_of(value);
                break;
            default:
                bg.top = color_of(value);
        }
    });
    if (!seen.has(kType)) throw Decline{};
    const bool constant = bg.type == BackgroundType::constant;
    if (constant != seen.has(kColor) || !constant != seen.has(kBottom) ||
        !constant != seen.has(kTop)) {
        throw Decline{};
    }
}

void read_render(od::value& v, RenderSettings& render) {
    static constexpr std::array<std::string_view, 3> keys = {"max_depth", "seed", "epsilon"};
    KeySet seen(keys);
    read_fields(v, seen, [&](std::size_t which, od::value& value) {
        switch (which) {
            case 0:
                render.max_depth =
                    static_cast<int>(integer_of(value, 0, scene_json::kMaxDepthLimit));
                break;
            case 1:
                render.seed = unsigned64_of(value);
                break;
            default:
                render.epsilon = float_of(value);
        }
    });
}

Material read_material(od::value& v) {
    enum { kColor, kKd, kKs, kShininess, kReflect, kTransmit, kIor, kChecker };
    static constexpr std::array<std::string_view, 8> keys = {
        "color", "kd", "ks", "shininess", "reflect", "transmit", "ior", "checker"};
    KeySet seen(keys);
    Material m;
    read_fields(v, seen, [&](std::size_t which, od::value& value) {
        switch (which) {
            case kColor:
                m.color = color_of(value);
                break;
            case kKd:
                m.kd = float_of(value);
                break;
            case kKs:
                m.ks = float_of(value);
                break;
            case kShininess:
                m.shininess = float_of(value);
                break;
            case kReflect:
                m.reflect = color_of(value);
                break;
            case kTransmit:
                m.transmit = float_of(value);
                break;
            case kIor:
                m.ior = float_of(value);
                break;
            default: {
                static constexpr std::array<std::string_view, 2> ckeys = {"color", "size"};
                KeySet cseen(ckeys);
                Checker checker;
                for (auto cf : take(value.get_object())) {
                    od::field cfield = take(std::move(cf));
                    od::value& cvalue = cfield.value();
                    if (cseen.see(key_of(cfield)) == 0) {
                        checker.color = color_of(cvalue);
                    } else {
                        checker.size = float_of(cvalue);
                    }
                }
                if (!cseen.has(0)) throw Decline{};
                m.checker = checker;
            }
        }
    });
    return m;
}

// How an object names its material, resolved once the whole file is read: the named
// materials come first in Scene::materials whatever the file's key order, then inline
// ones and the shared default in the order objects first use them (as read_scene.cpp does).
struct MaterialUse {
    enum Kind : std::uint8_t { by_default, named, named_later, inline_material } kind;
    std::uint32_t
        index;  // named: material index; named_later: into names; inline: into inlines
};

struct Materials {
    bool read = false;  // "materials" seen: names resolve at once
    std::unordered_map<std::string, std::uint32_t> by_name;
    std::vector<std::string> names_later;  // names used before "materials" was read
    std::vector<Material> inlines;
    // The last name looked up: most scenes give thousands of objects one material.
    std::string last_name;
    std::uint32_t last_index = 0;

    MaterialUse use(std::string_view name) {
        if (!read) {
            names_later.emplace_back(name);
            return {MaterialUse::named_later,
                    static_cast<std::uint32_t>(names_later.size() - 1)};
        }
        if (name != last_name || last_name.empty()) {
            const auto found = by_name.find(std::string(name));
            if (found == by_name.end()) throw Decline{};
            last_name = name;
            last_index = found->second;
        }
        return {MaterialUse::named, last_index};
    }
};

void read_materials(od::value& v, Scene& scene, Materials& materials) {
    for (auto f : take(v.get_object())) {
        od::field field = take(std::move(f));
        const std::string name(key_of(field));
        if (name.empty()) throw Decline{};
        const auto index = static_cast<std::uint32_t>(scene.materials.size());
        if (!materials.by_name.emplace(name, index).second) throw Decline{};  // duplicate key
        scene.materials.push_back(NamedMaterial{name, read_material(field.value())});
    }
    materials.read = true;
}

void read_objects(od::value& v, Scene& scene, Materials& materials,
                  std::vector<MaterialUse>& uses) {
    enum { kType, kName, kMaterial, kCenter, kRadius, kPoint, kNormal };
    static constexpr std::array<std::string_view, 7> keys = {
        "type", "name", "material", "center", "radius", "point", "normal"};
    static constexpr std::array<std::string_view, 2> types = {"sphere", "plane"};
    // Counting first (a skim over the structural index) spares the vector's regrowth.
    const std::size_t count = take(v.count_elements());
    scene.objects.reserve(count);
    uses.reserve(count);
    // 90 MB for a million spheres: 45 page faults instead of 22,000 (core/aligned.h).
    offer_huge_pages(scene.objects.data(), count * sizeof(Object));
    // Their pages mapped by another thread while this one parses: the file's hash, on the
    // other thread of the load (render/batch/plan.cpp), ends long before the parse, and
    // the kernel zeroing the objects' pages was about half of the parse's time on
    // random:1048576 (docs/performance-log.md, "The objects' pages mapped beside the
    // parse"). With one thread the task runs at the wait, over pages already mapped.
    tbb::task_group populate;
    populate.run([objects = scene.objects.data(), bytes = count * sizeof(Object)] {
        populate_pages(objects, bytes);
    });
    for (auto element : take(v.get_array())) {
        od::value o = take(std::move(element));
        KeySet seen(keys);
        Object obj;
        MaterialUse use{MaterialUse::by_default, 0};
        read_fields(o, seen, [&](std::size_t which, od::value& value) {
            switch (which) {
                case kType:
                    obj.type = static_cast<ObjectType>(choice_of(value, types));
                    break;
                case kName:
                    obj.name = string_of(value);
                    if (obj.name.empty()) throw Decline{};
                    break;
                case kMaterial:
                    if (take(value.type()) == od::json_type::string) {
                        use = materials.use(string_of(value));
                    } else {
                        materials.inlines.push_back(read_material(value));
                        use = {MaterialUse::inline_material,
                               static_cast<std::uint32_t>(materials.inlines.size() - 1)};
                    }
                    break;
                case kCenter:
                    obj.center = vec3_of(value);
                    break;
                case kRadius:
                    obj.radius = float_of(value);
                    break;
                case kPoint:
                    obj.point = vec3_of(value);
                    break;
                default:
                    obj.normal = vec3_of(value);
            }
        });
        if (!seen.has(kType)) throw Decline{};
        if (obj.type == ObjectType::sphere) {
            if (!seen.has(kCenter) || !seen.has(kRadius) || seen.has(kPoint) ||
                seen.has(kNormal)) {
                throw Decline{};
            }
        } else {
            if (!seen.has(kPoint) || !seen.has(kNormal) || seen.has(kCenter) ||
                seen.has(kRadius)) {
                throw Decline{};
            }
            const std::optional<Vec3> unit = scene_json::unit_plane_normal(obj.normal);
            if (!unit) throw Decline{};
            obj.normal = *unit;
        }
        scene.objects.push_back(std::move(obj));
        uses.push_back(use);
    }
    populate.wait();  // (a Decline thrown above waits in task_group's destructor)
}

void resolve_materials(Scene& scene, const Materials& materials,
                       const std::vector<MaterialUse>& uses) {
    std::optional<std::uint32_t> default_slot;
    for (std::size_t i = 0; i < uses.size(); ++i) {
        const MaterialUse use = uses[i];
        std::uint32_t& material = scene.objects[i].material;
        switch (use.kind) {
            case MaterialUse::named:
                material = use.index;
                break;
            case MaterialUse::named_later: {
                const auto found = materials.by_name.find(materials.names_later[use.index]);
                if (found == materials.by_name.end()) throw Decline{};
                material = found->second;
                break;
            }
            case MaterialUse::inline_material:
                material = static_cast<std::uint32_t>(scene.materials.size());
                scene.materials.push_back(NamedMaterial{"", materials.inlines[use.index]});
                break;
            case MaterialUse::by_default:
                if (!default_slot) {
                    default_slot = static_cast<std::uint32_t>(scene.materials.size());
                    scene.materials.push_back(NamedMaterial{"", Material{}});
                }
                material = *default_slot;
        }
    }
}

void read_lights(od::value& v, Scene& scene) {
    enum { kType, kPosition, kColor, kFalloff, kDirection };
    static constexpr std::array<std::string_view, 5> keys = {"type", "position", "color",
                                                             "falloff", "direction"};
    static constexpr std::array<std::string_view, 2> types = {"point", "directional"};
    static constexpr std::array<std::string_view, 2> falloffs = {"none", "inverse-square"};
    for (auto element : take(v.get_array())) {
        od::value l = take(std::move(element));
        KeySet seen(keys);
        Light light;
        read_fields(l, seen, [&](std::size_t which, od::value& value) {
            switch (which) {
                case kType:
                    light.type = static_cast<LightType>(choice_of(value, types));
                    break;
                case kPosition:
                    light.position = vec3_of(value);
                    break;
                case kColor:
                    light.color = color_of(value);
                    break;
                case kFalloff:
                    light.inverse_square = choice_of(value, falloffs) == 1;
                    break;
                default:
                    light.direction = vec3_of(value);
            }
        });
        if (!seen.has(kType)) throw Decline{};
        const bool point = light.type == LightType::point;
        if (point ? (!seen.has(kPosition) || seen.has(kDirection))
                  : (!seen.has(kDirection) || seen.has(kPosition) || seen.has(kFalloff))) {
            throw Decline{};
        }
        scene.lights.push_back(light);
    }
}

// The animation block; its rules on values (frame order, what fits the camera or object)
// are validate_scene's.
std::vector<CameraKey> read_camera_keys(od::value& v) {
    enum { kFrame, kEye, kLookat, kUp, kFov };
    static constexpr std::array<std::string_view, 5> keys = {"frame", "eye", "lookat", "up",
                                                             "fov"};
    std::vector<CameraKey> out;
    for (auto element : take(v.get_array())) {
        od::value k = take(std::move(element));
        KeySet seen(keys);
        CameraKey key;
        read_fields(k, seen, [&](std::size_t which, od::value& value) {
            switch (which) {
                case kFrame:
                    key.frame = static_cast<int>(integer_of(value, 0, kMaxIntValue));
                    break;
                case kEye:
                    key.eye = vec3_of(value);
                    break;
                case kLookat:
                    key.lookat = vec3_of(value);
                    break;
                case kUp:
                    key.up = vec3_of(value);
                    break;
                default:
                    key.fov = float_of(value);
            }
        });
        if (!seen.has(kFrame)) throw Decline{};
        out.push_back(key);
    }
    return out;
}

// Tracks by object name; the names resolve to object indices once the objects are read.
std::vector<ObjectTrack> read_object_tracks(od::value& v) {
    enum { kFrame, kCenter, kRadius };
    static constexpr std::array<std::string_view, 3> keys = {"frame", "center", "radius"};
    std::vector<ObjectTrack> out;
    std::unordered_set<std::string> names;
    for (auto f : take(v.get_object())) {
        od::field field = take(std::move(f));
        ObjectTrack track;
        track.name = key_of(field);
        if (!names.insert(track.name).second) throw Decline{};  // duplicate key
        for (auto element : take(field.value().get_array())) {
            od::value k = take(std::move(element));
            KeySet seen(keys);
            ObjectKey key;
            read_fields(k, seen, [&](std::size_t which, od::value& value) {
                switch (which) {
                    case kFrame:
                        key.frame = static_cast<int>(integer_of(value, 0, kMaxIntValue));
                        break;
                    case kCenter:
                        key.center = vec3_of(value);
                        break;
                    default:
                        key.radius = float_of(value);
                }
            });
            if (!seen.has(kFrame)) throw Decline{};
            track.keys.push_back(key);
        }
        out.push_back(std::move(track));
    }
    return out;
}

Animation read_animation(od::value& v) {
    enum { kFrames, kFps, kCamera, kObjects };
    static constexpr std::array<std::string_view, 4> keys = {"frames", "fps", "camera",
                                                             "objects"};
    KeySet seen(keys);
    Animation a;
    read_fields(v, seen, [&](std::size_t which, od::value& value) {
        switch (which) {
            case kFrames:
                a.frames = static_cast<int>(integer_of(value, 1, kMaxAnimationFrames));
                break;
            case kFps:
                a.fps = number_of(value);
                break;
            case kCamera:
                a.camera = read_camera_keys(value);
                break;
            default:
                a.objects = read_object_tracks(value);
        }
    });
    if (!seen.has(kFrames)) throw Decline{};
    return a;
}

void resolve_tracks(const Scene& scene, Animation& a) {
    if (a.objects.empty()) return;
    std::unordered_map<std::string_view, std::uint32_t> by_name;
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        if (!scene.objects[i].name.empty()) {
            by_name.emplace(scene.objects[i].name, static_cast<std::uint32_t>(i));
        }
    }
    for (ObjectTrack& track : a.objects) {
        const auto found = by_name.find(track.name);
        if (found == by_name.end()) throw Decline{};
        track.object = found->second;
    }
}

Scene read_scene(od::document& doc, const std::string& source) {
    enum {
        kImage,
        kCamera,
        kBackground,
        kAmbient,
        kRender,
        kMaterials,
        kObjects,
        kLights,
        kAnimation
    };
    static constexpr std::array<std::string_view, 9> keys = {"image",   "camera", "background",
                                                             "ambient", "render", "materials",
                                                             "objects", "lights", "animation"};
    KeySet seen(keys);
    Scene scene;
    scene.source = source;
    Materials materials;
    std::vector<MaterialUse> uses;
    read_fields(doc, seen, [&](std::size_t which, od::value& value) {
        switch (which) {
            case kImage:
                read_image(value, scene.image);
                break;
            case kCamera:
                read_camera(value, scene.camera);
                break;
            case kBackground:
                read_background(value, scene.background);
                break;
            case kAmbient:
                scene.ambient = color_of(value);
                break;
            case kRender:
                read_render(value, scene.render);
                break;
            case kMaterials:
                read_materials(value, scene, materials);
                break;
            case kObjects:
                read_objects(value, scene, materials, uses);
                break;
            case kLights:
                read_lights(value, scene);
                break;
            default:
                scene.animation = read_animation(value);
        }
    });
    // Nothing may follow the top-level object but whitespace.
    if (doc.current_location().error() != simdjson::OUT_OF_BOUNDS) throw Decline{};
    if (!seen.has(kCamera)) throw Decline{};
    resolve_materials(scene, materials, uses);
    if (scene.animation) resolve_tracks(scene, *scene.animation);
    return scene;
}

}  // namespace

std::optional<Scene> parse_scene_json_fast(std::string_view json_text,
                                           const std::string& source, std::size_t readable) {
    // nlohmann skips a UTF-8 byte order mark at the start; simdjson does not.
    constexpr std::string_view kBom = "\xEF\xBB\xBF";
    const std::size_t skip = json_text.substr(0, kBom.size()) == kBom ? kBom.size() : 0;
    // A NUL byte is never JSON text (the diagnosing reader says where it is).
    if (json_text.find('\0') != std::string_view::npos) return std::nullopt;
    try {
        simdjson::padded_string copy;
        simdjson::padded_string_view text;
        if (readable >= json_text.size() + simdjson::SIMDJSON_PADDING) {
            text = simdjson::padded_string_view(json_text.data() + skip,
                                                json_text.size() - skip, readable - skip);
        } else {
            copy = simdjson::padded_string(json_text.data() + skip, json_text.size() - skip);
            text = copy;
        }
        od::parser parser;
        od::document doc = take(parser.iterate(text));
        Scene scene = read_scene(doc, source);
        validate_scene(scene);
        return scene;
    } catch (const Decline&) {
        return std::nullopt;
    } catch (const SceneError&) {
        return std::nullopt;  // validate_scene's: the diagnosing reader says it again
    }
}

}  // namespace octray
