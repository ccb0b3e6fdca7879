#pragma once
// The scene the viewer's in-process tests serve: whitted, small enough to render at once.

#include "scene/builtin.h"
#include "scene/scene.h"

namespace octray::view::testing {

inline Scene small_whitted() {
    Scene scene = make_builtin_scene("whitted");
    scene.image.width = 64;
    scene.image.height = 36;
    scene.image.spp = 4;
    return scene;
}

}  // namespace octray::view::testing
