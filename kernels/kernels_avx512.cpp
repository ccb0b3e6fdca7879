// The packet kernels for AVX-512 (F, VL, BW, DQ), compiled with its own flags
// (kernels/CMakeLists.txt). Only reached through kernels/dispatch.h after the CPU has been
// checked. Everything here lives in namespace octray::kernels::avx512.
//
// The BVH traversal takes 16 rays at a time, one 16-lane register per packet: two of the
// stream's 8-ray packets share every node visit and every leaf's sphere loads
// (OCTRAY_TRAVERSAL_ARCH, kernels/bvh/bvh_packet.h), and so do brute force and the beams'
// slopes; shading and camera rays take 16 rays per register while 16 remain
// (OCTRAY_SHADE_ARCH, kernels/stream/shading.h, kernels/stream/camera_rays.h). Node tests
// (8 children) stay 8 lanes wide: measured, AVX-512 encodings of the 8-lane kernels gained
// nothing (docs/performance-log.md).

#define OCTRAY_KERNEL_NAMESPACE avx512
#define OCTRAY_TRAVERSAL_ARCH xsimd::avx512f
#define OCTRAY_SHADE_ARCH xsimd::avx512f
#include "kernels/kernel_table.h"
#include "kernels/stream/camera_rays.h"
#include "kernels/stream/hit_kernels.h"
#include "kernels/stream/shading.h"

namespace octray::kernels {

// Constant-initialised (no code runs at start-up in this translation unit).
constexpr KernelTable make_table_avx512() {
    using Arch = xsimd::fma3<xsimd::avx2>;
    static_assert(xsimd::batch<float, Arch>::size == 8);
    static_assert(xsimd::batch<float, avx512::RayArch<Arch>>::size == 16);
    return KernelTable{Isa::avx512,
                       "avx512",
                       8,
                       avx512::kTraversalWidth,
                       &avx512::camera_rays<Arch>,
                       &avx512::closest_hit<Arch>,
                       &avx512::any_hit<Arch>,
                       &avx512::shade<Arch>};
}

const KernelTable kKernelsAvx512 = make_table_avx512();

}  // namespace octray::kernels
