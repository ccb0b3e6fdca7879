#pragma once
// Key-frame animation of the camera and of named spheres (docs/scene-format.md,
// "Animation"), and the still scene a frame renders. Rules chosen where the spec is
// silent are in scene/README.md ("Animation").
//
// Interpolation is per property: a property (camera eye, lookat, up, fov; object center,
// radius) is interpolated linearly between the keys that set it, held at the first such
// key's value before it and at the last one's after it; a property no key sets keeps the
// scene's authored value. Interpolation runs in double precision (std::lerp, exact at the
// keys) and is rounded to float once.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/vec3.h"

namespace octray {

struct Scene;
struct Camera;

struct CameraKey {
    int frame = 0;
    std::optional<Vec3> eye, lookat, up;
    std::optional<float> fov;
};

struct ObjectKey {
    int frame = 0;
    std::optional<Vec3> center;
    std::optional<float> radius;
};

struct ObjectTrack {
    std::string name;          // the object's "name" in the file
    std::uint32_t object = 0;  // index into Scene::objects (a sphere with that name)
    std::vector<ObjectKey> keys;
};

struct Animation {
    int frames = 1;                    // the sequence is frames 0 .. frames - 1
    double fps = 24.0;                 // frame f shows time f / fps seconds
    std::vector<CameraKey> camera;     // strictly increasing frames
    std::vector<ObjectTrack> objects;  // file order; each key list strictly increasing
};

// At most this many frames per animation: validate_scene checks the camera of every frame,
// and a typo such as "frames": 100000000000 must be an error, not a hang.
inline constexpr int kMaxAnimationFrames = 1'000'000;

// The fps of a still scene, for frame_time.
inline constexpr double kStillFps = 24.0;

// The camera at `frame` (frames outside [0, frames) take the nearest end frame's pose);
// the scene's own camera for a still scene. Not validated.
Camera camera_at_frame(const Scene& scene, int frame);

// Calls visit(f, camera_at_frame(scene, f)) for f = first ... last in order, indexing the
// keys once (camera_at_frame indexes them on every call): validate_scene checks every
// frame's camera this way.
void visit_camera_frames(const Scene& scene, int first, int last,
                         const std::function<void(int, const Camera&)>& visit);

// A still scene (animation reset) posed at `frame`; frames outside [0, frames) hold the
// end values (frame < 0 poses frame 0, frame >= frames poses frames - 1). A still scene
// is returned as it is. The posed scene is validated: a pose the renderers cannot use
// (a bounding box that overflows, a camera frame that cannot be built on a scene that
// skipped validate_scene) throws SceneError with the path and "at frame N" in the message.
Scene scene_at_frame(const Scene& scene, int frame);

// Poses `posed` at `frame` in place: `posed` is what scene_at_frame(scene, f) returned
// for some frame f of the same `scene` (possibly reposed since). Only the camera and the
// animated spheres are written, nothing else is copied, and only what they can break is
// checked again; an unusable pose throws the SceneError scene_at_frame would. Nothing
// for a still scene. After a throw, posed holds a mix of frames until its next repose.
void repose_at_frame(const Scene& scene, int frame, Scene& posed);

// Seconds: frame / fps (kStillFps for a still scene).
double frame_time(const Scene& scene, int frame);

// 0 .. frames - 1 for an animated scene, {0} for a still one.
std::vector<int> default_frames(const Scene& scene);

}  // namespace octray
