// Ray sets, pixel orders, the oracle and validation for `octray bench`.

#include "bench/ray_sets.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace octray::bench {

// ---- Pixel orders --------------------------------------------------------------------

const char* pixel_order_name(PixelOrder order) {
    switch (order) {
        case PixelOrder::rowmajor:
            return "rowmajor";
        case PixelOrder::tiled:
            return "tiled";
        case PixelOrder::morton:
            return "morton";
    }
    return "?";
}

std::optional<PixelOrder> parse_pixel_order(std::string_view name) {
    for (PixelOrder o : {PixelOrder::rowmajor, PixelOrder::tiled, PixelOrder::morton})
        if (name == pixel_order_name(o)) return o;
    return std::nullopt;
}

namespace {

// The even bits of a Morton code: x of (x, y) interleaved as y1 x1 y0 x0.
std::uint32_t compact_even_bits(std::uint32_t v) {
    v &= 0x55555555u;
    v = (v | (v >> 1)) & 0x33333333u;
    v = (v | (v >> 2)) & 0x0F0F0F0Fu;
    v = (v | (v >> 4)) & 0x00FF00FFu;
    v = (v | (v >> 8)) & 0x0000FFFFu;
    return v;
}

}  // namespace

std::vector<std::uint32_t> pixel_order(int width, int height, PixelOrder order, TileSize tile) {
    std::vector<std::uint32_t> out;
    if (width <= 0 || height <= 0) return out;
    const auto w = static_cast<std::uint32_t>(width), h = static_cast<std::uint32_t>(height);
    out.reserve(static_cast<std::size_t>(w) * h);
    switch (order) {
        case PixelOrder::rowmajor:
            for (std::uint32_t y = 0; y < h; ++y)
                for (std::uint32_t x = 0; x < w; ++x) out.push_back(y * w + x);
            break;
        case PixelOrder::tiled: {
            const auto tw = static_cast<std::uint32_t>(std::max(1, tile.width));
            const auto th = static_cast<std::uint32_t>(std::max(1, tile.height));
            for (std::uint32_t y0 = 0; y0 < h; y0 += th)
                for (std::uint32_t x0 = 0; x0 < w; x0 += tw)
                    for (std::uint32_t y = y0; y < std::min(h, y0 + th); ++y)
                        for (std::uint32_t x = x0; x < std::min(w, x0 + tw); ++x)
                            out.push_back(y * w + x);
            break;
        }
        case PixelOrder::morton: {
            // Walk the codes of the enclosing power-of-two square, skipping pixels outside
            // the frame: x in the even bits, so a run of 8 codes is a 4 x 2 block.
            const std::uint32_t side = std::bit_ceil(std::max(w, h));
            const std::uint64_t codes = static_cast<std::uint64_t>(side) * side;
            for (std::uint64_t code = 0; code < codes; ++code) {
                const std::uint32_t x = compact_even_bits(static_cast<std::uint32_t>(code));
                const std::uint32_t y =
                    compact_even_bits(static_cast<std::uint32_t>(code >> 1));
                if (x < w && y < h) out.push_back(y * w + x);
            }
            break;
        }
    }
    return out;
}

// ---- Ray sets ------------------------------------------------------------------------

const char* ray_kind_name(RayKind kind) {
    switch (kind) {
        case RayKind::primary:
            return "primary";
        case RayKind::shadow:
            return "shadow";
        case RayKind::secondary:
            return "secondary";
    }
    return "?";
}

namespace {

std::size_t padded_size(std::uint32_t n) {
    const std::size_t w = kernels::kPacketWidth;
    return (static_cast<std::size_t>(n) + w - 1) / w * w + w;
}

}  // namespace

void RaySet::resize(std::uint32_t n) {
    count = n;
    const std::size_t size = padded_size(n);
    // Padding: a ray from the origin along +z with an empty live interval.
    for (AlignedVector<float>* column : {&ox, &oy, &oz, &dx, &dy}) column->assign(size, 0.0f);
    dz.assign(size, 1.0f);
    t_max.assign(size, 0.0f);
    std::fill(t_max.begin(), t_max.begin() + n, kInfinity);
}

kernels::RayStream RaySet::ray_stream(std::uint32_t first) const {
    // The kernels take non-const pointers for streams they may also write; closest_hit
    // only reads these columns.
    const auto at = [first](const AlignedVector<float>& v) {
        return const_cast<float*>(v.data() + first);
    };
    return {at(ox), at(oy), at(oz), at(dx), at(dy), at(dz), nullptr, nullptr, nullptr, nullptr};
}

