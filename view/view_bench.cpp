#include "view/view_bench.h"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/vec3.h"
#include "render/image/image_io.h"
#include "view/jpeg.h"
#include "view/tone_map.h"

namespace octray::view {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kEncodeRepeats = 10;

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
    double rays = 0.0, render_seconds = 0.0, sent_bytes = 0.0;
    const auto orbit_start = Clock::now();
    for (int i = 1; i <= updates; ++i) {
        const float angle =
            6.28318530718f * static_cast<float>(i) / static_cast<float>(updates);
        const std::uint64_t version = session.set_camera(orbit(initial, angle), true);
        const auto frame = wait_for_version(session, version);
        sent_bytes += static_cast<double>(encode_for_page(*frame, 0.0f).bytes.size());
        rays += frame->mrays_per_second * 1e6 * frame->pass_seconds;
        render_seconds += frame->pass_seconds;
        result.update_width = frame->image.width();
        result.update_height = frame->image.height();
    }
    result.seconds = std::chrono::duration<double>(Clock::now() - orbit_start).count();
    result.updates = updates;
    result.updates_per_second = updates / result.seconds;
    result.mrays_per_second = render_seconds > 0.0 ? rays / render_seconds / 1e6 : 0.0;
    result.sent_bytes = sent_bytes / updates;

    // The encodings of the last picture, timed one after the other.
    const auto last = session.latest();
    const auto time_ms = [](const auto& work) {
        const auto t0 = Clock::now();
        for (int i = 0; i < kEncodeRepeats; ++i) work();
        return std::chrono::duration<double, std::milli>(Clock::now() - t0).count() /
               kEncodeRepeats;
    };
    const int w = last->image.width(), h = last->image.height();
    std::vector<std::uint8_t> rgb;
    result.tone_map_ms = time_ms([&] { rgb = tone_map_srgb8(last->image, 0.0f); });
    std::string bytes;
    result.png_ms = time_ms([&] { bytes = encode_png_rgb8(w, h, rgb); });
    result.last_png_bytes = static_cast<double>(bytes.size());
    result.jpeg_ms = time_ms([&] { bytes = encode_jpeg_rgb8(w, h, rgb, kStreamJpegQuality); });
    result.jpeg_bytes = static_cast<double>(bytes.size());
    std::vector<std::uint8_t> rgba;
    result.rgba_ms = time_ms([&] {
        rgba.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4);
        for (std::size_t p = 0, n = rgba.size() / 4; p < n; ++p) {
            rgba[4 * p] = rgb[3 * p];
            rgba[4 * p + 1] = rgb[3 * p + 1];
            rgba[4 * p + 2] = rgb[3 * p + 2];
            rgba[4 * p + 3] = 255;
        }
    });
    result.rgba_bytes = static_cast<double>(rgba.size());
    return result;
}

}  // namespace octray::view
