// `octray render`: load a scene, apply command-line overrides, render, write EXR (+ PNG).

#include <CLI/CLI.hpp>
#include <oneapi/tbb/global_control.h>

#include <cctype>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>

#include "core/version.h"
#include "kernels/dispatch.h"
#include "render/image_io.h"
#include "render/packet_renderer.h"
#include "render/reference.h"
#include "render/types.h"
#include "scene/builtin.h"
#include "scene/load.h"
#include "scene/scene.h"
#include "scene/scene_error.h"
#include "tools/commands.h"

namespace octray::tools {
namespace {

namespace fs = std::filesystem;

// ---- Render paths: the one place that knows which renderers exist -----------------------

enum class RenderPath { scalar, simd };

// What `octray render` uses without --path.
constexpr RenderPath kDefaultRenderPath = RenderPath::simd;

std::string_view to_string(RenderPath path) {
    return path == RenderPath::scalar ? "scalar" : "simd";
}

using Renderer = std::function<RenderResult(const Scene&, const RenderOptions&)>;

// Chosen before the scene is loaded, so an unavailable path (or an ISA this CPU lacks)
// fails at once. `isa` is already resolved for the simd path.
Renderer select_renderer(RenderPath path, Isa isa) {
    switch (path) {
        case RenderPath::scalar: return [](const Scene& scene, const RenderOptions& options) {
            return render_reference(scene, options);
        };
        case RenderPath::simd: return [isa](const Scene& scene, const RenderOptions& options) {
            return render_packet(scene, options, isa);
        };
    }
    throw UsageError("unknown render path");
}

// ---- Options ---------------------------------------------------------------------------

struct RenderArguments {
    std::string scene = "whitted";
    std::string output;  // empty: <scene name>.exr in the current directory
    int width = 0, height = 0, spp = 0, max_depth = 0;
    std::uint64_t seed = 0;
    int threads = 0;
    std::string path{to_string(kDefaultRenderPath)};
    std::string isa = "auto";
    std::string png;
    bool float32 = false;
    std::string compression{to_string(ExrWriteOptions{}.compression)};
    std::string tile = "16x16";
    // Set only when the user gave the option, so the scene's own value stays otherwise.
    CLI::Option* width_option = nullptr;
    CLI::Option* height_option = nullptr;
    CLI::Option* spp_option = nullptr;
    CLI::Option* max_depth_option = nullptr;
    CLI::Option* seed_option = nullptr;
};

struct TileSize {
    int width = 0, height = 0;
};

// "WxH", or "N" for a square tile; both sides in [1, 4096].
std::optional<TileSize> parse_tile(const std::string& text) {
    auto parse_side = [](std::string_view s) -> std::optional<int> {
        int value = 0;
        const auto [end, error] = std::from_chars(s.data(), s.data() + s.size(), value);
        if (error != std::errc() || end != s.data() + s.size() || value < 1 || value > 4096)
            return std::nullopt;
        return value;
    };
    const std::size_t x = text.find_first_of("xX");
    if (x == std::string::npos) {
        const auto side = parse_side(text);
        if (!side) return std::nullopt;
        return TileSize{*side, *side};
    }
    const auto w = parse_side(std::string_view(text).substr(0, x));
    const auto h = parse_side(std::string_view(text).substr(x + 1));
    if (!w || !h) return std::nullopt;
    return TileSize{*w, *h};
}

// The default output name: "whitted" -> whitted.exr, "random:8,width=32" -> random-8.exr,
// "scenes/room.json" -> room.exr (always in the current directory).
std::string default_output_name(const std::string& spec) {
    std::string stem;
    if (is_builtin_scene(spec)) {
        stem = spec.substr(0, spec.find(','));
        const std::size_t colon = stem.find(':');
        if (colon != std::string::npos) stem[colon] = '-';
    } else {
        stem = fs::path(spec).stem().string();
    }
    for (char& c : stem) {
        const auto u = static_cast<unsigned char>(c);
        if (!std::isalnum(u) && c != '-' && c != '_' && c != '.') c = '_';
    }
    if (stem.empty() || stem == "." || stem == "..") stem = "render";
    return stem + ".exr";
}

// Fails before the render when an output clearly cannot be written, rather than after
// minutes of rendering. (The write itself still reports anything this misses.)
void check_output_location(const std::string& path) {
    fs::path dir = fs::path(path).parent_path();
    if (dir.empty()) dir = ".";
    std::error_code error;
    if (!fs::is_directory(dir, error))
        throw IoError("cannot write " + path + ": directory " + dir.string() +
                      " does not exist");
    if (fs::is_directory(path, error))
        throw IoError("cannot write " + path + ": it is a directory");
}

// EXR's capDate convention: "YYYY:MM:DD HH:MM:SS" in local time, with utcOffset holding
// UTC minus local time in seconds.
std::pair<std::string, float> capture_date() {
    const std::time_t now = std::time(nullptr);
    std::tm local{};
    localtime_r(&now, &local);
    char text[32];
    std::strftime(text, sizeof text, "%Y:%m:%d %H:%M:%S", &local);
    return {text, static_cast<float>(-local.tm_gmtoff)};
}

std::string describe_counts(const RayCounts& rays) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "%llu (primary %llu, shadow %llu, reflected %llu, refracted %llu)",
                  static_cast<unsigned long long>(rays.total()),
                  static_cast<unsigned long long>(rays.primary),
                  static_cast<unsigned long long>(rays.shadow),
                  static_cast<unsigned long long>(rays.reflected),
                  static_cast<unsigned long long>(rays.refracted));
    return text;
}

