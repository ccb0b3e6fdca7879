#include "render/image/error_heatmap.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string_view>

#include "render/image/image_io.h"

namespace octray {
namespace {

// matplotlib's magma (van der Walt & Smith, 2015): every 4th entry of its 256-entry
// table plus the last, in sRGB [0, 1]. Linear interpolation between these knots stays
// within one 8-bit step of the full table (every 8th entry would not, at the dark end).
constexpr int magma_knot_count = 65;
constexpr float magma_knots[magma_knot_count][3] = {
    {0.001462f, 0.000466f, 0.013866f}, {0.005950f, 0.004843f, 0.037130f},
    {0.013708f, 0.011771f, 0.068667f}, {0.024792f, 0.020715f, 0.100676f},
    {0.039608f, 0.031090f, 0.133515f}, {0.056615f, 0.042160f, 0.167446f},
    {0.074257f, 0.052017f, 0.202660f}, {0.092949f, 0.059904f, 0.239164f},
    {0.113094f, 0.065492f, 0.276784f}, {0.135053f, 0.068391f, 0.315000f},
    {0.159018f, 0.068354f, 0.352688f}, {0.184801f, 0.065732f, 0.387973f},
    {0.211718f, 0.061992f, 0.418647f}, {0.238826f, 0.059517f, 0.443256f},
    {0.265447f, 0.060237f, 0.461840f}, {0.291366f, 0.064553f, 0.475462f},
    {0.316654f, 0.071690f, 0.485380f}, {0.341482f, 0.080564f, 0.492631f},
    {0.366012f, 0.090314f, 0.497960f}, {0.390384f, 0.100379f, 0.501864f},
    {0.414709f, 0.110431f, 0.504662f}, {0.439062f, 0.120298f, 0.506555f},
    {0.463508f, 0.129893f, 0.507652f}, {0.488088f, 0.139186f, 0.508011f},
    {0.512831f, 0.148179f, 0.507648f}, {0.537755f, 0.156894f, 0.506551f},
    {0.562866f, 0.165368f, 0.504692f}, {0.588158f, 0.173652f, 0.502035f},
    {0.613617f, 0.181811f, 0.498536f}, {0.639216f, 0.189921f, 0.494150f},
    {0.664915f, 0.198075f, 0.488836f}, {0.690661f, 0.206384f, 0.482558f},
    {0.716387f, 0.214982f, 0.475290f}, {0.742004f, 0.224025f, 0.467018f},
    {0.767398f, 0.233705f, 0.457755f}, {0.792427f, 0.244242f, 0.447543f},
    {0.816914f, 0.255895f, 0.436461f}, {0.840636f, 0.268953f, 0.424666f},
    {0.863320f, 0.283729f, 0.412403f}, {0.884651f, 0.300530f, 0.400047f},
    {0.904281f, 0.319610f, 0.388137f}, {0.921884f, 0.341098f, 0.377376f},
    {0.937221f, 0.364929f, 0.368567f}, {0.950210f, 0.390820f, 0.362468f},
    {0.960949f, 0.418323f, 0.359630f}, {0.969680f, 0.446936f, 0.360311f},
    {0.976690f, 0.476226f, 0.364466f}, {0.982279f, 0.505851f, 0.371874f},
    {0.986700f, 0.535582f, 0.382210f}, {0.990138f, 0.565296f, 0.395122f},
    {0.992785f, 0.594891f, 0.410283f}, {0.994738f, 0.624350f, 0.427397f},
    {0.996096f, 0.653659f, 0.446213f}, {0.996925f, 0.682828f, 0.466526f},
    {0.997325f, 0.711848f, 0.488154f}, {0.997285f, 0.740772f, 0.510983f},
    {0.996898f, 0.769591f, 0.534892f}, {0.996162f, 0.798348f, 0.559820f},
    {0.995131f, 0.827052f, 0.585701f}, {0.993866f, 0.855711f, 0.612482f},
    {0.992440f, 0.884330f, 0.640099f}, {0.990930f, 0.912915f, 0.668481f},
    {0.989434f, 0.941470f, 0.697519f}, {0.988033f, 0.970012f, 0.727077f},
    {0.987053f, 0.991438f, 0.749504f},
};

// Table index (0..255) of each knot: 0, 4, ..., 252, then 255.
constexpr double knot_index(int k) { return k == magma_knot_count - 1 ? 255.0 : 4.0 * k; }

// A 3x5 pixel font for the legend: each glyph is five rows of three bits, the high bit on
// the left. Only what "%.3g" prints and the scale's names ("linear", "log", "x") are here.
struct Glyph {
    char c;
    std::uint8_t rows[5];
};
constexpr Glyph glyphs[] = {
    {'0', {7, 5, 5, 5, 7}}, {'1', {2, 6, 2, 2, 7}}, {'2', {7, 1, 7, 4, 7}},
    {'3', {7, 1, 7, 1, 7}}, {'4', {5, 5, 7, 1, 1}}, {'5', {7, 4, 7, 1, 7}},
    {'6', {7, 4, 7, 5, 7}}, {'7', {7, 1, 1, 1, 1}}, {'8', {7, 5, 7, 5, 7}},
    {'9', {7, 5, 7, 1, 7}}, {'.', {0, 0, 0, 0, 2}}, {'e', {2, 5, 7, 4, 3}},
    {'-', {0, 0, 7, 0, 0}}, {'+', {0, 2, 7, 2, 0}}, {'l', {6, 2, 2, 2, 7}},
    {'i', {2, 0, 6, 2, 7}}, {'n', {0, 6, 5, 5, 5}}, {'a', {0, 3, 5, 5, 3}},
    {'r', {0, 5, 6, 4, 4}}, {'o', {0, 2, 5, 5, 2}}, {'g', {3, 4, 5, 5, 3}},
    {'x', {0, 0, 5, 2, 5}}, {' ', {0, 0, 0, 0, 0}},
};

constexpr int font_scale = 2;  // each font pixel is 2x2
constexpr int glyph_height = 5 * font_scale;
constexpr int glyph_advance = 4 * font_scale;  // one font pixel between glyphs
constexpr int min_canvas_width = 256;          // room for three labels under the bar
constexpr int margin = 8;
constexpr int bar_height = 14;
constexpr std::array<std::uint8_t, 3> background{24, 24, 24};
constexpr std::array<std::uint8_t, 3> text_color{235, 235, 235};

class Canvas {
  public:
    // A width x height picture of uint8 channels R, G, B.
    Canvas(Image& image, int width, int height)
        : image_(image), width_(width), height_(height) {
        image_.display_window = image_.data_window = PixelRect{0, 0, width, height};
        image_.channels.clear();
        for (const char* name : {"R", "G", "B"})
            image_.channels.push_back(
                make_channel(name, std::vector<std::uint8_t>(image_.pixel_count())));
    }

