// The semantic checks every scene passes before it is rendered (scene/load.h,
// validate_scene; scene/README.md, "Semantic checks and limits"). Every message names the
// scene's source, the JSON path and what was expected.

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_reduce.h>

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

#include "scene/animation.h"
#include "scene/camera.h"
#include "scene/json_messages.h"
#include "scene/json_rules.h"
#include "scene/load.h"

namespace octray {
namespace {

using namespace scene_json;
using scene_json::kMaxDepthLimit;
using scene_json::kMaxIntValue;

// Pixel indices must fit in an int (the renderers and image writers index with int).
constexpr std::int64_t kMaxPixels = std::numeric_limits<int>::max();
// validate_scene is looser than scene_json::kUnitTolerance: it only has to catch normals
// that were never normalised.
constexpr double kValidateUnitTolerance = 1e-5;
// Refraction scales directions by the index ratio (or its inverse); far beyond real
// materials (1 to about 4) the float refraction vector loses its precision and degenerate
// directions render NaN (issue 23: ior 1e8 did, 1e7 too). 100 leaves a wide margin.
constexpr float kMinIor = 0.01f;
constexpr float kMaxIor = 100.0f;
// A thin lens much wider than its focus distance starts rays so far off the view axis that
// float precision breaks down: measured on the built-in and golden scenes, 10 x renders
// normal values, 100 x absurd ones and 300 x infinite or NaN pixels (issue 23: aperture
// 1e20 rendered 13915 of 14400 pixels NaN).
constexpr float kMaxApertureRatio = 10.0f;
// Beyond this the focal point's distance overflows float when squared (a focus distance
// of 1e20 renders every pixel NaN, even through a pinhole-sized lens).
constexpr float kMaxFocusDistance = 1e18f;

class Validator {
  public:
    explicit Validator(const Scene& scene) : scene_(scene) {}

    [[noreturn]] void fail(const std::string& path, const std::string& message) const {
        throw SceneError(scene_.source, path, message);
    }

    void finite(float v, const std::string& path) const {
        if (!std::isfinite(v)) fail(path, "expected a finite number, found " + format_float(v));
    }
    void positive(float v, const std::string& path, std::string_view what) const {
        if (!(std::isfinite(v) && v > 0.0f)) {
            fail(path, "expected " + std::string(what) + " > 0, found " + format_float(v));
        }
    }
    void non_negative(float v, const std::string& path, std::string_view what) const {
        if (!(std::isfinite(v) && v >= 0.0f)) {
            fail(path, "expected " + std::string(what) + " >= 0, found " + format_float(v));
        }
    }
    void finite(Vec3 v, const std::string& path) const {
        if (!is_finite(v)) fail(path, "expected finite coordinates, found " + format_vec(v));
    }
    void color(Rgb c, const std::string& path) const {
        if (!(is_finite(c) && c.r >= 0.0f && c.g >= 0.0f && c.b >= 0.0f)) {
            fail(path, "expected a color with finite, non-negative components, found " +
                           format_rgb(c));
        }
    }
    void int_range(int v, const std::string& path, int lo, int hi) const {
        if (v < lo || v > hi) {
            fail(path, "expected an integer from " + std::to_string(lo) + " to " +
                           std::to_string(hi) + ", found " + std::to_string(v));
        }
    }

    // Where a material came from: materials.<name>, or the first object that uses it inline.
    std::string material_path(std::size_t index) const {
        const NamedMaterial& nm = scene_.materials[index];
        if (!nm.name.empty()) return child_path("materials", nm.name);
        for (std::size_t i = 0; i < scene_.objects.size(); ++i) {
            if (scene_.objects[i].material == index) {
                return child_path(index_path("objects", i), "material");
            }
        }
        return index_path("materials", index);
    }

