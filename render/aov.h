#pragma once
// Arbitrary output variables: per-pixel data about the first surface each camera ray hits
// (depth, normal, albedo, object id), written as extra channels of the render's EXR
// (render/README.md, "AOVs"). They come from one primary ray per pixel, its first hit found
// by either path and turned into values by the scalar reference tracer, so they are the
// same whichever path renders the color.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/vec3.h"
#include "render/image/image_io.h"
#include "render/render_result.h"
#include "scene/scene.h"

namespace octray {

struct AovSet {
    bool depth = false;   // Z
    bool normal = false;  // N.X N.Y N.Z
    bool albedo = false;  // albedo.R albedo.G albedo.B
    bool id = false;      // id
    bool any() const { return depth || normal || albedo || id; }
    friend bool operator==(const AovSet&, const AovSet&) = default;
};

// Parses a comma-separated list of AOV names ("depth,normal,albedo,id"; each at most once,
// no empty items). On failure returns nullopt and, if `error` is given, says why ("unknown
// AOV 'foo' (known: depth, normal, albedo, id)").
std::optional<AovSet> parse_aov_list(std::string_view list, std::string* error = nullptr);

// The AOVs are an Image (render/image/image.h) whose data window (and display window) is
// the rendered rectangle, with a float32 channel for each value asked for, in this order:
//   Z                              t of the first hit along the unit primary ray; +inf: miss
//   N.X N.Y N.Z                    world-space unit normal facing the ray; 0: miss
//   albedo.R albedo.G albedo.B     Cd at the hit (checker included); 0: miss
//   id (uint32)                    Scene::objects index + 1; 0: miss
// An empty set gives an image without channels.

// Computes `set` for the pixels of options.crop (or the whole image) of frame
// options.frame, from sample 0's primary ray of each pixel (the pixel center at 1 spp), in
// parallel over options.threads threads. The scene must have passed validate_scene().
// Throws std::invalid_argument for a bad crop, as the renderers do.
Image compute_aovs(const Scene& scene, const RenderOptions& options, AovSet set);

// The same from first hits traced beforehand (the packet path's: trace_first_hits in
// render/packet_renderer.h, over the same crop), with the same bits: the reference only
// turns each hit's t and object into a point, a normal and a color, as its own search
// would have. Throws std::invalid_argument when `hits` covers another rectangle.
Image compute_aovs(const Scene& scene, const RenderOptions& options, AovSet set,
                   const FirstHits& hits);

// Appends the AOV channels to `image` (whose data window must be the AOVs'): Z float32;
// N.* and albedo.* in `color_type` (the R, G, B type: half, or float32 with --float); id
// uint32. Throws std::invalid_argument if the windows disagree.
void append_aov_channels(Image& image, const Image& aovs, PixelFormat color_type);

// The same channels as sources of an EXR written from the AOVs themselves (image_io.h's
// ExrSources; `aovs` must outlive the write), in the same formats. Throws
// std::invalid_argument if the windows disagree.
void append_aov_sources(ExrSources& exr, const Image& aovs, PixelFormat color_type);

}  // namespace octray
