#pragma once
// The instruction sets the packet kernels are compiled for. A plain enum: this header is
// also included by the per-ISA translation units (kernels/README.md, "the ODR rule").

namespace octray {

enum class Isa {
    automatic,  // the best the CPU supports
    sse2,       // baseline x86-64: two 4-wide registers per 8-wide packet
    sse4_1,     // two 4-wide registers per packet, hardware floor and blend
    avx2,       // AVX2 + FMA: one 8-wide register per packet
    avx512,     // AVX-512 F/VL/BW/DQ: AVX2's kernels, BVH traversal 16 rays at a time
};

}  // namespace octray
