#pragma once
// The scalar reference renderer: one ray at a time, written for clarity. It implements
// docs/rendering-model.md literally and is the oracle the SIMD path is judged by.
// It is built on core/ and scene/ only, never on kernels/, so it stays an independent check.
// Its spheres are found through a plain binary BVH of its own (reference_bvh.h), or by
// testing every object (ReferenceAccel::brute_force): the same hits, bit for bit.

#include <atomic>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/ray.h"
#include "render/reference_bvh.h"
#include "render/render_result.h"
#include "scene/camera.h"
#include "scene/scene.h"

namespace octray {

struct SurfaceHit {
    float t = kInfinity;
    std::uint32_t object = 0;  // index into Scene::objects
    Vec3 point;
    Vec3 normal;  // geometric unit normal, not yet flipped towards the ray
};

// How the reference finds the objects a ray meets: its own BVH over the spheres (planes
// are always tested one by one), or every object in file order. Both give the same hits.
enum class ReferenceAccel { bvh, brute_force };

// The reference's choice for a render's `--accel` (render/render_options.h): none is brute
// force, auto and bvh its BVH.
constexpr ReferenceAccel reference_accel(Accel accel) {
    return accel == Accel::none ? ReferenceAccel::brute_force : ReferenceAccel::bvh;
}

class ReferenceTracer {
  public:
    // The scene must have passed validate_scene(), and outlive the tracer. Once *cancel is
    // true (a render being stopped, RenderOptions::cancel), trace() returns black at once,
    // so that a pixel of any spp and depth ends within a ray of it; the render then throws
    // RenderCancelled.
    explicit ReferenceTracer(const Scene& scene, ReferenceAccel accel = ReferenceAccel::bvh,
                             const std::atomic<bool>* cancel = nullptr);

    // The camera ray of sample `sample` of pixel (i, j) in frame `frame`. A fisheye
    // sample outside the image circle has no ray (it is black).
    std::optional<Ray> camera_ray(int i, int j, std::uint32_t sample,
                                  std::uint32_t frame = 0) const;

    // Closest hit over all objects in the ray's live interval (ties: first listed).
    std::optional<SurfaceHit> intersect(const Ray& ray) const;

    // The hit of `ray` on object `object` at `t` (found by another search, the packet
    // path's): its point and geometric normal, as intersect() computes them.
    SurfaceHit surface_hit(const Ray& ray, float t, std::uint32_t object) const;

    // True if any object is hit in the ray's live interval.
    bool occluded(const Ray& ray) const;

    // Radiance along `ray` at bounce `depth` (the primary ray has depth 0).
    Rgb trace(const Ray& ray, int depth, Rgb weight, RayCounts& counts) const;

    // The mean of all samples of pixel (i, j).
    Rgb render_pixel(int i, int j, std::uint32_t frame, RayCounts& counts) const;

    // `sum` plus the radiance of samples [samples.begin, samples.end) of pixel (i, j),
    // added one after the other in sample order (progressive passes: render_pixel is
    // sum_samples over [0, spp) from zero, divided by spp).
    Rgb sum_samples(int i, int j, std::uint32_t frame, SampleRange samples, Rgb sum,
                    RayCounts& counts) const;

    // The diffuse color Cd of the surface at `hit`: the material's color, or the checker's
    // second color on odd squares of a plane.
    Rgb surface_color(const SurfaceHit& hit) const;

    float epsilon() const { return epsilon_; }
    const CameraFrame& camera() const { return camera_; }

  private:
    Rgb shade(const Ray& ray, const SurfaceHit& hit, int depth, Rgb weight,
              RayCounts& counts) const;
    Rgb background(Vec3 direction) const;
    // The ray's hit t on object k in its live interval, if any.
    std::optional<float> intersect_object(std::uint32_t k, const Ray& ray) const;

    const Scene& scene_;
    std::optional<ReferenceBvh> bvh_;    // ReferenceAccel::bvh
    std::vector<std::uint32_t> planes_;  // with a BVH: the planes' object indices
    const std::atomic<bool>* cancel_;
    CameraFrame camera_;
    Vec3 background_up_;  // the camera's up as given, normalised (gradient background)
    float epsilon_;
};

// Renders the whole image, or options.crop of it, and options.samples of each pixel (see
// render/render_options.h); tiles may run in parallel (TBB), one ray at a time per thread. The
// image is bit-identical for any thread count, tile size, crop and options.accel.
RenderResult render_reference(const Scene& scene, const RenderOptions& options = {});

// Renders the pixels of each of `blocks` into `target` at their places, as
// render_packet_blocks (render/packet_renderer.h) does, with its checks; each pixel is
// the same pixel of render_reference's image. One tracer serves every block.
RenderResult render_reference_blocks(const Scene& scene, std::span<const PixelRect> blocks,
                                     Image& target, const RenderOptions& options = {});

}  // namespace octray
