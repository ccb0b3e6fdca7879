#pragma once
// The frameless pixel order of `octray view --order frameless` (Bishop et al., "Frameless
// rendering: double buffering considered harmful", 1994): instead of whole frames, small
// blocks of the picture are re-rendered one after another in a fixed pseudo-random
// permutation and shown as they land, so a moving camera updates the whole picture a
// little at a time, without frame boundaries.
//
// Blocks, not single pixels: the renderers take one rectangle per call
// (RenderOptions::crop), and each block of a crop render equals the same pixels of the full
// render bit for bit, so one sweep over every block of a still camera gives exactly the
// tiled order's picture.

#include <cstdint>
#include <vector>

#include "core/pixel_rect.h"

namespace octray::view {

// The blocks of a width x height picture, `block` x `block` pixels (smaller at the right
// and bottom edges), covering it once, in a pseudo-random order fixed by `seed`.
std::vector<PixelRect> frameless_blocks(int width, int height, int block,
                                        std::uint64_t seed = 1994);

}  // namespace octray::view
