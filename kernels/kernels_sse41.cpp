// The packet kernels for sse4.1, compiled with its own flags: -msse4.1
// (kernels/CMakeLists.txt). Only reached through kernels/dispatch.h after the CPU has been
// checked. Everything here lives in namespace octray::kernels::sse4_1.

#define OCTRAY_KERNEL_NAMESPACE sse4_1
#include "kernels/kernel_table.h"
#include "kernels/stream/camera_rays.h"
#include "kernels/stream/hit_kernels.h"
#include "kernels/stream/shading.h"

namespace octray::kernels {

// Constant-initialised (no code runs at start-up in this translation unit).
constexpr KernelTable make_table_sse4_1() {
    using Arch = xsimd::sse4_1;
    static_assert(xsimd::batch<float, Arch>::size == 4);
    return KernelTable{Isa::sse4_1,
                       "sse4.1",
                       4,
                       sse4_1::kTraversalWidth,
                       &sse4_1::camera_rays<Arch>,
                       &sse4_1::closest_hit<Arch>,
                       &sse4_1::any_hit<Arch>,
                       &sse4_1::shade<Arch>};
}

const KernelTable kKernelsSse41 = make_table_sse4_1();

}  // namespace octray::kernels
