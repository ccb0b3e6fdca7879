#pragma once
// Floats to the bits of IEEE binary16 (OpenEXR's HALF), the conversion every half channel
// octray writes goes through (make_channel). Rounded to nearest even, bit for bit as
// Imath's half(float): with the F16C instruction (8 at a time) where the CPU has it
// (checked once, at run time), with Imath's slower software conversion otherwise
// (measured: docs/performance-log.md, "Time to image on an AVX-512 Xeon").

#include <cstddef>
#include <cstdint>

namespace octray {

// out[k] = the half bits of values[k * stride], k < count.
void floats_to_half_bits(const float* values, std::size_t count, std::size_t stride,
                         std::uint16_t* out);

// Whether floats_to_half_bits uses F16C on this CPU (F16C and the OS's AVX state).
bool half_bits_use_f16c();

namespace detail {
// The two builds, for the tests: Imath's software conversion, and F16C (only where
// half_bits_use_f16c()). NaN lanes go through Imath's conversion in both: F16C would set
// the quiet bit of a signalling NaN, which Imath keeps as it is.
void floats_to_half_bits_imath(const float* values, std::size_t count, std::size_t stride,
                               std::uint16_t* out);
void floats_to_half_bits_f16c(const float* values, std::size_t count, std::size_t stride,
                              std::uint16_t* out);
}  // namespace detail

}  // namespace octray
