#pragma once
// compile_scene(): the authored scene turned into the flat layout the packet kernels
// stream through. Every per-primitive array is structure-of-arrays, 64-byte aligned
// (core/aligned.h) and padded to a multiple of kCompiledPadding with entries that can
// never be hit (NaN geometry: every comparison against NaN is false).
//
// The values stored are exactly the ones the scalar reference computes on the fly
// (r^2 = r * r, d = P0.N, the checker basis, -normalize(direction) for directional
// lights, ...), so a kernel that reads them performs the same IEEE operations in the same
// order as render/reference.cpp and gets the same bits.

#include <bit>
#include <cstddef>
#include <cstdint>

#include "core/aligned.h"
#include "core/color.h"
#include "core/vec3.h"
#include "scene/camera.h"
#include "scene/object_record.h"
#include "scene/scene.h"

namespace octray {

// Arrays are padded to a multiple of this many entries (one 8-wide packet, or two cache
// lines of floats).
inline constexpr std::uint32_t kCompiledPadding = 8;

// The geometry arrays: sized without being written, so that compile_scene's parallel fill
// is the first to touch their pages (on huge pages, a million spheres compiled slower:
// 0.048 s against 0.027 s).
template <class T>
using GeometryArray = UninitializedVector<T>;

// Spheres in file order (among spheres). `object` is the index in Scene::objects, the key
// that breaks ties between a sphere and a plane at the same t (the first listed wins).
struct CompiledSpheres {
    std::uint32_t count = 0;
    std::uint32_t padded_count = 0;
    GeometryArray<float> cx, cy, cz;
    GeometryArray<float> r2;  // radius * radius, as the reference computes it
    GeometryArray<std::uint32_t> object;
};

// Planes in file order (among planes): N normalised on load, d = P0.N.
struct CompiledPlanes {
    std::uint32_t count = 0;
    std::uint32_t padded_count = 0;
    GeometryArray<float> nx, ny, nz, d;
    GeometryArray<std::uint32_t> object;
};

// Everything shading needs per object, indexed by the object's index in the file (the id
// a hit carries). What every hit reads is interleaved in one record of
// kObjectRecordFloats floats (two records to a cache line): a hit costs one cache miss
// where nine columns cost up to nine, and shading the hits of random:1048576 waited on
// those gathers for half of its time. Spheres have a zero normal, planes center 0:
// shading evaluates both normal formulas for every lane and selects. The checker's
// tangent basis, read only for checkered planes, stays in columns. The record's layout:
// scene/object_record.h.
struct CompiledObjects {
    std::uint32_t count = 0;
    std::uint32_t padded_count = 0;
    GeometryArray<float> record;  // padded_count records
    // The checker's tangent basis (planes; 0 for spheres), only in a scene with a checkered
    // plane: empty otherwise, as no shading reads it.
    GeometryArray<float> t1x, t1y, t1z, t2x, t2y, t2z;

    const float* record_of(std::uint32_t k) const {
        return record.data() + std::size_t{k} * kObjectRecordFloats;
    }
    bool is_plane(std::uint32_t k) const { return record_of(k)[kRecordKind] != kKindSphere; }
    bool checker(std::uint32_t k) const {
        return record_of(k)[kRecordKind] == kKindCheckerPlane;
    }
    Vec3 center(std::uint32_t k) const {
        const float* r = record_of(k);
        return {r[kRecordCx], r[kRecordCy], r[kRecordCz]};
    }
    Vec3 normal(std::uint32_t k) const {
        const float* r = record_of(k);
        return {r[kRecordNx], r[kRecordNy], r[kRecordNz]};
    }
    std::uint32_t material(std::uint32_t k) const {
        return std::bit_cast<std::uint32_t>(record_of(k)[kRecordMaterial]);
    }
};

struct CompiledMaterials {
    std::uint32_t count = 0;
    std::uint32_t padded_count = 0;
    AlignedVector<float> cd_r, cd_g, cd_b;
    AlignedVector<float> kd, ks, shininess;
    AlignedVector<float> kr_r, kr_g, kr_b;
    AlignedVector<float> kt, ior;
    // The largest x in [0, 1] with powf(x, shininess) == 0 (-1 when there is none): a
    // highlight base at or below it needs no powf call to give powf's answer.
    AlignedVector<float> pow_zero_below;
    AlignedVector<float> checker_r, checker_g, checker_b, checker_size;
};

struct CompiledLights {
    std::uint32_t count = 0;
    std::uint32_t padded_count = 0;
    AlignedVector<std::uint32_t> directional;  // 0 point, 1 directional
    AlignedVector<std::uint32_t> inverse_square;
    AlignedVector<float> px, py, pz;  // point: position
    AlignedVector<float> lx, ly, lz;  // directional: l = -normalize(direction)
    AlignedVector<float> r, g, b;     // intensity
};

struct CompiledScene {
    CompiledSpheres spheres;
    CompiledPlanes planes;
    CompiledObjects objects;
    CompiledMaterials materials;
    CompiledLights lights;

    CameraFrame camera;
    Background background;
    Vec3 background_up;  // normalize(camera.up): the gradient's axis
    Rgb ambient;
    float epsilon = 0.0f;  // ε_s of the self-intersection rule
    int max_depth = 5;
    int spp = 1;
    std::uint64_t seed = 0;
    int width = 0;
    int height = 0;

    double compile_seconds = 0.0;  // wall-clock time compile_scene() took
};

// The scene must have passed validate_scene(). Throws std::invalid_argument for a scene
// the kernels cannot represent (more than 2^24 objects: hit ids travel as exact floats).
CompiledScene compile_scene(const Scene& scene);

// Updates `out` in place for a pose of the scene it was compiled from whose spheres moved
// or changed size (an animation's frame: the same objects in the same order, validated):
// the spheres' centers and radii and the self-intersection epsilon (which follows the
// spheres' box), as compile_scene would write them; nothing else of a compiled scene
// depends on them. Throws std::invalid_argument when the object counts differ.
void update_compiled_spheres(CompiledScene& out, const Scene& scene);

// Sets what compile_scene takes from the camera (its frame for the image's size, and the
// gradient background's axis) from `camera`: nothing else of a compiled scene depends on
// it, so another view of the same scene needs no new compile (octray view). The camera
// must pass validate_scene's camera rules for the compiled scene's image size.
void set_compiled_camera(CompiledScene& scene, const Camera& camera);

}  // namespace octray
