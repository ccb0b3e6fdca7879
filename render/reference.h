#pragma once
// The scalar reference renderer: one ray at a time, written for clarity. It implements
// shared/spec/rendering-model.md literally and is the oracle the SIMD path is judged by.
// It is built on core/ and scene/ only, never on kernels/, so it stays an independent check.

#include <cstdint>
#include <optional>
#include <vector>

#include "core/ray.h"
#include "render/types.h"
#include "scene/camera.h"
#include "scene/scene.h"

namespace octray {

struct SurfaceHit {
    float t = kInfinity;
    std::uint32_t object = 0;  // index into Scene::objects
    Vec3 point;
    Vec3 normal;  // geometric unit normal, not yet flipped towards the ray
};

class ReferenceTracer {
public:
    // The scene must have passed validate_scene().
    explicit ReferenceTracer(const Scene& scene);

    // The camera ray of sample `sample` of pixel (i, j) in frame `frame`. A fisheye
    // sample outside the image circle has no ray (it is black).
    std::optional<Ray> camera_ray(int i, int j, std::uint32_t sample,
                                  std::uint32_t frame = 0) const;

    // Closest hit over all objects in the ray's live interval (ties: first listed).
    std::optional<SurfaceHit> intersect(const Ray& ray) const;

    // True if any object is hit in the ray's live interval.
    bool occluded(const Ray& ray) const;

    // Radiance along `ray` at bounce `depth` (the primary ray has depth 0).
    Rgb trace(const Ray& ray, int depth, Rgb weight, RayCounts& counts) const;

    // The mean of all samples of pixel (i, j).
    Rgb render_pixel(int i, int j, std::uint32_t frame, RayCounts& counts) const;

    float epsilon() const { return epsilon_; }
    const CameraFrame& camera() const { return camera_; }

private:
    Rgb shade(const Ray& ray, const SurfaceHit& hit, int depth, Rgb weight,
              RayCounts& counts) const;
    Rgb background(Vec3 direction) const;

    const Scene& scene_;
    CameraFrame camera_;
    Vec3 background_up_;  // the camera's up as given, normalised (gradient background)
    float epsilon_;
    std::vector<TangentBasis> checker_bases_;  // per object; planes only
};

// Renders the whole image; tiles may run in parallel (TBB), one ray at a time per thread.
// The image is bit-identical for any thread count and tile size.
RenderResult render_reference(const Scene& scene, const RenderOptions& options = {});

}  // namespace octray
