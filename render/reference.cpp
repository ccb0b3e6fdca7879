// The scalar reference renderer. Each function follows docs/rendering-model.md
// step by step; render/README.md lists the few choices the model leaves open.

#include "render/reference.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/blocked_range2d.h>
#include <oneapi/tbb/combinable.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "core/random.h"
#include "render/crop.h"
#include "render/parallel.h"

namespace octray {
namespace {

// A new ray whose weight is below this in every channel is not traced.
constexpr float kMinRayWeight = 1e-3f;
// A plane whose normal is this close to perpendicular to the ray is missed.
constexpr float kPlaneParallelEpsilon = 1e-12f;

// Ray-sphere (rendering model, "Sphere"), in the form that keeps its digits for small,
// distant spheres (Haines, Guenther, Akenine-Moeller, "Precision Improvements for
// Ray/Sphere Intersection", Ray Tracing Gems, 2019, ch. 7). With O' = O - c, a = V.V,
// b = O'.V, c' = O'.O' - r^2:
// - the textbook discriminant b^2 - a c' subtracts two numbers of size |O'|^2 to get one
//   of size r^2, and for a sphere far away all its digits are rounding. The same value is
//   a (r^2 - l.l), with l = O' - (b/a) V the vector from the center to the point of the
//   ray nearest it: l.l is of size r^2 where it matters, so nothing cancels;
// - of the roots (-b -+ sqrt(disc))/a, the one where -b and -+sqrt(disc) have the same sign
//   adds without cancellation: q = -b - sign(b) sqrt(disc) gives q/a, and the other root
//   is c'/q (the roots' product is c'/a). q = 0 only when b = 0 and disc = 0, the double
//   root 0 (= q/a).
// The nearer root in (t_min, t_max) counts, a double root (tangent ray) too.
std::optional<float> intersect_sphere(const Object& s, const Ray& ray) {
    const Vec3 oc = ray.origin - s.center;
    const float a = dot(ray.direction, ray.direction);
    const float b = dot(oc, ray.direction);
    const float r2 = s.radius * s.radius;
    const Vec3 l = oc - ray.direction * (b / a);
    const float disc = a * (r2 - dot(l, l));
    if (!(disc >= 0.0f)) return std::nullopt;
    const float root = std::sqrt(disc);
    const float q = b >= 0.0f ? -b - root : -b + root;
    const float t_q = q / a;
    const float t_c = q != 0.0f ? (dot(oc, oc) - r2) / q : t_q;
    const bool swap = t_c < t_q;
    const float t_near = swap ? t_c : t_q;
    if (ray.live(t_near)) return t_near;
    const float t_far = swap ? t_q : t_c;
    if (ray.live(t_far)) return t_far;
    return std::nullopt;
}

// The model's sphere normal (P - c)/r, computed as normalize(P - c): the same direction,
// and unit length even when rounding put the hit off the surface. It was (P - c)/r: for a
// tiny sphere far away the textbook discriminant put hits at many radii from the center,
// and a normal of length 40 raised the Phong term max(0, R.W)^n to 1e30. A hit at the very
// center (a radius below the rounding of P) gets the normal facing the ray.
Vec3 sphere_normal(Vec3 point, const Object& s, const Ray& ray) {
    const Vec3 pc = point - s.center;
    return dot(pc, pc) > 0.0f ? normalize(pc) : -normalize(ray.direction);
}

// Ray-plane: t = ((P0 - O).N) / (V.N), computed as (d - O.N) / (V.N) with d = P0.N, the
// form the SoA plane arrays store (so both paths round identically). A denominator below
// 1e-12 in magnitude is a miss; so is a t outside the live interval (behind the origin).
std::optional<float> intersect_plane(const Object& p, const Ray& ray) {
    const float denom = dot(ray.direction, p.normal);
    if (!(std::fabs(denom) >= kPlaneParallelEpsilon)) return std::nullopt;
    const float t = (dot(p.point, p.normal) - dot(ray.origin, p.normal)) / denom;
    if (ray.live(t)) return t;
    return std::nullopt;
}

// Parity of floor(x) as 0 or 1, exact for every finite float (above 2^24 all floats are
// even integers, and x - 2 floor(x/2) has no rounding).
float floor_parity(float x) {
    const float f = std::floor(x);
    return f - 2.0f * std::floor(f * 0.5f);
}

}  // namespace

ReferenceTracer::ReferenceTracer(const Scene& scene, ReferenceAccel accel,
                                 const std::atomic<bool>* cancel)
    : scene_(scene),
      cancel_(cancel),
      camera_(make_camera_frame(scene.camera, scene.image.width, scene.image.height)),
      background_up_(normalize(scene.camera.up)),
      epsilon_(self_intersection_epsilon(scene)) {
    if (accel == ReferenceAccel::bvh) {
        bvh_.emplace(scene.objects);
        for (std::uint32_t k = 0; k < scene.objects.size(); ++k)
            if (scene.objects[k].type == ObjectType::plane) planes_.push_back(k);
    }
}

std::optional<Ray> ReferenceTracer::camera_ray(int i, int j, std::uint32_t sample,
                                               std::uint32_t frame) const {
    const auto ui = static_cast<std::uint32_t>(i), uj = static_cast<std::uint32_t>(j);
    const PixelOffset o =
        pixel_sample_offset(frame, ui, uj, sample, static_cast<std::uint32_t>(scene_.image.spp),
                            scene_.render.seed);
    const float x = film_x(i, o.ox, scene_.image.width);
    const float y = film_y(j, o.oy, scene_.image.height);
    const CameraFrame& c = camera_;

    Ray ray;
    ray.t_min = epsilon_;
    ray.t_max = kInfinity;
    switch (c.type) {
        case CameraType::pinhole:
            ray.origin = c.eye;
            ray.direction = normalize(c.ln + c.u * x + c.v * y);
            break;
        case CameraType::orthographic:
            ray.origin = c.eye + c.u_hat * (x * c.half_width) + c.v_hat * (y * c.half_height);
            ray.direction = c.ln;
            break;
        case CameraType::thinlens: {
            // Aim at the pinhole ray's point on the focal plane (perpendicular to ln at
            // focus_distance) from a point on the lens disk (polar mapping, r = a sqrt(u)).
            const Vec3 d = normalize(c.ln + c.u * x + c.v * y);
            const Vec3 focus = c.eye + d * (c.focus_distance / dot(d, c.ln));
            const float lu =
                sample_uniform(frame, ui, uj, sample, kDimLensU, scene_.render.seed);
            const float lv =
                sample_uniform(frame, ui, uj, sample, kDimLensV, scene_.render.seed);
            const float r = c.aperture * std::sqrt(lu);
            const float phi = 2.0f * std::numbers::pi_v<float> * lv;
            ray.origin = c.eye + c.u_hat * (r * std::cos(phi)) + c.v_hat * (r * std::sin(phi));
            ray.direction = normalize(focus - ray.origin);
            break;
        }
        case CameraType::fisheye: {
            // Equidistant: angle from the axis grows linearly with the film radius.
            const float ya = y / c.aspect;
            const float r = std::sqrt(x * x + ya * ya);
            if (r > 1.0f) return std::nullopt;  // outside the image circle: black
            const float psi = r * c.half_fov_radians;
            const float phi = std::atan2(ya, x);
            ray.origin = c.eye;
            ray.direction = c.ln * std::cos(psi) +
                            (c.u_hat * std::cos(phi) + c.v_hat * std::sin(phi)) * std::sin(psi);
            break;
        }
    }
    return ray;
}

std::optional<float> ReferenceTracer::intersect_object(std::uint32_t k, const Ray& ray) const {
    const Object& o = scene_.objects[k];
    return o.type == ObjectType::sphere ? intersect_sphere(o, ray) : intersect_plane(o, ray);
}

std::optional<SurfaceHit> ReferenceTracer::intersect(const Ray& ray) const {
    // The closest-hit rule: the smallest t in the live interval, and of equal t the object
    // listed first. Each object's t does not depend on the others, so the order in which
    // objects are tested (file order, or the BVH's) does not change the result.
    float best_t = kInfinity;
    std::optional<std::uint32_t> best;
    const auto consider = [&](std::uint32_t k) {
        const std::optional<float> t = intersect_object(k, ray);
        if (t && (*t < best_t || (*t == best_t && (!best || k < *best)))) best_t = *t, best = k;
    };
    if (bvh_) {
        for (const std::uint32_t k : planes_) consider(k);
        bvh_->closest(ray, best_t, consider);
    } else {
        for (std::uint32_t k = 0; k < scene_.objects.size(); ++k) consider(k);
    }
    if (!best) return std::nullopt;
    return surface_hit(ray, best_t, *best);
}

SurfaceHit ReferenceTracer::surface_hit(const Ray& ray, float t, std::uint32_t object) const {
    SurfaceHit hit{t, object, ray.at(t), {}};
    const Object& o = scene_.objects[object];
    hit.normal = o.type == ObjectType::sphere ? sphere_normal(hit.point, o, ray) : o.normal;
    return hit;
}

bool ReferenceTracer::occluded(const Ray& ray) const {
    const auto hits = [&](std::uint32_t k) { return intersect_object(k, ray).has_value(); };
    if (bvh_) {
        for (const std::uint32_t k : planes_)
            if (hits(k)) return true;
        return bvh_->any(ray, hits);
    }
    for (std::uint32_t k = 0; k < scene_.objects.size(); ++k)
        if (hits(k)) return true;
    return false;
}

Rgb ReferenceTracer::background(Vec3 direction) const {
    const Background& bg = scene_.background;
    if (bg.type == BackgroundType::constant) return bg.color;
    // Vertical gradient by the direction's component along the camera's up as given.
    const float s = 0.5f * (dot(normalize(direction), background_up_) + 1.0f);
    return mix(bg.bottom, bg.top, s);
}

Rgb ReferenceTracer::trace(const Ray& ray, int depth, Rgb weight, RayCounts& counts) const {
    // A render being stopped: black, and no rays below (a pixel of 2^20 samples at depth 64
    // would otherwise run for minutes after the signal). The image is thrown away.
    if (cancel_ != nullptr && cancel_->load(std::memory_order_relaxed)) return Rgb();
    const std::optional<SurfaceHit> hit = intersect(ray);
    if (!hit) return background(ray.direction);
    return shade(ray, *hit, depth, weight, counts);
}

Rgb ReferenceTracer::surface_color(const SurfaceHit& hit) const {
    // Cd, or the checker's second color on odd squares (planes only).
    const Object& object = scene_.objects[hit.object];
    const Material& m = scene_.materials[object.material].material;
    if (m.checker && object.type == ObjectType::plane) {
        // Found per hit, not kept per object: a few operations against a table of 36 bytes
        // an object, which a scene of a million spheres filled (36 MB, its first touch
        // included) before each AOV pass and each reference render.
        const TangentBasis tb = checker_basis(object.normal);
        const float parity = floor_parity(dot(hit.point, tb.t1) / m.checker->size) +
                             floor_parity(dot(hit.point, tb.t2) / m.checker->size);
        if (parity == 1.0f) return m.checker->color;
    }
    return m.color;
}

Rgb ReferenceTracer::shade(const Ray& ray, const SurfaceHit& hit, int depth, Rgb weight,
                           RayCounts& counts) const {
    const Object& object = scene_.objects[hit.object];
    const Material& m = scene_.materials[object.material].material;
    const Vec3 v_hat = normalize(ray.direction);
    const Vec3 p = hit.point;
    // The normal facing the incoming ray; refraction below still uses hit.normal.
    const Vec3 n = dot(hit.normal, ray.direction) > 0.0f ? -hit.normal : hit.normal;
    const Vec3 w = -v_hat;

    const Rgb cd = surface_color(hit);

    // Ambient term.
    Rgb color = scene_.ambient * (cd * m.kd);

    // Direct light: Phong diffuse + highlight, gated by a shadow ray.
    const Vec3 shadow_origin = p + n * epsilon_;
    for (const Light& light : scene_.lights) {
        Vec3 to_light, l;
        float dist2 = 0.0f;
        Ray shadow;
        shadow.origin = shadow_origin;
        shadow.t_min = 0.0f;
        if (light.type == LightType::point) {
            to_light = light.position - p;
            dist2 = dot(to_light, to_light);
            l = normalize(to_light);
            shadow.direction = to_light;  // not normalised: the light sits at t = 1
            shadow.t_max = 1.0f;
        } else {
            l = -normalize(light.direction);
            shadow.direction = l;
            shadow.t_max = kInfinity;
        }
        const float n_dot_l = dot(n, l);
        if (!(n_dot_l > 0.0f)) continue;  // light behind the surface: no term, no shadow ray
        ++counts.shadow;
        if (occluded(shadow)) continue;

        Rgb radiance = light.color;
        if (light.type == LightType::point && light.inverse_square) radiance = radiance / dist2;
        const Vec3 r = n * (2.0f * n_dot_l) - l;  // R_l = 2(N.l)N - l
        const float r_dot_w = std::max(0.0f, dot(r, w));
        const float highlight = m.ks * std::pow(r_dot_w, m.shininess);
        color += radiance * (cd * (m.kd * n_dot_l) + Rgb(highlight));
    }

    // Refraction direction first: total internal reflection moves kt onto the mirror ray.
    Rgb kr = m.reflect;
    std::optional<Vec3> refracted;
    if (m.transmit > 0.0f) {
        // Snell's law with the unflipped normal: entering when V.N < 0.
        const float cos_i = dot(v_hat, hit.normal);
        const bool entering = cos_i < 0.0f;
        const float eta = entering ? 1.0f / m.ior : m.ior;
        const Vec3 nt = entering ? hit.normal : -hit.normal;
        const float c = entering ? -cos_i : cos_i;
        const float k = 1.0f - eta * eta * (1.0f - c * c);
        if (k < 0.0f) {
            kr = kr + Rgb(m.transmit);  // TIR
        } else {
            refracted = v_hat * eta + nt * (eta * c - std::sqrt(k));
        }
    }

    // A secondary ray: traced when within max_depth and heavy enough, else it sees the
    // background along its direction.
    const auto secondary = [&](Vec3 origin, Vec3 direction, Rgb factor,
                               std::uint64_t& counter) {
        const Rgb child_weight = weight * factor;
        if (depth + 1 > scene_.render.max_depth ||
            !(max_component(child_weight) >= kMinRayWeight))
            return factor * background(direction);
        ++counter;
        const Ray child{origin, direction, 0.0f, kInfinity};
        return factor * trace(child, depth + 1, child_weight, counts);
    };

    if (max_component(kr) > 0.0f) {
        const Vec3 reflected =
            ray.direction - hit.normal * (2.0f * dot(hit.normal, ray.direction));
        color += secondary(p + n * epsilon_, reflected, kr, counts.reflected);
    }
    if (refracted) {
        color += secondary(p - n * epsilon_, *refracted, Rgb(m.transmit), counts.refracted);
    }
    return color;
}

Rgb ReferenceTracer::sum_samples(int i, int j, std::uint32_t frame, SampleRange samples,
                                 Rgb sum, RayCounts& counts) const {
    for (int s = samples.begin; s < samples.end; ++s) {
        const std::optional<Ray> ray = camera_ray(i, j, static_cast<std::uint32_t>(s), frame);
        if (!ray) continue;  // fisheye sample outside the image circle: black
        ++counts.primary;
        sum += trace(*ray, 0, Rgb(1.0f), counts);
    }
    return sum;
}

Rgb ReferenceTracer::render_pixel(int i, int j, std::uint32_t frame, RayCounts& counts) const {
    const int spp = scene_.image.spp;
    return sum_samples(i, j, frame, SampleRange{0, spp}, Rgb(), counts) /
           static_cast<float>(spp);
}

RenderResult render_reference(const Scene& scene, const RenderOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    const ReferenceTracer tracer(scene, reference_accel(options.accel), options.cancel);
    RenderResult result;
    // The crop and the sample range (render/crop.h): pixel (i, j) of the full image lands
    // at (i - rect.x0, j - rect.y0); its value does not depend on either.
    const PixelRect rect = render_rect(options, scene.image.width, scene.image.height);
    const SampleRange samples = render_sample_range(options, scene.image.spp, rect);
    const bool partial_samples = options.samples.has_value();
    // Every pixel of the rectangle is written by its tile.
    const PixelRect full{0, 0, scene.image.width, scene.image.height};
    result.image = make_rgb_image(
        rect, full, options.spare_image != nullptr ? std::move(*options.spare_image) : Image());
    if (options.spare_image != nullptr) *options.spare_image = Image();
    if (partial_samples) result.sample_sums = make_rgb_image(rect, full);
    tbb::combinable<RayCounts> counts;
    TileControl control(options);

    const int tw = std::max(1, options.tile_width), th = std::max(1, options.tile_height);
    const auto render_tiles = [&] {
        // Each pixel depends only on its own counters, so any split gives the same bits.
        tbb::parallel_for(
            tbb::blocked_range2d<int>(rect.y0, rect.y1, th, rect.x0, rect.x1, tw),
            [&](const tbb::blocked_range2d<int>& tile) {
                if (!control.proceed()) return;
                RayCounts& local = counts.local();
                for (int j = tile.rows().begin(); j < tile.rows().end(); ++j)
                    for (int i = tile.cols().begin(); i < tile.cols().end(); ++i) {
                        // Also pixel by pixel: the tracer returns at once when cancelled.
                        if (!control.proceed()) return;
                        const int x = i - rect.x0, y = j - rect.y0;
                        if (!partial_samples) {
                            set_rgb(result.image, x, y,
                                    tracer.render_pixel(i, j, options.frame, local));
                            continue;
                        }
                        const Rgb start =
                            samples.begin > 0 ? rgb_at(*options.sample_sums, x, y) : Rgb();
                        const Rgb sum =
                            tracer.sum_samples(i, j, options.frame, samples, start, local);
                        set_rgb(result.sample_sums, x, y, sum);
                        set_rgb(result.image, x, y, sum / static_cast<float>(samples.end));
                    }
                control.done(static_cast<std::uint64_t>(tile.rows().size()) *
                             tile.cols().size());
            },
            tbb::simple_partitioner());
    };
    run_with_threads(options.threads, render_tiles);
    control.finish();
    counts.combine_each([&](const RayCounts& c) { result.rays += c; });
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

RenderResult render_reference_blocks(const Scene& scene, std::span<const PixelRect> blocks,
                                     Image& target, const RenderOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    check_block_render(blocks, target, scene.image.width, scene.image.height, options);
    const ReferenceTracer tracer(scene, reference_accel(options.accel), options.cancel);
    RenderResult result;
    result.image.display_window = PixelRect{0, 0, scene.image.width, scene.image.height};
    tbb::combinable<RayCounts> counts;
    TileControl control(options);
    run_with_threads(options.threads, [&] {
        tbb::parallel_for(
            tbb::blocked_range<std::size_t>(0, blocks.size(), 1),
            [&](const tbb::blocked_range<std::size_t>& range) {
                RayCounts& local = counts.local();
                for (std::size_t b = range.begin(); b < range.end(); ++b) {
                    if (!control.proceed()) return;
                    const PixelRect& r = blocks[b];
                    for (int j = r.y0; j < r.y1; ++j)
                        for (int i = r.x0; i < r.x1; ++i) {
                            const Rgb value = tracer.render_pixel(i, j, options.frame, local);
                            // A pixel the cancel flag cut short never reaches the caller's
                            // image.
                            if (!control.proceed()) return;
                            set_rgb(target, i, j, value);
                        }
                    control.done(static_cast<std::uint64_t>(r.width()) *
                                 static_cast<std::uint64_t>(r.height()));
                }
            },
            tbb::simple_partitioner());
    });
    control.finish();
    counts.combine_each([&](const RayCounts& c) { result.rays += c; });
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace octray
