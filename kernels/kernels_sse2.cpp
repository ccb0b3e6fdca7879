// The packet kernels for sse2, compiled with its own flags: (none: SSE2 is baseline x86-64)
// (kernels/CMakeLists.txt). Only reached through kernels/dispatch.h after the CPU has been
// checked. Everything here lives in namespace octray::kernels::sse2.

#define OCTRAY_KERNEL_NAMESPACE sse2
#include "kernels/kernel_table.h"
#include "kernels/stream/camera_rays.h"
#include "kernels/stream/hit_kernels.h"
#include "kernels/stream/shading.h"

namespace octray::kernels {

// Constant-initialised (no code runs at start-up in this translation unit).
constexpr KernelTable make_table_sse2() {
    using Arch = xsimd::sse2;
    static_assert(xsimd::batch<float, Arch>::size == 4);
    return KernelTable{Isa::sse2,
                       "sse2",
                       4,
                       sse2::kTraversalWidth,
                       &sse2::camera_rays<Arch>,
                       &sse2::closest_hit<Arch>,
                       &sse2::any_hit<Arch>,
                       &sse2::shade<Arch>};
}

const KernelTable kKernelsSse2 = make_table_sse2();

}  // namespace octray::kernels
