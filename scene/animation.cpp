// Posing an animated scene at one frame: per-property linear interpolation between the
// keys that set the property, held outside them (scene/animation.h, scene/README.md).

#include "scene/animation.h"

#include <algorithm>
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

Scene scene_at_frame(const Scene& scene, int frame) {
    if (!scene.animation) return scene;
    const Animation& a = *scene.animation;
    const int f = clamp_frame(a, frame);
    const std::string at = "at frame " + std::to_string(frame) +
                           (f != frame ? " (posed as frame " + std::to_string(f) + ")" : "");

    Scene posed = scene;
    posed.animation.reset();
    posed.camera = camera_at_frame(scene, f);
    for (const ObjectTrack& track : a.objects) {
        if (track.object >= posed.objects.size()) {
            throw SceneError(scene.source, "animation.objects",
                             "the track for " + track.name + " names objects[" +
                                 std::to_string(track.object) + "], but the scene has " +
                                 std::to_string(posed.objects.size()) + " objects");
        }
        Object& o = posed.objects[track.object];
        const auto& keys = track.keys;
        const PropertyTrack<Vec3> center(keys, [](const ObjectKey& k) { return k.center; });
        const PropertyTrack<float> radius(keys, [](const ObjectKey& k) { return k.radius; });
        if (auto v = center.at(f)) o.center = *v;
        if (auto v = radius.at(f)) o.radius = *v;
    }
    try {
        validate_scene(posed);
    } catch (const SceneError& e) {
        throw SceneError(e.file(), e.json_path(),
                         at + ", as posed by the animation: " + bare_message(e));
    }
    return posed;
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
