// The `--accel` choice (render/accel.h): names, and `auto` resolved by sphere count.

#include "render/accel.h"

namespace octray {

const char* accel_name(Accel accel) {
    switch (accel) {
        case Accel::automatic:
            return "auto";
        case Accel::bvh:
            return "bvh";
        case Accel::none:
            return "none";
    }
    return "?";
}

std::optional<Accel> parse_accel(std::string_view name) {
    for (Accel a : {Accel::automatic, Accel::bvh, Accel::none})
        if (name == accel_name(a)) return a;
    return std::nullopt;
}

bool accel_uses_bvh(Accel accel, std::uint32_t sphere_count) {
    switch (accel) {
        case Accel::automatic:
            return sphere_count >= kBvhAutoMinSpheres;
        case Accel::bvh:
            return sphere_count > 0;
        case Accel::none:
            return false;
    }
    return false;
}

}  // namespace octray
