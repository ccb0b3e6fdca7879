#include "scene/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene/camera.h"

namespace octray {

namespace {

std::string short_number(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", value);
    return text;
}

}  // namespace

std::vector<std::string> scene_warnings(const Scene& scene) {
    std::vector<std::string> out;
    const Camera& camera = scene.camera;
    if ((camera.type != CameraType::pinhole && camera.type != CameraType::thinlens) ||
        camera.fov_units_stated)
        return out;
    const std::string file = scene.source.empty() ? std::string() : scene.source + ": ";
    const auto check = [&](const std::string& path, float fov) {
        if (!(fov < kSmallFovDegrees)) return;
        const double degrees = static_cast<double>(fov) * 180.0 / std::numbers::pi;
        out.push_back(file + path + ": fov " + short_number(fov) + " is below " +
                      short_number(kSmallFovDegrees) +
                      "; fov is in degrees (were it radians, it would be " +
                      short_number(degrees) +
                      " degrees). If the small angle is meant, add \"fov_units\": "
                      "\"degrees\" to the camera");
    };
    check("camera.fov", camera.fov);
    if (scene.animation) {
        const std::vector<CameraKey>& keys = scene.animation->camera;
        for (std::size_t i = 0; i < keys.size(); ++i)
            if (keys[i].fov)
                check("animation.camera[" + std::to_string(i) + "].fov", *keys[i].fov);
    }
    return out;
}

float self_intersection_epsilon(const Scene& scene, const SphereBox& box) {
    if (scene.render.epsilon) return *scene.render.epsilon;
    const float extent = box.any ? length(box.hi - box.lo) : 0.0f;
    return 1e-4f * std::max(1.0f, extent);
}

float self_intersection_epsilon(const Scene& scene) {
    if (scene.render.epsilon) return *scene.render.epsilon;
    SphereBox box;
    for (const Object& o : scene.objects)
        if (o.type == ObjectType::sphere) box.add(o);
    return self_intersection_epsilon(scene, box);
}

TangentBasis checker_basis(Vec3 n) {
    const float ax = std::fabs(n.x), ay = std::fabs(n.y), az = std::fabs(n.z);
    Vec3 axis{1.0f, 0.0f, 0.0f};
    if (ay < ax && ay <= az) {
        axis = {0.0f, 1.0f, 0.0f};
    } else if (az < ax && az < ay) {
        axis = {0.0f, 0.0f, 1.0f};
    }
    // Gram-Schmidt: remove the normal's share of the axis.
    const Vec3 t1 = normalize(axis - n * dot(axis, n));
    return {t1, cross(t1, n)};
}

CameraFrame make_camera_frame(const Camera& camera, int width, int height) {
    CameraFrame f;
    f.type = camera.type;
    f.eye = camera.eye;
    f.aspect = static_cast<float>(width) / static_cast<float>(height);
    const Vec3 view = camera.lookat - camera.eye;
    if (!(length(view) > 0.0f)) throw std::invalid_argument("eye and lookat coincide");
    // Lengths are float: a vector longer than sqrt(FLT_MAX) (about 1.8e19) has a length of
    // infinity, normalises to zero and so would read as "parallel" below. Say what it is.
    const auto overflow = [](const char* what, Vec3 v) {
        const double x = v.x, y = v.y, z = v.z;
        char length_text[32];
        std::snprintf(length_text, sizeof length_text, "%g", std::sqrt(x * x + y * y + z * z));
        return std::invalid_argument(
            std::string(what) + " has a length of " + length_text +
            ", whose square overflows float: the camera's vectors must be shorter than about "
            "1.8e19 (move the scene nearer the origin, or scale it down)");
    };
    if (!std::isfinite(length(view))) throw overflow("the view direction lookat - eye", view);
    if (!std::isfinite(length(camera.up))) throw overflow("the up vector", camera.up);
    f.ln = normalize(view);
    const Vec3 side = cross(f.ln, camera.up);
    if (!(length(side) > 1e-6f * length(camera.up)) || !(length(camera.up) > 0.0f))
        throw std::invalid_argument("up vector is parallel to the view direction");
    f.u_hat = normalize(side);
    f.v_hat = normalize(cross(f.u_hat, f.ln));

    const float max_fov = camera.type == CameraType::fisheye ? 360.0f : 180.0f;
    const bool fov_ok = camera.type == CameraType::fisheye
                            ? (camera.fov > 0.0f && camera.fov <= 360.0f)
                            : (camera.fov > 0.0f && camera.fov < 180.0f);
    if (camera.type != CameraType::orthographic && !fov_ok)
        throw std::invalid_argument(
            "field of view must lie in (0, " + std::to_string(static_cast<int>(max_fov)) +
            (camera.type == CameraType::fisheye ? "]" : ")") + " degrees");

    const float half_fov = camera.fov * (std::numbers::pi_v<float> / 180.0f) * 0.5f;
    const float tan_half = std::tan(half_fov);
    f.u = f.u_hat * tan_half;
    f.v = f.v_hat * (tan_half / f.aspect);
    f.half_fov_radians = half_fov;
    f.half_width = camera.width * 0.5f;
    f.half_height = camera.width / (2.0f * f.aspect);
    f.aperture = camera.aperture;
    f.focus_distance = camera.focus_distance;
    return f;
}

}  // namespace octray
