#pragma once
// What this CPU runs of the instructions octray's hand-written intrinsics use outside the
// kernels (whose ISA is chosen through xsimd: kernels/dispatch.h), read from CPUID once per
// process; for the VEX- and EVEX-encoded ones, also whether the OS saves the YMM and ZMM
// registers (XCR0). One reading for every such choice: the preview's sRGB gathers
// (render/image/png.cpp), the float-to-half conversion (render/image/half_bits.cpp), the
// scene digest (render/batch/digest.cpp), the BVH builder's AVX binning
// (render/prepare/bvh_sah.cpp) and the width of a tile's row stores (render/stream_row.h).
// __builtin_cpu_supports would do, but clang 14 (the asan preset's compiler) knows neither
// "f16c" nor "sha".

#include <cpuid.h>

namespace octray {

struct CpuFeatures {
    bool avx2 = false;    // AVX2
    bool f16c = false;    // F16C: float to half and back
    bool sha = false;     // the SHA extensions, with the SSSE3 and SSE4.1 their code uses
    bool avx512 = false;  // AVX-512 F, with the ZMM registers saved by the OS
};

inline CpuFeatures read_cpu_features() {
    CpuFeatures f;
    unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
    if (__get_cpuid(1, &eax, &ebx, &ecx, &edx) == 0) return f;
    const bool ssse3 = (ecx & bit_SSSE3) != 0, sse41 = (ecx & bit_SSE4_1) != 0;
    const bool avx = (ecx & bit_AVX) != 0, f16c = (ecx & bit_F16C) != 0;
    bool ymm_saved = false, zmm_saved = false;
    if (avx && (ecx & bit_OSXSAVE) != 0) {
        unsigned xcr0_lo = 0, xcr0_hi = 0;
        __asm__("xgetbv" : "=a"(xcr0_lo), "=d"(xcr0_hi) : "c"(0));
        ymm_saved = (xcr0_lo & 0x6u) == 0x6u;    // the XMM and YMM state
        zmm_saved = (xcr0_lo & 0xe6u) == 0xe6u;  // and the opmask and ZMM state
    }
    f.f16c = f16c && ymm_saved;
    if (__get_cpuid_count(7, 0, &eax, &ebx, &ecx, &edx) == 0) return f;
    f.avx2 = (ebx & bit_AVX2) != 0 && ymm_saved;
    f.sha = (ebx & bit_SHA) != 0 && ssse3 && sse41;
    f.avx512 = (ebx & bit_AVX512F) != 0 && zmm_saved;
    return f;
}

// This process's reading, made on first use.
inline const CpuFeatures& cpu_features() {
    static const CpuFeatures features = read_cpu_features();
    return features;
}

}  // namespace octray
