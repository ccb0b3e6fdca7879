#pragma once
// The value rules of scene files that both JSON readers apply: the diagnosing reader
// (read_scene.cpp, nlohmann) and the fast one (load_fast.cpp, simdjson). One copy, so that
// the two cannot drift apart; the messages for breaking them are the diagnosing reader's.

#include <cmath>
#include <limits>
#include <optional>

#include "core/vec3.h"

namespace octray::scene_json {

// Integers the scene stores in an int (image size, spp, key frame numbers).
inline constexpr int kMaxIntValue = std::numeric_limits<int>::max();
// Samples per pixel, wherever they are set (a scene file's image.spp, a built-in's spp=,
// `--spp`, the viewer, the API): 2^20. A 1x1 frame at the limit is 2^20 camera rays, a
// second or so of work; a render checks its cancel flag inside tiles, so any spp stops
// promptly on a signal.
inline constexpr int kMaxSpp = 1 << 20;
// Deeper than this, the kr/kt weight cut-off has long ended every real path; the cap
// keeps the renderers' recursion (or ray queues) bounded.
inline constexpr int kMaxDepthLimit = 64;
// Doubles below FLT_MAX + half an ulp round to FLT_MAX (the writer prints FLT_MAX as
// 3.4028235e+38, just above it); from there on they would round to infinity.
inline constexpr double kFloatRoundingLimit = 0x1.ffffffp+127;
// Plane normals within this of unit length (squared) are kept bit for bit, so that a
// written scene reads back identical; float normalisation lands well inside it.
inline constexpr double kUnitTolerance = 1e-6;

// Whether a number read as a double becomes a finite float.
inline bool fits_float(double d) { return std::fabs(d) < kFloatRoundingLimit; }

// A plane normal of unit length: normalised in double (no overflow or underflow for any
// float input), kept bit for bit when already unit; none for a zero (or NaN) vector.
inline std::optional<Vec3> unit_plane_normal(Vec3 n) {
    const double x = n.x, y = n.y, z = n.z;
    const double len2 = x * x + y * y + z * z;
    if (!(len2 > 0.0)) return std::nullopt;
    if (std::fabs(len2 - 1.0) <= kUnitTolerance) return n;
    const double len = std::sqrt(len2);
    return Vec3{static_cast<float>(x / len), static_cast<float>(y / len),
                static_cast<float>(z / len)};
}

// A thinlens camera without focus_distance focuses on the look-at point: what a
// photographer means by "looking at" it.
inline float default_focus_distance(Vec3 eye, Vec3 lookat) {
    const Vec3 d = lookat - eye;
    return static_cast<float>(std::sqrt(static_cast<double>(d.x) * d.x +
                                        static_cast<double>(d.y) * d.y +
                                        static_cast<double>(d.z) * d.z));
}

}  // namespace octray::scene_json
