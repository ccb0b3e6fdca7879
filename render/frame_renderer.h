#pragma once
// Prepare once, render many: the frames of one scene on either path, behind one interface
// (the batch frame loop and the library API render through it). It poses each frame of an
// animated scene in place (repose_at_frame; a camera-only animation is not even copied:
// each frame takes its camera) and keeps what frames share: on the simd path the compiled
// scene and its BVH (PreparedScene), prepared for the first frame; a still's or a
// camera-only animation's next frames only take their camera, and moving spheres are
// updated in place with the BVH refitted (PreparedScene::update). The scalar path renders
// each frame from its posed scene with the reference. Either way a frame is, bit for bit,
// the frame rendered on its own, whatever frames came before it.

#include <optional>

#include "kernels/isa.h"
#include "render/accel.h"
#include "render/aov.h"
#include "render/packet_renderer.h"
#include "render/render_result.h"
#include "scene/scene.h"

namespace octray {

class FrameRenderer {
  public:
    // Frames of `scene` (validated, and alive as long as the renderer) on `path`: the simd
    // path with the kernels of `isa` and the sphere BVH per `accel`, prepared on `threads`
    // threads (0: every core TBB sees).
    FrameRenderer(const Scene& scene, RenderPath path, Isa isa = Isa::automatic,
                  Accel accel = Accel::automatic, int threads = 0);

    // What preparing a frame took: compiling and building the BVH for the simd path's
    // first frame; updating the spheres and refitting the BVH (bvh_seconds) for a next
    // frame whose spheres move; nothing otherwise.
    struct Timing {
        double compile_seconds = 0.0;
        double bvh_seconds = 0.0;
        double seconds() const { return compile_seconds + bvh_seconds; }
    };
    // A posed frame: the scene its objects, materials, lights and settings come from (the
    // scene itself when still or when only the camera moves; a posed copy when spheres
    // move), and the frame's camera, which is scene.camera but for a camera-only animation.
    struct Pose {
        const Scene& scene;
        Camera camera;
    };
    // Poses frame `frame` and prepares it for render() and aovs(); returns its pose, whose
    // scene is valid until the next prepare(). Throws SceneError for a pose the renderers
    // cannot use.
    Pose prepare(int frame, Timing* timing = nullptr);
    // The prepared frame; options.frame should be the frame prepared (it seeds the jitter).
    RenderResult render(const RenderOptions& options) const;
    // The prepared frame's AOVs: each pixel's first hit traced by the kernels (simd) or by
    // the reference (scalar), the same values either way.
    Image aovs(const RenderOptions& options, AovSet set) const;

    RenderPath path() const { return path_; }
    Isa isa() const { return isa_; }

  private:
    // The prepared frame's whole scene, camera included: for a camera-only animation the
    // scene is copied only when a renderer needs it (the scalar path, AOVs), once.
    const Scene& posed_scene() const;

    const Scene& source_;
    RenderPath path_;
    Isa isa_;
    Accel accel_;
    int threads_;
    bool camera_only_;                       // animated, and only the camera moves
    mutable std::optional<Scene> posed_;     // an animated scene's last pose
    std::optional<PreparedScene> prepared_;  // simd: from the first frame on
    const Scene* current_ = nullptr;         // the prepared frame's scene ...
    Camera camera_;                          // ... and camera
};

}  // namespace octray
