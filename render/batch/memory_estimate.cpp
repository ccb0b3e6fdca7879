// The memory estimate of render/batch/memory_estimate.h. Every size below names the layout it
// comes from; when those layouts change, change the constants with them.

#include "render/batch/memory_estimate.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <limits>
#include <system_error>
#include <thread>

#include "kernels/bvh/bvh_node.h"
#include "render/tile_layout.h"
#include "scene/scene_error.h"

namespace octray::batch {
namespace {

constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();

std::uint64_t sat_add(std::uint64_t a, std::uint64_t b) { return a > kMax - b ? kMax : a + b; }
std::uint64_t sat_mul(std::uint64_t a, std::uint64_t b) {
    if (a != 0 && b > kMax / a) return kMax;
    return a * b;
}
std::uint64_t u64(int v) { return v > 0 ? static_cast<std::uint64_t>(v) : 0; }

// render/image/image.h make_rgb_image: a render's image, three float32 planes.
constexpr std::uint64_t kFramebufferBytesPerPixel = 12;
// render/batch/progressive.cpp: while a pass renders, the last pass's image and sample sums are
// kept, and the pass makes its own: four images.
constexpr std::uint64_t kProgressiveImages = 4;
// render/image/exr_write.cpp write_exr(path, ExrSources): an EXR in a compression OpenEXR
// packs (PIZ, DWAA, ...) is first made as an image, every channel copied in as half (2
// bytes) or float (4), the id AOV as UINT (4). (ZIP, ZIPS and uncompressed files are packed
// from the render's and the AOVs' own planes, without that copy; it is counted anyway: an
// upper bound.)
constexpr std::uint64_t kColorChannels = 3;
constexpr std::uint64_t kDepthChannels = 1, kNormalChannels = 3, kAlbedoChannels = 3;
// OpenEXR's scan-line writer holds one block of lines of every channel, uncompressed and
// compressed (at worst as large again, plus the codec's own state): three copies.
constexpr std::uint64_t kExrLineBufferCopies = 3;
// render/image/png.cpp write_png_file: 8-bit RGB rows and a row pointer per row.
constexpr std::uint64_t kPngBytesPerPixel = 3, kPngBytesPerRow = 8;
// render/aov.h Image: depth a float, normal a Vec3, albedo an Rgb, id a uint32.
constexpr std::uint64_t kAovDepthBytes = 4, kAovNormalBytes = 12, kAovAlbedoBytes = 12,
                        kAovIdBytes = 4;

// scene/compile.h, per entry (arrays are padded to kCompiledPadding = 8 entries):
constexpr std::uint64_t kCompiledSphereBytes = 5 * 4;  // cx cy cz r2 object
constexpr std::uint64_t kCompiledPlaneBytes = 5 * 4;   // nx ny nz d object
// An 8-float record and 6 tangent columns (counted always: the columns exist only with a
// checkered plane, which the estimate does not look for).
constexpr std::uint64_t kCompiledObjectBytes = 14 * 4;
constexpr std::uint64_t kCompiledMaterialBytes = 16 * 4;  // CompiledMaterials' 16 columns
constexpr std::uint64_t kCompiledLightBytes = 11 * 4;     // CompiledLights' 11 columns
constexpr std::uint64_t kPadding = 8;

// render/prepare/bvh_build.cpp build_sphere_bvh, per sphere: one PrimRef array (32 bytes; the
// partitions work in place) and n - 1 BinaryNodes (28 bytes; inner nodes only) while
// building (render/prepare/bvh_sah.h), the 8-wide nodes (224 bytes each; one per 26 spheres
// measured on random:1000000, counted as one per 4) and the BVH's copy of the spheres
// (5 columns). Its arrays sit on 2 MiB huge pages: a
// page of rounding for each of its 8 arrays.
constexpr std::uint64_t kBvhBuildBytesPerSphere = 32 + 28;
constexpr std::uint64_t kBvhNodeBytesPerSphere = sizeof(BvhNode8) / 4;
constexpr std::uint64_t kBvhSphereBytes = 5 * 4;
constexpr std::uint64_t kBvhPageRounding = 8 * (std::uint64_t{2} << 20);

// render/reference_bvh.cpp, per sphere: the builder's copy of the spheres (40 bytes), the
// object indices in leaf order (4) and about 2 nodes per kLeafSize = 4 spheres (32 bytes
// each), counted as one node per sphere.
constexpr std::uint64_t kReferenceBvhBytesPerSphere = 40 + 4 + 32;

// render/frame_renderer.cpp: an animated scene's frames render a posed copy of the scene
// while the batch keeps the loaded one (a still, and a camera-only animation on the simd
// path without AOVs, make no copy: counted all the same).
constexpr std::uint64_t kAuthoredCopies = 2;

// render/packet_renderer.cpp TileScratch, in its layout (render/tile_layout.h). A tile
// traces each generation of its ray tree in chunks of at most kTileRayChunk rays (its
// kDefaultRayChunk), depth first; a stream of n rays has n rounded up to a packet plus a
// spare packet in each column (at most n + kTileStreamSlack).
// Per ray of the camera-sample chunk: samples and primary rays.
constexpr std::uint64_t kTileRayChunk = kDefaultRayChunk;
constexpr std::uint64_t kTileStreamSlack = 2 * kTileStreamPacket;
constexpr std::uint64_t kTileBytesPerSample = (kSampleColumns + kRayColumns) * kTileColumnBytes;
// Per ray of the largest chunk of any generation: hits; shadow rays per (ray, light).
constexpr std::uint64_t kTileBytesPerChunkRay = kHitColumns * kTileColumnBytes;
constexpr std::uint64_t kTileBytesPerShadowRay = kShadowColumns * kTileColumnBytes;
// Per ray of a generation's chunk (max_depth + 1 generations): its colors, and its
// children: ray and link columns at twice the count.
constexpr std::uint64_t kTileBytesPerGenerationRay =
    (kColorColumns + 2 * (kRayColumns + kLinkColumns)) * kTileColumnBytes;
// The tile's accumulators and its pixel order, per pixel.
constexpr std::uint64_t kTileBytesPerPixel =
    (kTileAccumulatorColumns + kTilePixelOrderColumns) * kTileColumnBytes;
// The same numbers as before the layout had a header of its own.
static_assert(kTileBytesPerSample == 5 * 4 + 10 * 4 && kTileBytesPerChunkRay == 2 * 4 &&
              kTileBytesPerShadowRay == 12 * 4 &&
              kTileBytesPerGenerationRay == 9 * 4 + 2 * (10 * 4 + 4 * 4) &&
              kTileBytesPerPixel == 3 * 4 + 2 * 4 && kTileRayChunk == 4096 &&
              kTileStreamSlack == 16);

// Measured (peak resident set size of `octray render`, Debian 12, glibc malloc): the
// process rendering a 1x1 image of a small scene, code, libraries and TBB's threads
// included, peaks at 14 MiB; counted as 32.
constexpr std::uint64_t kProcessBytes = std::uint64_t{32} << 20;
// Loading a scene file: its text, the JSON tree (an object of `octray scene`'s output,
// about 110 bytes of text, takes several hundred bytes of tree) and the scene built from
// it; a file of random spheres peaks at about 6.2 bytes per byte, counted as 8.
constexpr std::uint64_t kLoadBytesPerFileByte = 8;

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
    if (aovs) out += ", AOVs " + gib(aovs);
    out += ", scene " + gib(scene);
    if (load) out += ", loading the scene " + gib(load) + " before that";
    if (per_thread) {
        out += ", ray streams " + gib(per_thread) + " per thread x " + std::to_string(threads);
    }
    if (fixed) out += ", the process " + gib(fixed);
    return out + ")";
}

RenderMemoryEstimate estimate_render_memory(const Scene& scene,
                                            const RenderMemoryParams& params) {
    RenderMemoryEstimate e;
    const std::uint64_t width = u64(scene.image.width), height = u64(scene.image.height);
    const std::uint64_t pixels = sat_mul(width, height);

    // The render's images, plus the packet path's per-column and per-row film positions.
    e.framebuffer = sat_mul(sat_mul(pixels, kFramebufferBytesPerPixel),
                            params.progressive ? kProgressiveImages : 1);
    if (params.packet_path) e.framebuffer = sat_add(e.framebuffer, sat_mul(width + height, 4));

    // The AOV buffers, and the EXR image: a copy of every channel, and the writer's block
    // of lines of all of them.
    if (params.aov_depth) e.aovs = sat_add(e.aovs, sat_mul(pixels, kAovDepthBytes));
    if (params.aov_normal) e.aovs = sat_add(e.aovs, sat_mul(pixels, kAovNormalBytes));
    if (params.aov_albedo) e.aovs = sat_add(e.aovs, sat_mul(pixels, kAovAlbedoBytes));
    if (params.aov_id) e.aovs = sat_add(e.aovs, sat_mul(pixels, kAovIdBytes));
    std::uint64_t float_channels = kColorChannels;
    if (params.aov_depth) float_channels += kDepthChannels;
    if (params.aov_normal) float_channels += kNormalChannels;
    if (params.aov_albedo) float_channels += kAlbedoChannels;
    const std::uint64_t bytes_per_pixel =
        float_channels * (params.float32_output ? 4 : 2) + (params.aov_id ? 4 : 0);
    const std::uint64_t lines = std::min(height, u64(std::max(params.exr_lines_per_chunk, 1)));
    e.output =
        sat_add(sat_mul(pixels, bytes_per_pixel),
                sat_mul(sat_mul(sat_mul(lines, width), bytes_per_pixel), kExrLineBufferCopies));
    if (params.png_preview)
        e.output = sat_add(e.output, sat_add(sat_mul(pixels, kPngBytesPerPixel),
                                             sat_mul(height, kPngBytesPerRow)));
    // Writing behind: the frame being written keeps its image and its files' buffers
    // while the next frame renders into its own.
    if (params.write_behind) {
        e.framebuffer = sat_add(e.framebuffer, sat_mul(pixels, kFramebufferBytesPerPixel));
        e.output = sat_mul(e.output, 2);
    }

    // The authored scene (scene/scene.h), its compiled copy and the BVH. The objects are
    // counted on every core: a million of them took 5 ms on one.
    struct Counts {
        std::uint64_t spheres = 0, names = 0;
    };
    const Counts counts = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, scene.objects.size(), 1u << 14), Counts{},
        [&](const tbb::blocked_range<std::size_t>& r, Counts c) {
            for (std::size_t k = r.begin(); k < r.end(); ++k) {
                const Object& o = scene.objects[k];
                c.spheres += o.type == ObjectType::sphere;
                c.names = sat_add(c.names, o.name.size());
            }
            return c;
        },
        [](Counts a, const Counts& b) {
            return Counts{a.spheres + b.spheres, sat_add(a.names, b.names)};
        });
    const std::uint64_t spheres = counts.spheres, planes = scene.objects.size() - spheres;
    std::uint64_t names = counts.names;
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
    std::uint64_t bvh = 0;
    const std::uint32_t bvh_spheres =
        static_cast<std::uint32_t>(std::min<std::uint64_t>(spheres, 0xFFFFFFFFu));
    if (params.packet_path && spheres > 0 && accel_uses_bvh(params.accel, bvh_spheres)) {
        bvh = sat_mul(spheres + kPadding,
                      kBvhBuildBytesPerSphere + kBvhNodeBytesPerSphere + kBvhSphereBytes);
        bvh = sat_add(bvh, kBvhPageRounding);
    }
    // The scalar path builds its own BVH (render/reference_bvh.h) unless --accel none.
    if (!params.packet_path && spheres > 0 && params.accel != Accel::none)
        bvh = sat_mul(spheres, kReferenceBvhBytesPerSphere);
    e.scene = sat_add(sat_mul(authored, kAuthoredCopies),
                      params.packet_path ? sat_add(compiled, bvh) : bvh);
    // Loading comes before rendering, and what it allocates is freed before the first
    // frame (measured: the peak of a render is the larger of the two, not their sum).
    e.load = params.scene_file_bytes > 0
                 ? estimate_load_memory(params.scene_file_bytes).load
                 : authored;  // a built-in is generated; its digest hashes the spec string
    e.fixed = kProcessBytes;

    // One thread's tile scratch. A tile never exceeds the image.
    if (params.packet_path) {
        const std::uint64_t tile_pixels =
            sat_mul(std::min(u64(std::max(params.tile_width, 1)), width),
                    std::min(u64(std::max(params.tile_height, 1)), height));
        const std::uint64_t samples = sat_mul(tile_pixels, u64(scene.image.spp));
        // Generation d holds min(chunk, 2^d C) rays at a time, C the camera-sample chunk.
        const std::uint64_t first_chunk = std::min(samples, kTileRayChunk);
        std::uint64_t per_thread =
            sat_add(sat_mul(first_chunk + kTileStreamSlack, kTileBytesPerSample),
                    sat_mul(tile_pixels, kTileBytesPerPixel));
        std::uint64_t largest = 0, chunk = first_chunk;
        for (int d = 0; d <= std::max(scene.render.max_depth, 0); ++d) {
            largest = std::max(largest, chunk);
            per_thread = sat_add(per_thread,
                                 sat_mul(chunk + kTileStreamSlack, kTileBytesPerGenerationRay));
            chunk = std::min(sat_mul(chunk, 2), kTileRayChunk);
        }
        per_thread =
            sat_add(per_thread, sat_mul(largest + kTileStreamSlack, kTileBytesPerChunkRay));
        e.per_thread =
            sat_add(per_thread, sat_mul(sat_add(sat_mul(largest, lights), kTileStreamSlack),
                                        kTileBytesPerShadowRay));
    }
    unsigned threads = params.threads > 0 ? static_cast<unsigned>(params.threads)
                                          : std::thread::hardware_concurrency();
    e.threads = std::max(1u, threads);

    const std::uint64_t rendering =
        sat_add(sat_add(sat_add(e.framebuffer, e.output), sat_add(e.aovs, e.scene)),
                sat_mul(e.threads, e.per_thread));
    e.total = sat_add(e.fixed, std::max(e.load, rendering));
    return e;
}

