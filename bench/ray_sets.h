#pragma once
// The ray sets of `octray bench`: primary, shadow and secondary rays in plain SoA arrays,
// generated once per scene and pixel order and then traced by every system under test
// (octray's packet kernels, octray's scalar reference, Embree) from the same memory.
//
// Also the pixel orders the rays are generated in (row-major, tiled, Morton), the hit
// arrays each system writes, and the validation of a hit set against the scalar oracle
// (tinybvh validates every traversal variant before timing it; so do we).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/aligned.h"
#include "core/pixel_rect.h"
#include "kernels/kernel_types.h"
#include "render/reference.h"
#include "scene/compile.h"

namespace octray::bench {

// ---- Pixel orders --------------------------------------------------------------------

enum class PixelOrder {
    rowmajor,  // scanlines, top to bottom: a packet is 8 pixels of one row
    tiled,     // tiles in row-major order, row-major inside a tile
    morton,    // Z-order over the whole frame: a packet is a 4 x 2 block
};

const char* pixel_order_name(PixelOrder order);
std::optional<PixelOrder> parse_pixel_order(std::string_view name);

// Every pixel index y * width + x exactly once, in the visiting order. `tile` is used by
// PixelOrder::tiled only.
std::vector<std::uint32_t> pixel_order(int width, int height, PixelOrder order,
                                       TileSize tile = {});

// ---- Ray sets ------------------------------------------------------------------------

enum class RayKind {
    primary,    // camera rays on (ε_s, inf)
    shadow,     // from primary hits to each light in front of the surface, on (0, t_max)
    secondary,  // mirror reflections at primary hits, on (0, inf)
};

const char* ray_kind_name(RayKind kind);

// Rays in SoA, every array 64-byte aligned, its size `count` rounded up to whole 8-wide
// packets plus one spare packet (the kernels' stream contract, kernels/kernel_types.h).
// Padding rays are copies of a harmless ray: origin 0, direction +z, empty interval.
struct RaySet {
    RayKind kind = RayKind::primary;
    std::uint32_t count = 0;
    // Every ray of a set shares t_min: ε_s for primary rays, 0 otherwise.
    float t_min = 0.0f;
    AlignedVector<float> ox, oy, oz, dx, dy, dz;
    AlignedVector<float> t_max;  // inf, or 1 for a shadow ray towards a point light

    void resize(std::uint32_t n);
    // Views of rays [first, first + n) for the kernels; `first` must be a multiple of
    // kernels::kPacketWidth. The kernels' intersection entry points read only the origin,
    // direction and (shadow rays) t_max columns; the other columns of the views are null.
    kernels::RayStream ray_stream(std::uint32_t first) const;
    kernels::ShadowStream shadow_stream(std::uint32_t first) const;
    Ray ray(std::uint32_t i) const;
};

// What a system reports per ray. Closest-hit sets: t and the object's file index
// (kernels::kNoHit for a miss). Any-hit sets (shadow rays): object is kOccluded when
// something blocks the ray, kNoHit when it reaches the light; t is not used.
inline constexpr std::int32_t kOccluded = 0x7fffffff;

struct HitSet {
    AlignedVector<float> t;
    AlignedVector<std::int32_t> object;
    void resize(std::uint32_t padded);
    kernels::HitStream stream(std::uint32_t first);
    bool hit(std::uint32_t i) const { return object[i] != kernels::kNoHit; }
};

// Primary rays of one sample per pixel (the pixel center), in the given pixel order,
// from the scalar reference's camera (ReferenceTracer::camera_ray).
RaySet make_primary_rays(const ReferenceTracer& tracer, int width, int height,
                         const std::vector<std::uint32_t>& order);

// Shadow rays of the rendering model at the primary hits, in primary-ray order and light
// order: origin P + ε_s N_facing, direction light - P (t_max 1) or l (t_max inf), only
// for lights with N.l > 0.
RaySet make_shadow_rays(const Scene& scene, const RaySet& primary, const HitSet& hits);

// Mirror rays R = V - 2 (N.V) N at the primary hits, from P + ε_s N_facing, on (0, inf):
// one per primary hit, whatever the material (a ray set, not a render).
RaySet make_secondary_rays(const Scene& scene, const RaySet& primary, const HitSet& hits);

// ---- The oracle and validation -------------------------------------------------------

// The scalar reference's answer (ReferenceTracer::intersect / occluded) for a subset of
// the rays: every ray when max_rays is 0 or at least the count, else max_rays rays at an
// even stride over the set.
struct OracleHits {
    std::vector<std::uint32_t> index;  // ray indices checked, increasing
    std::vector<float> t;
    std::vector<std::int32_t> object;  // as in HitSet
};
OracleHits oracle_hits(const ReferenceTracer& tracer, const RaySet& rays,
                       std::uint32_t max_rays);

// The same rays as `like` (its index), answered in double precision by brute force with
// the textbook formulas: the truth another intersector is held to. octray's float
// quadratic (the scalar oracle) loses digits on small, distant spheres, so Embree, which
// rounds differently, would otherwise be judged against octray's own rounding.
OracleHits oracle_hits_double(const Scene& scene, const RaySet& rays, const OracleHits& like);

// The first root of `object` above the ray's t_min in double precision, the textbook
// formulas (t_max is not checked); NaN when there is none (a sphere missed, a plane
// parallel to the ray within 1e-12).
double exact_root(const Object& object, const Ray& ray);

struct ValidationRule {
    // Exact: t bit for bit and the object id, on every ray (octray's two paths perform the
    // same IEEE operations). Otherwise two fractions must reach their minimum: of the
    // checked rays, those on which system and oracle agree about hit or miss; of the rays
    // both hit, those with |t - t_oracle| <= t_rel_tolerance * |t_oracle|. Another
    // intersector rounds differently: a grazing ray may flip, and the oracle's textbook
    // quadratic loses digits on small, distant spheres (bench/README.md, "Validation").
    bool exact = true;
    double t_rel_tolerance = 1e-4;
    double min_hit_agreement = 0.9999;
    double min_t_agreement = 0.99;
};

inline constexpr ValidationRule kExactRule{true, 0.0, 1.0, 1.0};
inline constexpr ValidationRule kToleranceRule{false, 1e-4, 0.9999, 0.99};

struct Validation {
    bool valid = false;
    std::uint64_t checked = 0;
    std::uint64_t both_hit = 0;           // closest-hit rays that both hit
    std::uint64_t hit_mismatches = 0;     // one hits, the other misses
    std::uint64_t t_mismatches = 0;       // both hit, t outside the rule
    std::uint64_t object_mismatches = 0;  // both hit, different objects
    double hit_agreement = 0.0;           // agree on hit / miss, of the checked rays
    double t_agreement = 0.0;             // t within the rule, of the rays both hit
    double max_t_rel_error = 0.0;         // over rays where both hit
    std::string summary() const;
};

// Compares a system's hits with the oracle's on the oracle's rays.
Validation validate_hits(const HitSet& hits, const OracleHits& oracle,
                         const ValidationRule& rule);

// Fraction of rays that hit something (closest hit) or are occluded (shadow rays).
double hit_fraction(const HitSet& hits, std::uint32_t count);

}  // namespace octray::bench
