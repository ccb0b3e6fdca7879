// compact_sse2(): the packet kernels' compaction primitives compiled for sse2
// (bench/CMakeLists.txt gives this file its flags), in a namespace of its own.

#define OCTRAY_KERNEL_NAMESPACE bench_sse2
#include "bench/compaction_kernels.h"
#include "kernels/stream/compaction.h"

namespace octray::bench {

std::uint32_t compact_sse2(const float* src, const float* keep, std::uint32_t n, float* dst) {
    using namespace octray::kernels::bench_sse2;
    using F = xsimd::batch<float, xsimd::sse2>;
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
