#include "view/view_session.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "kernels/dispatch.h"
#include "render/batch/progressive.h"
#include "render/packet_renderer.h"
#include "render/reference.h"
#include "scene/animation.h"
#include "scene/load.h"
#include "scene/scene_error.h"
#include "view/frameless.h"

namespace octray::view {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

double mrays_per_second(const RenderResult& result) {
    return result.seconds > 0.0
               ? static_cast<double>(result.rays.total()) / result.seconds / 1e6
               : 0.0;
}

// `source` posed at `frame` (a still scene is its own pose), with the spp and max depth of
// the switches.
Scene posed_scene(const Scene& source, int frame, int spp, int max_depth) {
    Scene posed = source.animation ? scene_at_frame(source, frame) : source;
    posed.image.spp = spp;
    posed.render.max_depth = max_depth;
    return posed;
}

}  // namespace

ViewSession::ViewSession(Scene scene, ViewSettings settings)
    : animated_(scene.animation ? std::optional<Scene>(scene) : std::nullopt),
      frame_count_(scene.animation ? scene.animation->frames : 1),
      fps_(scene.animation ? scene.animation->fps : kStillFps),
      scene_(animated_ ? posed_scene(*animated_, settings.frame, scene.image.spp,
                                     scene.render.max_depth)
                       : std::move(scene)),
      settings_(settings),
      camera_(scene_.camera) {
    if (!animated_) settings_.frame = 0;
    thread_ = std::thread([this] { run(); });
}

ViewSession::~ViewSession() { stop(); }

const char* to_string(PixelOrder order) {
    switch (order) {
        case PixelOrder::tiled:
            return "tiled";
        case PixelOrder::rows:
            return "rows";
        case PixelOrder::frameless:
            return "frameless";
    }
    return "tiled";
}

std::optional<PixelOrder> parse_pixel_order(const std::string& name) {
    for (const PixelOrder order : {PixelOrder::tiled, PixelOrder::rows, PixelOrder::frameless})
        if (name == to_string(order)) return order;
    return std::nullopt;
}

Scene ViewSession::scene() const {
    std::lock_guard lock(mutex_);
    return scene_;
}

RenderSwitches ViewSession::switches() const {
    std::lock_guard lock(mutex_);
    return RenderSwitches{settings_.render, scene_.image.spp, scene_.render.max_depth,
                          settings_.order, settings_.frame};
}

RenderOptions ViewSession::render_options(int width) const {
    RenderOptions options;
    options.threads = settings_.render.threads;
    options.cancel = &cancel_;
    options.frame = static_cast<std::uint32_t>(settings_.frame);
    if (settings_.order == PixelOrder::rows) {
        options.tile_width = width;
        options.tile_height = 1;
    }
    return options;
}

// A picture of camera `version` with what the switches say of how it is made.
ViewFrame ViewSession::frame_of(std::uint64_t version, const Camera& camera) const {
    ViewFrame frame;
    frame.camera_version = version;
    frame.camera = camera;
    frame.target_spp = scene_.image.spp;
    frame.max_depth = scene_.render.max_depth;
    frame.animation_frame = settings_.frame;
    frame.path = settings_.render.path;
    frame.isa = settings_.render.isa;
    return frame;
}

std::uint64_t ViewSession::reconfigure(const RenderSwitches& switches) {
    std::lock_guard guard(reconfigure_mutex_);
    if (switches.frame < 0 || switches.frame >= frame_count_)
        throw std::out_of_range("frame " + std::to_string(switches.frame) +
                                " is outside the animation's frames 0 to " +
                                std::to_string(frame_count_ - 1));
    if (switches.render.path == RenderPath::simd)
        resolve_isa(switches.render.isa);  // throws: no change
    // Only this function changes scene_, and only from here on: reading it needs no lock.
    Scene next = animated_
                     ? posed_scene(*animated_, switches.frame, switches.spp, switches.max_depth)
                     : posed_scene(scene_, 0, switches.spp, switches.max_depth);
    validate_scene(next);  // throws SceneError: nothing changes
    // A new frame of an animated camera shows that frame's camera.
    const bool frame_camera =
        animated_ && !animated_->animation->camera.empty() && switches.frame != settings_.frame;
    {
        std::lock_guard lock(mutex_);
        if (stop_) return camera_version_;
        restart_ = true;
        cancel_ = true;
    }
    changed_.notify_all();
    if (thread_.joinable()) thread_.join();
    std::uint64_t version = 0;
    {
        std::lock_guard lock(mutex_);
        if (frame_camera) camera_ = next.camera;
        scene_ = std::move(next);
        settings_.render = switches.render;
        settings_.order = switches.order;
        settings_.frame = switches.frame;
        restart_ = false;
        cancel_ = false;
        version = ++camera_version_;  // the current camera again, under the new switches
        moving_ = false;
    }
    thread_ = std::thread([this] { run(); });
    return version;
}

