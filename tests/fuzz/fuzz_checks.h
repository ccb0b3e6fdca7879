#pragma once
// The invariants the fuzzers check, one function per reader of outside input. The
// libFuzzer targets (fuzz_*.cpp) call them on every input; tests/hardening replays the
// checked-in corpus (seeds and regression inputs) through the same functions, so a crash
// input kept in tests/fuzz/corpus/ stays a test in every ordinary build.
//
// Refusing bad input with the reader's own error type is success. A broken invariant
// throws InvariantBroken: in a fuzzer that escapes LLVMFuzzerTestOneInput, std::terminate
// aborts and libFuzzer keeps the input; in a GoogleTest it fails the test.

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "render/batch/memory_estimate.h"
#include "render/image/image_io.h"
#include "render/image/image_read.h"
#include "scene/builtin.h"
#include "scene/compile.h"
#include "scene/load.h"
#include "scene_diff.h"

namespace octray::fuzz {

class InvariantBroken : public std::logic_error {
  public:
    InvariantBroken(const std::string& invariant, const std::string& detail)
        : std::logic_error("invariant broken: " + invariant + ": " + detail) {}
};

// A scene that loaded must validate, survive scene_to_json -> parse_scene_json bit for
// bit, write the same text again, and be digestible by the memory estimate and
// compile_scene (the packet path's layout).
inline void check_loaded_scene(const Scene& scene) {
    try {
        validate_scene(scene);
    } catch (const SceneError& e) {
        throw InvariantBroken("a loaded scene passes validate_scene", e.what());
    }
    const std::string written = scene_to_json(scene);
    Scene back;
    try {
        back = parse_scene_json(written, "written.json");
    } catch (const SceneError& e) {
        throw InvariantBroken("scene_to_json output loads",
                              std::string(e.what()) + "\n" + written);
    }
    const std::string difference = first_scene_difference(scene, back);
    if (!difference.empty()) {
        throw InvariantBroken("the round trip is bit-identical", difference + "\n" + written);
    }
    if (scene_to_json(back) != written) {
        throw InvariantBroken("writing a read-back scene gives the same text", written);
    }
    // Saturating arithmetic: a signed overflow here would be a UBSan report.
    const batch::RenderMemoryEstimate estimate = batch::estimate_render_memory(scene);
    if (estimate.total < estimate.framebuffer) {
        throw InvariantBroken("the memory estimate covers the framebuffer",
                              estimate.describe());
    }
    if (scene.objects.size() <= (std::size_t{1} << 24)) {
        const CompiledScene compiled = compile_scene(scene);
        if (compiled.objects.count != scene.objects.size()) {
            throw InvariantBroken("compile_scene keeps every object",
                                  std::to_string(compiled.objects.count));
        }
    }
}

// parse_scene_json on arbitrary bytes: SceneError, or a scene passing check_loaded_scene.
// Its two readers must agree: the fast one (simdjson) gives a scene exactly when the
// diagnosing one (nlohmann) does, and the same scene bit for bit. The fast reader reads
// the bytes in place with exactly kJsonPadding bytes after them, as from a file, so ASan
// sees any read beyond its padding.
inline void check_scene_json(std::string_view text) {
    std::vector<char> padded(text.size() + kJsonPadding, '\0');
    std::copy(text.begin(), text.end(), padded.begin());
    const std::optional<Scene> fast = parse_scene_json_fast(
        std::string_view(padded.data(), text.size()), "fuzz.json", padded.size());
    Scene scene;
    try {
        scene = parse_scene_json_diagnosing(text, "fuzz.json");
    } catch (const SceneError& e) {
        // Refused with a located message: the expected outcome for most inputs.
        if (fast) {
            throw InvariantBroken("the fast reader refuses what the diagnosing reader refuses",
                                  e.what());
        }
        return;
    }
    if (!fast) {
        throw InvariantBroken("the fast reader accepts what the diagnosing reader accepts",
                              std::string(text.substr(0, 4096)));
    }
    const std::string difference = first_scene_difference(*fast, scene);
    if (!difference.empty()) {
        throw InvariantBroken("both readers build the same scene", difference);
    }
    check_loaded_scene(scene);
}

// The built-in generators accept up to 2^24 spheres (random:N) and level 7 (sphereflake,
// 5.4 million spheres): their documented limit, but up to 1.5 GB per input. Specs that are
// valid but would build more than kMaxFuzzSpheres spheres are skipped before generation;
// counts beyond the generators' limits are not, since refusing them quickly is what must
// be tested. 256 keeps an input under ~10 ms with ASan (at 4096 the fuzzer spent a whole
// 30-second CI run replaying its corpus).
inline constexpr std::uint64_t kMaxFuzzSpheres = 256;
inline constexpr std::uint64_t kMaxFuzzSphereflakeLevel = 2;  // 91 spheres

inline bool builtin_spec_too_big_to_fuzz(std::string_view spec) {
    const std::size_t colon = spec.find(':');
    if (colon == std::string_view::npos) return false;
    const std::string_view name = spec.substr(0, colon);
    if (name.find(',') != std::string_view::npos) return false;  // options before ':'
    std::string_view argument = spec.substr(colon + 1);
    argument = argument.substr(0, argument.find(','));
    std::uint64_t n = 0;
    const auto [end, ec] =
        std::from_chars(argument.data(), argument.data() + argument.size(), n);
    if (ec != std::errc{} || end != argument.data() + argument.size()) return false;
    if (name == "random") return n > kMaxFuzzSpheres && n <= (std::uint64_t{1} << 24);
    if (name == "sphereflake") return n > kMaxFuzzSphereflakeLevel && n <= 7;
    return false;
}

// make_builtin_scene on an arbitrary string: a SceneError naming the spec, or a scene
// passing check_loaded_scene. Returns false for a spec skipped as too big to fuzz.
inline bool check_builtin_spec(const std::string& spec) {
    if (builtin_spec_too_big_to_fuzz(spec)) return false;
    Scene scene;
    try {
        scene = make_builtin_scene(spec);
    } catch (const SceneError& e) {
        if (e.file() != spec) throw InvariantBroken("a spec error names the spec", e.what());
        return true;
    }
    if (!is_builtin_scene(spec)) throw InvariantBroken("only built-in names build", spec);
    if (scene.objects.size() > kMaxFuzzSpheres + 1) {  // + 1: sphereflake's floor
        throw InvariantBroken("the fuzz size cap holds",
                              std::to_string(scene.objects.size()) + " objects");
    }
    check_loaded_scene(scene);
    return true;
}

// A value OpenEXR can hold in a channel of `type`: any half for HALF (NaN and Inf
// included), a whole number in [0, 2^32] for UINT (a float rounds 2^32 - 1 up), anything for
// FLOAT.
inline bool fits_pixel_type(float v, PixelFormat type) {
    if (type == PixelFormat::float32 || std::isnan(v)) return true;
    if (type == PixelFormat::uint32)
        return v >= 0.0f && v <= 4294967296.0f && std::trunc(v) == v;  // 2^32 - 1 rounds up
    if (std::isinf(v)) return true;
    // half: 11 significant bits, exponents -24 (subnormal) to 15.
    if (v == 0.0f) return true;
    int exponent = 0;
    const float mantissa = std::frexp(std::fabs(v), &exponent);  // v = m 2^e, m in [0.5, 1)
    if (exponent > 16 || exponent < -23) return false;
    const int bits = std::min(11, exponent + 24);  // subnormals keep fewer
    const float scaled = std::ldexp(mantissa, bits);
    return std::trunc(scaled) == scaled;
}

// An image read from an OpenEXR file agrees with the file's header: the data window, the
// channels, the formats they were stored in, every value one that the declared type can
// hold, and (the check behind "files that lie") every chunk unpacking to the size the
// header implies.
inline void check_exr_read_matches_header(const std::string& path, const Image& image) {
    ExrLayout layout;
    try {
        layout = read_exr_layout(path);
        check_exr_pixel_data(path);
    } catch (const IoError& e) {
        throw InvariantBroken("an EXR that reads has chunks matching its header", e.what());
    }
    const PixelRect& window = layout.data_window;
    if (image.width() != window.x1 - window.x0 || image.height() != window.y1 - window.y0 ||
        image.data_window.x0 != window.x0 || image.data_window.y0 != window.y0)
        throw InvariantBroken("an EXR reads with its header's data window", image.file_format);
    if (static_cast<std::size_t>(image.channel_count()) != layout.channels.size())
        throw InvariantBroken("an EXR reads with its header's channels", image.file_format);
    for (const ExrChunkChannel& channel : layout.channels) {
        const int c = image.channel_index(channel.name);
        if (c < 0)
            throw InvariantBroken("an EXR reads with its header's channels", channel.name);
        const std::string type(to_string(channel.type));
        if (image.file_format.find(type) == std::string::npos)
            throw InvariantBroken("the format names every declared type", image.file_format);
        const float* plane = image.plane(c);
        for (std::size_t i = 0; i < image.pixel_count(); ++i)
            if (!fits_pixel_type(plane[i], channel.type))
                throw InvariantBroken(
                    "every value fits its declared type",
                    channel.name + " (" + type + "): " + std::to_string(plane[i]));
    }
}

// read_image on a file holding `bytes`: an IoError, or a consistent image.
inline void check_image_file(const std::string& path) {
    Image image;
    try {
        image = read_image(path);
    } catch (const IoError&) {
        return;
    }
    if (image.width() <= 0 || image.height() <= 0) {
        throw InvariantBroken("a read image has pixels", image.file_format);
    }
    if (image.channel_count() < 1)
        throw InvariantBroken("a read image has channels", image.file_format);
    std::size_t values = 0;
    for (const ImageChannel& c : image.channels)
        values += c.format == PixelFormat::float32 ? c.size() : 0;
    if (values != image.pixel_count() * image.channels.size()) {
        throw InvariantBroken("the planes hold every channel of every pixel",
                              image.file_format);
    }
    // Touch every value (ASan sees a short plane); PNG samples lie in [0, 1].
    const bool png = image.file_format.rfind("PNG", 0) == 0;
    for (const ImageChannel& c : image.channels)
        for (std::size_t k = 0; k < c.size(); ++k) {
            const float v = c.floats()[k];
            if (png && !(v >= 0.0f && v <= 1.0f)) {
                throw InvariantBroken("PNG samples lie in [0, 1]", image.file_format);
            }
        }
    if (!png) check_exr_read_matches_header(path, image);
}

// A private temporary file for the image fuzzer, made once per process, removed at exit.
inline const std::string& scratch_image_path() {
    static const std::string path = [] {
        const char* dir = std::getenv("TMPDIR");
        std::string templ = std::string(dir && *dir ? dir : "/tmp") + "/octray_fuzz_XXXXXX";
        const int fd = mkstemp(templ.data());
        if (fd < 0) throw std::runtime_error("mkstemp failed for " + templ);
        close(fd);
        std::atexit([] { std::remove(scratch_image_path().c_str()); });
        return templ;
    }();
    return path;
}

// read_image has no in-memory entry point, so the bytes go through a file.
inline void check_image_bytes(const std::uint8_t* data, std::size_t size) {
    const std::string& path = scratch_image_path();
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) throw std::runtime_error("cannot open " + path);
    const bool written = size == 0 || std::fwrite(data, 1, size, f) == size;
    std::fclose(f);
    if (!written) throw std::runtime_error("cannot write " + path);
    check_image_file(path);
}

}  // namespace octray::fuzz
