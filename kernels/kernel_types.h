#pragma once
// The plain-data boundary of the packet kernels: raw pointers into SoA arrays, counts and
// scalars. No member functions, no std containers, no inline code: this header is
// included by the per-ISA translation units (see kernels/README.md, "the ODR rule").
//
// Streams are ranges over SoA storage owned by render/: every array is 64-byte aligned
// and its capacity is a multiple of kPacketWidth, so a kernel may load and store whole
// 8-wide packets; lanes past the stream's count are dead (masked, never written back as
// results that matter).

#include <cstdint>

#include "kernels/bvh/bvh_node.h"
#include "scene/object_record.h"

namespace octray::kernels {

// Rays per packet. AVX2 holds a packet in one register, SSE in two.
inline constexpr std::uint32_t kPacketWidth = 8;

// A hit id of a ray that hit nothing.
inline constexpr std::int32_t kNoHit = -1;

enum class CameraKind : std::int32_t {
    pinhole = 0,
    orthographic = 1,
    thinlens = 2,
    fisheye = 3
};
enum class BackgroundKind : std::int32_t { constant = 0, gradient = 1 };

// The sphere and plane arrays of a SceneView hold a multiple of this many entries, those
// past the count with NaN geometry that no comparison accepts (scene/compile.h), so that
// a kernel may load them a register at a time.
inline constexpr std::uint32_t kSceneArrayPadding = 8;

// A view of a CompiledScene (scene/compile.h) in plain pointers.
struct SceneView {
    // Spheres and planes in file order within their kind; `object` is the file index.
    std::uint32_t sphere_count;
    const float *sphere_cx, *sphere_cy, *sphere_cz, *sphere_r2;
    const std::uint32_t* sphere_object;
    std::uint32_t plane_count;
    const float *plane_nx, *plane_ny, *plane_nz, *plane_d;
    const std::uint32_t* plane_object;

    // Per object (file index): what shading needs. object_record: kObjectRecordFloats
    // floats an object, laid out as scene/object_record.h says; the checker's tangents in
    // columns.
    std::uint32_t object_count;
    const float* object_record;
    const float *object_t1x, *object_t1y, *object_t1z, *object_t2x, *object_t2y, *object_t2z;

    // Materials.
    const float *mat_cd_r, *mat_cd_g, *mat_cd_b, *mat_kd, *mat_ks, *mat_shininess;
    const float *mat_kr_r, *mat_kr_g, *mat_kr_b, *mat_kt, *mat_ior;
    const float* mat_pow_zero_below;
    const float *mat_checker_r, *mat_checker_g, *mat_checker_b, *mat_checker_size;

    // Lights.
    std::uint32_t light_count;
    const std::uint32_t *light_directional, *light_inverse_square;
    const float *light_px, *light_py, *light_pz, *light_lx, *light_ly, *light_lz;
    const float *light_r, *light_g, *light_b;

    // Camera frame (scene/camera.h), flattened.
    CameraKind camera;
    float eye[3], ln[3], u_hat[3], v_hat[3], u[3], v[3];
    float aspect, half_width, half_height, half_fov_radians, aperture, focus_distance;

    // Background.
    BackgroundKind background;
    float bg_color[3], bg_bottom[3], bg_top[3], bg_up[3];

    float ambient[3];
    float epsilon;  // ε_s
    std::int32_t max_depth;

