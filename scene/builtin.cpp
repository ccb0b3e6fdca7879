// The built-in scenes of docs/scene-format.md: whitted, random:N, sphereflake:L,
// and the ",key=value" overrides after them. Geometry, camera and lights of each are
// documented in scene/README.md.

#include "scene/builtin.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "core/aligned.h"
#include "core/populate.h"
#include "core/random.h"
#include "scene/json_rules.h"
#include "scene/load.h"
#include "scene/max_depth.h"
#include "scene/scene_error.h"
#include "scene/suggest.h"

namespace octray {
namespace {

// The authored scene costs about 90 bytes per sphere before it is compiled; 2^24 spheres
// (1.5 GB) is the most we generate, so a typo such as random:1000000000 fails at once
// instead of exhausting memory.
constexpr std::uint64_t kMaxGeneratedSpheres = std::uint64_t{1} << 24;
// sum 9^k for k = 0..7 is 5,380,840 spheres; level 8 would be 48 million, over the limit.
constexpr int kMaxSphereflakeLevel = 7;
// The big scenes are generated in parallel (oneTBB) in tasks of about this many spheres:
// enough to outweigh a task's cost, few enough to balance two to a few dozen threads.
constexpr std::uint64_t kSpheresPerTask = 4096;

std::string quote_text(std::string_view s) { return "\"" + std::string(s) + "\""; }

struct Overrides {
    std::optional<int> width, height, spp, max_depth;
    std::optional<std::uint64_t> seed;
};

struct BuiltinSpec {
    std::string_view name;
    std::optional<std::string_view> argument;  // text after ':' up to the first ','
    Overrides overrides;
};

template <typename Int>
std::optional<Int> parse_integer(std::string_view text) {
    Int value{};
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc{} || end != text.data() + text.size() || text.empty())
        return std::nullopt;
    return value;
}

std::string_view builtin_name(std::string_view spec) {
    return spec.substr(0, spec.find_first_of(":,"));
}

BuiltinSpec parse_spec(const std::string& spec) {
    BuiltinSpec out;
    std::string_view rest = spec;
    out.name = builtin_name(rest);
    rest.remove_prefix(out.name.size());
    if (!rest.empty() && rest.front() == ':') {
        rest.remove_prefix(1);
        const std::size_t comma = rest.find(',');
        out.argument = rest.substr(0, comma);
        rest.remove_prefix(comma == std::string_view::npos ? rest.size() : comma);
    }
    std::vector<std::string_view> seen;
    while (!rest.empty()) {
        rest.remove_prefix(1);  // the ','
        const std::size_t comma = rest.find(',');
        const std::string_view option = rest.substr(0, comma);
        rest.remove_prefix(comma == std::string_view::npos ? rest.size() : comma);
        if (option.empty()) {
            throw SceneError(spec, "",
                             "empty option between commas; expected key=value with key "
                             "one of width, height, spp, seed, max_depth");
        }
        const std::size_t equals = option.find('=');
        const std::string_view key = option.substr(0, equals);
        if (equals == std::string_view::npos) {
            throw SceneError(spec, std::string(key),
                             "expected key=value, found " + quote_text(option));
        }
        const std::string_view value = option.substr(equals + 1);
        const std::string path(key);
        for (std::string_view s : seen) {
            if (s == key) throw SceneError(spec, path, "option given twice; expected it once");
        }
        seen.push_back(key);

        const auto int_option = [&](int lo, int hi) {
            const auto v = parse_integer<int>(value);
            if (!v || *v < lo || *v > hi) {
                throw SceneError(spec, path,
                                 "expected an integer from " + std::to_string(lo) + " to " +
                                     std::to_string(hi) + ", found " + quote_text(value));
            }
            return *v;
        };
        constexpr int kIntMax = std::numeric_limits<int>::max();
        if (key == "width") {
            out.overrides.width = int_option(1, kIntMax);
        } else if (key == "height") {
            out.overrides.height = int_option(1, kIntMax);
        } else if (key == "spp") {
            out.overrides.spp = int_option(1, scene_json::kMaxSpp);
        } else if (key == "max_depth") {
            out.overrides.max_depth = int_option(0, kMaxDepthLimit);
        } else if (key == "seed") {
            const auto v = parse_integer<std::uint64_t>(value);
            if (!v) {
                throw SceneError(spec, path,
                                 "expected a non-negative integer from 0 to "
                                 "18446744073709551615, found " +
                                     quote_text(value));
            }
            out.overrides.seed = *v;
        } else {
            throw SceneError(spec, path,
                             "unknown option " + quote_text(key) +
                                 "; valid options: width, height, spp, seed, max_depth");
        }
    }
    return out;
}

std::uint32_t add_material(Scene& scene, std::string name, const Material& m) {
    scene.materials.push_back(NamedMaterial{std::move(name), m});
    return static_cast<std::uint32_t>(scene.materials.size() - 1);
}

Object make_sphere(Vec3 center, float radius, std::uint32_t material, std::string name = {}) {
    Object o;
    o.type = ObjectType::sphere;
    o.name = std::move(name);
    o.center = center;
    o.radius = radius;
    o.material = material;
    return o;
}

Object make_plane(Vec3 point, Vec3 normal, std::uint32_t material, std::string name = {}) {
    Object o;
    o.type = ObjectType::plane;
    o.name = std::move(name);
    o.point = point;
    o.normal = normal;
    o.material = material;
    return o;
}

Light point_light(Vec3 position, Rgb color) {
    Light l;
    l.type = LightType::point;
    l.position = position;
    l.color = color;
    return l;
}

// ---------------------------------------------------------------------------------------
// whitted: after the cover image of Whitted's 1980 paper — a red and yellow checkered
// floor under a blue sky, a glass sphere in front of a mirror sphere.

Scene make_whitted() {
    Scene s;
    s.image = {1280, 720, 1};
    s.camera.type = CameraType::pinhole;
    s.camera.eye = {0.0f, 2.2f, 7.0f};  // a little above the spheres, looking down
    s.camera.lookat = {0.2f, 0.8f, -0.4f};
    s.camera.up = {0.0f, 1.0f, 0.0f};
    s.camera.fov = 50.0f;
    s.background.type = BackgroundType::gradient;
    s.background.bottom = {0.85f, 0.9f, 1.0f};
    s.background.top = {0.25f, 0.45f, 0.85f};
    s.ambient = Rgb(0.08f);
    s.render.max_depth = 5;
    s.render.seed = 0;

    Material floor;
    floor.color = {0.85f, 0.12f, 0.08f};
    floor.kd = 0.9f;
    floor.checker = Checker{{0.95f, 0.85f, 0.15f}, 1.0f};
    Material mirror;
    mirror.color = Rgb(0.9f);
    mirror.kd = 0.05f;
    mirror.ks = 0.8f;
    mirror.shininess = 200.0f;
    mirror.reflect = Rgb(0.85f);
    Material glass;
    glass.color = Rgb(1.0f);
    glass.kd = 0.0f;
    glass.ks = 0.8f;
    glass.shininess = 200.0f;
    glass.reflect = Rgb(0.1f);
    glass.transmit = 0.9f;
    glass.ior = 1.5f;
    Material matte;
    matte.color = {0.2f, 0.35f, 0.9f};
    matte.kd = 0.9f;
    matte.ks = 0.3f;
    matte.shininess = 32.0f;

    const std::uint32_t floor_id = add_material(s, "floor", floor);
    const std::uint32_t mirror_id = add_material(s, "mirror", mirror);
    const std::uint32_t glass_id = add_material(s, "glass", glass);
    const std::uint32_t matte_id = add_material(s, "matte", matte);

    // Every sphere rests on the floor: center height = radius.
    s.objects.push_back(make_plane({0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, floor_id, "floor"));
    s.objects.push_back(make_sphere({-1.3f, 1.2f, -1.5f}, 1.2f, mirror_id, "mirror_ball"));
    s.objects.push_back(make_sphere({0.6f, 0.9f, 0.6f}, 0.9f, glass_id, "glass_ball"));
    s.objects.push_back(make_sphere({2.4f, 0.6f, -0.9f}, 0.6f, matte_id, "blue_ball"));

    s.lights.push_back(point_light({-5.0f, 9.0f, 7.0f}, Rgb(0.8f)));
    s.lights.push_back(point_light({6.0f, 6.0f, 4.0f}, Rgb(0.5f)));
    return s;
}

// ---------------------------------------------------------------------------------------
// random:N — exactly as docs/scene-format.md specifies it.

// Room for `count` objects, its pages mapped on every thread (huge where the kernel gives
// them: core/aligned.h), so that the objects a generator then constructs one after another
// fault none: random:1048576 was generated in 41 ms, its page faults most of it.
void reserve_mapped(std::vector<Object>& objects, std::uint64_t count) {
    objects.reserve(count);
    auto* const storage = reinterpret_cast<unsigned char*>(objects.data());
    const std::uint64_t bytes = count * sizeof(Object);
    offer_huge_pages(storage, bytes);
    populate_pages_parallel(storage, bytes);
}

Scene make_random(std::uint64_t count, std::uint64_t seed) {
    Scene s;
    s.image = {1920, 1080, 1};
    s.camera.type = CameraType::pinhole;
    s.camera.eye = {0.0f, 0.0f, 4.0f};
    s.camera.lookat = {0.0f, 0.0f, 0.0f};
    s.camera.up = {0.0f, 1.0f, 0.0f};
    s.camera.fov = 60.0f;
    s.background.type = BackgroundType::constant;
    s.background.color = Rgb(0.1f);
    // Without ambient the spheres' unlit sides would be indistinguishable from each other.
    s.ambient = Rgb(0.1f);
    s.render.seed = seed;
    s.lights.push_back(point_light({4.0f, 6.0f, 5.0f}, Rgb(1.0f)));
    const std::uint32_t material = add_material(s, "diffuse", Material{});

    // radius = 0.6 N^(-1/3): the spheres fill about the same fraction of the cube for any N.
    const auto radius =
        static_cast<float>(0.6 * std::pow(static_cast<double>(count), -1.0 / 3.0));
    reserve_mapped(s.objects, count);
    s.objects.resize(count, make_sphere({}, radius, material));
    // Blocks of spheres in parallel, each from the generator skipped to its first sphere
    // (three draws per sphere): the same scene for any thread count.
    tbb::parallel_for(tbb::blocked_range<std::uint64_t>(0, count, kSpheresPerTask),
                      [&](const tbb::blocked_range<std::uint64_t>& block) {
                          SplitMix64 rng(seed);
                          rng.discard(3 * block.begin());
                          for (std::uint64_t i = block.begin(); i != block.end(); ++i) {
                              const float x = 2.0f * rng.next_float() - 1.0f;
                              const float y = 2.0f * rng.next_float() - 1.0f;
                              const float z = 2.0f * rng.next_float() - 1.0f;
                              s.objects[i].center = {x, y, z};
                          }
                      });
    return s;
}

// ---------------------------------------------------------------------------------------
// sphereflake:L — Eric Haines' SPD "balls" (1987): each sphere carries 9 children of a
// third its radius touching it, 6 around its equator and 3 above, recursively.

struct Dir {
    double x, y, z;
};
Dir operator*(Dir a, double s) { return {a.x * s, a.y * s, a.z * s}; }

using Mat3 = std::array<Dir, 3>;  // rows

Dir apply(const Mat3& m, Dir v) {
    return {m[0].x * v.x + m[0].y * v.y + m[0].z * v.z,
            m[1].x * v.x + m[1].y * v.y + m[1].z * v.z,
            m[2].x * v.x + m[2].y * v.y + m[2].z * v.z};
}

// Rodrigues' rotation by `angle` (right-handed) about the unit vector `k`.
Mat3 axis_rotation(Dir k, double angle) {
    const double c = std::cos(angle), s = std::sin(angle), t = 1.0 - c;
    return {Dir{t * k.x * k.x + c, t * k.x * k.y - s * k.z, t * k.x * k.z + s * k.y},
            Dir{t * k.x * k.y + s * k.z, t * k.y * k.y + c, t * k.y * k.z - s * k.x},
            Dir{t * k.x * k.z - s * k.y, t * k.y * k.z + s * k.x, t * k.z * k.z + c}};
}

// The 9 unit directions from a parent's center to its children, for a parent whose own
// axis is +z (SPD's create_objset). Three cube-edge directions (1,1,0), (1,0,-1), (0,1,-1)
// are tilted so the cube diagonal (1,1,1) becomes +z: (1,1,0) then points 54.7 degrees
// above the equator and the other two lie on it. Three copies 120 degrees apart about z
// give 3 children above and 6 around the equator, 60 degrees apart.
std::array<Dir, 9> child_directions() {
    const double h = 1.0 / std::sqrt(2.0);
    const std::array<Dir, 3> trio = {Dir{h, h, 0.0}, Dir{h, 0.0, -h}, Dir{0.0, h, -h}};
    const Mat3 tilt = axis_rotation(Dir{h, -h, 0.0}, std::asin(2.0 / std::sqrt(6.0)));
    std::array<Dir, 9> out{};
    for (int set = 0; set < 3; ++set) {
        const Mat3 turn = axis_rotation(Dir{0.0, 0.0, 1.0}, set * 2.0 * std::numbers::pi / 3.0);
        for (int v = 0; v < 3; ++v)
            out[static_cast<std::size_t>(set * 3 + v)] =
                apply(turn, apply(tilt, trio[static_cast<std::size_t>(v)]));
    }
    return out;
}

// The rotation taking +z to the unit vector `d` (SPD's output_object).
Mat3 rotation_from_z(Dir d) {
    if (d.z >= 1.0) return {Dir{1, 0, 0}, Dir{0, 1, 0}, Dir{0, 0, 1}};
    if (d.z <= -1.0) return axis_rotation(Dir{0.0, 1.0, 0.0}, std::numbers::pi);
    // axis = z x d, normalised.
    const double len = std::sqrt(d.x * d.x + d.y * d.y);
    return axis_rotation(Dir{-d.y / len, d.x / len, 0.0}, std::acos(d.z));
}

// Spheres in a flake of `levels` levels below its root: sum 9^k for k = 0..levels.
std::uint64_t flake_size(int levels) {
    std::uint64_t count = 0, level_count = 1;
    for (int k = 0; k <= levels; ++k, level_count *= 9) count += level_count;
    return count;
}

// Depth-first, parent before children, as SPD writes them, into objects[at ...]: each
// subtree has a known size, so the subtrees of the top levels are written in parallel,
// at their serial positions. Positions are computed in double and rounded once, so deep
// levels do not accumulate float error.
void add_flake(std::vector<Object>& objects, std::size_t at,
               const std::array<Dir, 9>& directions, Dir center, double radius, Dir axis,
               int levels_left, std::uint32_t material) {
    objects[at] = make_sphere({static_cast<float>(center.x), static_cast<float>(center.y),
                               static_cast<float>(center.z)},
                              static_cast<float>(radius), material);
    if (levels_left == 0) return;
    const Mat3 m = rotation_from_z(axis);
    // Touching: the child's center lies r + r/3 from the parent's.
    const double distance = radius * (1.0 + 1.0 / 3.0);
    const std::uint64_t child_size = flake_size(levels_left - 1);
    const auto add_child = [&](std::size_t c) {
        const Dir child_axis = apply(m, directions[c]);
        const Dir offset = child_axis * distance;
        add_flake(objects, at + 1 + c * child_size, directions,
                  Dir{center.x + offset.x, center.y + offset.y, center.z + offset.z},
                  radius / 3.0, child_axis, levels_left - 1, material);
    };
    if (child_size >= kSpheresPerTask) {
        tbb::parallel_for(std::size_t{0}, directions.size(), add_child);
    } else {
        for (std::size_t c = 0; c < directions.size(); ++c) add_child(c);
    }
}

Scene make_sphereflake(int levels) {
    Scene s;
    // SPD's view: z is up, a 45-degree square image looking at the flake from above.
    s.image = {1024, 1024, 1};
    s.camera.type = CameraType::pinhole;
    s.camera.eye = {2.1f, 1.3f, 1.7f};
    s.camera.lookat = {0.0f, 0.0f, 0.0f};
    s.camera.up = {0.0f, 0.0f, 1.0f};
    s.camera.fov = 45.0f;
    s.background.type = BackgroundType::constant;
    s.background.color = {0.078f, 0.361f, 0.753f};  // SPD's "UNC sky blue"
    s.ambient = Rgb(0.1f);
    s.render.max_depth = 5;
    // SPD scales its three lights by 1/sqrt(3) so they sum to about one.
    const Rgb light = Rgb(static_cast<float>(1.0 / std::sqrt(3.0)));
    s.lights.push_back(point_light({4.0f, 3.0f, 2.0f}, light));
    s.lights.push_back(point_light({1.0f, -4.0f, 4.0f}, light));
    s.lights.push_back(point_light({-3.0f, 1.0f, 5.0f}, light));

    Material floor;
    floor.color = {1.0f, 0.75f, 0.33f};  // SPD's beige floor
    floor.kd = 0.8f;
    Material flake;
    flake.color = {1.0f, 0.9f, 0.7f};
    flake.kd = 0.5f;
    flake.ks = 0.5f;
    // SPD gives a 37-degree highlight; cos(37/2 degrees)^13 is one half.
    flake.shininess = 13.0f;
    flake.reflect = Rgb(0.5f);
    const std::uint32_t floor_id = add_material(s, "floor", floor);
    const std::uint32_t flake_id = add_material(s, "flake", flake);

    // The floor touches the bottom of the root sphere (radius 0.5 at the origin).
    reserve_mapped(s.objects, 1 + flake_size(levels));
    s.objects.push_back(make_plane({0.0f, 0.0f, -0.5f}, {0.0f, 0.0f, 1.0f}, floor_id, "floor"));
    s.objects.resize(1 + flake_size(levels));
    add_flake(s.objects, 1, child_directions(), Dir{0.0, 0.0, 0.0}, 0.5, Dir{0.0, 0.0, 1.0},
              levels, flake_id);
    return s;
}

}  // namespace

std::uint64_t SplitMix64::next() {
    state_ += 0x9E3779B97F4A7C15ull;
    return mix64(state_);
}

float SplitMix64::next_float() { return static_cast<float>(next() >> 40) * 0x1.0p-24f; }

void SplitMix64::discard(std::uint64_t n) { state_ += n * 0x9E3779B97F4A7C15ull; }

bool is_builtin_scene(const std::string& spec) {
    const std::string_view name = builtin_name(spec);
    return name == "whitted" || name == "random" || name == "sphereflake";
}

std::optional<std::string> builtin_suggestion(const std::string& spec) {
    const std::string_view name = builtin_name(spec);
    static constexpr std::array<std::string_view, 3> names{"whitted", "random", "sphereflake"};
    const std::optional<std::string_view> best = closest_word(name, names);
    if (!best) return std::nullopt;
    return std::string(*best) + spec.substr(name.size());
}

Scene make_builtin_scene(const std::string& spec) {
    const BuiltinSpec parsed = parse_spec(spec);
    const Overrides& o = parsed.overrides;
    Scene scene;
    if (parsed.name == "whitted") {
        if (parsed.argument) {
            throw SceneError(
                spec, "",
                "whitted takes no argument; expected \"whitted\", found " + quote_text(spec));
        }
        scene = make_whitted();
        if (o.seed) scene.render.seed = *o.seed;
    } else if (parsed.name == "random") {
        const std::string expectation = "expected random:N with N a sphere count from 1 to " +
                                        std::to_string(kMaxGeneratedSpheres);
        if (!parsed.argument) throw SceneError(spec, "", expectation + ", found no count");
        const auto n = parse_integer<std::uint64_t>(*parsed.argument);
        if (!n || *n < 1 || *n > kMaxGeneratedSpheres) {
            throw SceneError(spec, "", expectation + ", found " + quote_text(*parsed.argument));
        }
        // One knob: seed=S starts the generator at S and is also the scene's render seed,
        // so random:N and random:N,seed=1 are the same scene.
        scene = make_random(*n, o.seed.value_or(1));
    } else if (parsed.name == "sphereflake") {
        const std::string expectation =
            "expected sphereflake:L with L a recursion level from 0 to " +
            std::to_string(kMaxSphereflakeLevel);
        if (!parsed.argument) throw SceneError(spec, "", expectation + ", found no level");
        const auto level = parse_integer<int>(*parsed.argument);
        if (!level || *level < 0 || *level > kMaxSphereflakeLevel) {
            throw SceneError(spec, "", expectation + ", found " + quote_text(*parsed.argument));
        }
        scene = make_sphereflake(*level);
        if (o.seed) scene.render.seed = *o.seed;
    } else {
        throw SceneError(spec, "",
                         "unknown built-in scene " + quote_text(parsed.name) +
                             "; expected whitted, random:N or sphereflake:L");
    }
    if (o.width) scene.image.width = *o.width;
    if (o.height) scene.image.height = *o.height;
    if (o.spp) scene.image.spp = *o.spp;
    if (o.max_depth) scene.render.max_depth = *o.max_depth;
    scene.source = spec;
    validate_scene(scene);
    return scene;
}

}  // namespace octray
