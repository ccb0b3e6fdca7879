// The packet kernels for avx2, compiled with its own flags: -mavx2 -mfma
// (kernels/CMakeLists.txt). Only reached through kernels/dispatch.h after the CPU has been
// checked. Everything here lives in namespace octray::kernels::avx2_fma.

#define OCTRAY_KERNEL_NAMESPACE avx2_fma
#include "kernels/kernel_table.h"
#include "kernels/stream/camera_rays.h"
#include "kernels/stream/hit_kernels.h"
#include "kernels/stream/shading.h"

namespace octray::kernels {

// Constant-initialised (no code runs at start-up in this translation unit).
constexpr KernelTable make_table_avx2_fma() {
    using Arch = xsimd::fma3<xsimd::avx2>;
    static_assert(xsimd::batch<float, Arch>::size == 8);
    return KernelTable{Isa::avx2,
                       "avx2",
                       8,
                       avx2_fma::kTraversalWidth,
                       &avx2_fma::camera_rays<Arch>,
                       &avx2_fma::closest_hit<Arch>,
                       &avx2_fma::any_hit<Arch>,
                       &avx2_fma::shade<Arch>};
}

const KernelTable kKernelsAvx2 = make_table_avx2_fma();

}  // namespace octray::kernels