    // The sphere BVH (render/prepare/bvh_build.h), or bvh_nodes == nullptr: closest_hit and
    // any_hit test every sphere. Spheres in leaf order; node 0 is the root.
    const BvhNode8* bvh_nodes;
    const float *bvh_cx, *bvh_cy, *bvh_cz, *bvh_r2;
    const std::uint32_t* bvh_object;
    // The root's box: the traversal's rounding margin (kernels/README.md, "The BVH").
    float bvh_lo[3], bvh_hi[3];
    // A packet with fewer live lanes than this goes on ray by ray (single-ray traversal);
    // 0 or 1: packets all the way, 9: single rays only.
    std::uint32_t bvh_packet_min_lanes;
    // The same for secondary rays (closest_hit with t_min 0: reflected and refracted rays,
    // which start on surfaces at any depth and spread). 9 in large BVHs, where neighbouring
    // pixels' secondary rays leave different tiny spheres in unrelated directions and share
    // too few nodes for a packet to pay (render/prepare/scene_view.h).
    std::uint32_t bvh_secondary_min_lanes;
    // Shadow rays are regrouped by origin and direction before tracing (stream/hit_kernels.h,
    // any_hit) in BVHs of at least this many spheres.
    std::uint32_t bvh_shadow_sort_min_spheres;
    // In BVHs of at most this many spheres, shadow rays, and closest-hit rays that form no
    // beam, test every sphere as without a BVH (stream/hit_kernels.h;
    // render/prepare/scene_view.h).
    std::uint32_t bvh_brute_force_max_spheres;
    // Brute-force shadow rays skip the spheres far from a packet's segments
    // (stream/brute_force.h, SegmentBox) in scenes of at least this many spheres, with a BVH
    // or without (render/prepare/scene_view.h).
    std::uint32_t shadow_cull_min_spheres;
};

// Film positions of camera samples, in [-1, 1]^2 with y up, plus the thin-lens aperture
// sample; `pixel` is carried into the ray stream untouched.
struct CameraSamples {
    const float *x, *y, *lens_u, *lens_v;
    const std::uint32_t* pixel;
};

// A generation of rays: origin, direction, path weight (the product of the kr / kt
// factors along the path, for the weight cut-off) and, for primary rays only, the tile
// pixel (a secondary ray reaches its pixel through its parent: ChildLinks).
struct RayStream {
    float *ox, *oy, *oz, *dx, *dy, *dz;
    float *wr, *wg, *wb;
    std::uint32_t* pixel;
};

// Closest hits: t and the hit object's file index (kNoHit for a miss).
struct HitStream {
    float* t;
    std::int32_t* object;
};

// Shadow rays live on (0, t_max): t_max = 1 towards a point light, +inf along a
// directional one. `term` is the light's contribution to the parent ray's color, added
// when nothing occludes the ray; `parent` is the parent's slot in its generation.
struct ShadowStream {
    float *ox, *oy, *oz, *dx, *dy, *dz, *t_max;
    float *term_r, *term_g, *term_b;
    std::uint32_t* parent;
};

// What shade() leaves per ray slot. The ray's color is
//   ((local + tail_reflect) + tail_refract)
// once the visible light terms have been added to `local` in light order: the reference's
// order of terms (ambient, lights, mirror ray, refracted ray). A tail is factor ⊙ the
// background for a secondary ray cut off by depth or weight, 0 for none; for a traced
// one, render/ writes factor ⊙ the child's color into it once the child's color is known
// (generations are resolved last to first), exactly the reference's factor * trace(child).
struct SurfaceColor {
    float *local_r, *local_g, *local_b;
    float *tail_reflect_r, *tail_reflect_g, *tail_reflect_b;
    float *tail_refract_r, *tail_refract_g, *tail_refract_b;
};

// Per secondary ray: where its color goes. parent = 2 * (parent slot) + (0 mirror ray,
// 1 refracted ray); factor is kr (kr + kt on total internal reflection) or kt.
struct ChildLinks {
    std::uint32_t* parent;
    float *factor_r, *factor_g, *factor_b;
};

struct ShadeInput {
    RayStream rays;
    HitStream hits;
    std::uint32_t count;
    std::int32_t depth;  // bounce of this generation (primary rays: 0)
};

// Output capacities the caller guarantees: shadows count * light_count, next 2 * count
// (each rounded up to a whole packet).
struct ShadeOutput {
    SurfaceColor color;
    ShadowStream shadows;
    RayStream next;
    ChildLinks next_links;  // one per ray of `next`
};

struct ShadeCounts {
    std::uint32_t shadow;  // shadow rays written
    std::uint32_t next;    // secondary rays written (reflected + refracted)
    std::uint32_t reflected;
    std::uint32_t refracted;
};

}  // namespace octray::kernels
