// AOVs: one primary ray per pixel (sample 0), its first hit (the reference's search, or
// hits the packet path traced), and what the shading of that hit would use, computed by
// the scalar reference tracer (render/README.md, "AOVs").

#include "render/aov.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <limits>
#include <stdexcept>
#include <utility>

#include "render/crop.h"
#include "render/parallel.h"
#include "render/reference.h"

namespace octray {
namespace {

constexpr std::array<std::string_view, 4> kAovNames{"depth", "normal", "albedo", "id"};

bool* flag_of(AovSet& set, std::string_view name) {
    if (name == "depth") return &set.depth;
    if (name == "normal") return &set.normal;
    if (name == "albedo") return &set.albedo;
    if (name == "id") return &set.id;
    return nullptr;
}

std::string known_names() {
    std::string s;
    for (std::string_view n : kAovNames) {
        if (!s.empty()) s += ", ";
        s += n;
    }
    return s;
}

}  // namespace

std::optional<AovSet> parse_aov_list(std::string_view list, std::string* error) {
    const auto failed = [&](std::string why) -> std::optional<AovSet> {
        if (error != nullptr) *error = std::move(why);
        return std::nullopt;
    };
    AovSet set;
    std::size_t start = 0;
    while (true) {
        const std::size_t comma = list.find(',', start);
        const std::string_view item = list.substr(
            start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
        if (item.empty()) {
            std::string why = "empty item in the AOV list '";
            why += list;
            why += "' (known: " + known_names() + ")";
            return failed(std::move(why));
        }
        bool* flag = flag_of(set, item);
        if (flag == nullptr) {
            std::string why = "unknown AOV '";
            why += item;
            why += "' (known: " + known_names() + ")";
            return failed(std::move(why));
        }
        if (*flag) {
            std::string why = "AOV '";
            why += item;
            why += "' is listed twice";
            return failed(std::move(why));
        }
        *flag = true;
        if (comma == std::string_view::npos) break;
        start = comma + 1;
    }
    return set;
}

namespace {

// The AOVs of the pixels of options.crop from each pixel's first hit: traced by the
// reference here (`hits` null), or given (the packet path's, trace_first_hits).
Image aovs_from(const Scene& scene, const RenderOptions& options, AovSet set,
                const FirstHits* hits) {
    const PixelRect rect = render_rect(options, scene.image.width, scene.image.height);
    const std::size_t n = rect.pixel_count();
    std::vector<std::string> names;
    if (set.depth) names.push_back("Z");
    if (set.normal) names.insert(names.end(), {"N.X", "N.Y", "N.Z"});
    if (set.albedo) names.insert(names.end(), {"albedo.R", "albedo.G", "albedo.B"});
    // The channels' storage is sized, not filled: the rows below write every pixel once, a
    // miss's values included, on every thread (a zero fill first, on one thread, took
    // 64 MB at 1920x1080 and its first touch before them).
    Image out;
    out.data_window = out.display_window = rect;
    for (const std::string& name : names) {
        out.channels.push_back(ImageChannel{name, PixelFormat::float32, {}});
        out.channels.back().samples.resize(n * sizeof(float));
    }
    if (set.id) {
        out.channels.push_back(ImageChannel{"id", PixelFormat::uint32, {}});
        out.channels.back().samples.resize(n * sizeof(std::uint32_t));
    }
    if (!set.any()) return out;
    float* const depth = set.depth ? out.plane(out.channel_index("Z")) : nullptr;
    float* const normal[3] = {set.normal ? out.plane(out.channel_index("N.X")) : nullptr,
                              set.normal ? out.plane(out.channel_index("N.Y")) : nullptr,
                              set.normal ? out.plane(out.channel_index("N.Z")) : nullptr};
    float* const albedo[3] = {set.albedo ? out.plane(out.channel_index("albedo.R")) : nullptr,
                              set.albedo ? out.plane(out.channel_index("albedo.G")) : nullptr,
                              set.albedo ? out.plane(out.channel_index("albedo.B")) : nullptr};
    std::uint32_t* const id =
        set.id ? reinterpret_cast<std::uint32_t*>(out.channels.back().samples.data()) : nullptr;
    if (hits != nullptr &&
        (!(hits->rect == rect) || hits->t.size() != n || hits->object.size() != n))
        throw std::invalid_argument("compute_aovs: the first hits cover " +
                                    to_string(hits->rect) + ", the AOVs " + to_string(rect));

    // Given hits need no search: the tracer is only asked for camera rays, points, normals
    // and colors, so it builds no BVH.
    const ReferenceTracer tracer(
        scene, hits != nullptr ? ReferenceAccel::brute_force : reference_accel(options.accel));
    const auto compute_rows = [&] {
        tbb::parallel_for(tbb::blocked_range<int>(rect.y0, rect.y1), [&](const auto& rows) {
            for (int j = rows.begin(); j < rows.end(); ++j)
                for (int i = rect.x0; i < rect.x1; ++i) {
                    const std::size_t k =
                        static_cast<std::size_t>(j - rect.y0) * rect.width() + (i - rect.x0);
                    // Sample 0's camera ray (a fisheye pixel outside the image circle has
                    // none) and its hit.
                    const std::optional<Ray> ray = tracer.camera_ray(i, j, 0, options.frame);
                    std::optional<SurfaceHit> hit;
                    if (ray) {
                        if (hits == nullptr)
                            hit = tracer.intersect(*ray);
                        else if (hits->object[k] >= 0)
                            hit = tracer.surface_hit(
                                *ray, hits->t[k], static_cast<std::uint32_t>(hits->object[k]));
                    }
                    // Each pixel written once, a miss (or no ray) as depth +inf, normal and
                    // albedo 0, id 0.
                    if (set.depth)
                        depth[k] = hit ? hit->t : std::numeric_limits<float>::infinity();
                    if (set.normal) {  // the normal shading uses: facing the incoming ray
                        Vec3 v{0.0f, 0.0f, 0.0f};
                        if (hit)
                            v = dot(hit->normal, ray->direction) > 0.0f ? -hit->normal
                                                                        : hit->normal;
                        normal[0][k] = v.x, normal[1][k] = v.y, normal[2][k] = v.z;
                    }
                    if (set.albedo) {
                        const Rgb c = hit ? tracer.surface_color(*hit) : Rgb(0.0f, 0.0f, 0.0f);
                        albedo[0][k] = c.r, albedo[1][k] = c.g, albedo[2][k] = c.b;
                    }
                    if (set.id) id[k] = hit ? hit->object + 1 : 0;
                }
        });
    };
    run_with_threads(options.threads, compute_rows);
    return out;
}

}  // namespace

Image compute_aovs(const Scene& scene, const RenderOptions& options, AovSet set) {
    return aovs_from(scene, options, set, nullptr);
}

Image compute_aovs(const Scene& scene, const RenderOptions& options, AovSet set,
                   const FirstHits& hits) {
    return aovs_from(scene, options, set, &hits);
}

namespace {

// The format a file stores AOV channel `c` in: depth keeps float32 (its +inf misses and far
// hits); normals and albedo take the colour channels' type, ids stay uint32.
PixelFormat aov_file_format(const ImageChannel& c, PixelFormat color_type) {
    return c.format != PixelFormat::float32 || c.name == "Z" ? c.format : color_type;
}

void check_aov_appending(const PixelRect& data_window, const Image& aovs,
                         PixelFormat color_type, const char* function) {
    if (!(data_window == aovs.data_window))
        throw std::invalid_argument(std::string(function) + ": the AOVs cover " +
                                    to_string(aovs.data_window) +
                                    ", the image's data window is " + to_string(data_window));
    if (color_type != PixelFormat::half && color_type != PixelFormat::float32)
        throw std::invalid_argument(std::string(function) + ": colors are half or float");
}

}  // namespace

void append_aov_channels(Image& image, const Image& aovs, PixelFormat color_type) {
    check_aov_appending(image.data_window, aovs, color_type, "append_aov_channels");
    for (const ImageChannel& c : aovs.channels) {
        if (aov_file_format(c, color_type) == c.format)
            image.channels.push_back(c);
        else
            image.channels.push_back(make_channel(c.name, color_type, c.floats(), c.size()));
    }
}

void append_aov_sources(ExrSources& exr, const Image& aovs, PixelFormat color_type) {
    check_aov_appending(exr.data_window, aovs, color_type, "append_aov_sources");
    for (const ImageChannel& c : aovs.channels)
        exr.channels.push_back({&c, aov_file_format(c, color_type)});
}

}  // namespace octray