    void image() const {
        const ImageSettings& im = scene_.image;
        int_range(im.width, "image.width", 1, kMaxIntValue);
        int_range(im.height, "image.height", 1, kMaxIntValue);
        int_range(im.spp, "image.spp", 1, scene_json::kMaxSpp);
        // Both factors are below 2^31, so neither product overflows 64 bits (nor does the
        // sample count width * height * spp, which stays below 2^51).
        const std::int64_t pixels = static_cast<std::int64_t>(im.width) * im.height;
        const std::string size = std::to_string(im.width) + " x " + std::to_string(im.height);
        if (pixels > kMaxPixels) {
            fail("image", "a " + size + " image has " + std::to_string(pixels) +
                              " pixels; expected at most 2147483647 (2^31 - 1)");
        }
        // Whether the image fits in memory depends on the machine, not on the scene: the
        // render command checks it (render/batch/memory_estimate.h, `--max-memory`).
    }

    void camera() const {
        const Camera& c = scene_.camera;
        finite(c.eye, "camera.eye");
        finite(c.lookat, "camera.lookat");
        finite(c.up, "camera.up");
        if (c.up == Vec3{}) fail("camera.up", "expected a non-zero up vector, found [0, 0, 0]");
        // Only a scene built in code (the API) can hold another value.
        if (static_cast<unsigned>(c.type) > static_cast<unsigned>(CameraType::fisheye))
            fail("camera.type",
                 "expected pinhole, orthographic, thinlens or fisheye, found the value " +
                     std::to_string(static_cast<int>(c.type)));
        switch (c.type) {
            case CameraType::orthographic:
                positive(c.width, "camera.width", "a film width");
                break;
            case CameraType::thinlens:
                non_negative(c.aperture, "camera.aperture", "a lens radius");
                positive(c.focus_distance, "camera.focus_distance", "a focus distance");
                if (c.focus_distance > kMaxFocusDistance) {
                    fail("camera.focus_distance",
                         "expected a focus distance of at most " +
                             format_float(kMaxFocusDistance) +
                             " (farther, the focal point overflows float), found " +
                             format_float(c.focus_distance));
                }
                if (c.aperture > kMaxApertureRatio * c.focus_distance) {
                    fail("camera.aperture",
                         "expected a lens radius of at most 10 x the focus distance (here 10 "
                         "x " +
                             format_float(c.focus_distance) + " = " +
                             format_float(kMaxApertureRatio * c.focus_distance) +
                             "; a wider lens starts rays so far off the view axis that float "
                             "precision breaks down), found " +
                             format_float(c.aperture));
                }
                break;
            case CameraType::pinhole:
            case CameraType::fisheye:
                break;
        }
        // The camera frame is the one authority on what a usable camera is.
        try {
            (void)make_camera_frame(c, scene_.image.width, scene_.image.height);
        } catch (const std::invalid_argument& e) {
            static constexpr std::array<std::string_view, 4> names = {"pinhole", "orthographic",
                                                                      "thinlens", "fisheye"};
            std::string found = std::string(names[static_cast<std::size_t>(c.type)]) +
                                " camera, eye " + format_vec(c.eye) + ", lookat " +
                                format_vec(c.lookat) + ", up " + format_vec(c.up);
            if (c.type != CameraType::orthographic) found += ", fov " + format_float(c.fov);
            fail("camera", std::string(e.what()) + " (found " + found + ")");
        }
    }

    void background() const {
        const Background& bg = scene_.background;
        if (bg.type == BackgroundType::constant) {
            color(bg.color, "background.color");
        } else {
            color(bg.bottom, "background.bottom");
            color(bg.top, "background.top");
        }
        color(scene_.ambient, "ambient");
    }

    void render() const {
        int_range(scene_.render.max_depth, "render.max_depth", 0, kMaxDepthLimit);
        if (scene_.render.epsilon)
            positive(*scene_.render.epsilon, "render.epsilon", "epsilon");
    }

