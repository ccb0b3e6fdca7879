#pragma once
// The SIMD packet renderer: tiles of 8-wide SoA ray packets traced generation by
// generation, in chunks of at most RenderOptions::ray_chunk rays, through the kernels of
// kernels/ (render/README.md, "The packet path"). It implements the same
// rendering model as the scalar reference (render/reference.h) and is checked against it
// by `octray verify` and tests/render/packet_renderer_test.cpp.

#include <cstdint>
#include <span>
#include <vector>

#include "core/pixel_rect.h"
#include "kernels/isa.h"
#include "kernels/kernel_table.h"
#include "render/accel.h"
#include "render/prepare/bvh_build.h"
#include "render/render_result.h"
#include "render/tile_layout.h"
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

// A compiled scene with its spheres' BVH (when `accel` asks for one), made once for many
// renders: the frames of a still or camera-only animation (render/batch's frame loop),
// and the parts of the picture that `octray view`'s frameless order renders as 8x8 blocks
// (render_packet_blocks). Neither depends on the camera, so set_camera() keeps both.
class PreparedScene {
  public:
    // Compiles `scene` (which must have passed validate_scene()) and builds the BVH on
    // `threads` threads (0: every core TBB sees).
    explicit PreparedScene(const Scene& scene, Accel accel = Accel::automatic, int threads = 0);
    // The same scene seen through `camera` (valid for it: validate_scene's camera rules).
    void set_camera(const Camera& camera) { set_compiled_camera(compiled_, camera); }
    // ... on a `width` x `height` picture of `spp` samples a pixel (each at least 1): the
    // viewer's previews are smaller than its refined pictures, and neither the compiled
    // objects nor the BVH depend on the picture.
    void set_view(const Camera& camera, int width, int height, int spp) {
        compiled_.width = width;
        compiled_.height = height;
        compiled_.spp = spp;
        set_compiled_camera(compiled_, camera);
    }

    // The scene posed again (an animation's frame: the same objects in the same order,
    // validated, its spheres moved or resized, its camera moved): the compiled arrays are
    // updated in place and the BVH refitted, or rebuilt when the refit tree's cost
    // (sphere_bvh_cost) has grown past kRefitCostLimit times the built tree's. Renders are
    // then the posed scene's, bit for bit (the closest hit does not depend on the tree).
    struct Update {
        bool rebuilt = false;
        double cost_growth = 1.0;  // the refit tree's cost over the built tree's
        double seconds = 0.0;      // the whole update
    };
    Update update(const Scene& posed);
    // Measured (docs/performance-log.md, "Refit"): past this growth a frame traces slower
    // through the refit tree than a rebuild costs.
    static constexpr double kRefitCostLimit = 2.0;
    // Fewer spheres than this are updated on the calling thread's arena (update()).
    static constexpr std::uint32_t kArenaUpdateSpheres = 16384;
    const CompiledScene& compiled() const { return compiled_; }
    // The spheres' BVH, or nullptr where the scene is traced brute force.
    const SphereBvh* bvh() const { return use_bvh_ ? &bvh_ : nullptr; }
    // What preparing took: compiling, and building the BVH (0 without one).
    double compile_seconds() const { return compiled_.compile_seconds; }
    double bvh_seconds() const { return use_bvh_ ? bvh_.build_seconds : 0.0; }

  private:
    void build();  // bvh_ from compiled_ (its cost and leaf_sphere_ left to update())

    CompiledScene compiled_;
    bool use_bvh_ = false;
    int threads_ = 0;
    SphereBvh bvh_;
    // sphere_bvh_cost when last built, measured by the first update() of the tree (a
    // serial pass over every node, which a still or a camera-only animation never needs);
    // negative until then.
    double built_cost_ = -1.0;
    std::vector<std::uint32_t> leaf_sphere_;  // leaf slot -> compiled sphere (the first
                                              // refit of a tree finds it)
};

// Renders a frame of a prepared scene (its camera as set_camera left it): no compile and no
// BVH build, so seconds is the render alone. The same image as render_packet of the
// scene posed with that camera.
RenderResult render_packet(const PreparedScene& scene, const RenderOptions& options = {},
                           Isa isa = Isa::automatic);

// The closest hit of each pixel's sample-0 camera ray over options.crop (or the whole
// image) of frame options.frame, traced by the kernels of `isa` on options.threads
// threads: the hits the AOVs read (compute_aovs in render/aov.h), the same the scalar
// reference finds. The scene's camera is as set_camera left it.
FirstHits trace_first_hits(const PreparedScene& scene, const RenderOptions& options = {},
                           Isa isa = Isa::automatic);

// Renders the pixels of each of `blocks` into `target` (the scene's width x height
// picture) at their places, every sample of each; the other pixels of `target` keep their
// values. Each pixel is the same pixel of render_packet's image bit for bit. Each block is
// one tile; the blocks are spread over options.threads threads (0: all), and must not
// overlap. options.frame, cancel, pixels_done and ray_chunk apply; the tile size does not
// (a block is a tile), and crop and samples must be unset. Throws std::invalid_argument
// for an empty block or one outside the picture, a target of another size, a crop or a
// sample range; std::runtime_error for a forced ISA the CPU lacks. The result carries the
// rays and seconds; its image is empty (the pixels are in `target`).
RenderResult render_packet_blocks(const PreparedScene& scene, std::span<const PixelRect> blocks,
                                  Image& target, const RenderOptions& options = {},
                                  Isa isa = Isa::automatic);

}  // namespace octray