void ViewSession::stop() {
    std::lock_guard guard(reconfigure_mutex_);
    {
        std::lock_guard lock(mutex_);
        stop_ = true;
        cancel_ = true;
    }
    changed_.notify_all();
    if (thread_.joinable() && thread_.get_id() != std::this_thread::get_id()) thread_.join();
}

bool ViewSession::stopped() const {
    std::lock_guard lock(mutex_);
    return stop_;
}

std::shared_ptr<const ViewFrame> ViewSession::latest() const {
    std::lock_guard lock(mutex_);
    return latest_;
}

std::shared_ptr<const ViewFrame> ViewSession::wait_newer(
    std::uint64_t generation, std::chrono::milliseconds timeout) const {
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, timeout, [&] { return stop_ || generation_ > generation; });
    return latest_;
}

std::string ViewSession::error() const {
    std::lock_guard lock(mutex_);
    return error_;
}

Camera ViewSession::camera() const {
    std::lock_guard lock(mutex_);
    return camera_;
}

std::uint64_t ViewSession::set_camera(const Camera& camera, bool moving) {
    // The whole scene would be validated again for every move of the mouse; the camera's
    // rules need only the camera and the image size, so a scene of nothing else checks them.
    Scene probe;
    {
        std::lock_guard lock(mutex_);  // reconfigure() may replace scene_
        probe.source = scene_.source;
        probe.image = scene_.image;
    }
    probe.camera = camera;
    validate_scene(probe);
    std::uint64_t version = 0;
    {
        std::lock_guard lock(mutex_);
        camera_ = camera;
        moving_ = moving;
        version = ++camera_version_;
        if (!(moving && previewing_)) cancel_ = true;
    }
    changed_.notify_all();
    return version;
}

void ViewSession::publish(ViewFrame frame) {
    {
        std::lock_guard lock(mutex_);
        frame.generation = ++generation_;
        latest_ = std::make_shared<const ViewFrame>(std::move(frame));
    }
    changed_.notify_all();
}

void ViewSession::run() {
    if (settings_.order == PixelOrder::frameless) return run_frameless();
    std::optional<PreparedScene> prepared_scene;  // these switches' scene (simd path)
    std::uint64_t done_version = 0;  // the camera version of the last picture rendered
    bool refined = true;             // whether that picture was the full progressive one
    Clock::time_point last_preview;
    std::unique_lock lock(mutex_);
    while (!stop_ && !restart_) {
        if (camera_version_ == done_version && refined) {
            changed_.wait(lock);
            continue;
        }
        if (camera_version_ == done_version && !refined &&
            changed_.wait_until(lock, last_preview + settings_.settle, [&] {
                return stop_ || restart_ || camera_version_ != done_version;
            })) {
            continue;  // moved again (or stopping) before it settled
        }
        const std::uint64_t version = camera_version_;
        const Camera camera = camera_;
        const bool preview = moving_ && !(version == done_version && !refined);
        moving_ = false;
        previewing_ = preview;
        cancel_ = false;
        error_.clear();
        lock.unlock();
        try {
            if (preview) {
                render_preview(camera, version, prepared_scene);
                last_preview = Clock::now();
                refined = false;
            } else {
                refined = render_passes(camera, version, prepared_scene);
            }
            done_version = version;
        } catch (const RenderCancelled&) {
            // A new camera or stop(): the loop picks up whichever it was.
        } catch (const std::exception& e) {
            // The thread must not end the process; the page shows why, and the next
            // camera tries again.
            lock.lock();
            previewing_ = false;
            error_ = e.what();
            done_version = version;
            refined = true;
            changed_.notify_all();
            continue;
        }
        lock.lock();
        previewing_ = false;
    }
}