kernels::ShadowStream RaySet::shadow_stream(std::uint32_t first) const {
    const auto at = [first](const AlignedVector<float>& v) {
        return const_cast<float*>(v.data() + first);
    };
    return {at(ox),    at(oy),  at(oz),  at(dx),  at(dy), at(dz),
            at(t_max), nullptr, nullptr, nullptr, nullptr};
}

Ray RaySet::ray(std::uint32_t i) const {
    return Ray{{ox[i], oy[i], oz[i]}, {dx[i], dy[i], dz[i]}, t_min, t_max[i]};
}

void HitSet::resize(std::uint32_t padded) {
    t.assign(padded, kInfinity);
    object.assign(padded, kernels::kNoHit);
}

kernels::HitStream HitSet::stream(std::uint32_t first) {
    return {t.data() + first, object.data() + first};
}

RaySet make_primary_rays(const ReferenceTracer& tracer, int width, int height,
                         const std::vector<std::uint32_t>& order) {
    RaySet rays;
    rays.kind = RayKind::primary;
    rays.t_min = tracer.epsilon();
    rays.resize(static_cast<std::uint32_t>(order.size()));
    const auto w = static_cast<std::uint32_t>(width);
    (void)height;
    std::uint32_t n = 0;
    for (const std::uint32_t pixel : order) {
        const std::optional<Ray> ray =
            tracer.camera_ray(static_cast<int>(pixel % w), static_cast<int>(pixel / w), 0);
        if (!ray) continue;  // fisheye: outside the image circle
        rays.ox[n] = ray->origin.x, rays.oy[n] = ray->origin.y, rays.oz[n] = ray->origin.z;
        rays.dx[n] = ray->direction.x, rays.dy[n] = ray->direction.y;
        rays.dz[n] = ray->direction.z;
        ++n;
    }
    if (n != rays.count) {  // shrink to the rays written, keeping the padding contract
        RaySet shrunk;
        shrunk.kind = rays.kind;
        shrunk.t_min = rays.t_min;
        shrunk.resize(n);
        for (std::uint32_t i = 0; i < n; ++i) {
            shrunk.ox[i] = rays.ox[i], shrunk.oy[i] = rays.oy[i], shrunk.oz[i] = rays.oz[i];
            shrunk.dx[i] = rays.dx[i], shrunk.dy[i] = rays.dy[i], shrunk.dz[i] = rays.dz[i];
        }
        return shrunk;
    }
    return rays;
}

namespace {

// The hit point and the normal facing the ray, as ReferenceTracer::intersect and shade
// compute them.
struct FacingHit {
    Vec3 p, n;
};

FacingHit facing_hit(const Scene& scene, const Ray& ray, float t, std::uint32_t object) {
    const Object& o = scene.objects[object];
    const Vec3 p = ray.at(t);
    const Vec3 normal = o.type == ObjectType::sphere ? (p - o.center) / o.radius : o.normal;
    const Vec3 n = dot(normal, ray.direction) > 0.0f ? -normal : normal;
    return {p, n};
}

void push_ray(std::vector<float> (&columns)[7], Vec3 o, Vec3 d, float t_max) {
    columns[0].push_back(o.x), columns[1].push_back(o.y), columns[2].push_back(o.z);
    columns[3].push_back(d.x), columns[4].push_back(d.y), columns[5].push_back(d.z);
    columns[6].push_back(t_max);
}

RaySet from_columns(RayKind kind, const std::vector<float> (&columns)[7]) {
    RaySet rays;
    rays.kind = kind;
    rays.t_min = 0.0f;
    rays.resize(static_cast<std::uint32_t>(columns[0].size()));
    AlignedVector<float>* dst[7] = {&rays.ox, &rays.oy, &rays.oz,   &rays.dx,
                                    &rays.dy, &rays.dz, &rays.t_max};
    for (int c = 0; c < 7; ++c)
        std::copy(columns[c].begin(), columns[c].end(), dst[c]->begin());
    return rays;
}

}  // namespace

RaySet make_shadow_rays(const Scene& scene, const RaySet& primary, const HitSet& hits) {
    const float eps = self_intersection_epsilon(scene);
    std::vector<float> columns[7];
    for (std::uint32_t i = 0; i < primary.count; ++i) {
        if (!hits.hit(i)) continue;
        const Ray ray = primary.ray(i);
        const FacingHit h =
            facing_hit(scene, ray, hits.t[i], static_cast<std::uint32_t>(hits.object[i]));
        const Vec3 origin = h.p + h.n * eps;
        for (const Light& light : scene.lights) {
            if (light.type == LightType::point) {
                const Vec3 to_light = light.position - h.p;
                if (!(dot(h.n, normalize(to_light)) > 0.0f)) continue;
                push_ray(columns, origin, to_light, 1.0f);
            } else {
                const Vec3 l = -normalize(light.direction);
                if (!(dot(h.n, l) > 0.0f)) continue;
                push_ray(columns, origin, l, kInfinity);
            }
        }
    }
    return from_columns(RayKind::shadow, columns);
}

