#include "render/frame_renderer.h"

#include <stdexcept>

#include "render/reference.h"
#include "scene/animation.h"

namespace octray {

FrameRenderer::FrameRenderer(const Scene& scene, RenderPath path, Isa isa, Accel accel,
                             int threads)
    : source_(scene), path_(path), isa_(isa), accel_(accel), threads_(threads) {}

const Scene& FrameRenderer::prepare(int frame, Timing* timing) {
    Timing t;
    // The pose: a still scene is its own (no copy of its objects); an animated one is
    // copied and validated for its first frame, and reposed in place after.
    current_ = nullptr;
    const Scene* pose = &source_;
    if (source_.animation) {
        if (posed_)
            repose_at_frame(source_, frame, *posed_);
        else
            posed_ = scene_at_frame(source_, frame);
        pose = &*posed_;
    }
    if (path_ == RenderPath::simd) {
        if (!prepared_) {
            prepared_.emplace(*pose, accel_, threads_);
            t.compile_seconds = prepared_->compile_seconds();
            t.bvh_seconds = prepared_->bvh_seconds();
        } else if (!source_.animation || source_.animation->objects.empty()) {
            prepared_->set_camera(pose->camera);
        } else {
            t.bvh_seconds = prepared_->update(*pose).seconds;
        }
    }
    current_ = pose;
    if (timing != nullptr) *timing = t;
    return *pose;
}

RenderResult FrameRenderer::render(const RenderOptions& options) const {
    if (current_ == nullptr) throw std::logic_error("FrameRenderer::render before prepare");
    return path_ == RenderPath::simd ? render_packet(*prepared_, options, isa_)
                                     : render_reference(*current_, options);
}

Image FrameRenderer::aovs(const RenderOptions& options, AovSet set) const {
    if (current_ == nullptr) throw std::logic_error("FrameRenderer::aovs before prepare");
    if (!set.any() || path_ != RenderPath::simd) return compute_aovs(*current_, options, set);
    return compute_aovs(*current_, options, set, trace_first_hits(*prepared_, options, isa_));
}

}  // namespace octray