    void materials() const {
        std::unordered_set<std::string_view> names;
        for (std::size_t i = 0; i < scene_.materials.size(); ++i) {
            const std::string path = material_path(i);
            const NamedMaterial& nm = scene_.materials[i];
            if (!nm.name.empty() && !names.insert(nm.name).second) {
                fail(path, "duplicate material name " + quote_text(nm.name));
            }
            const Material& m = nm.material;
            color(m.color, child_path(path, "color"));
            non_negative(m.kd, child_path(path, "kd"), "kd");
            non_negative(m.ks, child_path(path, "ks"), "ks");
            non_negative(m.shininess, child_path(path, "shininess"), "a Phong exponent");
            color(m.reflect, child_path(path, "reflect"));
            non_negative(m.transmit, child_path(path, "transmit"), "transmit");
            positive(m.ior, child_path(path, "ior"), "an index of refraction");
            if (m.ior < kMinIor || m.ior > kMaxIor) {
                fail(child_path(path, "ior"),
                     "expected an index of refraction from " + format_float(kMinIor) + " to " +
                         format_float(kMaxIor) +
                         " (far beyond that ratio refraction loses float precision), found " +
                         format_float(m.ior));
            }
            if (m.checker) {
                const std::string cpath = child_path(path, "checker");
                color(m.checker->color, child_path(cpath, "color"));
                positive(m.checker->size, child_path(cpath, "size"), "a checker size");
            }
        }
    }

    // The checks of object i but its name's: false where one fails, which `report` makes
    // a SceneError. Paths are built only for a failing object: a valid scene of millions
    // of spheres would otherwise build several strings per object for nothing.
    bool object_holds(std::size_t i, bool report) const {
        const auto path = [i] { return index_path("objects", i); };
        const Object& o = scene_.objects[i];
        if (o.material >= scene_.materials.size()) {
            if (!report) return false;
            fail(child_path(path(), "material"),
                 "expected a material index below " + std::to_string(scene_.materials.size()) +
                     " (the scene's material count), found " + std::to_string(o.material));
        }
        if (o.type == ObjectType::sphere) {
            if (!is_finite(o.center) || !(std::isfinite(o.radius) && o.radius > 0.0f)) {
                if (!report) return false;
                finite(o.center, child_path(path(), "center"));
                positive(o.radius, child_path(path(), "radius"), "a radius");
            }
            return true;
        }
        if (!is_finite(o.point) || !is_finite(o.normal)) {
            if (!report) return false;
            finite(o.point, child_path(path(), "point"));
            finite(o.normal, child_path(path(), "normal"));
        }
        const double len2 = static_cast<double>(o.normal.x) * o.normal.x +
                            static_cast<double>(o.normal.y) * o.normal.y +
                            static_cast<double>(o.normal.z) * o.normal.z;
        if (!(std::fabs(len2 - 1.0) <= kValidateUnitTolerance)) {
            if (!report) return false;
            fail(child_path(path(), "normal"),
                 "expected a unit-length normal (scene files are normalised on load), found " +
                     format_vec(o.normal));
        }
        return true;
    }

    void objects() const {
        // Every object's checks on every core, the spheres' box in the same pass; an object
        // that fails is checked again to say why. Names need a map in file order: a scene
        // that names any object is checked one object after another, as it always was
        // (two serial passes over a million unnamed spheres took 7 ms).
        struct Pass {
            std::size_t first_failing = std::numeric_limits<std::size_t>::max();
            bool named = false;
            SphereBox box;
        };
        const Pass pass = tbb::parallel_reduce(
            tbb::blocked_range<std::size_t>(0, scene_.objects.size(), std::size_t{1} << 14),
            Pass{},
            [&](const tbb::blocked_range<std::size_t>& r, Pass p) {
                for (std::size_t i = r.begin(); i < r.end(); ++i) {
                    const Object& o = scene_.objects[i];
                    p.named = p.named || !o.name.empty();
                    if (!object_holds(i, false)) {
                        p.first_failing = std::min(p.first_failing, i);
                        break;
                    }
                    if (o.type == ObjectType::sphere) p.box.add(o);
                }
                return p;
            },
            [](const Pass& a, const Pass& b) {
                return Pass{std::min(a.first_failing, b.first_failing), a.named || b.named,
                            SphereBox::unite(a.box, b.box)};
            });
        if (pass.named) {
            std::unordered_map<std::string_view, std::size_t> names;
            for (std::size_t i = 0; i < scene_.objects.size(); ++i) {
                object_holds(i, true);
                const Object& o = scene_.objects[i];
                if (o.name.empty()) continue;
                const auto [it, inserted] = names.emplace(o.name, i);
                if (!inserted) {
                    fail(child_path(index_path("objects", i), "name"),
                         "expected a unique object name, found " + quote_text(o.name) +
                             " again (first used by objects[" + std::to_string(it->second) +
                             "])");
                }
            }
        } else if (pass.first_failing < scene_.objects.size()) {
            object_holds(pass.first_failing, true);  // throws
        }
        // The self-intersection offset is derived from the spheres' bounding box; a box
        // that overflows float would make it infinite.
        if (!std::isfinite(self_intersection_epsilon(scene_, pass.box))) {
            fail("objects",
                 "the spheres' bounding box overflows float range; expected "
                 "coordinates and radii small enough that its diagonal is finite");
        }
    }

