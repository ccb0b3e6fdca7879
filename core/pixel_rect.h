#pragma once
// Rectangles of pixels and tile sizes: one type for a crop (`octray render --crop`), an EXR
// data window, a part of `octray assemble` and a render's pixel region, and one for the
// --tile sizes of `octray render` and `octray bench`.

#include <charconv>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>

namespace octray {

// A half-open rectangle of pixels [x0, x1) x [y0, y1) of the full image, row 0 on top
// (pixel (x, y) is column x, row y). A crop, an EXR data window, a part of `assemble`.
struct PixelRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;

    int width() const { return x1 - x0; }
    int height() const { return y1 - y0; }
    bool empty() const { return x1 <= x0 || y1 <= y0; }
    std::size_t pixel_count() const {
        return empty() ? 0
                       : static_cast<std::size_t>(width()) * static_cast<std::size_t>(height());
    }
    bool contains(int x, int y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
    // True if `r` lies wholly inside this rectangle (an empty `r` never does).
    bool contains(const PixelRect& r) const {
        return !r.empty() && r.x0 >= x0 && r.y0 >= y0 && r.x1 <= x1 && r.y1 <= y1;
    }
    friend bool operator==(const PixelRect&, const PixelRect&) = default;
};

// The pixels two rectangles share (empty() when none).
inline PixelRect intersection(const PixelRect& a, const PixelRect& b) {
    PixelRect r{a.x0 > b.x0 ? a.x0 : b.x0, a.y0 > b.y0 ? a.y0 : b.y0, a.x1 < b.x1 ? a.x1 : b.x1,
                a.y1 < b.y1 ? a.y1 : b.y1};
    if (r.empty()) r = PixelRect{};
    return r;
}

// "(x0, y0)-(x1, y1)", as error messages quote a rectangle.
inline std::string to_string(const PixelRect& r) {
    // Appended piece by piece: g++ 12 warns (-Wrestrict, a false positive) on "(" + ....
    std::string s = "(";
    s += std::to_string(r.x0);
    s += ", ";
    s += std::to_string(r.y0);
    s += ")-(";
    s += std::to_string(r.x1);
    s += ", ";
    s += std::to_string(r.y1);
    s += ")";
    return s;
}

// The largest tile side `octray render --tile` and `octray bench --tile` accept.
inline constexpr int kMaxTileSide = 4096;

// The width x height of the tiles a frame is cut into.
struct TileSize {
    int width = 32;
    int height = 32;
    friend bool operator==(const TileSize&, const TileSize&) = default;
};

// "WxH" with decimal sides in [1, max_side]; nullopt for anything else.
inline std::optional<TileSize> parse_tile_size(std::string_view text,
                                               int max_side = kMaxTileSide) {
    const std::size_t x = text.find('x');
    if (x == std::string_view::npos) return std::nullopt;
    TileSize t;
    const auto parse = [max_side](std::string_view s, int& out) {
        const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
        return ec == std::errc() && end == s.data() + s.size() && out >= 1 && out <= max_side;
    };
    if (!parse(text.substr(0, x), t.width) || !parse(text.substr(x + 1), t.height))
        return std::nullopt;
    return t;
}

inline std::string tile_size_name(TileSize tile) {
    return std::to_string(tile.width) + "x" + std::to_string(tile.height);
}

}  // namespace octray
