// Posing an animated scene at one frame: per-property linear interpolation between the
// keys that set the property, held outside them (scene/animation.h, scene/README.md).

#include "scene/animation.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "scene/load.h"
#include "scene/scene.h"
#include "scene/scene_error.h"

namespace octray {
namespace {

float lerp_float(float a, float b, double t) {
    // std::lerp is exact at t = 0 and t = 1 and returns a when a == b; in double it
    // cannot overflow for float inputs, and the single rounding to float stays within
    // [min(a, b), max(a, b)].
    return static_cast<float>(std::lerp(static_cast<double>(a), static_cast<double>(b), t));
}

Vec3 lerp_value(Vec3 a, Vec3 b, double t) {
    return {lerp_float(a.x, b.x, t), lerp_float(a.y, b.y, t), lerp_float(a.z, b.z, t)};
}

float lerp_value(float a, float b, double t) { return lerp_float(a, b, t); }

// One property's keys (only those that set it), in frame order: evaluated by binary
// search, so posing many frames costs O(log keys) each (validate_scene poses every frame).
template <typename T>
class PropertyTrack {
  public:
    template <typename Key, typename Get>
    PropertyTrack(const std::vector<Key>& keys, Get get) {
        for (const Key& k : keys) {
            if (const std::optional<T> v = get(k)) {
                frames_.push_back(k.frame);
                values_.push_back(*v);
            }
        }
    }

    // nullopt when no key sets the property: the scene's value stays.
    std::optional<T> at(int frame) const {
        if (frames_.empty()) return std::nullopt;
        // The first key after `frame`; the one before it is at or before `frame`.
        const auto after = std::upper_bound(frames_.begin(), frames_.end(), frame);
        if (after == frames_.begin()) return values_.front();  // held before the first key
        if (after == frames_.end()) return values_.back();     // held after the last key
        const std::size_t i = static_cast<std::size_t>(after - frames_.begin());
        const double t = (static_cast<double>(frame) - frames_[i - 1]) /
                         (static_cast<double>(frames_[i]) - frames_[i - 1]);
        return lerp_value(values_[i - 1], values_[i], t);
    }

  private:
    std::vector<int> frames_;  // strictly increasing (validate_scene)
    std::vector<T> values_;
};

// The camera keys indexed per property once.
struct CameraTracks {
    explicit CameraTracks(const std::vector<CameraKey>& keys)
        : eye(keys, [](const CameraKey& k) { return k.eye; }),
          lookat(keys, [](const CameraKey& k) { return k.lookat; }),
          up(keys, [](const CameraKey& k) { return k.up; }),
          fov(keys, [](const CameraKey& k) { return k.fov; }) {}

    Camera pose(Camera camera, int frame) const {
        if (auto v = eye.at(frame)) camera.eye = *v;
        if (auto v = lookat.at(frame)) camera.lookat = *v;
        if (auto v = up.at(frame)) camera.up = *v;
        if (auto v = fov.at(frame)) camera.fov = *v;
        return camera;
    }