// Frameless: one framebuffer, re-rendered a batch of blocks at a time in the permutation
// of frameless_blocks, continuing where the last camera left off (the oldest pixels are
// renewed first); each batch is published at once. A camera that stays still is rendered
// once over (a full sweep), which is then exactly the tiled order's picture. The SIMD path
// compiles the scene and builds its BVH once (PreparedScene); a new camera only re-aims it.
void ViewSession::run_frameless() {
    const int width = scene_.image.width, height = scene_.image.height;
    const std::vector<PixelRect> blocks =
        frameless_blocks(width, height, std::max(1, settings_.frameless_block));
    // About 16 pictures a sweep, of at least 16 blocks each (enough work for the threads).
    const std::size_t batch_size = std::max<std::size_t>(16, blocks.size() / 16);
    Image framebuffer(width, height, {"R", "G", "B"});  // black until rendered
    std::vector<PixelRect> batch;
    std::size_t cursor = 0;             // next block of the permutation
    std::size_t fresh = blocks.size();  // blocks rendered with the current camera
    std::uint64_t version = 0;
    std::optional<Scene> scalar;  // the scalar path's scene, with the current camera
    if (settings_.render.path == RenderPath::scalar) scalar = scene_;
    std::optional<PreparedScene> prepared;
    RenderOptions options;
    options.threads = settings_.render.threads;
    options.frame = static_cast<std::uint32_t>(settings_.frame);
    Clock::time_point camera_start;

    std::unique_lock lock(mutex_);
    while (!stop_ && !restart_) {
        if (camera_version_ == version && fresh >= blocks.size()) {
            changed_.wait(lock);
            continue;
        }
        const bool new_camera = camera_version_ != version;
        version = camera_version_;
        const Camera camera = camera_;
        if (new_camera) error_.clear();
        lock.unlock();
        try {
            if (new_camera) {
                if (settings_.render.path == RenderPath::simd) {
                    this->prepared(prepared).set_camera(camera);
                } else {
                    scalar->camera = camera;
                }
                fresh = 0;
                camera_start = Clock::now();
            }
            const std::size_t count = std::min(batch_size, blocks.size() - fresh);
            batch.clear();
            for (std::size_t i = 0; i < count; ++i)
                batch.push_back(blocks[(cursor + i) % blocks.size()]);
            const RenderResult result =
                prepared ? render_packet_blocks(*prepared, batch, framebuffer, options,
                                                settings_.render.isa)
                         : render_reference_blocks(*scalar, batch, framebuffer, options);
            cursor = (cursor + count) % blocks.size();
            fresh += count;
            ViewFrame frame = frame_of(version, camera);
            frame.image = framebuffer;
            frame.spp = scene_.image.spp;
            frame.pass_seconds = result.seconds;
            frame.frame_seconds = seconds_since(camera_start);
            frame.mrays_per_second = mrays_per_second(result);
            frame.coverage = static_cast<double>(fresh) / static_cast<double>(blocks.size());
            publish(std::move(frame));
        } catch (const std::exception& e) {
            lock.lock();
            error_ = e.what();
            fresh = blocks.size();
            changed_.notify_all();
            continue;
        }
        lock.lock();
    }
}

// The SIMD path's scene, compiled and its BVH built for the first picture of these
// switches; each picture after only re-aims it (and sizes it, for a preview).
PreparedScene& ViewSession::prepared(std::optional<PreparedScene>& prepared) const {
    if (!prepared) prepared.emplace(scene_, Accel::automatic, settings_.render.threads);
    return *prepared;
}

void ViewSession::render_preview(const Camera& camera, std::uint64_t version,
                                 std::optional<PreparedScene>& prepared_scene) {
    const int d = std::max(1, settings_.preview_divisor);
    const int width = std::max(1, (scene_.image.width + d - 1) / d);
    const int height = std::max(1, (scene_.image.height + d - 1) / d);
    const RenderOptions options = render_options(width);
    const auto start = Clock::now();
    RenderResult result;
    if (settings_.render.path == RenderPath::simd) {
        PreparedScene& scene = prepared(prepared_scene);
        scene.set_view(camera, width, height, 1);
        result = render_packet(scene, options, settings_.render.isa);
    } else {
        Scene scene = scene_;
        scene.camera = camera;
        scene.image.width = width;
        scene.image.height = height;
        scene.image.spp = 1;
        result = render_reference(scene, options);
    }
    ViewFrame frame = frame_of(version, camera);
    frame.image = std::move(result.image);
    frame.preview = true;
    frame.spp = 1;
    frame.pass_seconds = result.seconds;
    frame.frame_seconds = seconds_since(start);
    frame.mrays_per_second = mrays_per_second(result);
    publish(std::move(frame));
}

bool ViewSession::render_passes(const Camera& camera, std::uint64_t version,
                                std::optional<PreparedScene>& prepared_scene) {
    const RenderOptions options = render_options(scene_.image.width);
    const auto start = Clock::now();
    std::optional<Scene> scalar;  // the scalar path's scene with this camera
    PreparedScene* simd = nullptr;
    if (settings_.render.path == RenderPath::simd) {
        simd = &prepared(prepared_scene);
        simd->set_view(camera, scene_.image.width, scene_.image.height, scene_.image.spp);
    } else {
        scalar = scene_;
        scalar->camera = camera;
    }
    const batch::PassRenderer render_pass = [&](const RenderOptions& pass_options) {
        return simd ? render_packet(*simd, pass_options, settings_.render.isa)
                    : render_reference(*scalar, pass_options);
    };
    RayCounts rays;
    double render_seconds = 0.0;
    const batch::PassCallback on_pass = [&](const RenderResult& so_far, int samples_so_far) {
        rays += so_far.rays;
        render_seconds += so_far.seconds;
        ViewFrame frame = frame_of(version, camera);
        frame.rays = rays;
        frame.render_seconds = render_seconds;
        frame.image = so_far.image;
        frame.spp = samples_so_far;
        frame.pass_seconds = so_far.seconds;
        frame.frame_seconds = seconds_since(start);
        frame.mrays_per_second = mrays_per_second(so_far);
        publish(std::move(frame));
    };
    batch::render_progressive(render_pass, scene_.image.spp, options, on_pass);
    return true;
}

}  // namespace octray::view