void run_render(const RenderArguments& args) {
    // Everything about the command line first: no render time is spent on a bad one.
    const RenderPath path = args.path == "simd" ? RenderPath::simd : RenderPath::scalar;
    Isa isa = Isa::automatic;
    if (path == RenderPath::simd) {
        try {
            isa = resolve_isa(parse_isa(args.isa).value_or(Isa::automatic));
        } catch (const std::runtime_error& e) {
            throw UsageError(std::string("--isa: ") + e.what());
        }
    }
    const Renderer render = select_renderer(path, isa);
    const auto tile = parse_tile(args.tile);
    if (!tile) throw UsageError("--tile: expected WxH, e.g. 16x16");
    const auto compression = parse_exr_compression(args.compression);
    if (!compression) throw UsageError("--compression: unknown codec " + args.compression);
    const std::string output = args.output.empty() ? default_output_name(args.scene) : args.output;
    if (!args.png.empty() && fs::path(args.png) == fs::path(output))
        throw UsageError("-o and --png name the same file: " + output);
    check_output_location(output);
    if (!args.png.empty()) check_output_location(args.png);

    Scene scene = load_scene(args.scene);
    const bool overridden = args.width_option->count() || args.height_option->count() ||
                            args.spp_option->count() || args.max_depth_option->count() ||
                            args.seed_option->count();
    if (args.width_option->count()) scene.image.width = args.width;
    if (args.height_option->count()) scene.image.height = args.height;
    if (args.spp_option->count()) scene.image.spp = args.spp;
    if (args.max_depth_option->count()) scene.render.max_depth = args.max_depth;
    if (args.seed_option->count()) scene.render.seed = args.seed;
    if (overridden) {
        // The scene itself was valid when loaded, so a failure now is the overrides' fault.
        try {
            validate_scene(scene);
        } catch (const SceneError& e) {
            throw UsageError(std::string("the options make the scene invalid: ") + e.what());
        }
    }

    // Limit TBB for the whole process; 0 keeps its default (every core it may use).
    std::optional<tbb::global_control> thread_limit;
    if (args.threads > 0)
        thread_limit.emplace(tbb::global_control::max_allowed_parallelism,
                             static_cast<std::size_t>(args.threads));
    const std::size_t threads =
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);

    RenderOptions options;
    options.threads = args.threads;
    options.tile_width = tile->width;
    options.tile_height = tile->height;

    std::printf("scene    %s (%zu objects, %zu lights)\n", args.scene.c_str(),
                scene.objects.size(), scene.lights.size());
    std::printf("image    %dx%d, %d spp, max depth %d, seed %llu\n", scene.image.width,
                scene.image.height, scene.image.spp, scene.render.max_depth,
                static_cast<unsigned long long>(scene.render.seed));
    const std::string path_name =
        path == RenderPath::simd ? args.path + " (" + isa_name(isa) + ")" : args.path;
    std::printf("render   %s path, %zu threads, %dx%d tiles\n", path_name.c_str(), threads,
                tile->width, tile->height);
    std::fflush(stdout);

    const RenderResult result = render(scene, options);

    const double mrays_per_second =
        result.seconds > 0.0 ? static_cast<double>(result.rays.total()) / result.seconds / 1e6
                             : 0.0;
    std::printf("time     %.3f s\n", result.seconds);
    std::printf("rays     %s\n", describe_counts(result.rays).c_str());
    std::printf("rate     %.2f Mrays/s\n", mrays_per_second);

    const auto [date, utc_offset] = capture_date();
    ExrAttributes attributes;
    attributes.strings = {
        {"software", std::string("octray ") + kVersion},
        {"capDate", date},
        {"octray.scene", args.scene},
        {"octray.path", path_name},
        // A string keeps all 64 bits of the seed.
        {"octray.seed", std::to_string(scene.render.seed)},
    };
    attributes.floats = {{"utcOffset", utc_offset}};
    attributes.ints = {
        {"samplesPerPixel", scene.image.spp},
        {"octray.maxDepth", scene.render.max_depth},
    };
    // Ray counts are 64-bit; a double holds them exactly up to 2^53 (9e15 rays).
    attributes.doubles = {
        {"renderTimeSeconds", result.seconds},
        {"octray.rays.primary", static_cast<double>(result.rays.primary)},
        {"octray.rays.shadow", static_cast<double>(result.rays.shadow)},
        {"octray.rays.reflected", static_cast<double>(result.rays.reflected)},
        {"octray.rays.refracted", static_cast<double>(result.rays.refracted)},
        {"octray.rays.total", static_cast<double>(result.rays.total())},
    };
    write_exr(output, result.image, {args.float32, *compression}, attributes);
    std::printf("wrote    %s (%s, %s)\n", output.c_str(), args.float32 ? "float" : "half",
                args.compression.c_str());
    if (!args.png.empty()) {
        write_png_preview(args.png, result.image);
        std::printf("wrote    %s (8-bit sRGB preview)\n", args.png.c_str());
    }
}

