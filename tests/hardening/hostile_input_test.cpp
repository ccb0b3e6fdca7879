// Hostile input to the scene readers: nesting 10000 deep, a 100 MB scene, 100 MB strings,
// huge names in the places that build "did you mean" suggestions, built-in specs asking
// for absurd sizes, and images over the memory limit. Each must fail with a SceneError
// whose message says what is wrong, without a stack overflow, and (measured where it
// matters) within bounded memory.

#include <gtest/gtest.h>
#include <pthread.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <string_view>

#include "render/batch/memory_estimate.h"
#include "scene/builtin.h"
#include "scene/load.h"
#include "scene/scene_error.h"

namespace octray {
namespace {

// Runs `body` on a thread with a 256 KiB stack: a parser that recursed once per nesting
// level would overflow it long before depth 10000.
void run_on_small_stack(const std::function<void()>& body) {
    pthread_attr_t attr;
    ASSERT_EQ(pthread_attr_init(&attr), 0);
    ASSERT_EQ(pthread_attr_setstacksize(&attr, 256 * 1024), 0);
    struct Call {
        const std::function<void()>* body;
    } call{&body};
    pthread_t thread;
    ASSERT_EQ(pthread_create(
                  &thread, &attr,
                  [](void* p) -> void* {
                      (*static_cast<Call*>(p)->body)();
                      return nullptr;
                  },
                  &call),
              0);
    pthread_join(thread, nullptr);
    pthread_attr_destroy(&attr);
}

// The message of the SceneError parsing `text` throws ("" if it loads).
std::string load_error(const std::string& text) {
    try {
        (void)parse_scene_json(text, "hostile.json");
    } catch (const SceneError& e) {
        return e.what();
    }
    return "";
}

// Resident set size now and at its peak since the last reset, in bytes (Linux).
std::int64_t status_kib(const char* field) {
    std::ifstream in("/proc/self/status");
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind(field, 0) == 0)
            return std::stoll(line.substr(std::string(field).size()));
    }
    return -1;
}
bool reset_peak_rss() {
    std::ofstream clear("/proc/self/clear_refs");
    clear << "5";  // resets VmHWM to the current RSS (Linux 4.0+)
    return static_cast<bool>(clear);
}
// Peak RSS growth while running `body`, in MiB; -1 when the kernel cannot tell.
double peak_rss_growth_mib(const std::function<void()>& body) {
    const bool can_reset = reset_peak_rss();
    const std::int64_t before = status_kib("VmRSS:");
    const std::int64_t hwm_before = status_kib("VmHWM:");
    body();
    const std::int64_t hwm = status_kib("VmHWM:");
    if (!can_reset || before < 0 || hwm < 0 || hwm_before > before + 1024) return -1.0;
    return static_cast<double>(hwm - before) / 1024.0;
}

const std::string kCamera = R"("camera": {"eye": [0, 0, 5], "lookat": [0, 0, 0]})";

TEST(HostileJson, NestingTenThousandDeepFailsAtTheCapOnASmallStack) {
    const int depth = 10000;
    const std::string arrays = std::string(depth, '[') + std::string(depth, ']');
    std::string objects;
    for (int i = 0; i < depth; ++i) objects += "{\"a\":";
    objects += "1" + std::string(depth, '}');
    std::string mixed = "{" + kCamera + ", \"objects\": ";
    for (int i = 0; i < depth; ++i) mixed += (i % 2 ? "{\"k\":" : "[");
    for (int i = depth - 1; i >= 0; --i) mixed += (i % 2 ? "}" : "]");
    mixed += "}";
    // Unterminated: the parser must stop at the cap, not at the end of the text.
    const std::string unterminated = std::string(depth, '[');

    const std::string* texts[] = {&arrays, &objects, &mixed, &unterminated};
    for (const std::string* text : texts) {
        std::string message;
        run_on_small_stack([&] { message = load_error(*text); });
        EXPECT_NE(message.find("nesting deeper than 64 levels"), std::string::npos) << message;
        EXPECT_EQ(message.rfind("hostile.json:", 0), 0u) << message;
        EXPECT_LT(message.size(), 400u) << message;
    }
}

