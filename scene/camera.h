#pragma once
// The camera's derived frame: the vectors of the rendering model's camera formulas,
// computed once per frame from the authored camera and image size. Both render paths
// map film positions to rays from this frame.

#include "core/vec3.h"
#include "scene/scene.h"

namespace octray {

struct CameraFrame {
    CameraType type = CameraType::pinhole;
    Vec3 eye;
    Vec3 ln;                        // normalize(lookat - eye)
    Vec3 u_hat;                     // normalize(ln x up)
    Vec3 v_hat;                     // normalize(u_hat x ln)
    Vec3 u;                         // pinhole/thinlens: u_hat * tan(fov/2)
    Vec3 v;                         // pinhole/thinlens: v_hat * tan(fov/2) / aspect
    float aspect = 1.0f;            // W / H
    float half_width = 1.0f;        // orthographic: width / 2
    float half_height = 1.0f;       // orthographic: width / (2 * aspect)
    float half_fov_radians = 0.0f;  // fisheye: fov / 2 in radians
    float aperture = 0.0f;
    float focus_distance = 1.0f;
};

// Throws std::invalid_argument with a message naming the problem when the camera cannot
// form a frame (up parallel to the view, zero-length view, field of view out of range).
CameraFrame make_camera_frame(const Camera& camera, int width, int height);

// The film position of pixel (i, j) at offset (ox, oy) inside it, in [-1, 1]^2 with y up:
// x = 2(i + ox)/W - 1, y = 1 - 2(j + oy)/H (row 0 is the top row).
inline float film_x(int i, float ox, int width) {
    return 2.0f * (static_cast<float>(i) + ox) / static_cast<float>(width) - 1.0f;
}
inline float film_y(int j, float oy, int height) {
    return 1.0f - 2.0f * (static_cast<float>(j) + oy) / static_cast<float>(height);
}

}  // namespace octray
