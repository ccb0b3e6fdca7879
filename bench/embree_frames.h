#pragma once
// Whole Whitted frames traced by Embree, for `octray bench --rays whitted`: octray's
// packet renderer (camera rays, shading, compaction and requeueing, the tile loop over
// TBB) with a kernel table whose closest_hit and any_hit ask Embree (EmbreeScene's
// stream calls, 16- or 8-wide packets of each generation's consecutive rays) instead of
// octray's traversal. The frame is the same model on the same rays, so only the hit
// queries differ; its image is validated against the scalar reference's.
//
// Kernel tables hold plain function pointers, so the Embree scene is reached through one
// process-wide slot, which a frame holds while it renders: several EmbreeFrames may exist
// (the bench times their frames in rounds), but one renders at a time (a second throws).

#include <memory>

#include "bench/embree_baseline.h"
#include "kernels/isa.h"
#include "kernels/kernel_table.h"
#include "render/render_result.h"
#include "scene/compile.h"

namespace octray::bench {

struct EmbreeFramesSlot;

class EmbreeFrames {
  public:
    // `scene` must outlive this object. `isa`: octray's kernels for everything else.
    EmbreeFrames(const EmbreeScene& scene, EmbreeMode mode, Isa isa);
    ~EmbreeFrames();
    EmbreeFrames(const EmbreeFrames&) = delete;
    EmbreeFrames& operator=(const EmbreeFrames&) = delete;

    // One frame of `compiled` (options.accel is ignored: Embree has its own BVH).
    RenderResult render(const CompiledScene& compiled, RenderOptions options) const;

  private:
    kernels::KernelTable table_;
    std::unique_ptr<const EmbreeFramesSlot> slot_;  // this object's scene and mode
};

}  // namespace octray::bench
