#pragma once
// The counter-based random numbers of the rendering model.
//
// Every random number is a pure function of (frame, pixel i, pixel j, sample index,
// dimension, seed): there is no generator state shared across pixels, so an image is
// bit-identical whatever the thread count, tile size or tile order, and the scalar and
// SIMD paths see the same sample positions.

#include <cstdint>

namespace octray {

// Dimensions drawn per camera sample.
enum SampleDimension : std::uint32_t {
    kDimPixelX = 0,  // jitter inside the pixel (or stratum)
    kDimPixelY = 1,
    kDimLensU = 2,  // thin-lens aperture sample
    kDimLensV = 3,
};

// SplitMix64's output function (Steele, Lea, Flood 2014): a bijective 64-bit mixer.
constexpr std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

// Hash of the whole counter; each field is folded in through its own mix round, so
// neighbouring counters give unrelated outputs.
constexpr std::uint64_t sample_hash(std::uint32_t frame, std::uint32_t i, std::uint32_t j,
                                    std::uint32_t sample, std::uint32_t dimension,
                                    std::uint64_t seed) {
    std::uint64_t h = mix64(seed + 0x9E3779B97F4A7C15ull);
    h = mix64(h ^ frame);
    h = mix64(h ^ ((static_cast<std::uint64_t>(j) << 32) | i));
    h = mix64(h ^ ((static_cast<std::uint64_t>(sample) << 32) | dimension));
    return h;
}

// Uniform float in [0, 1): the top 24 bits of the hash times 2^-24 (exact in a float).
constexpr float sample_uniform(std::uint32_t frame, std::uint32_t i, std::uint32_t j,
                               std::uint32_t sample, std::uint32_t dimension,
                               std::uint64_t seed) {
    return static_cast<float>(sample_hash(frame, i, j, sample, dimension, seed) >> 40) *
           0x1.0p-24f;
}

struct PixelOffset {
    float ox, oy;  // position inside the pixel, each in [0, 1)
};

// The sample's offset inside pixel (i, j): the pixel center for spp == 1; for a square
// spp = n*n a jittered point in stratum (s mod n, s div n); otherwise uniform jitter.
inline PixelOffset pixel_sample_offset(std::uint32_t frame, std::uint32_t i, std::uint32_t j,
                                       std::uint32_t sample, std::uint32_t spp,
                                       std::uint64_t seed) {
    if (spp <= 1) return {0.5f, 0.5f};
    const float u = sample_uniform(frame, i, j, sample, kDimPixelX, seed);
    const float v = sample_uniform(frame, i, j, sample, kDimPixelY, seed);
    std::uint32_t n = 1;
    while ((n + 1) * (n + 1) <= spp) ++n;
    if (n * n != spp) return {u, v};
    const float inv_n = 1.0f / static_cast<float>(n);
    return {(static_cast<float>(sample % n) + u) * inv_n,
            (static_cast<float>(sample / n) + v) * inv_n};
}

}  // namespace octray
