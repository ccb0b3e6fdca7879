#pragma once
// Progressive rendering: a frame in passes of 1, 2, 4, ... samples per pixel so far, with
// the mean so far after each pass, ending on exactly the plain render's image
// (render/batch/README.md, "Progressive passes").
//
// Each pass renders samples [begin, end) of every pixel with RenderOptions::samples and
// adds them, one after the other, onto the previous passes' per-pixel sums
// (RenderOptions::sample_sums); a pixel's samples are therefore summed in sample order from
// zero, as a plain render sums them, and the last pass divides by spp as it does: the
// final image is the plain render's bit for bit, on both paths.

#include <functional>
#include <vector>

#include "render/render_result.h"

namespace octray::batch {

// The samples per pixel so far after each pass: 1, 2, 4, ... (powers of two below spp),
// then spp. spp 1: {1}; 5: {1, 2, 4, 5}; 16: {1, 2, 4, 8, 16}. Throws
// std::invalid_argument for spp < 1.
std::vector<int> progressive_schedule(int spp);

// Renders one pass: render_reference or render_packet with the given options.
using PassRenderer = std::function<RenderResult(const RenderOptions& options)>;
// Called after every pass (the last one too) with the result so far: its image is the mean
// of samples [0, samples_so_far) of each pixel; rays and seconds are this pass's.
using PassCallback = std::function<void(const RenderResult& so_far, int samples_so_far)>;

// Renders `spp` samples per pixel (the scene's spp) in the passes of progressive_schedule,
// each with `options` (crop, threads, frame, ...; its samples and sample_sums must be
// unset) and on_pass after each (may be empty). Returns the last pass's result with the
// rays and seconds of all passes summed and sample_sums cleared: the plain render's image.
// An exception from `render` or `on_pass` passes on.
RenderResult render_progressive(const PassRenderer& render, int spp,
                                const RenderOptions& options, const PassCallback& on_pass);

}  // namespace octray::batch