// A 100 MB scene of 1.3 million spheres, its last sphere broken: refused with the path
// of the bad value, after a DOM of bounded size.
TEST(HostileJson, HundredMegabyteSceneFailsWithThePathOfItsLastObject) {
    const std::string sphere =
        R"({"type": "sphere", "center": [0.125, -3.5, 12.75], "radius": 0.25, "material": "m"},)"
        "\n";
    const std::size_t count = (100u << 20) / sphere.size();
    std::string text =
        "{" + kCamera + R"(, "materials": {"m": {"kd": 0.5}}, "objects": [)" + "\n";
    text.reserve(count * sphere.size() + 1024);
    for (std::size_t i = 0; i < count; ++i) text += sphere;
    text += R"({"type": "sphere", "center": [0, 0, 0], "radius": -1}]})";
    ASSERT_GT(text.size(), 100u << 20);

    std::string message;
    const double growth = peak_rss_growth_mib([&] { message = load_error(text); });
    EXPECT_NE(
        message.find("objects[" + std::to_string(count) + "].radius: expected a radius > 0"),
        std::string::npos)
        << message.substr(0, 300);
    std::printf("  100 MB scene (%zu spheres): peak RSS growth %.0f MiB\n", count + 1, growth);
    // The DOM (nlohmann ordered_json) costs about 12x the text; anything far beyond that
    // means a copy per object or a leak. -1: the kernel cannot reset the peak.
    if (growth >= 0) {
        EXPECT_LT(growth, 3000.0);
    }
}

// Issue 38: a sparse scene file (all NUL bytes, as `truncate -s 2G` makes one) was read
// whole before its first byte was reported. The reader stops at the first NUL: no chunk of
// the file reaches the caller's hash, and the error is where it is, line 1, column 1.
TEST(HostileJson, SparseSceneFileStopsAtItsFirstNulByte) {
    const std::string path =
        std::string(OCTRAY_TEST_TMPDIR) + "/sparse-" + std::to_string(::getpid()) + ".json";
    std::filesystem::create_directories(OCTRAY_TEST_TMPDIR);
    { std::ofstream create(path); }
    ASSERT_EQ(::truncate(path.c_str(), std::int64_t{256} << 20), 0);
    std::size_t bytes_read = 0;
    std::string message;
    try {
        read_scene_file(path, [&](std::string_view chunk) { bytes_read += chunk.size(); });
    } catch (const SceneError& e) {
        message = e.what();
    }
    std::remove(path.c_str());
    EXPECT_NE(message.find(":1:1: invalid JSON: a NUL byte"), std::string::npos) << message;
    EXPECT_EQ(bytes_read, 0u) << "the file was read past its first chunk";
}

// Strings of 100 MB where the loader quotes them or suggests a correction: the message
// must stay short and the work bounded (an edit distance against a 100 MB word would
// need an 8.8 GB table).
TEST(HostileJson, HundredMegabyteStringsGiveShortMessages) {
    const std::string huge(100u << 20, 'k');
    const std::string cases[] = {
        "{" + kCamera + ", \"" + huge + "\": 1}",                         // unknown key
        "{" + kCamera + R"(, "background": {"type": ")" + huge + "\"}}",  // bad word
        "{" + kCamera +
            R"(, "objects": [{"type": "sphere", "center": [0,0,0], "radius": 1, )"
            R"("material": ")" +
            huge + "\"}]}",  // unknown name
        "\"" + huge + "\"",  // top level
    };
    for (const std::string& text : cases) {
        std::string message;
        const double growth = peak_rss_growth_mib([&] { message = load_error(text); });
        ASSERT_FALSE(message.empty());
        EXPECT_LT(message.size(), 1000u) << message.substr(0, 300);
        if (growth >= 0) {
            EXPECT_LT(growth, 1500.0) << message.substr(0, 300);
        }
    }
}

