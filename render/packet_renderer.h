#pragma once
// The SIMD packet renderer: tiles of 8-wide SoA ray packets traced generation by
// generation, in chunks of at most RenderOptions::ray_chunk rays, through the kernels of
// kernels/ (render/README.md, "The packet path"). It implements the same
// rendering model as the scalar reference (render/reference.h) and is checked against it
// by `octray verify` and tests/render/packet_renderer_test.cpp.

#include <cstdint>

#include "kernels/isa.h"
#include "kernels/kernel_table.h"
#include "render/tile_layout.h"
#include "render/types.h"
#include "scene/compile.h"
#include "scene/scene.h"

namespace octray {

// kDefaultRayChunk, the rays a tile traces at once by default: render/tile_layout.h.

// Renders the whole image with the kernels of `isa` (Isa::automatic: the best the CPU
// has; a forced ISA the CPU lacks throws std::runtime_error). Tiles of
// options.tile_width x options.tile_height pixels are spread over options.threads
// threads (0: all); the image is bit-identical for any thread count and tile size.
// The scene must have passed validate_scene(); RenderResult::seconds includes compiling it.
RenderResult render_packet(const Scene& scene, const RenderOptions& options = {},
                           Isa isa = Isa::automatic);

// The same from a scene compiled once (benchmarks, animations); seconds is render only.
RenderResult render_packet(const CompiledScene& scene, const RenderOptions& options = {},
                           Isa isa = Isa::automatic);

// The same with a kernel table of the caller's: `octray bench` renders whole frames whose
// closest_hit and any_hit trace with Embree (bench/embree_frames.h), the rest octray's.
RenderResult render_packet(const CompiledScene& scene, const RenderOptions& options,
                           const kernels::KernelTable& table);

}  // namespace octray