// A validator whose range or set is already spelled out in the option's help text, so
// CLI11 does not append it to the type name a second time.
CLI::Validator quiet(CLI::Validator validator) { return validator.description(""); }

}  // namespace

void add_render_command(CLI::App& app, CommandRunner& run) {
    auto args = std::make_shared<RenderArguments>();
    CLI::App* cmd = app.add_subcommand("render", "Render a scene to an OpenEXR image");

    cmd->add_option("scene", args->scene,
                    "Scene: a JSON file or a built-in (whitted, random:N, sphereflake:L, each\n"
                    "with optional ,width=W,height=H,spp=N,seed=S,max_depth=D)")
        ->type_name("SCENE")
        ->capture_default_str();
    cmd->add_option("-o,--output", args->output,
                    "Output EXR file [default: <scene name>.exr in the current directory,\n"
                    "e.g. whitted.exr, random-8.exr, room.exr for scenes/room.json]")
        ->type_name("FILE");
    args->width_option =
        cmd->add_option("--width", args->width, "Image width in pixels, 1..65536 (overrides the scene)")
            ->type_name("W")
            ->check(quiet(CLI::Range(1, 65536)));
    args->height_option =
        cmd->add_option("--height", args->height,
                        "Image height in pixels, 1..65536 (overrides the scene)")
            ->type_name("H")
            ->check(quiet(CLI::Range(1, 65536)));
    args->spp_option =
        cmd->add_option("--spp", args->spp,
                        "Samples per pixel, 1..2^20; square counts are stratified, others\n"
                        "jittered (overrides the scene)")
            ->type_name("N")
            ->check(quiet(CLI::Range(1, 1 << 20)));
    args->max_depth_option =
        cmd->add_option("--max-depth", args->max_depth,
                        "Reflection/refraction bounces, 0..1000; 0 = primary rays only\n"
                        "(overrides the scene)")
            ->type_name("D")
            ->check(quiet(CLI::Range(0, 1000)));
    args->seed_option =
        cmd->add_option("--seed", args->seed,
                        "Seed of the sample jitter, 0..2^64-1 (overrides the scene)")
            ->type_name("S")
            // CLI11 would wrap a negative number around into a huge unsigned one.
            ->check([](const std::string& text) {
                return text.find('-') == std::string::npos ? std::string()
                                                           : "the seed cannot be negative";
            });
    cmd->add_option("--threads", args->threads,
                    "Worker threads, 0..4096; 0 = every core available (the image does not\n"
                    "depend on it)")
        ->type_name("N")
        ->check(quiet(CLI::Range(0, 4096)))
        ->capture_default_str();
    cmd->add_option("--path", args->path,
                    "Render path: simd (8-ray packets) or scalar (the reference renderer);\n"
                    "both give the same image")
        ->type_name("PATH")
        ->check(quiet(CLI::IsMember({"scalar", "simd"})))
        ->capture_default_str();
    cmd->add_option("--isa", args->isa,
                    "Instruction set of the simd path: auto (the best this CPU has), avx2,\n"
                    "sse4.1 or sse2 (`octray info` lists them; the image does not depend on it)")
        ->type_name("ISA")
        ->check(quiet(CLI::IsMember({"auto", "avx2", "sse4.1", "sse2"})))
        ->capture_default_str();
    cmd->add_option("--png", args->png, "Also write an 8-bit sRGB PNG preview (clamped to [0,1])")
        ->type_name("FILE");
    cmd->add_flag("--float", args->float32, "Write 32-bit float channels instead of half");
    cmd->add_option("--compression", args->compression,
                    "EXR codec: none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa, dwab\n"
                    "(pxr24 is lossy for --float; b44*, dwa* are lossy)")
        ->type_name("C")
        ->check(quiet(CLI::IsMember({"none", "rle", "zips", "zip", "piz", "pxr24", "b44",
                                     "b44a", "dwaa", "dwab"})))
        ->capture_default_str();
    cmd->add_option("--tile", args->tile,
                    "Tile size WxH (or N for NxN) handed to the worker threads; the image\n"
                    "does not depend on it")
        ->type_name("WxH")
        ->check([](const std::string& text) {
            return parse_tile(text) ? std::string() : "expected WxH with sides 1..4096, e.g. 16x16";
        })
        ->capture_default_str();
    cmd->footer(
        "Examples:\n"
        "  octray render                                  # whitted scene -> whitted.exr\n"
        "  octray render whitted -o whitted.exr --png whitted.png\n"
        "  octray render random:1024,width=640,height=360 --spp 4 -o random.exr\n"
        "  octray render scene.json --width 320 --height 240 --threads 2 --float\n"
        "  octray render sphereflake:3 --compression piz --tile 32x8\n\n"
        "The EXR carries the attributes software, capDate, utcOffset, samplesPerPixel,\n"
        "renderTimeSeconds (double), octray.scene, octray.path, octray.seed (string),\n"
        "octray.maxDepth (int) and octray.rays.{primary,shadow,reflected,refracted,total}\n"
        "(doubles: exact up to 2^53). Files are written to a temporary and renamed, so an\n"
        "output is either complete or absent.\n\n" +
        exit_code_help());
    cmd->callback([args, &run] { run.action = [args] { run_render(*args); }; });
}

}  // namespace octray::tools
