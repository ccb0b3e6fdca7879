#include "render/render_config.h"

#include <string>

#include "kernels/dispatch.h"

namespace octray {

namespace {

std::string quoted(std::string_view text) { return "\"" + std::string(text) + "\""; }

void check_range(const char* setting, long long value, long long low, long long high,
                 const std::string& what) {
    if (value < low || value > high)
        throw ConfigError(setting, "must be " + what + " from " + std::to_string(low) + " to " +
                                       std::to_string(high) + ", not " + std::to_string(value));
}

}  // namespace

void apply_overrides(Scene& scene, const SceneOverrides& o) {
    if (o.width) scene.image.width = *o.width;
    if (o.height) scene.image.height = *o.height;
    if (o.spp) scene.image.spp = *o.spp;
    if (o.max_depth) scene.render.max_depth = *o.max_depth;
    if (o.seed) scene.render.seed = *o.seed;
}

void RenderConfig::set_path(std::string_view name) {
    const auto parsed = parse_render_path(name);
    if (!parsed) throw ConfigError("path", "expected simd or scalar, not " + quoted(name));
    path = *parsed;
}

void RenderConfig::set_isa(std::string_view name) {
    const auto parsed = parse_isa(name);
    if (!parsed)
        throw ConfigError("isa",
                          "expected auto, avx512, avx2, sse4.1 or sse2, not " + quoted(name));
    isa = *parsed;
}

void RenderConfig::set_accel(std::string_view name) {
    const auto parsed = parse_accel(name);
    if (!parsed) throw ConfigError("accel", "expected auto, bvh or none, not " + quoted(name));
    accel = *parsed;
}

void RenderConfig::set_tile(std::string_view text) {
    const auto parsed = parse_tile_size(text);
    if (!parsed)
        throw ConfigError("tile", "expected WxH with sides from 1 to " +
                                      std::to_string(kMaxTileSide) + ", such as 16x16, not " +
                                      quoted(text));
    tile = *parsed;
}

void RenderConfig::set_aovs(std::string_view list) {
    std::string error;
    const auto parsed = parse_aov_list(list, &error);
    if (!parsed) throw ConfigError("aovs", error);
    aovs = *parsed;
}

void RenderConfig::check() const {
    check_range("threads", threads, 0, kMaxRenderThreads, "a thread count");
    check_range("tile", tile.width, 1, kMaxTileSide, "a tile width");
    check_range("tile", tile.height, 1, kMaxTileSide, "a tile height");
}

void RenderConfig::check_crop(int width, int height) const {
    if (!crop) return;
    const PixelRect& c = *crop;
    const PixelRect image{0, 0, width, height};
    if (c.empty() || !image.contains(c))
        throw ConfigError("crop", "x0,y0,x1,y1 = " + std::to_string(c.x0) + "," +
                                      std::to_string(c.y0) + "," + std::to_string(c.x1) + "," +
                                      std::to_string(c.y1) +
                                      " must satisfy 0 <= x0 < x1 <= " + std::to_string(width) +
                                      " and 0 <= y0 < y1 <= " + std::to_string(height) +
                                      " (a non-empty region of the " + std::to_string(width) +
                                      " x " + std::to_string(height) + " image)");
}

Isa RenderConfig::resolve_isa() {
    if (path != RenderPath::simd) return isa;
    try {
        isa = octray::resolve_isa(isa);
    } catch (const std::runtime_error& e) {
        throw ConfigError("isa", e.what());
    }
    return isa;
}

std::string RenderConfig::path_label() const {
    std::string label(render_path_name(path));
    if (path == RenderPath::simd) label.append(" (").append(isa_name(isa)).append(")");
    return label;
}

RenderOptions RenderConfig::render_options() const {
    RenderOptions o;
    o.threads = threads;
    o.tile_width = tile.width;
    o.tile_height = tile.height;
    o.accel = accel;
    o.crop = crop;
    return o;
}

}  // namespace octray
