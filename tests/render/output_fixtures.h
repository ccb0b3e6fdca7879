#pragma once
// Scenes and helpers for the batch-output tests (crops, progressive passes, AOVs, EXR
// windows, assembling): the golden scenes at a small size, bit-exact image comparison,
// and a per-test temporary directory.

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "render/crop.h"
#include "render/image/image.h"
#include "render/packet_renderer.h"
#include "render/reference.h"
#include "scene/load.h"

namespace octray::testing {

// A golden feature scene (tests/golden/scenes/<name>.json) at width x height, with spp
// samples per pixel (0: the file's).
inline Scene golden_scene(const std::string& name, int width, int height, int spp = 0) {
    Scene s = load_scene_file(std::string(OCTRAY_SOURCE_DIR) + "/tests/golden/scenes/" + name +
                              ".json");
    s.image.width = width;
    s.image.height = height;
    if (spp > 0) s.image.spp = spp;
    validate_scene(s);
    return s;
}

enum class Path { reference, packet };
inline const char* path_name(Path p) { return p == Path::reference ? "reference" : "packet"; }

inline RenderResult render_with(Path path, const Scene& scene, const RenderOptions& options) {
    return path == Path::reference ? render_reference(scene, options)
                                   : render_packet(scene, options);
}

// Bit-for-bit equality of the samples of two images of one size, whatever their windows
// (float == would take -0 for +0 and NaN for unequal).
inline bool same_bits(const Image& a, const Image& b) {
    if (a.width() != b.width() || a.height() != b.height() ||
        a.channels.size() != b.channels.size())
        return false;
    for (std::size_t c = 0; c < a.channels.size(); ++c)
        if (!(a.channels[c] == b.channels[c])) return false;
    return true;
}

// Pixels x0..x1, y0..y1 of a render's image `full` as their own image (a crop's windows:
// data window r inside full's display window).
inline Image sub_image(const Image& full, const PixelRect& r) {
    Image out = make_rgb_image(r, full.display_window);
    for (int y = r.y0; y < r.y1; ++y)
        for (int x = r.x0; x < r.x1; ++x) set_rgb(out, x - r.x0, y - r.y0, rgb_at(full, x, y));
    return out;
}

// A fresh directory for one test's files.
inline std::filesystem::path test_dir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    const std::filesystem::path dir =
        std::filesystem::path(OCTRAY_TEST_TMPDIR) /
        (std::string(info->test_suite_name()) + "." + info->name());
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

}  // namespace octray::testing