    void set(int x, int y, std::array<std::uint8_t, 3> color) {
        if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
        const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
                              static_cast<std::size_t>(x);
        for (std::size_t c = 0; c < 3; ++c) image_.channels[c].samples[i] = color[c];
    }

    void text(int x, int y, std::string_view s) {
        for (char c : s) {
            for (const Glyph& g : glyphs) {
                if (g.c != c) continue;
                for (int row = 0; row < 5; ++row)
                    for (int col = 0; col < 3; ++col)
                        if (g.rows[row] & (4 >> col))
                            for (int dy = 0; dy < font_scale; ++dy)
                                for (int dx = 0; dx < font_scale; ++dx)
                                    set(x + col * font_scale + dx, y + row * font_scale + dy,
                                        text_color);
            }
            x += glyph_advance;
        }
    }

  private:
    Image& image_;
    int width_, height_;
};

int text_width(std::string_view s) {
    return s.empty() ? 0 : static_cast<int>(s.size()) * glyph_advance - font_scale;
}

std::string label(double value) {
    if (value == 0.0) return "0";
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", value);
    return text;
}

}  // namespace

std::string_view to_string(HeatmapScale scale) {
    return scale == HeatmapScale::log ? "log" : "linear";
}

std::optional<HeatmapScale> parse_heatmap_scale(std::string_view name) {
    if (name == "linear") return HeatmapScale::linear;
    if (name == "log") return HeatmapScale::log;
    return std::nullopt;
}

double heatmap_position(double error, double scale_min, double scale_max, HeatmapScale scale) {
    if (!(error > 0.0) || !(scale_max > 0.0)) return 0.0;
    if (scale == HeatmapScale::linear) return std::min(error / scale_max, 1.0);
    if (error <= scale_min) return 0.0;
    return std::min(std::log10(error / scale_min) / std::log10(scale_max / scale_min), 1.0);
}

std::array<std::uint8_t, 3> magma_color(double t) {
    if (!(t > 0.0)) t = 0.0;
    if (t > 1.0) t = 1.0;
    const double index = t * 255.0;
    int k = std::min(static_cast<int>(index / 4.0), magma_knot_count - 2);
    const double f = (index - knot_index(k)) / (knot_index(k + 1) - knot_index(k));
    std::array<std::uint8_t, 3> color{};
    for (int c = 0; c < 3; ++c) {
        const double v = magma_knots[k][c] + (magma_knots[k + 1][c] - magma_knots[k][c]) * f;
        color[static_cast<std::size_t>(c)] =
            static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
    }
    return color;
}

std::array<std::uint8_t, 3> ErrorHeatmap::color(int x, int y) const {
    const std::size_t i =
        static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width()) +
        static_cast<std::size_t>(x);
    return {image.channels[0].samples[i], image.channels[1].samples[i],
            image.channels[2].samples[i]};
}

