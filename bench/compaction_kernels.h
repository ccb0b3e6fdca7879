#pragma once
// Stream compaction as the packet kernels do it (kernels/stream/compaction.h: compaction()
// and store_compacted(), the lanes of a mask packed to the front), exposed per ISA for the
// microbenchmarks. Each ISA lives in its own translation unit with its own flags, like
// the kernels: call one only after isa_supported() says the CPU has it.

#include <cstdint>

namespace octray::bench {

// Packs src[i] for every i < n with keep[i] != 0 to the front of dst, in order; returns
// how many. n is a multiple of 8; dst has room for n + 8 floats (AVX2 stores whole
// packets past the last kept lane).
using CompactFn = std::uint32_t (*)(const float* src, const float* keep, std::uint32_t n,
                                    float* dst);

std::uint32_t compact_sse2(const float* src, const float* keep, std::uint32_t n, float* dst);
std::uint32_t compact_avx2(const float* src, const float* keep, std::uint32_t n, float* dst);

}  // namespace octray::bench