    // Key frames strictly increasing, within [0, 2^31 - 1].
    template <typename Key>
    void key_frames(const std::vector<Key>& keys, const std::string& path) const {
        for (std::size_t i = 0; i < keys.size(); ++i) {
            const std::string fpath = child_path(index_path(path, i), "frame");
            if (keys[i].frame < 0) {
                fail(fpath,
                     "expected a frame number >= 0, found " + std::to_string(keys[i].frame));
            }
            if (i > 0 && keys[i].frame <= keys[i - 1].frame) {
                fail(fpath, "expected key frames in strictly increasing order, found frame " +
                                std::to_string(keys[i].frame) + " after frame " +
                                std::to_string(keys[i - 1].frame) + " (" +
                                index_path(path, i - 1) + ")");
            }
        }
    }

    // The animation's own rules, then the camera of every frame that can differ (the pose
    // is constant after the last camera key) through the same checks as the still camera.
    void animation() const {
        if (!scene_.animation) return;
        const Animation& a = *scene_.animation;
        int_range(a.frames, "animation.frames", 1, kMaxAnimationFrames);
        if (!(std::isfinite(a.fps) && a.fps > 0.0)) {
            char buf[64];
            std::snprintf(buf, sizeof buf, "%g", a.fps);
            fail("animation.fps", std::string("expected frames per second > 0, found ") + buf);
        }

        const Camera& c = scene_.camera;
        key_frames(a.camera, "animation.camera");
        for (std::size_t i = 0; i < a.camera.size(); ++i) {
            const CameraKey& k = a.camera[i];
            const std::string path = index_path("animation.camera", i);
            if (!k.eye && !k.lookat && !k.up && !k.fov) {
                fail(path,
                     "a camera key sets nothing; expected at least one of \"eye\", "
                     "\"lookat\", \"up\", \"fov\" besides \"frame\"");
            }
            if (k.eye) finite(*k.eye, child_path(path, "eye"));
            if (k.lookat) finite(*k.lookat, child_path(path, "lookat"));
            if (k.up) {
                finite(*k.up, child_path(path, "up"));
                if (*k.up == Vec3{}) {
                    fail(child_path(path, "up"),
                         "expected a non-zero up vector, found [0, 0, 0]");
                }
            }
            if (k.fov) {
                const std::string fpath = child_path(path, "fov");
                if (c.type == CameraType::orthographic) {
                    fail(fpath,
                         "key \"fov\" applies only to pinhole, thinlens and fisheye "
                         "cameras, not to an orthographic camera");
                }
                const float fov = *k.fov;
                const bool fisheye = c.type == CameraType::fisheye;
                const bool ok =
                    fisheye ? (fov > 0.0f && fov <= 360.0f) : (fov > 0.0f && fov < 180.0f);
                if (!ok) {
                    fail(fpath, std::string("expected a field of view in ") +
                                    (fisheye ? "(0, 360]" : "(0, 180)") + " degrees, found " +
                                    format_float(fov));
                }
            }
        }

        std::unordered_set<std::uint32_t> animated;
        for (const ObjectTrack& track : a.objects) {
            const std::string path = child_path("animation.objects", track.name);
            if (track.object >= scene_.objects.size()) {
                fail(path,
                     "expected an object index below " + std::to_string(scene_.objects.size()) +
                         " (the scene's object count), found " + std::to_string(track.object));
            }
            const Object& o = scene_.objects[track.object];
            const std::string opath = index_path("objects", track.object);
            if (o.name != track.name) {
                fail(path, "the track is for " + quote_text(track.name) + " but " + opath +
                               " is named " + quote_text(o.name));
            }
            if (!animated.insert(track.object).second) {
                fail(path, "expected one track per object, found a second one for " +
                               quote_text(track.name));
            }
            key_frames(track.keys, path);
            for (std::size_t i = 0; i < track.keys.size(); ++i) {
                const ObjectKey& k = track.keys[i];
                const std::string kpath = index_path(path, i);
                if (!k.center && !k.radius) {
                    fail(kpath,
                         "an object key sets nothing; expected \"center\" and/or "
                         "\"radius\" besides \"frame\"");
                }
                const auto sphere_only = [&](std::string_view key) {
                    fail(child_path(kpath, key),
                         "key " + quote_text(key) +
                             " applies only to spheres, not to a plane (" + opath + ", " +
                             quote_text(o.name) + ")");
                };
                if (k.center) {
                    if (o.type != ObjectType::sphere) sphere_only("center");
                    finite(*k.center, child_path(kpath, "center"));
                }
                if (k.radius) {
                    if (o.type != ObjectType::sphere) sphere_only("radius");
                    positive(*k.radius, child_path(kpath, "radius"), "a radius");
                }
            }
        }

        animated_bounds(a);
        animated_cameras(a);
    }