RaySet make_secondary_rays(const Scene& scene, const RaySet& primary, const HitSet& hits) {
    const float eps = self_intersection_epsilon(scene);
    std::vector<float> columns[7];
    for (std::uint32_t i = 0; i < primary.count; ++i) {
        if (!hits.hit(i)) continue;
        const Ray ray = primary.ray(i);
        const auto object = static_cast<std::uint32_t>(hits.object[i]);
        const FacingHit h = facing_hit(scene, ray, hits.t[i], object);
        const Object& o = scene.objects[object];
        const Vec3 normal =
            o.type == ObjectType::sphere ? (h.p - o.center) / o.radius : o.normal;
        const Vec3 reflected = ray.direction - normal * (2.0f * dot(normal, ray.direction));
        push_ray(columns, h.p + h.n * eps, reflected, kInfinity);
    }
    return from_columns(RayKind::secondary, columns);
}

// ---- The oracle and validation -------------------------------------------------------

namespace {

// An oracle's answer for one ray: t (closest hit) and the object, kOccluded or kNoHit.
struct Answer {
    float t = kInfinity;
    std::int32_t object = kernels::kNoHit;
};

// Answers each ray of out.index, in parallel (brute force: a few rays per task).
template <class AnswerRay>
void answer_rays(const RaySet& rays, OracleHits& out, const AnswerRay& answer_ray) {
    out.t.assign(out.index.size(), kInfinity);
    out.object.assign(out.index.size(), kernels::kNoHit);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, out.index.size(), 64),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t k = r.begin(); k < r.end(); ++k) {
                              const Answer answer = answer_ray(rays.ray(out.index[k]));
                              out.t[k] = answer.t;
                              out.object[k] = answer.object;
                          }
                      });
}

}  // namespace

OracleHits oracle_hits(const ReferenceTracer& tracer, const RaySet& rays,
                       std::uint32_t max_rays) {
    OracleHits out;
    const std::uint32_t n = rays.count;
    if (max_rays == 0 || max_rays >= n) {
        out.index.resize(n);
        for (std::uint32_t i = 0; i < n; ++i) out.index[i] = i;
    } else {
        // Even stride over the set: i * n / max_rays, strictly increasing.
        out.index.resize(max_rays);
        for (std::uint32_t k = 0; k < max_rays; ++k)
            out.index[k] =
                static_cast<std::uint32_t>(static_cast<std::uint64_t>(k) * n / max_rays);
    }
    const bool any_hit = rays.kind == RayKind::shadow;
    answer_rays(rays, out, [&](const Ray& ray) {
        if (any_hit) return tracer.occluded(ray) ? Answer{kInfinity, kOccluded} : Answer{};
        const auto hit = tracer.intersect(ray);
        return hit ? Answer{hit->t, static_cast<std::int32_t>(hit->object)} : Answer{};
    });
    return out;
}

double exact_root(const Object& object, const Ray& ray) {
    const double dx = ray.direction.x, dy = ray.direction.y, dz = ray.direction.z;
    if (object.type == ObjectType::plane) {
        const Vec3& n = object.normal;
        const double denom = dx * n.x + dy * n.y + dz * n.z;
        if (!(std::fabs(denom) >= 1e-12)) return std::nan("");
        const double num = (static_cast<double>(object.point.x) - ray.origin.x) * n.x +
                           (static_cast<double>(object.point.y) - ray.origin.y) * n.y +
                           (static_cast<double>(object.point.z) - ray.origin.z) * n.z;
        return num / denom;
    }
    const double ox = static_cast<double>(ray.origin.x) - object.center.x;
    const double oy = static_cast<double>(ray.origin.y) - object.center.y;
    const double oz = static_cast<double>(ray.origin.z) - object.center.z;
    // The renderers' robust form (render/reference.cpp, intersect_sphere) in double: in
    // double even the textbook b^2 - a c' would cancel for spheres far enough away.
    const double a = dx * dx + dy * dy + dz * dz, b = ox * dx + oy * dy + oz * dz;
    const double radius = object.radius, r2 = radius * radius;
    const double bt = b / a;
    const double lx = ox - bt * dx, ly = oy - bt * dy, lz = oz - bt * dz;
    const double disc = a * (r2 - (lx * lx + ly * ly + lz * lz));
    if (!(disc >= 0.0)) return std::nan("");
    const double root = std::sqrt(disc);
    const double q = b >= 0.0 ? -b - root : -b + root;
    const double t_q = q / a;
    const double t_c = q != 0.0 ? (ox * ox + oy * oy + oz * oz - r2) / q : t_q;
    const double t_near = std::min(t_q, t_c), t_far = std::max(t_q, t_c);
    return t_near > ray.t_min ? t_near : t_far;
}

