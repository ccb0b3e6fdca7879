// Baseline x86-64 (no ISA flags): Imath's conversion and the run-time choice of F16C
// (render/image/half_bits.h).

#include "render/image/half_bits.h"

#include <cpuid.h>
#include <half.h>

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
    if (half_bits_use_f16c())
        detail::floats_to_half_bits_f16c(values, count, stride, out);
    else
        detail::floats_to_half_bits_imath(values, count, stride, out);
}

}  // namespace octray