    // Interpolated centers and radii stay within the range of the keys' and the authored
    // values, so the box of all of them bounds every frame's spheres: if its diagonal is
    // finite, so is every frame's ε_s.
    void animated_bounds(const Animation& a) const {
        if (scene_.render.epsilon || a.objects.empty()) return;
        Scene hull;
        hull.objects = scene_.objects;
        for (const ObjectTrack& track : a.objects) {
            const Object& o = scene_.objects[track.object];
            float radius = o.radius;
            for (const ObjectKey& k : track.keys) {
                if (k.radius) radius = std::max(radius, *k.radius);
            }
            for (const ObjectKey& k : track.keys) {
                if (!k.center) continue;
                Object extra = o;
                extra.center = *k.center;
                extra.radius = radius;
                hull.objects.push_back(extra);
            }
            hull.objects[track.object].radius = radius;
        }
        if (!std::isfinite(self_intersection_epsilon(hull))) {
            fail("animation.objects",
                 "the spheres' bounding box over all frames overflows float range; expected "
                 "coordinates and radii small enough that its diagonal is finite");
        }
    }

    void animated_cameras(const Animation& a) const {
        if (a.camera.empty()) return;
        // After the last camera key every frame has the pose of that key's frame.
        const int last = std::min(a.frames - 1, a.camera.back().frame);
        Scene still;
        still.source = scene_.source;
        still.image = scene_.image;
        visit_camera_frames(scene_, 0, last, [&](int f, const Camera& camera) {
            still.camera = camera;
            try {
                Validator(still).camera();
            } catch (const SceneError& e) {
                std::string what = e.what();
                const std::string prefix = e.json_path() + ": ";
                const std::size_t at = what.find(prefix);
                if (at != std::string::npos) what.erase(0, at + prefix.size());
                fail("animation.camera", "at frame " + std::to_string(f) +
                                             " the interpolated camera is unusable: " + what);
            }
        });
    }

    void lights() const {
        for (std::size_t i = 0; i < scene_.lights.size(); ++i) {
            const std::string path = index_path("lights", i);
            const Light& l = scene_.lights[i];
            if (l.type == LightType::point) {
                finite(l.position, child_path(path, "position"));
            } else {
                finite(l.direction, child_path(path, "direction"));
                if (l.direction == Vec3{}) {
                    fail(child_path(path, "direction"),
                         "expected a non-zero direction, found [0, 0, 0]");
                }
            }
            color(l.color, child_path(path, "color"));
        }
    }

  private:
    const Scene& scene_;
};

}  // namespace

void validate_scene(const Scene& scene) {
    const Validator v(scene);
    v.image();
    v.camera();
    v.background();
    v.render();
    v.materials();
    v.objects();
    v.lights();
    v.animation();
}

}  // namespace octray
