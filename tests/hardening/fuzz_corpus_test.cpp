// The fuzz corpus (tests/fuzz/corpus/<target>/: hand-made seeds, the fuzzers' minimised
// finds named by SHA-1, and any crash input kept as regress-*) replayed through the fuzzers'
// own invariant checks (tests/fuzz/fuzz_checks.h), so every kept input stays a test in ordinary
// builds, with or without clang and libFuzzer.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz_checks.h"

namespace octray {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> corpus(const std::string& target) {
    const fs::path dir = fs::path(OCTRAY_SOURCE_DIR) / "tests" / "fuzz" / "corpus" / target;
    std::vector<fs::path> files;
    for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
        if (e.is_regular_file()) files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    return files;
}

std::string read_bytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(FuzzCorpus, SceneJsonInputsKeepTheLoaderInvariants) {
    const std::vector<fs::path> files = corpus("fuzz_scene_json");
    ASSERT_GE(files.size(), 5u);
    for (const fs::path& f : files) {
        SCOPED_TRACE(f.filename().string());
        EXPECT_NO_THROW(fuzz::check_scene_json(read_bytes(f)));
    }
}

TEST(FuzzCorpus, EverySceneJsonSeedLoads) {
    // The hand-written seeds (*.json; the fuzzers' own finds are named by their SHA-1)
    // are there to steer the fuzzer into valid scenes; one that stopped loading would
    // silently make the fuzzer weaker.
    for (const fs::path& f : corpus("fuzz_scene_json")) {
        if (f.extension() != ".json") continue;
        SCOPED_TRACE(f.filename().string());
        EXPECT_NO_THROW((void)parse_scene_json(read_bytes(f), f.string()));
    }
}

TEST(FuzzCorpus, BuiltinSpecInputsKeepTheGeneratorInvariants) {
    const std::vector<fs::path> files = corpus("fuzz_builtin_spec");
    ASSERT_GE(files.size(), 5u);
    for (const fs::path& f : files) {
        SCOPED_TRACE(f.filename().string());
        EXPECT_NO_THROW((void)fuzz::check_builtin_spec(read_bytes(f)));
    }
}

TEST(FuzzCorpus, ImageInputsReadOrFailWithAnIoError) {
    const std::vector<fs::path> files = corpus("fuzz_image_read");
    ASSERT_GE(files.size(), 5u);
    for (const fs::path& f : files) {
        SCOPED_TRACE(f.filename().string());
        EXPECT_NO_THROW(fuzz::check_image_file(f.string()));
    }
}

TEST(FuzzCorpus, EveryImageSeedReads) {
    for (const fs::path& f : corpus("fuzz_image_read")) {
        if (f.extension() != ".exr" && f.extension() != ".png") continue;  // seeds only
        const std::string name = f.filename().string();
        if (name.rfind("lie_", 0) == 0 || name.rfind("cut_", 0) == 0) continue;
        SCOPED_TRACE(name);
        const Image image = read_image(f.string());
        EXPECT_GT(image.pixel_count(), 0u);
    }
}

// The seeds that lie (a header declaring other pixel types than the data, a chunk cut
// short: tests/image/lying_exr.h) are file errors naming the file, for every codec.
TEST(FuzzCorpus, EveryLyingImageSeedIsAFileError) {
    int lying = 0;
    for (const fs::path& f : corpus("fuzz_image_read")) {
        const std::string name = f.filename().string();
        if (name.rfind("lie_", 0) != 0 && name.rfind("cut_", 0) != 0) continue;
        SCOPED_TRACE(name);
        ++lying;
        try {
            read_image(f.string());
            ADD_FAILURE() << "read";
        } catch (const IoError& e) {
            EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
        }
    }
    EXPECT_GE(lying, 28);
}

// The resource cap of the spec fuzzer skips exactly the valid-but-big specs.
TEST(FuzzCorpus, SpecFuzzerSkipsOnlyValidButBigScenes) {
    EXPECT_TRUE(fuzz::builtin_spec_too_big_to_fuzz("random:257"));
    EXPECT_TRUE(fuzz::builtin_spec_too_big_to_fuzz("random:16777216,width=2"));
    EXPECT_TRUE(fuzz::builtin_spec_too_big_to_fuzz("sphereflake:3"));
    EXPECT_TRUE(fuzz::builtin_spec_too_big_to_fuzz("sphereflake:7"));
    EXPECT_FALSE(fuzz::builtin_spec_too_big_to_fuzz("random:256"));
    EXPECT_FALSE(fuzz::builtin_spec_too_big_to_fuzz("sphereflake:2"));
    EXPECT_FALSE(fuzz::builtin_spec_too_big_to_fuzz("random:16777217"));  // refused: test it
    EXPECT_FALSE(fuzz::builtin_spec_too_big_to_fuzz("sphereflake:8"));
    EXPECT_FALSE(fuzz::builtin_spec_too_big_to_fuzz("random:x"));
    EXPECT_FALSE(fuzz::builtin_spec_too_big_to_fuzz("whitted"));
}

}  // namespace
}  // namespace octray
