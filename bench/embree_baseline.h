#pragma once
// Embree 3 as the baseline of `octray bench`: the identical scene tracing the identical
// rays, read from the same SoA arrays (bench/ray_sets.h), into the same hit arrays. Two
// configurations (EmbreeGeometry):
// - user: what an expert Embree user builds for spheres. Each sphere is a user primitive
//   whose callbacks test it against the whole packet at once with the robust sphere form
//   (bench/embree_user_spheres.h); the planes (each one large quad) live in a scene of
//   their own, instanced with the identity, so that their huge boxes stay out of the
//   spheres' BVH. Traced with rtcIntersect16/8/1.
// - sphere_point: Embree's built-in sphere primitive, RTC_GEOMETRY_TYPE_SPHERE_POINT, and
//   the quads in the same scene. Embree 3 routes that primitive through its curve ("hair")
//   code (BVH8 with oriented boxes), which is far slower; kept for comparison.
//
// Compiled only when CMake finds Embree (OCTRAY_HAVE_EMBREE == 1); the declarations are
// always visible so that callers can be written once and test embree_compiled().
//
// Semantics, checked against Embree 3.13's kernels/geometry/sphere_intersector.h: a
// sphere reports its entry root when it lies in (tnear, tfar), else its exit root (so a
// ray that starts inside a sphere hits its far side, as in octray); both bounds are
// strict, as octray's live interval. Directions need not be unit length (shadow rays
// reach the light at t = 1). The two differences that remain, and that validation
// tolerates: Embree computes t by projecting the center onto the ray (it rounds
// differently), and an infinite plane becomes a finite quad (see embree_baseline.cpp).

#include <cstdint>
#include <memory>
#include <string>

#include "bench/ray_sets.h"
#include "scene/compile.h"
#include "scene/scene.h"

#ifndef OCTRAY_HAVE_EMBREE
#define OCTRAY_HAVE_EMBREE 0
#endif

namespace octray::bench {

enum class EmbreeMode {
    single,    // rtcIntersect1 / rtcOccluded1, one ray at a time
    packet8,   // rtcIntersect8 / rtcOccluded8 over 8 consecutive rays of the set
    packet16,  // rtcIntersect16 / rtcOccluded16 over 16 consecutive rays
};

enum class EmbreeGeometry { user, sphere_point };

// rtcSetSceneBuildQuality: LOW (Embree's Morton builder, the fastest build), MEDIUM (its
// default, binned SAH), HIGH (SAH with spatial splits where it applies; the ray-set rows).
enum class EmbreeBuildQuality { low, medium, high };
const char* embree_build_quality_name(EmbreeBuildQuality quality);

const char* embree_mode_name(EmbreeMode mode);
// "user" or "sphere_point": the bench's `isa` column for Embree rows.
const char* embree_geometry_name(EmbreeGeometry geometry);

constexpr bool embree_compiled() { return OCTRAY_HAVE_EMBREE != 0; }

class EmbreeScene {
  public:
    // Builds the device and the scene (BVH build quality high by default: the scene is
    // static). `threads` (0: all) caps Embree's own TBB use. Throws std::runtime_error with
    // Embree's message on failure.
    // `compiled` must outlive this object (user geometry reads its sphere arrays).
    EmbreeScene(const Scene& scene, const CompiledScene& compiled, int threads,
                EmbreeGeometry geometry, EmbreeBuildQuality quality = EmbreeBuildQuality::high);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    // Closest hits of rays [first, first + n) on (rays.t_min, t_max): t and the object's
    // file index, kNoHit for a miss. For packet8 and packet16, first is a multiple of 8
    // (the rays past first + n in a packet are switched off).
    // Coherent sets the coherent-ray hint (RTC_INTERSECT_CONTEXT_FLAG_COHERENT).
    void intersect(EmbreeMode mode, const RaySet& rays, std::uint32_t first, std::uint32_t n,
                   HitSet& hits, bool coherent) const;

    // Any hit on (t_min, t_max): object is kOccluded or kNoHit.
    void occluded(EmbreeMode mode, const RaySet& rays, std::uint32_t first, std::uint32_t n,
                  HitSet& hits, bool coherent) const;

    // The same on plain arrays (the kernels' streams, bench/embree_frames.h): rays
    // [0, count) with origin, direction and t_max (null: +inf), on (t_min, t_max); nothing
    // past `count` is read. Closest hits write
    // t (+inf for a miss) and the file index (kNoHit); any hits write 1 (occluded) or 0.
    struct RayArrays {
        const float *ox, *oy, *oz, *dx, *dy, *dz, *t_max;
        float t_min;
    };
    void intersect(EmbreeMode mode, const RayArrays& rays, std::uint32_t count, float* t,
                   std::int32_t* object, bool coherent) const;
    void occluded(EmbreeMode mode, const RayArrays& rays, std::uint32_t count,
                  std::uint32_t* occluded, bool coherent) const;

    // Seconds rtcCommitScene took (the BVH build), in the calling thread's TBB arena.
    double build_seconds() const;
    // Builds the BVH again from scratch, as a new frame of an animation would (every
    // geometry marked modified, the planes' scene and the top scene committed again; the
    // device and geometry buffers kept): returns the seconds the commits took.
    double rebuild();
    EmbreeBuildQuality build_quality() const;
    // User geometry: how many builds have asked for the spheres' bounds so far (1 after
    // the constructor, one more per rebuild), the proof that rebuild() builds.
    std::uint64_t sphere_builds() const;

    // Bytes the device held once the scene was committed (its memory monitor callback:
    // geometry buffers, BVH and build leftovers).
    std::int64_t memory_bytes() const;

    // "3.13.5", and what the device reports (native packet support, ISA-relevant flags).
    static std::string version();
    std::string device_info() const;
    EmbreeGeometry geometry() const;

    struct Impl;  // embree_baseline.cpp's

  private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace octray::bench
