#pragma once
// `octray view`'s options (tools/cmd_view.cpp) and its body, which runs in octray-view
// (tools/own_executable.h, tools/view_run.cpp).

#include <string>
#include <vector>

namespace octray::tools {

struct ViewArguments {
    std::vector<std::string> inputs;  // SCENE, or A B (two images to compare)
    std::string bind{"127.0.0.1"};
    int port = 8090;
    int width = 0, height = 0, spp = 0, max_depth = 0;
    int threads = 0;
    int preview_divisor = 4;
    int frameless_block = 8;  // --frameless-block: side of the frameless order's blocks
    int bench = 0;            // orbit updates to measure; 0: serve
    std::string path{"simd"};
    std::string isa{"auto"};
    std::string order{"tiled"};
    std::string max_memory;  // empty: this machine's memory
};

// Serves the scene (or compares two images) until Ctrl-C, or measures (--bench).
void run_view(const ViewArguments& args);

}  // namespace octray::tools
