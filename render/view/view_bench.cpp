#include "render/view/view_bench.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/vec3.h"
#include "render/image/image_io.h"
#include "render/view/tone_map.h"

namespace octray::view {
namespace {

using Clock = std::chrono::steady_clock;

// The eye turned by `angle` about the up axis through the look-at point (Rodrigues).
Camera orbit(const Camera& camera, float angle) {
    const Vec3 k = normalize(camera.up);
    const Vec3 v = camera.eye - camera.lookat;
    const float c = std::cos(angle), s = std::sin(angle);
    const Vec3 turned = v * c + cross(k, v) * s + k * (dot(k, v) * (1.0f - c));
    Camera out = camera;
    out.eye = camera.lookat + turned;
    return out;
}

// Waits for the picture of camera `version` (previews and passes alike).
std::shared_ptr<const ViewFrame> wait_for_version(const ViewSession& session,
                                                  std::uint64_t version) {
    std::uint64_t seen = 0;
    for (;;) {
        const auto frame = session.wait_newer(seen, std::chrono::milliseconds(1000));
        if (session.stopped()) throw std::runtime_error("the view session stopped");
        if (!session.error().empty()) throw std::runtime_error(session.error());
        if (frame && frame->camera_version >= version) return frame;
        if (frame) seen = frame->generation;
    }
}

}  // namespace

ViewBenchResult bench_orbit(const Scene& scene, const ViewSettings& settings, int updates) {
    if (updates < 1) throw std::invalid_argument("bench_orbit: updates must be >= 1");
    ViewBenchResult result;
    const auto start = Clock::now();
    ViewSession session(scene, settings);
    const auto first = session.wait_newer(0, std::chrono::hours(24));
    if (!first)
        throw std::runtime_error(session.error().empty() ? "no picture" : session.error());
    result.first_picture_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    result.first_width = first->image.width();
    result.first_height = first->image.height();
    result.first_spp = first->spp;

    const Camera initial = session.camera();  // an animation's: its first frame's
    double rays = 0.0, render_seconds = 0.0, png_bytes = 0.0;
    const auto orbit_start = Clock::now();
    for (int i = 1; i <= updates; ++i) {
        const float angle =
            6.28318530718f * static_cast<float>(i) / static_cast<float>(updates);
        const std::uint64_t version = session.set_camera(orbit(initial, angle), true);
        const auto frame = wait_for_version(session, version);
        png_bytes +=
            static_cast<double>(encode_png_rgb8(frame->image.width(), frame->image.height(),
                                                tone_map_srgb8(frame->image, 0.0f))
                                    .size());
        rays += frame->mrays_per_second * 1e6 * frame->pass_seconds;
        render_seconds += frame->pass_seconds;
        result.update_width = frame->image.width();
        result.update_height = frame->image.height();
    }
    result.seconds = std::chrono::duration<double>(Clock::now() - orbit_start).count();
    result.updates = updates;
    result.updates_per_second = updates / result.seconds;
    result.mrays_per_second = render_seconds > 0.0 ? rays / render_seconds / 1e6 : 0.0;
    result.png_bytes = png_bytes / updates;
    return result;
}

}  // namespace octray::view
