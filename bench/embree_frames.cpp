// Whole frames with Embree answering the hit queries (bench/embree_frames.h).

#include "bench/embree_frames.h"

#include <atomic>
#include <stdexcept>

#include "kernels/dispatch.h"
#include "render/packet_renderer.h"

namespace octray::bench {

struct EmbreeFramesSlot {
    const EmbreeScene* scene;
    EmbreeMode mode;
};

namespace {

using Slot = EmbreeFramesSlot;
// The scene and mode of the EmbreeFrames rendering now, read by the kernel table's two
// entries below.
std::atomic<const Slot*> g_slot{nullptr};

// Primary rays are the only ones traced from t_min = ε_s > 0: they get the coherent hint.
void closest_hit(const kernels::SceneView&, const kernels::RayStream& rays, std::uint32_t count,
                 float t_min, const kernels::HitStream& hits) {
    const Slot& s = *g_slot.load(std::memory_order_acquire);
    s.scene->intersect(s.mode,
                       {rays.ox, rays.oy, rays.oz, rays.dx, rays.dy, rays.dz, nullptr, t_min},
                       count, hits.t, hits.object, t_min > 0.0f);
}

void any_hit(const kernels::SceneView&, const kernels::ShadowStream& rays, std::uint32_t count,
             std::uint32_t* occluded) {
    const Slot& s = *g_slot.load(std::memory_order_acquire);
    s.scene->occluded(s.mode,
                      {rays.ox, rays.oy, rays.oz, rays.dx, rays.dy, rays.dz, rays.t_max, 0.0f},
                      count, occluded, false);
}

}  // namespace

EmbreeFrames::EmbreeFrames(const EmbreeScene& scene, EmbreeMode mode, Isa isa)
    : table_(kernel_table(resolve_isa(isa))),
      slot_(std::make_unique<Slot>(Slot{&scene, mode})) {
    table_.closest_hit = closest_hit;
    table_.any_hit = any_hit;
}

EmbreeFrames::~EmbreeFrames() = default;

RenderResult EmbreeFrames::render(const CompiledScene& compiled, RenderOptions options) const {
    // This object's scene and mode in the slot for the frame, released whatever happens.
    const Slot* expected = nullptr;
    if (!g_slot.compare_exchange_strong(expected, slot_.get(), std::memory_order_acq_rel))
        throw std::logic_error("EmbreeFrames: one frame at a time (another is rendering)");
    struct Release {
        ~Release() { g_slot.store(nullptr, std::memory_order_release); }
    } release;
    options.accel = Accel::none;  // no octray BVH: Embree traverses its own
    return render_packet(compiled, options, table_);
}

}  // namespace octray::bench
