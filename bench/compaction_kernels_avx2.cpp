// compact_avx2(): the packet kernels' compaction primitives compiled for avx2
// (bench/CMakeLists.txt gives this file its flags), in a namespace of its own.

#define OCTRAY_KERNEL_NAMESPACE bench_avx2_fma
#include "bench/compaction_kernels.h"
#include "kernels/stream/compaction.h"

namespace octray::bench {

std::uint32_t compact_avx2(const float* src, const float* keep, std::uint32_t n, float* dst) {
    using namespace octray::kernels::bench_avx2_fma;
    using F = xsimd::batch<float, xsimd::fma3<xsimd::avx2>>;
    std::uint32_t written = 0;
    for (std::uint32_t base = 0; base < n; base += F::size) {
        const auto mask = F::load_unaligned(keep + base) != F(0.0f);
        const Compaction<F> c = compaction<F>(mask);
        store_compacted(c, F::load_unaligned(src + base), dst + written);
        written += c.count;
    }
    return written;
}

}  // namespace octray::bench