ErrorHeatmap render_error_heatmap(const Image& a, const Image& b, const CompareResult& result,
                                  const HeatmapOptions& options) {
    if (!a.all_float32() || !b.all_float32())
        return render_error_heatmap(to_float32(a), to_float32(b), result, options);
    ErrorHeatmap map;
    const int width = result.width, height = result.height;
    map.scale_max = options.factor > 0.0 ? 1.0 / options.factor : result.overall.max_abs_error;
    if (options.scale == HeatmapScale::log)
        map.scale_min = map.scale_max * std::pow(10.0, -heatmap_log_decades);
    map.legend = std::string(to_string(options.scale));
    if (options.factor > 0.0) map.legend += " x" + label(options.factor);
    // Enlarge small images so a few pixels are visible, but keep huge ones as they are.
    map.zoom = std::clamp(min_canvas_width / std::max(width, 1), 1, 64);
    map.zoom = std::max(1, std::min(map.zoom, 4096 / std::max(height, 1)));
    const int map_w = width * map.zoom, map_h = height * map.zoom;

    const int canvas_w = std::max(map_w, min_canvas_width);
    const int legend_top = map_h + margin;
    const int canvas_h = legend_top + bar_height + 2 * (4 + glyph_height) + margin;
    Canvas canvas(map.image, canvas_w, canvas_h);
    for (int y = 0; y < canvas_h; ++y)
        for (int x = 0; x < canvas_w; ++x) canvas.set(x, y, background);

    // The map: the largest error over the compared channels, per pixel.
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    for (std::size_t i = 0; i < pixels; ++i) {
        double error = 0.0;
        bool finite = true;
        for (const auto& [index_a, index_b] : result.channel_indices) {
            const float va = a.plane(index_a)[i], vb = b.plane(index_b)[i];
            if (std::isinf(va) && va == vb) continue;  // equal infinities: no error
            if (!std::isfinite(va) || !std::isfinite(vb)) {
                finite = false;
                break;
            }
            error = std::max(error, std::fabs(static_cast<double>(va) - vb));
        }
        const std::array<std::uint8_t, 3> color =
            !finite ? heatmap_nonfinite_color
                    : magma_color(
                          heatmap_position(error, map.scale_min, map.scale_max, options.scale));
        const int x0 = static_cast<int>(i % static_cast<std::size_t>(width)) * map.zoom;
        const int y0 = static_cast<int>(i / static_cast<std::size_t>(width)) * map.zoom;
        for (int dy = 0; dy < map.zoom; ++dy)
            for (int dx = 0; dx < map.zoom; ++dx) canvas.set(x0 + dx, y0 + dy, color);
    }

    // The legend: the ramp from its bottom to its top, with the bottom, the middle (the
    // geometric middle on the log scale) and the top printed, and the scale's name below.
    map.bar_x0 = margin;
    map.bar_x1 = canvas_w - margin;
    map.bar_y0 = legend_top;
    map.bar_y1 = legend_top + bar_height;
    const int bar_span = std::max(map.bar_x1 - map.bar_x0 - 1, 1);
    for (int x = map.bar_x0; x < map.bar_x1; ++x) {
        const auto color = magma_color(static_cast<double>(x - map.bar_x0) / bar_span);
        for (int y = map.bar_y0; y < map.bar_y1; ++y) canvas.set(x, y, color);
    }
    const int text_y = map.bar_y1 + 4;
    const bool log = options.scale == HeatmapScale::log;
    const std::string low = label(map.scale_min),
                      mid = label(log ? std::sqrt(map.scale_min * map.scale_max)
                                      : map.scale_max / 2),
                      high = label(map.scale_max);
    canvas.text(map.bar_x0, text_y, low);
    if (map.scale_max > 0.0) {
        canvas.text((map.bar_x0 + map.bar_x1 - text_width(mid)) / 2, text_y, mid);
        canvas.text(map.bar_x1 - text_width(high), text_y, high);
    }
    canvas.text(map.bar_x0, text_y + glyph_height + 4, map.legend);
    return map;
}

ErrorHeatmap write_error_heatmap(const std::string& path, const Image& a, const Image& b,
                                 const CompareResult& result, const HeatmapOptions& options) {
    const ErrorHeatmap map = render_error_heatmap(a, b, result, options);
    write_png(path, map.image);
    return map;
}

}  // namespace octray
