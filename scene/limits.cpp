// The memory estimate of scene/limits.h. Every size below names the layout it comes from;
// when those layouts change, change the constants with them.

#include "scene/limits.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <limits>
#include <system_error>
#include <thread>

#include "scene/scene_error.h"

namespace octray {
namespace {

constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();

std::uint64_t sat_add(std::uint64_t a, std::uint64_t b) { return a > kMax - b ? kMax : a + b; }
std::uint64_t sat_mul(std::uint64_t a, std::uint64_t b) {
    if (a != 0 && b > kMax / a) return kMax;
    return a * b;
}
std::uint64_t u64(int v) { return v > 0 ? static_cast<std::uint64_t>(v) : 0; }

// core/image.h: one Rgb (three floats) per pixel.
constexpr std::uint64_t kFramebufferBytesPerPixel = 12;
// render/image_io.cpp write_exr: half output converts the image into interleaved RGB
// halves first; float output points OpenEXR at the framebuffer itself.
constexpr std::uint64_t kHalfOutputBytesPerPixel = 6;

// scene/compile.h, per entry (arrays are padded to kCompiledPadding = 8 entries):
constexpr std::uint64_t kCompiledSphereBytes = 7 * 4;     // cx cy cz r2 radius material object
constexpr std::uint64_t kCompiledPlaneBytes = 6 * 4;      // nx ny nz d material object
constexpr std::uint64_t kCompiledObjectBytes = 16 * 4;    // CompiledObjects' 16 columns
constexpr std::uint64_t kCompiledMaterialBytes = 16 * 4;  // CompiledMaterials' 16 columns
constexpr std::uint64_t kCompiledLightBytes = 11 * 4;     // CompiledLights' 11 columns
constexpr std::uint64_t kPadding = 8;

// render/packet_renderer.cpp TileScratch, per camera sample of a tile (S = tile pixels *
// spp): samples 5 columns; rays and next 10 columns each, each grown to 2 S (next is
// reserved at twice the live count); hits 2 columns; the primary pixel index.
constexpr std::uint64_t kTileBytesPerSample = 5 * 4 + 2 * (10 * 4 * 2) + 2 * 4 + 4;
// Shadow rays: 12 columns per (ray, light).
constexpr std::uint64_t kTileBytesPerShadowRay = 12 * 4;
// Per generation of the ray tree (max_depth + 2 generations): 9 color columns per ray
// and 4 link columns reserved at twice the count.
constexpr std::uint64_t kTileBytesPerGenerationSample = 9 * 4 + 2 * (4 * 4);
// The tile's three accumulators per pixel.
constexpr std::uint64_t kTileBytesPerPixel = 3 * 4;

std::string gib(std::uint64_t bytes) {
    char buf[48];
    if (bytes == kMax) return "more than 16 EiB";
    if (bytes >= (std::uint64_t{1} << 30)) {
        std::snprintf(buf, sizeof buf, "%.1f GiB", static_cast<double>(bytes) / 1073741824.0);
    } else {
        std::snprintf(buf, sizeof buf, "%.1f MiB", static_cast<double>(bytes) / 1048576.0);
    }
    return buf;
}

}  // namespace

std::string RenderMemoryEstimate::describe() const {
    std::string out = "about " + gib(total) + " (framebuffer " + gib(framebuffer);
    if (output) out += ", EXR output " + gib(output);
    out += ", scene " + gib(scene);
    if (per_thread) {
        out += ", ray streams " + gib(per_thread) + " per thread x " + std::to_string(threads);
    }
    return out + ")";
}

RenderMemoryEstimate estimate_render_memory(const Scene& scene,
                                            const RenderMemoryParams& params) {
    RenderMemoryEstimate e;
    const std::uint64_t width = u64(scene.image.width), height = u64(scene.image.height);
    const std::uint64_t pixels = sat_mul(width, height);

    // The framebuffer, plus the packet path's per-column and per-row film positions.
    e.framebuffer = sat_mul(pixels, kFramebufferBytesPerPixel);
    if (params.packet_path) e.framebuffer = sat_add(e.framebuffer, sat_mul(width + height, 4));
    e.output = params.float32_output ? 0 : sat_mul(pixels, kHalfOutputBytesPerPixel);

    // The authored scene (scene/scene.h) and its compiled copy.
    std::uint64_t spheres = 0, planes = 0, names = 0;
    for (const Object& o : scene.objects) {
        (o.type == ObjectType::sphere ? spheres : planes) += 1;
        names = sat_add(names, o.name.size());
    }
    for (const NamedMaterial& m : scene.materials) names = sat_add(names, m.name.size());
    const std::uint64_t objects = scene.objects.size(), materials = scene.materials.size(),
                        lights = scene.lights.size();
    std::uint64_t authored = sat_mul(objects, sizeof(Object));
    authored = sat_add(authored, sat_mul(materials, sizeof(NamedMaterial)));
    authored = sat_add(authored, sat_mul(lights, sizeof(Light)));
    authored = sat_add(authored, names);
    std::uint64_t compiled = sat_mul(spheres + kPadding, kCompiledSphereBytes);
    compiled = sat_add(compiled, sat_mul(planes + kPadding, kCompiledPlaneBytes));
    compiled = sat_add(compiled, sat_mul(objects + kPadding, kCompiledObjectBytes));
    compiled = sat_add(compiled, sat_mul(materials + kPadding, kCompiledMaterialBytes));
    compiled = sat_add(compiled, sat_mul(lights + kPadding, kCompiledLightBytes));
    e.scene = sat_add(authored, params.packet_path ? compiled : 0);

    // One thread's tile scratch. A tile never exceeds the image.
    if (params.packet_path) {
        const std::uint64_t tile_pixels =
            sat_mul(std::min(u64(std::max(params.tile_width, 1)), width),
                    std::min(u64(std::max(params.tile_height, 1)), height));
        const std::uint64_t samples = sat_mul(tile_pixels, u64(scene.image.spp));
        const std::uint64_t generations = u64(scene.render.max_depth) + 2;
        std::uint64_t per_sample = kTileBytesPerSample;
        per_sample = sat_add(per_sample, sat_mul(lights, kTileBytesPerShadowRay));
        per_sample = sat_add(per_sample, sat_mul(generations, kTileBytesPerGenerationSample));
        e.per_thread =
            sat_add(sat_mul(samples, per_sample), sat_mul(tile_pixels, kTileBytesPerPixel));
    }
    unsigned threads = params.threads > 0 ? static_cast<unsigned>(params.threads)
                                          : std::thread::hardware_concurrency();
    e.threads = std::max(1u, threads);

    e.total = sat_add(sat_add(e.framebuffer, e.output),
                      sat_add(e.scene, sat_mul(e.threads, e.per_thread)));
    return e;
}

void check_memory_limit(const Scene& scene, std::uint64_t limit_bytes,
                        const RenderMemoryParams& params) {
    const RenderMemoryEstimate e = estimate_render_memory(scene, params);
    if (e.total <= limit_bytes) return;
    throw SceneError(scene.source, "image",
                     "a " + std::to_string(scene.image.width) + " x " +
                         std::to_string(scene.image.height) + " image at " +
                         std::to_string(scene.image.spp) + " spp needs " + e.describe() +
                         "; expected at most the memory limit of " + gib(limit_bytes) + " (" +
                         std::to_string(limit_bytes) + " bytes)");
}

std::optional<std::uint64_t> parse_memory_size(std::string_view text) {
    std::uint64_t value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc{} || end == text.data()) return std::nullopt;
    std::string unit(end, text.data() + text.size());
    std::transform(unit.begin(), unit.end(), unit.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    // "B", "KB", "KiB" and "K" all mean the same.
    const bool bytes_suffix = !unit.empty() && unit.back() == 'B';
    if (bytes_suffix) unit.pop_back();
    if (bytes_suffix && unit.size() == 2 && unit[1] == 'I') unit.pop_back();
    int shift = 0;
    if (unit.empty())
        shift = 0;
    else if (unit == "K")
        shift = 10;
    else if (unit == "M")
        shift = 20;
    else if (unit == "G")
        shift = 30;
    else if (unit == "T")
        shift = 40;
    else
        return std::nullopt;
    if (value == 0 || value > (kMax >> shift)) return std::nullopt;
    return value << shift;
}

}  // namespace octray
