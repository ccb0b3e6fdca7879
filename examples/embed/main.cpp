// Renders a scene built in code with octray's public API and writes it as OpenEXR.
//   embed OUT.exr [OUT.json]
// With OUT.json it also writes the scene, so that `octray render OUT.json` can check that
// the command line renders the same image (tests/install/run.sh does).

#include <octray/octray.h>

#include <cstdio>
#include <fstream>

namespace api = octray::api;

int main(int argc, char** argv) {
    if (argc < 2 || argc > 3) {
        std::fprintf(stderr, "usage: embed OUT.exr [OUT.json]\n");
        return 2;
    }
    try {
        api::Scene scene;
        scene.set_image(320, 180, 4);
        scene.set_camera(
            {.eye = {0.0f, 1.5f, 6.0f}, .lookat = {0.0f, 0.8f, 0.0f}, .fov = 45.0f});
        scene.set_background({1.0f, 1.0f, 1.0f}, {0.4f, 0.6f, 1.0f});
        scene.set_ambient({0.05f, 0.05f, 0.05f});

        const auto floor = scene.add_material(
            {.color = {0.9f, 0.9f, 0.9f}, .checker = true, .checker_color = {0.1f, 0.1f, 0.1f}},
            "floor");
        const auto mirror = scene.add_material({.color = {0.9f, 0.9f, 0.9f},
                                                .kd = 0.1f,
                                                .ks = 0.5f,
                                                .shininess = 64.0f,
                                                .reflect = {0.8f, 0.8f, 0.8f}},
                                               "mirror");
        const auto red = scene.add_material({.color = {0.8f, 0.2f, 0.1f}, .ks = 0.3f}, "red");

        scene.add_plane({0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, floor);
        scene.add_sphere({-1.1f, 1.0f, 0.0f}, 1.0f, mirror);
        scene.add_sphere({1.2f, 0.7f, 0.5f}, 0.7f, red);
        scene.add_point_light({5.0f, 8.0f, 5.0f}, {1.0f, 1.0f, 1.0f});

        const api::RenderResult result = api::render(scene, {.threads = 2});
        api::write_exr(argv[1], result.image, {.float32 = true});
        if (argc == 3) std::ofstream(argv[2]) << scene.to_json();

        // Read the file back: what was written is what was rendered, bit for bit.
        const api::CompareResult check = api::compare(result.image, api::read_image(argv[1]));
        std::printf("octray %s, %s path: %dx%d, %llu rays in %.3f s; wrote %s (%s)\n",
                    api::version(), result.path.c_str(), result.image.width,
                    result.image.height, static_cast<unsigned long long>(result.rays.total()),
                    result.seconds, argv[1], check.reason.c_str());
        return check.verdict == api::Verdict::pass ? 0 : 1;
    } catch (const api::Error& e) {
        std::fprintf(stderr, "embed: %s\n", e.what());
        return 1;
    }
}
