#pragma once
// The camera of a frame as OpenEXR's standard matrix attributes, worldToCamera and
// worldToNDC (render/batch/README.md, "Camera matrices"), so that compositing tools can project
// 3D points onto the image and relate the Z AOV to world space.
//
// Convention (Imath's): row vectors, p' = p * M, translation in the last row.
// - Camera space: the eye at the origin, +X along the camera's right (û), +Y along its up
//   (v̂), looking down -Z (the view direction is -Z); right-handed, unscaled (world units).
// - NDC (OpenEXR's and RenderMan's): (0, 0) is the top-left corner of the display window,
//   (1, 1) the bottom-right, y pointing down. p * worldToNDC is homogeneous; divide x and y
//   by w (Imath's multVecMatrix does) and discard z. For a perspective camera z/w = 1/depth,
//   for an orthographic one z = depth (distance in front of the eye along the view).

#include <optional>

#include "render/image/image_io.h"
#include "scene/scene.h"

namespace octray::batch {

// World to camera space for the scene's camera. Throws std::invalid_argument if the
// camera cannot form a frame (as make_camera_frame does).
Matrix44 world_to_camera(const Scene& scene);

// World to NDC: pinhole and thinlens (its in-focus projection through the lens center) as
// a perspective projection, orthographic as an orthographic one. A fisheye has no
// projective matrix: nullopt.
std::optional<Matrix44> world_to_ndc(const Scene& scene);

// Adds worldToCamera and, where the camera has one, worldToNDC to `attributes`: of `camera`
// on the scene's picture (its own camera: scene.camera; an animation's frame: that frame's).
void add_camera_attributes(ExrAttributes& attributes, const Scene& scene, const Camera& camera);

// p * M for a point (w = 1), divided by the resulting w: Imath's multVecMatrix.
Vec3 transform_point(const Matrix44& m, Vec3 p);

}  // namespace octray::batch
