// The two JSON scene readers behind parse_scene_json (scene/README.md, "Two readers"): the
// fast one (simdjson) must build, for every valid file, the scene the diagnosing one
// (nlohmann) builds, bit for bit; on anything the diagnosing reader refuses it must
// decline, so that the message, with its line and column or JSON path, stays the
// diagnosing reader's.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scene/builtin.h"
#include "scene/load.h"
#include "scene_diff.h"

namespace octray {
namespace {

namespace fs = std::filesystem;

// The text with exactly kJsonPadding bytes after it, as read_scene_file leaves it.
std::optional<Scene> fast_in_place(std::string_view text, const std::string& source) {
    std::vector<char> padded(text.size() + kJsonPadding, '\0');
    std::copy(text.begin(), text.end(), padded.begin());
    return parse_scene_json_fast(std::string_view(padded.data(), text.size()), source,
                                 padded.size());
}

// Both readers take `text` and build the same scene; returns it.
Scene expect_same_scene(const std::string& text, const std::string& source) {
    Scene diagnosed;
    try {
        diagnosed = parse_scene_json_diagnosing(text, source);
    } catch (const SceneError& e) {
        ADD_FAILURE() << "the diagnosing reader refuses " << source << ": " << e.what();
        return diagnosed;
    }
    const std::optional<Scene> fast = fast_in_place(text, source);
    if (!fast) {
        ADD_FAILURE() << "the fast reader declines the valid " << source;
        return diagnosed;
    }
    EXPECT_EQ(fuzz::first_scene_difference(*fast, diagnosed), "") << source;
    // Without padding the fast reader copies the text; the scene is the same.
    const std::optional<Scene> copied = parse_scene_json_fast(text, source);
    EXPECT_TRUE(copied && fuzz::first_scene_difference(*copied, diagnosed).empty()) << source;
    EXPECT_EQ(fuzz::first_scene_difference(parse_scene_json(text, source), diagnosed), "");
    return diagnosed;
}

std::vector<fs::path> json_files_in(const fs::path& dir) {
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(dir)) {
        if (entry.path().extension() == ".json") files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    return files;
}

TEST(JsonReaders, AgreeOnEveryExampleAndGoldenScene) {
    const fs::path root = OCTRAY_SOURCE_DIR;
    std::vector<fs::path> files = json_files_in(root / "scene/examples");
    const std::vector<fs::path> golden = json_files_in(root / "tests/golden/scenes");
    files.insert(files.end(), golden.begin(), golden.end());
    ASSERT_GE(files.size(), 10u);
    for (const fs::path& file : files) {
        // As the loader reads a file: in place, in the padding read_scene_file leaves.
        const std::string text = read_scene_file(file.string());
        ASSERT_GE(text.capacity(), text.size() + kJsonPadding) << file;
        const std::optional<Scene> in_place =
            parse_scene_json_fast(text, file.string(), text.capacity());
        ASSERT_TRUE(in_place.has_value()) << file;
        const Scene diagnosed = expect_same_scene(text, file.string());
        EXPECT_EQ(fuzz::first_scene_difference(*in_place, diagnosed), "") << file;
        EXPECT_EQ(fuzz::first_scene_difference(load_scene_file(file.string()), diagnosed), "");
    }
}

TEST(JsonReaders, AgreeOnTheBuiltInsAsOctraySceneWritesThem) {
    for (const char* spec : {"whitted", "random:1000", "random:64,seed=7,width=33,spp=3",
                             "sphereflake:3", "sphereflake:0,max_depth=0"}) {
        const Scene built = make_builtin_scene(spec);
        const Scene read = expect_same_scene(scene_to_json(built), spec);
        EXPECT_EQ(fuzz::first_scene_difference(read, built), "") << spec;
    }
}

// Valid files in every form the format allows that a writer would not produce.
TEST(JsonReaders, AgreeOnUnusualButValidForms) {
    const std::string camera = R"("camera": {"eye": [0, 0, 5], "lookat": [0, 0, 0]})";
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"keys in any order: objects and animation before materials and the camera",
         R"({"animation": {"objects": {"b": [{"frame": 0, "radius": 2}]}, "frames": 3},
             "objects": [{"material": "m", "type": "sphere", "radius": 1,
                          "center": [0, 0, 0], "name": "b"},
                         {"radius": 1, "center": [3, 0, 0], "type": "sphere"},
                         {"type": "sphere", "center": [0, 3, 0], "radius": 1,
                          "material": {"kd": 0.5}},
                         {"type": "sphere", "center": [0, 3, 3], "radius": 1, "material": "m"}],
             "materials": {"m": {"color": 0.5}, "n": {}}, )" +
             camera + "}"},
        {"escaped keys, names and words",
         R"({"\u0063amera": {"eye": [0, 0, 5], "lookat": [0, 0, 0], "typ\u0065": "pinhol\u0065"},
             "materials": {"caf\u00e9 \"x\"": {"color": 0.5}},
             "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1,
                          "material": "caf\u00e9 \"x\"", "name": "\ud83d\ude00 a\\b\u0000c"}]})"},
        {"number forms: -0, integral floats, exponents, big integers as floats",
         R"({"image": {"width": 6.4e2, "height": 480.0, "spp": 1E0},
             "render": {"seed": 18446744073709551615, "max_depth": -0},
             "ambient": [-0, -0.0, 0e-5],
             "objects": [{"type": "sphere", "center": [1e-320, -1E+2, -9223372036854775809],
                          "radius": 0.100000000000000000000000000000000000000001},
                         {"type": "sphere", "center": [1e00000000000000000001, 0, 0],
                          "radius": 2.5e-00000000000000000000001}], )" +
             camera + "}"},
        {"a byte order mark and every kind of JSON whitespace",
         "\xEF\xBB\xBF\t{\r\n " + camera + " \n}\r\n\t "},
        {"a thinlens camera with a derived focus distance, a gradient, directional light",
         R"({"camera": {"type": "thinlens", "eye": [0, 1, 5], "lookat": [0, 0, 0],
                        "aperture": 0.1, "fov": 40},
             "background": {"top": 1, "type": "gradient", "bottom": [0, 0.5, 1]},
             "lights": [{"color": 2, "direction": [0, -1, 0], "type": "directional"},
                        {"type": "point", "position": [1, 2, 3], "falloff": "inverse-square"}],
             "objects": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 3, 4],
                          "material": {"checker": {"size": 2, "color": 0}}}]})"},
        {"a tiny fov stated in degrees (fov_units)",
         R"({"camera": {"fov_units": "degrees", "eye": [0, 0, 5], "lookat": [0, 0, 0],
                        "fov": 0.5, "type": "thinlens", "aperture": 0.1}})"},
        {"an orthographic camera with animated camera keys",
         R"({"camera": {"type": "orthographic", "eye": [0, 0, 5], "lookat": [0, 0, 0],
                        "width": 4, "up": [0, 1, 0]},
             "animation": {"frames": 10, "fps": 29.97,
                           "camera": [{"frame": 0, "eye": [0, 0, 5]},
                                      {"frame": 9, "lookat": [1, 0, 0], "up": [0, 1, 1]}]}})"},
    };
    for (const auto& [name, text] : cases) {
        SCOPED_TRACE(name);
        expect_same_scene(text, "valid.json");
    }
    // The forms read as nlohmann reads them: "-0" is the integer 0 (+0.0), "-0.0" is -0.0.
    const Scene s = parse_scene_json_fast(cases[2].second, "valid.json").value();
    EXPECT_FALSE(std::signbit(s.ambient.r));
    EXPECT_TRUE(std::signbit(s.ambient.g));
    EXPECT_EQ(s.image.width, 640);
    EXPECT_EQ(s.render.seed, 18446744073709551615u);
    EXPECT_EQ(s.objects[0].center.z, -9223372036854775809.0f);
    EXPECT_EQ(s.objects[1].center.x, 10.0f);
    EXPECT_TRUE(
        parse_scene_json_fast(cases[5].second, "valid.json").value().camera.fov_units_stated);
}

