// Baseline x86-64 (no ISA flags): Imath's conversion and the run-time choice of F16C
// (render/image/half_bits.h).

#include "render/image/half_bits.h"

#include <half.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "core/cpu_features.h"

namespace octray {

namespace detail {

void floats_to_half_bits_imath(const float* values, std::size_t count, std::size_t stride,
                               std::uint16_t* out) {
    for (std::size_t k = 0; k < count; ++k) out[k] = half(values[k * stride]).bits();
}

}  // namespace detail

bool half_bits_use_f16c() { return cpu_features().f16c; }

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