namespace {

void check_estimate(const Scene& scene, std::uint64_t limit_bytes,
                    const RenderMemoryEstimate& e) {
    if (e.total <= limit_bytes) return;
    throw SceneError(scene.source, "image",
                     "a " + std::to_string(scene.image.width) + " x " +
                         std::to_string(scene.image.height) + " image at " +
                         std::to_string(scene.image.spp) + " spp needs " + e.describe() +
                         "; expected at most the memory limit of " + gib(limit_bytes) + " (" +
                         std::to_string(limit_bytes) + " bytes)");
}

}  // namespace

void check_memory_limit(const Scene& scene, std::uint64_t limit_bytes,
                        const RenderMemoryParams& params) {
    check_estimate(scene, limit_bytes, estimate_render_memory(scene, params));
}

RenderMemoryEstimate fit_memory_limit(const Scene& scene, std::uint64_t limit_bytes,
                                      RenderMemoryParams& params) {
    RenderMemoryEstimate e = estimate_render_memory(scene, params);
    if (params.write_behind && e.total > limit_bytes) {
        params.write_behind = false;
        e = estimate_render_memory(scene, params);
    }
    check_estimate(scene, limit_bytes, e);
    return e;
}

RenderMemoryEstimate estimate_load_memory(std::uint64_t file_bytes) {
    RenderMemoryEstimate e;
    e.load = sat_mul(file_bytes, kLoadBytesPerFileByte);
    e.fixed = kProcessBytes;
    e.threads = 0;
    e.total = sat_add(e.load, e.fixed);
    return e;
}

