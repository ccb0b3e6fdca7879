#pragma once
// What both render paths take and give back.

#include <cstdint>

#include "core/image.h"

namespace octray {

struct RayCounts {
    std::uint64_t primary = 0;
    std::uint64_t shadow = 0;
    std::uint64_t reflected = 0;
    std::uint64_t refracted = 0;

    std::uint64_t total() const { return primary + shadow + reflected + refracted; }
    RayCounts& operator+=(const RayCounts& o) {
        primary += o.primary;
        shadow += o.shadow;
        reflected += o.reflected;
        refracted += o.refracted;
        return *this;
    }
};

struct RenderOptions {
    int threads = 0;           // 0: every core TBB sees
    std::uint32_t frame = 0;   // the frame counter of the random hash
    int tile_width = 16;
    int tile_height = 16;
};

struct RenderResult {
    Image image;
    RayCounts rays;
    double seconds = 0.0;  // wall-clock time of the render itself
};

}  // namespace octray
