#include "view/compare_view.h"

#include <algorithm>
#include <array>
#include <set>
#include <stdexcept>
#include <utility>

namespace octray::view {

namespace {

// Channels `source` (red, green, blue) of `image` as a picture; black without channels.
Image picture_of(const Image& image, const std::array<int, 3>& source) {
    Image rgb(image.width(), image.height(), {"R", "G", "B"});
    if (source[0] < 0) return rgb;
    for (int c = 0; c < 3; ++c)
        std::copy_n(image.plane(source[static_cast<std::size_t>(c)]), image.pixel_count(),
                    rgb.plane(c));
    return rgb;
}

}  // namespace

Image display_rgb(const Image& image) {
    std::array<int, 3> source{image.channel_index("R"), image.channel_index("G"),
                              image.channel_index("B")};
    if (source[0] < 0 || source[1] < 0 || source[2] < 0) {
        int gray = image.channel_index("Y");
        if (gray < 0) gray = image.channel_count() > 0 ? 0 : -1;
        source = {gray, gray, gray};
    }
    return picture_of(image, source);
}

std::vector<std::string> display_layers(const Image& image) {
    std::set<std::string> named;
    for (const std::string& name : image.channel_names()) {
        const std::size_t dot = name.rfind('.');
        if (dot != std::string::npos && dot > 0)
            named.insert(name.substr(0, dot));
        else if (name != "R" && name != "G" && name != "B" && name != "A" && name != "Y")
            named.insert(name);
    }
    std::vector<std::string> layers{""};
    layers.insert(layers.end(), named.begin(), named.end());
    return layers;
}

Image display_rgb(const Image& image, const std::string& layer) {
    if (layer.empty()) return display_rgb(image);
    const auto find = [&](const char* suffix) {
        return image.channel_index(layer + "." + suffix);
    };
    std::array<int, 3> source{find("R"), find("G"), find("B")};
    if (source[0] < 0 || source[1] < 0 || source[2] < 0)
        source = {find("X"), find("Y"), find("Z")};
    if (source[0] < 0 || source[1] < 0 || source[2] < 0) {
        // One channel as gray: the layer's first, or the unprefixed channel of that name.
        int gray = image.channel_index(layer);
        for (int c = 0; gray < 0 && c < image.channel_count(); ++c)
            if (image.channels[static_cast<std::size_t>(c)].name.rfind(layer + ".", 0) == 0)
                gray = c;
        if (gray < 0) throw std::invalid_argument("no layer \"" + layer + "\" in the image");
        source = {gray, gray, gray};
    }
    return picture_of(image, source);
}

CompareView load_compare_view(const std::string& path_a, const std::string& path_b,
                              const CompareOptions& options) {
    CompareView view;
    view.path_a = path_a;
    view.path_b = path_b;
    view.options = options;
    view.a = read_image(path_a);
    view.b = read_image(path_b);
    view.result = compare_images(view.a, view.b, options);
    view.figures_json = format_compare_json(view.result, options, path_a, path_b);
    view.rgb_a = display_rgb(view.a);
    view.rgb_b = display_rgb(view.b);
    view.diff = difference_image(view.a, view.b, view.result);
    view.rgb_diff = display_rgb(view.diff);
    view.layers = display_layers(view.a);
    view.heatmap = render_error_heatmap(view.a, view.b, view.result);
    return view;
}

}  // namespace octray::view