    PropertyTrack<Vec3> eye, lookat, up;
    PropertyTrack<float> fov;
};

// Frames outside the sequence take the nearest end frame's pose.
int clamp_frame(const Animation& a, int frame) {
    return std::clamp(frame, 0, std::max(a.frames, 1) - 1);
}

// The message of a SceneError without its "file: path: " prefix.
std::string bare_message(const SceneError& e) { return e.message(); }

}  // namespace

Camera camera_at_frame(const Scene& scene, int frame) {
    if (!scene.animation) return scene.camera;
    const Animation& a = *scene.animation;
    return CameraTracks(a.camera).pose(scene.camera, clamp_frame(a, frame));
}

void visit_camera_frames(const Scene& scene, int first, int last,
                         const std::function<void(int, const Camera&)>& visit) {
    if (!scene.animation) {
        for (int f = first; f <= last; ++f) visit(f, scene.camera);
        return;
    }
    const Animation& a = *scene.animation;
    const CameraTracks tracks(a.camera);
    for (int f = first; f <= last; ++f) visit(f, tracks.pose(scene.camera, clamp_frame(a, f)));
}

namespace {

// The value at `frame` of the property that `get` reads from a sphere's keys: the same
// interpolation as PropertyTrack::at, read from the keys directly (posing a million
// spheres a frame should not build two small vectors for each).
template <typename T, typename Get>
std::optional<T> object_property_at(const std::vector<ObjectKey>& keys, int frame, Get get) {
    const ObjectKey* before = nullptr;  // the last key that sets it at or before `frame`
    const ObjectKey* after = nullptr;   // the first key that sets it after `frame`
    for (const ObjectKey& k : keys) {
        if (!get(k)) continue;
        if (k.frame > frame) {
            after = &k;
            break;
        }
        before = &k;
    }
    if (before == nullptr) return after != nullptr ? get(*after) : std::nullopt;
    if (after == nullptr) return get(*before);
    const double t = (static_cast<double>(frame) - before->frame) /
                     (static_cast<double>(after->frame) - before->frame);
    return lerp_value(*get(*before), *get(*after), t);
}

// Sets the camera and every animated sphere of `posed` (a copy of `scene`'s objects) to
// their values at frame `f` (clamped). Returns whether every moved sphere is still usable
// (finite center, finite positive radius), the check validate_scene would make of it.
bool pose_in_place(const Scene& scene, int f, Scene& posed) {
    const Animation& a = *scene.animation;
    posed.camera = camera_at_frame(scene, f);
    for (const ObjectTrack& track : a.objects) {
        if (track.object >= posed.objects.size()) {
            throw SceneError(scene.source, "animation.objects",
                             "the track for " + track.name + " names objects[" +
                                 std::to_string(track.object) + "], but the scene has " +
                                 std::to_string(posed.objects.size()) + " objects");
        }
    }
    std::atomic<bool> usable{true};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, a.objects.size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          bool ok = true;
                          for (std::size_t i = r.begin(); i < r.end(); ++i) {
                              const ObjectTrack& track = a.objects[i];
                              Object& o = posed.objects[track.object];
                              const auto& keys = track.keys;
                              if (auto v = object_property_at<Vec3>(
                                      keys, f, [](const ObjectKey& k) { return k.center; }))
                                  o.center = *v;
                              if (auto v = object_property_at<float>(
                                      keys, f, [](const ObjectKey& k) { return k.radius; }))
                                  o.radius = *v;
                              ok &= is_finite(o.center) && std::isfinite(o.radius) &&
                                    o.radius > 0.0f;
                          }
                          if (!ok) usable = false;
                      });
    return usable;
}

// "at frame 7" or "at frame 60 (posed as frame 47)".
std::string frame_label(const Animation& a, int frame) {
    const int f = clamp_frame(a, frame);
    return "at frame " + std::to_string(frame) +
           (f != frame ? " (posed as frame " + std::to_string(f) + ")" : "");
}

// validate_scene(posed), its errors naming the frame.
void validate_pose(const Scene& scene, int frame, const Scene& posed) {
    try {
        validate_scene(posed);
    } catch (const SceneError& e) {
        throw SceneError(e.file(), e.json_path(),
                         frame_label(*scene.animation, frame) +
                             ", as posed by the animation: " + bare_message(e));
    }
}

}  // namespace

Scene scene_at_frame(const Scene& scene, int frame) {
    if (!scene.animation) return scene;
    Scene posed = scene;
    posed.animation.reset();
    pose_in_place(scene, clamp_frame(*scene.animation, frame), posed);
    validate_pose(scene, frame, posed);
    return posed;
}

void repose_at_frame(const Scene& scene, int frame, Scene& posed) {
    if (!scene.animation) return;
    const bool usable = pose_in_place(scene, clamp_frame(*scene.animation, frame), posed);
    // Only the camera and the moved spheres changed since posed was validated: the camera
    // of every frame was checked when the scene loaded, the spheres just now, and what
    // else a pose can break is the spheres' bounding box. Anything wrong takes the whole
    // validation, for the message scene_at_frame would give.
    if (!usable || !std::isfinite(self_intersection_epsilon(posed)))
        validate_pose(scene, frame, posed);
}

double frame_time(const Scene& scene, int frame) {
    const double fps = scene.animation ? scene.animation->fps : kStillFps;
    return static_cast<double>(frame) / fps;
}

std::vector<int> default_frames(const Scene& scene) {
    if (!scene.animation) return {0};
    std::vector<int> frames(static_cast<std::size_t>(std::max(scene.animation->frames, 1)));
    for (std::size_t i = 0; i < frames.size(); ++i) frames[i] = static_cast<int>(i);
    return frames;
}

}  // namespace octray
