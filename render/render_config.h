#pragma once
// One description of a render (render/README.md, "One description of a render"): how it
// runs (path, ISA, sphere acceleration, threads, tiles), what it changes of the scene
// (size, spp, depth, seed), which pixels (a crop) and which AOVs. `octray render` and its
// batch library, `octray view`, the memory estimate and the library API all build from
// it; the names its settings take and their limits are parsed and checked here, once.

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "core/pixel_rect.h"
#include "kernels/isa.h"
#include "render/accel.h"
#include "render/aov.h"
#include "render/render_options.h"
#include "scene/scene.h"

namespace octray {

// A setting that cannot be used as given: setting() names it ("isa", "crop", "aovs", ...),
// detail() says why and what it takes; what() is "setting: detail".
class ConfigError : public std::invalid_argument {
  public:
    ConfigError(std::string setting, std::string detail)
        : std::invalid_argument(setting + ": " + detail),
          setting_(std::move(setting)),
          detail_(std::move(detail)) {}
    const std::string& setting() const { return setting_; }
    const std::string& detail() const { return detail_; }

  private:
    std::string setting_;
    std::string detail_;
};

// A scene's settings that a render replaces; unset: the scene's own.
struct SceneOverrides {
    std::optional<int> width, height, spp, max_depth;
    std::optional<std::uint64_t> seed;
    bool any() const { return width || height || spp || max_depth || seed; }
};

// `scene` with the overrides applied (not validated again).
void apply_overrides(Scene& scene, const SceneOverrides& overrides);

struct RenderConfig {
    RenderPath path = RenderPath::simd;
    Isa isa = Isa::automatic;  // as asked, or resolved by resolve_isa()
    Accel accel = Accel::automatic;
    int threads = 0;  // 0: every core TBB sees; at most kMaxRenderThreads
    TileSize tile;    // sides 1..kMaxTileSide; never changes the image
    SceneOverrides overrides;
    // Only these pixels of the full image (render/README.md, "Crops"); each equals the
    // same pixel of the full render bit for bit.
    std::optional<PixelRect> crop;
    AovSet aovs;  // rendered alongside the color, from each pixel's first hit

    // The settings from their names, as the command line and the viewer spell them; each
    // throws ConfigError naming the setting and what it takes.
    void set_path(std::string_view name);   // "simd", "scalar"
    void set_isa(std::string_view name);    // "auto", "sse2", "sse4.1", "avx2", "avx512"
    void set_accel(std::string_view name);  // "auto", "bvh", "none"
    void set_tile(std::string_view text);   // "WxH"
    void set_aovs(std::string_view list);   // "depth,normal,albedo,id" (parse_aov_list)

    // Throws ConfigError for threads or tile sides out of their ranges. The overrides are
    // the scene's settings: validate_scene checks the scene they make (the scene format's
    // limits, wherever they are set).
    void check() const;
    // Throws ConfigError ("crop") unless the crop (if any) is a non-empty rectangle inside
    // a width x height image.
    void check_crop(int width, int height) const;
    // The ISA the simd path runs: Isa::automatic becomes this CPU's best; stored in `isa`.
    // Throws ConfigError ("isa") for a forced ISA this CPU lacks. Nothing for the scalar
    // path.
    Isa resolve_isa();
    // "scalar", or "simd (avx2)" with the ISA (resolved: resolve_isa()): the EXR's
    // octray.path.
    std::string path_label() const;

    // What the renderers take from it: threads, tiles, acceleration and the crop (the
    // frame, cancel flag and progress are the caller's).
    RenderOptions render_options() const;
    // What the memory estimate takes from it: batch::memory_params(config)
    // (render/batch/memory_estimate.h).
};

}  // namespace octray
