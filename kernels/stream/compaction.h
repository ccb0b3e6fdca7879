#pragma once
// Stream compaction, as the shade kernel (shading.h) packs its shadow rays and traced
// children into their output streams. (The fisheye camera compacts lane by lane itself.)
//
// Included ONLY by the per-ISA translation units, under their OCTRAY_KERNEL_NAMESPACE
// (packet_math.h; kernels/README.md, "the ODR rule").

#ifndef OCTRAY_KERNEL_NAMESPACE
#error "define OCTRAY_KERNEL_NAMESPACE (one per ISA translation unit) before including"
#endif

#include <immintrin.h>

#include <cstdint>

#include "kernels/packet_math.h"

namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE {

// Stream compaction: the lanes of a mask packed to the front of an output stream, in lane
// order. AVX2 permutes whole registers (vpermps with an index vector from a 256-entry
// table, then one unaligned store of all 8 lanes: the caller's streams have a spare
// packet at the end); AVX-512 does the same for each 8-lane half of its register (the
// upper half stored after the lower one's selected lanes: vcompressps was slower, in
// docs/performance-log.md); SSE copies lane by lane.
struct CompressTable {
    std::uint8_t lanes[256][8];
};
constexpr CompressTable make_compress_table() {
    CompressTable t{};
    for (int m = 0; m < 256; ++m) {
        int n = 0;
        for (int i = 0; i < 8; ++i)
            if (m & (1 << i)) t.lanes[m][n++] = static_cast<std::uint8_t>(i);
    }
    return t;
}
alignas(64) inline constexpr CompressTable kCompressTable = make_compress_table();

template <class F>
struct Compaction {
    std::uint32_t bits;   // bit i: lane i is selected
    std::uint32_t count;  // selected lanes
    // The selected lanes in order, then zeros (kCompressTable's row for `bits`).
    const std::uint8_t* lanes() const { return kCompressTable.lanes[bits]; }
};
template <class F, class M>
Compaction<F> compaction(const M& m) {
    const std::uint32_t bits = mask_bits<F>(m);
    return {bits, static_cast<std::uint32_t>(__builtin_popcount(bits))};
}

// The permutation that packs a compaction's lanes to the front, widened from the byte
// table straight into a register (no store and reload of a lane array in between).
// (An 8-lane permutation: AVX-512's 16-lane registers are compacted as two halves.)
template <class F>
__m256i compaction_index(std::uint32_t bits) {
    static_assert(F::size >= 8, "AVX2 and AVX-512 only");
    return _mm256_cvtepu8_epi32(
        _mm_loadl_epi64(reinterpret_cast<const __m128i*>(kCompressTable.lanes[bits])));
}

// The lower and upper 8 lanes of a 16-lane register. (This and store_slots are templates so
// that a translation unit without AVX-512 or AVX2 never instantiates their intrinsics.)
template <class F>
__m256 lower_half(const F& v) {
    return _mm512_castps512_ps256(v);
}
template <class F>
__m256 upper_half(const F& v) {
    return _mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(v), 1));
}

// (base + lane) * scale + offset for the 8 lanes of `lane`, stored whole.
template <class F>
void store_slots(const __m256i& lane, std::uint32_t base, std::uint32_t scale,
                 std::uint32_t offset, std::uint32_t* dst) {
    const __m256i slot = _mm256_add_epi32(
        _mm256_mullo_epi32(_mm256_add_epi32(_mm256_set1_epi32(static_cast<int>(base)), lane),
                           _mm256_set1_epi32(static_cast<int>(scale))),
        _mm256_set1_epi32(static_cast<int>(offset)));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(dst), slot);
}

// The first `count` lanes of a 16-lane register, as a write mask.
inline __mmask16 first_lanes(std::uint32_t count) {
    return static_cast<__mmask16>((std::uint32_t{1} << count) - 1u);
}

// Writes the selected lanes of v to dst[0, count); with AVX2 and AVX-512 also scribbles on
// dst[count, count + 8).
// (Always inlined: GCC called the 16-lane one, 6 % of a whitted frame.)
template <class F>
[[gnu::always_inline]] inline void store_compacted(const Compaction<F>& c, const F& v,
                                                   float* dst) {
    if constexpr (F::size == 16) {
        // As two 8-lane halves, each permuted as AVX2 permutes it (vcompressps measured
        // slower): the upper half's store scribbles up to 8 lanes past the count.
        const std::uint32_t low = c.bits & 0xffu, high = c.bits >> 8;
        _mm256_storeu_ps(dst,
                         _mm256_permutevar8x32_ps(lower_half(v), compaction_index<F>(low)));
        _mm256_storeu_ps(dst + __builtin_popcount(low),
                         _mm256_permutevar8x32_ps(upper_half(v), compaction_index<F>(high)));
    } else if constexpr (F::size == 8) {
        _mm256_storeu_ps(dst, _mm256_permutevar8x32_ps(v, compaction_index<F>(c.bits)));
    } else {
        alignas(64) float lanes[F::size];
        v.store_aligned(lanes);
        const std::uint8_t* selected = c.lanes();
        for (std::uint32_t k = 0; k < c.count; ++k) dst[k] = lanes[selected[k]];
    }
}
template <class F>
[[gnu::always_inline]] inline void store_compacted(const Compaction<F>& c, const V3<F>& v,
                                                   float* x, float* y, float* z,
                                                   std::uint32_t at) {
    store_compacted(c, v.x, x + at);
    store_compacted(c, v.y, y + at);
    store_compacted(c, v.z, z + at);
}
// base + lane for each selected lane, times `scale`, plus `offset`; with AVX2 and AVX-512
// also scribbles on dst[count, count + 8).
template <class F>
void store_compacted_slots(const Compaction<F>& c, std::uint32_t base, std::uint32_t scale,
                           std::uint32_t offset, std::uint32_t* dst) {
    if constexpr (F::size == 16) {
        const std::uint32_t low = c.bits & 0xffu, high = c.bits >> 8;
        store_slots<F>(compaction_index<F>(low), base, scale, offset, dst);
        store_slots<F>(compaction_index<F>(high), base + 8, scale, offset,
                       dst + __builtin_popcount(low));
    } else if constexpr (F::size == 8) {
        store_slots<F>(compaction_index<F>(c.bits), base, scale, offset, dst);
    } else {
        const std::uint8_t* selected = c.lanes();
        for (std::uint32_t k = 0; k < c.count; ++k)
            dst[k] = (base + selected[k]) * scale + offset;
    }
}
// `value` in dst[0, count); with AVX2 also scribbles on dst[count, 8).
template <class F>
void store_count(const Compaction<F>& c, float value, float* dst) {
    if constexpr (F::size == 16) {
        _mm512_mask_storeu_ps(dst, first_lanes(c.count), _mm512_set1_ps(value));
    } else if constexpr (F::size == 8) {
        _mm256_storeu_ps(dst, _mm256_set1_ps(value));
    } else {
        for (std::uint32_t k = 0; k < c.count; ++k) dst[k] = value;
    }
}

}  // namespace octray::kernels::OCTRAY_KERNEL_NAMESPACE
