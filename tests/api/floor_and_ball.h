#pragma once
// The API tests' small scene of outputs: a checkered floor (object 1) and a red ball named
// "ball" (object 2) under one point light, seen from the front, so that every AOV has hits
// and misses.

#include "octray/octray.h"

namespace octray::api::testing {

inline Scene floor_and_ball(int width, int height, int spp) {
    Scene scene;
    scene.set_image(width, height, spp)
        .set_camera({.eye = {0.0f, 1.5f, 6.0f}, .lookat = {0.0f, 0.8f, 0.0f}, .fov = 45.0f});
    const auto floor = scene.add_material(
        {.color = {0.9f, 0.9f, 0.9f}, .checker = true, .checker_color = {0.1f, 0.1f, 0.1f}});
    const auto ball = scene.add_material({.color = {0.8f, 0.2f, 0.1f}, .ks = 0.4f});
    scene.add_plane({0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, floor);
    scene.add_sphere({0.0f, 1.0f, 0.0f}, 1.0f, ball, "ball");
    scene.add_point_light({5.0f, 8.0f, 5.0f}, {1.0f, 1.0f, 1.0f});
    return scene;
}

}  // namespace octray::api::testing
