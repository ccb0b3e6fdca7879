#pragma once
// The layout of the packet renderer's per-thread tile scratch (render/packet_renderer.cpp,
// TileScratch): how many rays a tile traces at once, how its SoA streams are padded, and
// how many columns each stream has. The renderer sizes its buffers from these constants
// (it checks its column lists against them at compile time) and the memory estimate
// (render/batch/memory_estimate.cpp) counts them: one definition for both.

#include <cstddef>
#include <cstdint>

namespace octray {

// Rays a tile traces at once per generation of its ray tree when RenderOptions::ray_chunk
// is 0: a multiple of the widest packet (16 rays). A tile's scratch then holds at most this
// many rays per generation, whatever the depth and the samples per pixel.
inline constexpr std::uint32_t kDefaultRayChunk = 4096;

// A stream of n rays is n rounded up to whole packets of this many rays
// (kernels::kPacketWidth), plus one spare packet, in each column: at most n + 2 packets.
inline constexpr std::size_t kTileStreamPacket = 8;

// Every column holds 4-byte elements (float, std::int32_t or std::uint32_t).
inline constexpr std::size_t kTileColumnBytes = 4;

// Columns per stream of TileScratch.
inline constexpr std::size_t kSampleColumns = 5;   // camera samples: x y lens_u lens_v pixel
inline constexpr std::size_t kRayColumns = 10;     // rays: origin, direction, weight, pixel
inline constexpr std::size_t kHitColumns = 2;      // hits: t, object
inline constexpr std::size_t kShadowColumns = 12;  // shadow rays: origin, direction, t_max,
                                                   // light term, parent, occluded
inline constexpr std::size_t kColorColumns = 9;    // a generation's colors: local, mirror
                                                   // tail, refraction tail
inline constexpr std::size_t kLinkColumns = 4;     // a child's parent slot and its factor
// Per pixel of a tile: three accumulators (r, g, b) and its place in sample order (x, y).
inline constexpr std::size_t kTileAccumulatorColumns = 3;
inline constexpr std::size_t kTilePixelOrderColumns = 2;

}  // namespace octray