// Two long names one typo apart: the suggestion's edit distance must not build a
// (60 KB)^2 table (28 GB) for a 120 KB file.
TEST(HostileJson, LongMaterialNamesDoNotMakeSuggestionsQuadratic) {
    const std::string name(60000, 'm');
    const std::string typo = name.substr(1) + "n";
    const std::string text = "{" + kCamera + R"(, "materials": {")" + name +
                             R"(": {}}, "objects": [{"type": "sphere", "center": [0,0,0], )"
                             R"("radius": 1, "material": ")" +
                             typo + "\"}]}";
    std::string message;
    const auto start = std::chrono::steady_clock::now();
    const double growth = peak_rss_growth_mib([&] { message = load_error(text); });
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_NE(message.find("objects[0].material: unknown material"), std::string::npos)
        << message.substr(0, 300);
    EXPECT_LT(message.size(), 1000u);
    std::printf("  60 KB material names: %.3f s, peak RSS growth %.0f MiB\n", seconds, growth);
    if (growth >= 0) {
        EXPECT_LT(growth, 200.0);
    }
}

TEST(HostileSpec, AbsurdSizesAreRefusedBeforeAnythingIsGenerated) {
    const struct {
        const char* spec;
        const char* expected;
    } cases[] = {
        {"random:1000000000", "expected random:N with N a sphere count from 1 to 16777216"},
        {"random:16777217", "from 1 to 16777216"},
        {"random:99999999999999999999999", "from 1 to 16777216"},
        {"random:0", "from 1 to 16777216"},
        {"sphereflake:8", "a recursion level from 0 to 7"},
        {"sphereflake:2147483648", "a recursion level from 0 to 7"},
        {"whitted,width=2147483648", "expected an integer from 1 to 2147483647"},
        {"whitted,max_depth=65", "expected an integer from 0 to 64"},
        {"whitted,width=2147483647,height=2147483647", "expected at most 2147483647"},
    };
    for (const auto& c : cases) {
        try {
            (void)make_builtin_scene(c.spec);
            ADD_FAILURE() << c.spec << " was accepted";
        } catch (const SceneError& e) {
            EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos)
                << c.spec << ": " << e.what();
            EXPECT_EQ(e.file(), c.spec);
        }
    }
}

std::int64_t physical_memory() {
    return static_cast<std::int64_t>(sysconf(_SC_PHYS_PAGES)) * sysconf(_SC_PAGE_SIZE);
}

// A framebuffer larger than physical memory: the scene is valid (whether it fits depends on
// the machine), and the render command's check (check_memory_limit at its default limit,
// the machine's memory) refuses it with the framebuffer's size in the message. Only
// described, never allocated.
TEST(HostileImageSize, FramebufferOverPhysicalMemoryIsRefusedUpFront) {
    const std::int64_t memory = physical_memory();
    // The largest image the pixel cap allows: 46340 x 46340 = 2147395600 pixels, 24 GiB.
    const std::int64_t bytes = std::int64_t{46340} * 46340 * 12;
    if (memory <= 0 || bytes <= memory)
        GTEST_SKIP() << "this machine has more memory than that";
    const Scene s = make_builtin_scene("whitted,width=46340,height=46340");
    try {
        batch::check_memory_limit(s, static_cast<std::uint64_t>(memory));
        FAIL() << "a 24 GiB framebuffer was accepted";
    } catch (const SceneError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("46340 x 46340 image at"), std::string::npos) << what;
        EXPECT_NE(what.find("framebuffer 24.0 GiB"), std::string::npos) << what;
        EXPECT_NE(what.find("expected at most the memory limit of"), std::string::npos) << what;
    }
}

// The --max-memory check on a scene that validate_scene accepts.
TEST(HostileImageSize, RenderOverTheMemoryLimitIsRefusedWithTheEstimate) {
    const Scene s = make_builtin_scene("whitted,width=30000,height=20000,spp=4");
    try {
        batch::check_memory_limit(s, std::uint64_t{2} << 30);
        FAIL() << "a 30000 x 20000 render fits in 2 GiB?";
    } catch (const SceneError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("30000 x 20000 image at 4 spp needs about"), std::string::npos)
            << what;
        EXPECT_NE(what.find("framebuffer 6.7 GiB"), std::string::npos) << what;
        EXPECT_NE(what.find("memory limit of 2.0 GiB"), std::string::npos) << what;
    }
}

}  // namespace
}  // namespace octray