// Hostile input: the fast reader declines, and parse_scene_json gives the diagnosing
// reader's message, naming the file and the line and column or the JSON path.
struct Hostile {
    std::string name;
    std::string text;
    std::string path;                  // the error's JSON path ("" for syntax errors)
    std::vector<std::string> needles;  // in the message
};

std::string nested_path(std::string path, int depth) {
    for (int i = 0; i < depth; ++i) path += "[0]";
    return path;
}

std::vector<Hostile> hostile_inputs() {
    const std::string camera = R"("camera": {"eye": [0, 0, 5], "lookat": [0, 0, 0]})";
    const std::string sphere = R"({"type": "sphere", "center": [0, 0, 0], "radius": 1})";
    return {
        {"empty", "", "", {":1:1: invalid JSON"}},
        {"only a byte order mark", "\xEF\xBB\xBF", "", {":1:", "invalid JSON"}},
        {"trailing content", "{" + camera + "}\n x", "", {":2:2: "}},
        {"a second document", "{" + camera + "} {}", "", {":1:"}},
        {"trailing comma", "{" + camera + ",}", "", {":1:", "invalid JSON"}},
        {"a comment", "{" + camera + " // eye\n}", "", {":1:", "invalid JSON"}},
        {"fov_units other than degrees",
         R"({"camera": {"eye": [0, 0, 5], "lookat": [0, 0, 0], "fov_units": "radians"}})",
         "camera.fov_units",
         {"degrees"}},
        {"fov_units on an orthographic camera",
         R"({"camera": {"type": "orthographic", "eye": [0, 0, 5], "lookat": [0, 0, 0],
                        "fov_units": "degrees"}})",
         "camera.fov_units",
         {"fov_units"}},
        {"a NUL after the object",
         "{" + camera + "}\n\n" + std::string(1, '\0'),
         "",
         {":3:1: ", "NUL byte"}},
        {"invalid UTF-8 in a name",
         "{" + camera + R"(, "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1,
           "name": "a)" +
             "\xff" + R"("}]})",
         "",
         {":2:", "invalid JSON", "UTF-8"}},
        {"a lone low surrogate in a name",
         "{" + camera +
             R"(, "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "name": "\udc00"}]})",
         "",
         {":1:", "invalid JSON", "surrogate"}},
        {"a high surrogate without its low half",
         "{" + camera + R"(, "materials": {"\ud83d x": {}}})",
         "",
         {"surrogate"}},
        {"a raw control character in a string",
         "{" + camera + R"(, "objects": [{"type": "sph)" + "\t" + R"(ere"}]})",
         "",
         {":1:", "invalid JSON", "control character"}},
        {"a leading plus", "{" + camera + R"(, "ambient": +1})", "", {":1:", "invalid JSON"}},
        {"a leading zero", "{" + camera + R"(, "ambient": 01})", "", {":1:", "invalid JSON"}},
        {"a bare decimal point",
         "{" + camera + R"(, "ambient": 1.})",
         "",
         {":1:", "invalid JSON"}},
        {"NaN", "{" + camera + R"(, "ambient": NaN})", "", {":1:", "invalid JSON"}},
        {"a number overflowing double",
         "{" + camera + ",\n \"ambient\": [0, 1e999, 0]}",
         "ambient[1]",
         {"1e999", ":2:", "overflows to infinity"}},
        {"a number beyond float range",
         "{" + camera + R"(, "ambient": [0, 1e39, 0]})",
         "ambient[1]",
         {"within float range"}},
        {"a duplicate top-level key",
         "{" + camera + ", " + camera + "}",
         "camera",
         {"duplicate key \"camera\""}},
        {"a duplicate key written with an escape",
         R"({"camera": {"eye": [0, 0, 5], "lookat": [0, 0, 0], "\u0065ye": [1, 1, 1]}})",
         "camera.eye",
         {"duplicate key \"eye\""}},
        {"a duplicate material name",
         "{" + camera + R"(, "materials": {"m": {}, "n": {}, "m": {"kd": 1}}})",
         "materials.m",
         {"duplicate key \"m\""}},
        {"a duplicate animation track",
         "{" + camera + R"(, "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1,
           "name": "b"}], "animation": {"frames": 2, "objects": {"b": [], "b": []}}})",
         "animation.objects.b",
         {"duplicate key \"b\""}},
        {"an unknown key",
         "{" + camera + R"(, "objects": [{"type": "sphere", "center": [0, 0, 0],
           "radius": 1, "radius2": 1}]})",
         "objects[0].radius2",
         {"unknown key \"radius2\""}},
        {"a key of another type",
         "{" + camera + R"(, "objects": [{"type": "plane",
           "point": [0, 0, 0], "normal": [0, 1, 0], "radius": 1}]})",
         "objects[0].radius",
         {"applies only to spheres"}},
        {"a missing required key",
         R"({"camera": {"eye": [0, 0, 5]}})",
         "camera.lookat",
         {"missing required key \"lookat\""}},
        {"a string for a number",
         "{" + camera + R"(, "ambient": "0.5"})",
         "ambient",
         {"expected a color", "the string \"0.5\""}},
        {"a vector of four",
         "{" + camera + R"(, "objects": [{"type": "sphere",
           "center": [0, 0, 0, 0], "radius": 1}]})",
         "objects[0].center",
         {"expected an array of 3 numbers"}},
        {"a width of zero",
         "{" + camera + R"(, "image": {"width": 0}})",
         "image.width",
         {"expected an integer from 1 to 2147483647, found 0"}},
        {"a fractional width",
         "{" + camera + R"(, "image": {"width": 640.5}})",
         "image.width",
         {"found 640.5"}},
        {"a width beyond int",
         "{" + camera + R"(, "image": {"width": 2147483648}})",
         "image.width",
         {"found 2147483648"}},
        {"a negative seed",
         "{" + camera + R"(, "render": {"seed": -1}})",
         "render.seed",
         {"non-negative integer"}},
        {"a seed written as a float",
         "{" + camera + R"(, "render": {"seed": 1.0}})",
         "render.seed",
         {"without a fraction or exponent"}},
        {"a seed beyond 2^64",
         "{" + camera + R"(, "render": {"seed": 18446744073709551616}})",
         "render.seed",
         {"18446744073709551615"}},
        {"an unknown material",
         "{" + camera + R"(, "objects": [{"type": "sphere",
           "center": [0, 0, 0], "radius": 1, "material": "chrme"}],
           "materials": {"chrome": {}}})",
         "objects[0].material",
         {"unknown material \"chrme\"", "did you mean \"chrome\"?"}},
        {"an unknown animated object",
         "{" + camera + R"(, "objects": [)" + sphere +
             R"(], "animation": {"frames": 2, "objects": {"x": []}}})",
         "animation.objects.x",
         {"unknown object \"x\""}},
        {"a zero plane normal",
         "{" + camera + R"(, "objects": [{"type": "plane",
           "point": [0, 0, 0], "normal": [0, -0, 0]}]})",
         "objects[0].normal",
         {"non-zero normal"}},
        {"a negative radius, refused by validation",
         "{" + camera + R"(, "objects": [)" + sphere + R"(, {"type": "sphere",
           "center": [0, 0, 0], "radius": -1}]})",
         "objects[1].radius",
         {"expected a radius > 0, found -1"}},
        {"deep nesting under an unknown key",
         "{" + camera + R"(, "extra": )" + std::string(100, '[') + std::string(100, ']') + "}",
         nested_path("extra", 63),
         {"nesting deeper than 64"}},
        {"a top level array", "[" + camera.substr(10) + "]", "", {"expected a JSON object"}},
    };
}