OracleHits oracle_hits_double(const Scene& scene, const RaySet& rays, const OracleHits& like) {
    OracleHits out;
    out.index = like.index;
    const bool any_hit = rays.kind == RayKind::shadow;
    answer_rays(rays, out, [&](const Ray& ray) {
        double best = ray.t_max;
        std::int32_t best_object = kernels::kNoHit;
        for (std::size_t i = 0; i < scene.objects.size(); ++i) {
            const double t = exact_root(scene.objects[i], ray);
            if (!(t > ray.t_min && t < best)) continue;  // NaN too
            best = t;
            best_object = static_cast<std::int32_t>(i);
            if (any_hit) break;
        }
        if (best_object == kernels::kNoHit) return Answer{};
        return any_hit ? Answer{kInfinity, kOccluded}
                       : Answer{static_cast<float>(best), best_object};
    });
    return out;
}

Validation validate_hits(const HitSet& hits, const OracleHits& oracle,
                         const ValidationRule& rule) {
    Validation v;
    v.checked = oracle.index.size();
    for (std::size_t k = 0; k < oracle.index.size(); ++k) {
        const std::uint32_t i = oracle.index[k];
        const bool want_hit = oracle.object[k] != kernels::kNoHit;
        const bool got_hit = i < hits.object.size() && hits.object[i] != kernels::kNoHit;
        if (want_hit != got_hit) {
            ++v.hit_mismatches;
            continue;
        }
        if (!want_hit || oracle.object[k] == kOccluded) continue;
        ++v.both_hit;
        const float t = hits.t[i], want_t = oracle.t[k];
        const double rel = std::fabs(static_cast<double>(t) - want_t) /
                           std::max(std::fabs(static_cast<double>(want_t)), 1e-30);
        const double rel_or_inf = std::isfinite(rel) ? rel : kInfinity;
        v.max_t_rel_error = std::max(v.max_t_rel_error, rel_or_inf);
        if (hits.object[i] != oracle.object[k]) ++v.object_mismatches;
        const bool t_ok =
            rule.exact ? std::bit_cast<std::uint32_t>(t) == std::bit_cast<std::uint32_t>(want_t)
                       : rel_or_inf <= rule.t_rel_tolerance;
        if (!t_ok) ++v.t_mismatches;
    }
    v.hit_agreement =
        v.checked == 0 ? 1.0 : 1.0 - static_cast<double>(v.hit_mismatches) / v.checked;
    v.t_agreement =
        v.both_hit == 0 ? 1.0 : 1.0 - static_cast<double>(v.t_mismatches) / v.both_hit;
    if (rule.exact)
        v.valid = v.hit_mismatches == 0 && v.t_mismatches == 0 && v.object_mismatches == 0;
    else
        v.valid =
            v.hit_agreement >= rule.min_hit_agreement && v.t_agreement >= rule.min_t_agreement;
    return v;
}

std::string Validation::summary() const {
    char buffer[320];
    std::snprintf(buffer, sizeof buffer,
                  "%s: %llu rays checked; hit/miss agree on %.6f (%llu differ); t agrees on "
                  "%.6f of %llu both-hit rays (%llu differ, max relative error %.3g); %llu "
                  "object ids differ",
                  valid ? "valid" : "INVALID", static_cast<unsigned long long>(checked),
                  hit_agreement, static_cast<unsigned long long>(hit_mismatches), t_agreement,
                  static_cast<unsigned long long>(both_hit),
                  static_cast<unsigned long long>(t_mismatches), max_t_rel_error,
                  static_cast<unsigned long long>(object_mismatches));
    return buffer;
}

double hit_fraction(const HitSet& hits, std::uint32_t count) {
    if (count == 0) return 0.0;
    std::uint64_t n = 0;
    for (std::uint32_t i = 0; i < count; ++i) n += hits.object[i] != kernels::kNoHit ? 1 : 0;
    return static_cast<double>(n) / count;
}

}  // namespace octray::bench
