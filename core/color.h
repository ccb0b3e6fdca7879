#pragma once
// Rgb: linear RGB radiance as floats (HDR; never clamped except for 8-bit previews).

#include <cmath>

namespace octray {

struct Rgb {
    float r = 0.0f, g = 0.0f, b = 0.0f;

    constexpr Rgb() = default;
    constexpr Rgb(float r_, float g_, float b_) : r(r_), g(g_), b(b_) {}
    // A bare number is grey, as in the scene format.
    constexpr explicit Rgb(float grey) : r(grey), g(grey), b(grey) {}
};

constexpr Rgb operator+(Rgb a, Rgb b) { return {a.r + b.r, a.g + b.g, a.b + b.b}; }
constexpr Rgb operator-(Rgb a, Rgb b) { return {a.r - b.r, a.g - b.g, a.b - b.b}; }
// Component-wise (Hadamard) product: filtering light by a surface color.
constexpr Rgb operator*(Rgb a, Rgb b) { return {a.r * b.r, a.g * b.g, a.b * b.b}; }
constexpr Rgb operator*(Rgb a, float s) { return {a.r * s, a.g * s, a.b * s}; }
constexpr Rgb operator*(float s, Rgb a) { return {s * a.r, s * a.g, s * a.b}; }
constexpr Rgb operator/(Rgb a, float s) { return {a.r / s, a.g / s, a.b / s}; }
constexpr Rgb& operator+=(Rgb& a, Rgb b) { return a = a + b; }
constexpr Rgb& operator*=(Rgb& a, Rgb b) { return a = a * b; }
constexpr bool operator==(Rgb a, Rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

constexpr float max_component(Rgb c) {
    const float m = c.r > c.g ? c.r : c.g;
    return m > c.b ? m : c.b;
}

// Linear interpolation a + (b - a) * t, the order both render paths use.
constexpr Rgb mix(Rgb a, Rgb b, float t) {
    return {a.r + (b.r - a.r) * t, a.g + (b.g - a.g) * t, a.b + (b.b - a.b) * t};
}

inline bool is_finite(Rgb c) {
    return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b);
}

}  // namespace octray