TEST(JsonReaders, HostileInputKeepsTheDiagnosingMessage) {
    for (const Hostile& h : hostile_inputs()) {
        SCOPED_TRACE(h.name);
        EXPECT_FALSE(fast_in_place(h.text, "hostile.json").has_value());
        EXPECT_FALSE(parse_scene_json_fast(h.text, "hostile.json").has_value());
        std::string diagnosed;
        try {
            (void)parse_scene_json_diagnosing(h.text, "hostile.json");
            ADD_FAILURE() << "the diagnosing reader accepts it";
            continue;
        } catch (const SceneError& e) {
            diagnosed = e.what();
        }
        try {
            (void)parse_scene_json(h.text, "hostile.json");
            ADD_FAILURE() << "parse_scene_json accepts it";
        } catch (const SceneError& e) {
            const std::string what = e.what();
            EXPECT_EQ(what, diagnosed);
            EXPECT_EQ(e.file(), "hostile.json") << what;
            EXPECT_EQ(e.json_path(), h.path) << what;
            for (const std::string& needle : h.needles) {
                EXPECT_NE(what.find(needle), std::string::npos)
                    << "missing \"" << needle << "\" in: " << what;
            }
        }
    }
}

// The same through a file: read_scene_file's buffer, read in place.
TEST(JsonReaders, HostileFilesKeepTheDiagnosingMessage) {
    const fs::path dir = fs::path(OCTRAY_TEST_TMPDIR) / "json_readers";
    fs::create_directories(dir);
    const fs::path file = dir / "hostile.json";
    for (const Hostile& h : hostile_inputs()) {
        SCOPED_TRACE(h.name);
        {
            std::FILE* f = std::fopen(file.c_str(), "wb");
            ASSERT_NE(f, nullptr);
            ASSERT_EQ(std::fwrite(h.text.data(), 1, h.text.size(), f), h.text.size());
            std::fclose(f);
        }
        try {
            (void)load_scene_file(file.string());
            ADD_FAILURE() << "load_scene_file accepts it";
        } catch (const SceneError& e) {
            EXPECT_EQ(e.file(), file.string());
            EXPECT_EQ(e.json_path(), h.path) << e.what();
        }
    }
}

}  // namespace
}  // namespace octray
