// Baseline x86-64 (no ISA flags): Imath's conversion and the run-time choice of F16C
// (render/image/half_bits.h).

#include "render/image/half_bits.h"

#include <cpuid.h>
#include <half.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace octray {
namespace {

bool cpu_has_f16c() {
    unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
    if (__get_cpuid(1, &eax, &ebx, &ecx, &edx) == 0) return false;
    const bool f16c = (ecx & bit_F16C) != 0, avx = (ecx & bit_AVX) != 0;
    const bool osxsave = (ecx & bit_OSXSAVE) != 0;
    if (!f16c || !avx || !osxsave) return false;
    // The OS saves the XMM and YMM state (XCR0 bits 1 and 2): VEX instructions may run.
    unsigned xcr0_lo = 0, xcr0_hi = 0;
    __asm__("xgetbv" : "=a"(xcr0_lo), "=d"(xcr0_hi) : "c"(0));
    return (xcr0_lo & 0x6u) == 0x6u;
}

}  // namespace

namespace detail {

void floats_to_half_bits_imath(const float* values, std::size_t count, std::size_t stride,
                               std::uint16_t* out) {
    for (std::size_t k = 0; k < count; ++k) out[k] = half(values[k * stride]).bits();
}

}  // namespace detail

bool half_bits_use_f16c() {
    static const bool use = cpu_has_f16c();
    return use;
}

void floats_to_half_bits(const float* values, std::size_t count, std::size_t stride,
                         std::uint16_t* out) {
    const auto convert = half_bits_use_f16c() ? detail::floats_to_half_bits_f16c
                                              : detail::floats_to_half_bits_imath;
    // A frame's channel (a million samples) is converted on the threads of the caller's
    // arena, in blocks of 64 Ki samples; a small one on the calling thread.
    constexpr std::size_t kBlock = std::size_t{1} << 16;
    if (count <= kBlock) {
        convert(values, count, stride, out);
        return;
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, (count + kBlock - 1) / kBlock),
                      [&](const tbb::blocked_range<std::size_t>& blocks) {
                          for (std::size_t b = blocks.begin(); b != blocks.end(); ++b) {
                              const std::size_t first = b * kBlock;
                              convert(values + first * stride, std::min(kBlock, count - first),
                                      stride, out + first);
                          }
                      });
}

}  // namespace octray