void check_load_memory_limit(const std::string& path, std::uint64_t file_bytes,
                             std::uint64_t limit_bytes) {
    const RenderMemoryEstimate e = estimate_load_memory(file_bytes);
    if (e.total <= limit_bytes) return;
    throw SceneError(path, "",
                     "loading this " + std::to_string(file_bytes) +
                         "-byte scene file needs about " + gib(e.total) + " (parsing it " +
                         gib(e.load) + ", the process " + gib(e.fixed) +
                         "), before rendering; expected at most the memory limit of " +
                         gib(limit_bytes) + " (" + std::to_string(limit_bytes) + " bytes)");
}

std::uint64_t machine_memory_bytes() {
    const long pages = ::sysconf(_SC_PHYS_PAGES);
    const long page_size = ::sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page_size <= 0) return 0;
    const auto p = static_cast<std::uint64_t>(pages),
               size = static_cast<std::uint64_t>(page_size);
    return sat_mul(p, size);
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

RenderMemoryParams memory_params(const RenderConfig& config) {
    RenderMemoryParams p;
    p.threads = config.threads;
    p.tile_width = config.tile.width;
    p.tile_height = config.tile.height;
    p.packet_path = config.path == RenderPath::simd;
    p.accel = config.accel;
    p.aov_depth = config.aovs.depth;
    p.aov_normal = config.aovs.normal;
    p.aov_albedo = config.aovs.albedo;
    p.aov_id = config.aovs.id;
    return p;
}

}  // namespace octray::batch
