#pragma once
// The fixture and helpers of the end-to-end tests of `octray render` as a batch renderer
// (batch_cli_test.cpp, batch_resume_cli_test.cpp): an animated scene, a directory per test
// with an out/ folder, its files and hidden temporaries, a shell in it, bit-exact image
// comparison.

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfOutputFile.h>
#include <ImfRationalAttribute.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "render/batch/claim_owner.h"
#include "render/batch/digest.h"
#include "render/image/image_read.h"
#include "run_octray.h"

namespace octray::testing {

namespace fs = std::filesystem;

// A ball rolling over a checkered floor while the camera moves: 6 frames at 24 fps.
inline constexpr const char* kAnimatedScene = R"({
  "image": {"width": 40, "height": 30},
  "camera": {"type": "pinhole", "eye": [0, 1.5, 5], "lookat": [0, 0.5, 0], "fov": 50},
  "background": {"type": "gradient", "bottom": [0.8, 0.85, 1.0], "top": [0.2, 0.4, 0.8]},
  "materials": {
    "floor": {"color": [0.8, 0.2, 0.1], "checker": {"color": [0.9, 0.9, 0.2], "size": 1}},
    "ball": {"color": [0.2, 0.6, 0.9], "ks": 0.4, "reflect": 0.3}
  },
  "objects": [
    {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "floor"},
    {"type": "sphere", "name": "ball", "center": [-1, 0.5, 0], "radius": 0.5, "material": "ball"}
  ],
  "lights": [{"type": "point", "position": [3, 6, 4]}],
  "animation": {"frames": 6, "fps": 24,
    "camera": [{"frame": 0, "eye": [0, 1.5, 5]}, {"frame": 5, "eye": [1, 2, 4.5]}],
    "objects": {"ball": [{"frame": 0, "center": [-1, 0.5, 0]}, {"frame": 5, "center": [1, 0.5, 0]}]}}
})";

inline bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

class BatchCliTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = fs::path(OCTRAY_TEST_TMPDIR) / "batch" /
               ::testing::UnitTest::GetInstance()->current_test_info()->name();
        fs::remove_all(dir_);
        fs::create_directories(dir_ / "out");
        std::ofstream(dir_ / "shot.json") << kAnimatedScene;
    }

    // Every file in `sub`, by name.
    std::set<std::string> files_in(const std::string& sub) const {
        std::set<std::string> names;
        for (const auto& entry : fs::directory_iterator(dir_ / sub))
            names.insert(entry.path().filename().string());
        return names;
    }

    // Hidden temporaries the atomic writer uses (".<name>.tmp.*").
    std::vector<std::string> temporaries(const std::string& sub) const {
        std::vector<std::string> found;
        for (const auto& name : files_in(sub))
            if (contains(name, ".tmp.")) found.push_back(name);
        return found;
    }

    Image read(const std::string& name) const { return read_image((dir_ / name).string()); }

    // Runs a shell command line in the test directory; returns its exit status.
    int shell(const std::string& command) const {
        const std::string line = "cd " + shell_quote(dir_.string()) + " || exit 99; " + command;
        const int status = std::system(line.c_str());
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }

    fs::path dir_;
};

inline void expect_same_pixels(const Image& a, const Image& b, const std::string& what) {
    ASSERT_EQ(a.width(), b.width()) << what;
    ASSERT_EQ(a.height(), b.height()) << what;
    ASSERT_EQ(a.channel_names(), b.channel_names()) << what;
    EXPECT_TRUE(a.channels == b.channels) << what << ": pixels differ";
}

}  // namespace octray::testing
