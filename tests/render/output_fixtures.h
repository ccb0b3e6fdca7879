#pragma once
// Scenes and helpers for the batch-output tests (crops, progressive passes, AOVs, EXR
// windows, assembling): the golden scenes at a small size, bit-exact image comparison,
// and a per-test temporary directory.

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "core/image.h"
#include "render/crop.h"
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

// Bit-for-bit equality (RgbImage's == treats -0 as +0 and NaN as unequal).
inline bool same_bits(const RgbImage& a, const RgbImage& b) {
    return a.width() == b.width() && a.height() == b.height() &&
           std::memcmp(a.data(), b.data(), a.pixel_count() * sizeof(Rgb)) == 0;
}

// Pixels x0..x1, y0..y1 of `full` as their own image.
inline RgbImage sub_image(const RgbImage& full, const PixelRect& r) {
    RgbImage out(r.width(), r.height());
    for (int y = r.y0; y < r.y1; ++y)
        for (int x = r.x0; x < r.x1; ++x) out.at(x - r.x0, y - r.y0) = full.at(x, y);
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
