// worldToCamera and worldToNDC from the camera frame both render paths use
// (scene/camera.h), derived in render/batch/README.md, "Camera matrices".

#include "render/batch/camera_matrices.h"

#include <cmath>

#include "scene/camera.h"

namespace octray::batch {
namespace {

float& at(Matrix44& m, int row, int col) { return m[static_cast<std::size_t>(4 * row + col)]; }
float at(const Matrix44& m, int row, int col) {
    return m[static_cast<std::size_t>(4 * row + col)];
}

Matrix44 multiply(const Matrix44& a, const Matrix44& b) {
    Matrix44 c{};
    for (int r = 0; r < 4; ++r)
        for (int k = 0; k < 4; ++k) {
            float sum = 0.0f;
            for (int j = 0; j < 4; ++j) sum += at(a, r, j) * at(b, j, k);
            at(c, r, k) = sum;
        }
    return c;
}

Matrix44 world_to_camera(const CameraFrame& f) {
    // Columns: the world point's components along û, v̂ and -ln, after moving the eye to
    // the origin (the last row).
    const Vec3 x = f.u_hat, y = f.v_hat, z = -f.ln;
    Matrix44 m{};
    at(m, 0, 0) = x.x, at(m, 1, 0) = x.y, at(m, 2, 0) = x.z;
    at(m, 0, 1) = y.x, at(m, 1, 1) = y.y, at(m, 2, 1) = y.z;
    at(m, 0, 2) = z.x, at(m, 1, 2) = z.y, at(m, 2, 2) = z.z;
    at(m, 3, 0) = -dot(f.eye, x);
    at(m, 3, 1) = -dot(f.eye, y);
    at(m, 3, 2) = -dot(f.eye, z);
    at(m, 3, 3) = 1.0f;
    return m;
}

std::optional<Matrix44> world_to_ndc(const CameraFrame& f) {
    Matrix44 p{};  // camera space -> NDC
    switch (f.type) {
        case CameraType::pinhole:
        case CameraType::thinlens: {
            // A camera point (cx, cy, cz) at depth d = -cz is on film x = cx / (d tan),
            // y = cy aspect / (d tan), tan = tan(fov/2); NDC = ((x + 1)/2, (1 - y)/2).
            const float tan_half = std::tan(f.half_fov_radians);
            at(p, 0, 0) = 1.0f / (2.0f * tan_half);
            at(p, 2, 0) = -0.5f;
            at(p, 1, 1) = -f.aspect / (2.0f * tan_half);
            at(p, 2, 1) = -0.5f;
            at(p, 3, 2) = 1.0f;   // z / w = 1 / d
            at(p, 2, 3) = -1.0f;  // w = d
            break;
        }
        case CameraType::orthographic:
            // Film x = cx / half_width, y = cy / half_height.
            at(p, 0, 0) = 1.0f / (2.0f * f.half_width);
            at(p, 3, 0) = 0.5f;
            at(p, 1, 1) = -1.0f / (2.0f * f.half_height);
            at(p, 3, 1) = 0.5f;
            at(p, 2, 2) = -1.0f;  // z = d
            at(p, 3, 3) = 1.0f;
            break;
        case CameraType::fisheye:
            return std::nullopt;
    }
    return multiply(world_to_camera(f), p);
}

void add_camera_attributes(ExrAttributes& attributes, const CameraFrame& f) {
    attributes.matrices.emplace_back("worldToCamera", world_to_camera(f));
    if (const std::optional<Matrix44> ndc = world_to_ndc(f))
        attributes.matrices.emplace_back("worldToNDC", *ndc);
}

CameraFrame camera_frame_of(const Scene& scene) {
    return make_camera_frame(scene.camera, scene.image.width, scene.image.height);
}

}  // namespace

Matrix44 world_to_camera(const Scene& scene) { return world_to_camera(camera_frame_of(scene)); }

std::optional<Matrix44> world_to_ndc(const Scene& scene) {
    return world_to_ndc(camera_frame_of(scene));
}

void add_camera_attributes(ExrAttributes& attributes, const Scene& scene,
                           const Camera& camera) {
    add_camera_attributes(attributes,
                          make_camera_frame(camera, scene.image.width, scene.image.height));
}

Vec3 transform_point(const Matrix44& m, Vec3 p) {
    float out[4];
    for (int c = 0; c < 4; ++c)
        out[c] = p.x * at(m, 0, c) + p.y * at(m, 1, c) + p.z * at(m, 2, c) + at(m, 3, c);
    return {out[0] / out[3], out[1] / out[3], out[2] / out[3]};
}

}  // namespace octray::batch
