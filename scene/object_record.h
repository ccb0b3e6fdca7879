#pragma once
// The layout of a compiled object's record (scene/compile.h, CompiledObjects): written by
// compile_scene, read by the shading kernels (kernels/stream/shading.h). Plain constants
// only, so that the kernels' per-ISA translation units may include it (kernels/README.md,
// "the ODR rule").

#include <cstdint>

namespace octray {

// Floats per record: two records to a cache line.
inline constexpr std::uint32_t kObjectRecordFloats = 8;

// Where each field lies in a record.
enum ObjectRecordField : std::uint32_t {
    kRecordCx,
    kRecordCy,
    kRecordCz,  // a sphere's center (0 for a plane)
    kRecordNx,
    kRecordNy,
    kRecordNz,        // a plane's normal (0 for a sphere)
    kRecordKind,      // kKindSphere, kKindPlane or kKindCheckerPlane, as a float
    kRecordMaterial,  // the material's index: its bits, stored as a float's
};

// What an object is, as its record's kind field holds it.
inline constexpr float kKindSphere = 0.0f, kKindPlane = 1.0f, kKindCheckerPlane = 2.0f;

}  // namespace octray
