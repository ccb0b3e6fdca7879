#include "render/frame_renderer.h"

#include <stdexcept>

#include "render/reference.h"
#include "scene/animation.h"

namespace octray {

FrameRenderer::FrameRenderer(const Scene& scene, RenderPath path, Isa isa, Accel accel,
                             int threads)
    : source_(scene),
      path_(path),
      isa_(isa),
      accel_(accel),
      threads_(threads),
      camera_only_(scene.animation && scene.animation->objects.empty()) {}

FrameRenderer::Pose FrameRenderer::prepare(int frame, Timing* timing) {
    Timing t;
    // The pose: a still scene is its own (no copy of its objects), and so is one whose
    // camera alone moves: the frame takes its camera, and nothing is validated again
    // (validate_scene checked the camera of every frame when the scene loaded, and nothing
    // else changes; copying a million spheres took 30 ms, validating them 30-50 ms more).
    // One whose spheres move is copied and validated for its first frame, and reposed in
    // place after.
    current_ = nullptr;
    const Scene* pose = &source_;
    if (camera_only_) {
        camera_ = camera_at_frame(source_, frame);
    } else if (source_.animation) {
        if (posed_)
            repose_at_frame(source_, frame, *posed_);
        else
            posed_ = scene_at_frame(source_, frame);
        pose = &*posed_;
        camera_ = pose->camera;
    } else {
        camera_ = source_.camera;
    }
    if (path_ == RenderPath::simd) {
        if (!prepared_) {
            prepared_.emplace(*pose, accel_, threads_);
            if (camera_only_) prepared_->set_camera(camera_);
            t.compile_seconds = prepared_->compile_seconds();
            t.bvh_seconds = prepared_->bvh_seconds();
        } else if (!source_.animation || camera_only_) {
            prepared_->set_camera(camera_);
        } else {
            t.bvh_seconds = prepared_->update(*pose).seconds;
        }
    }
    current_ = pose;
    if (timing != nullptr) *timing = t;
    return {*pose, camera_};
}

const Scene& FrameRenderer::posed_scene() const {
    if (!camera_only_) return *current_;
    if (!posed_) {
        posed_.emplace(source_);
        posed_->animation.reset();
    }
    posed_->camera = camera_;
    return *posed_;
}

RenderResult FrameRenderer::render(const RenderOptions& options) const {
    if (current_ == nullptr) throw std::logic_error("FrameRenderer::render before prepare");
    return path_ == RenderPath::simd ? render_packet(*prepared_, options, isa_)
                                     : render_reference(posed_scene(), options);
}

Image FrameRenderer::aovs(const RenderOptions& options, AovSet set) const {
    if (current_ == nullptr) throw std::logic_error("FrameRenderer::aovs before prepare");
    // No AOVs: the frame's windows without channels (every pose has the scene's size).
    if (!set.any()) return compute_aovs(*current_, options, set);
    if (path_ != RenderPath::simd) return compute_aovs(posed_scene(), options, set);
    return compute_aovs(posed_scene(), options, set,
                        trace_first_hits(*prepared_, options, isa_));
}

}  // namespace octray
