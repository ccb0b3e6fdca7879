#pragma once
// A ray P(t) = origin + t * direction, live on the open interval (t_min, t_max).

#include <limits>

#include "core/vec3.h"

namespace octray {

inline constexpr float kInfinity = std::numeric_limits<float>::infinity();

struct Ray {
    Vec3 origin;
    Vec3 direction;  // not necessarily unit length (shadow rays run to the light at t = 1)
    float t_min = 0.0f;
    float t_max = kInfinity;

    constexpr Vec3 at(float t) const { return origin + direction * t; }
    constexpr bool live(float t) const { return t > t_min && t < t_max; }
};

}  // namespace octray
