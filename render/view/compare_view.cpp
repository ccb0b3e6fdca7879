#include "render/view/compare_view.h"

#include <array>
#include <utility>

namespace octray::view {

Image display_rgb(const ChannelImage& image) {
    Image rgb(image.width, image.height);
    std::array<int, 3> source{image.find_channel("R"), image.find_channel("G"),
                              image.find_channel("B")};
    if (source[0] < 0 || source[1] < 0 || source[2] < 0) {
        int gray = image.find_channel("Y");
        if (gray < 0) gray = image.channel_count() > 0 ? 0 : -1;
        source = {gray, gray, gray};
    }
    if (source[0] < 0) return rgb;  // no channels: black
    for (int y = 0; y < image.height; ++y) {
        for (int x = 0; x < image.width; ++x) {
            rgb.at(x, y) = Rgb{image.at(source[0], x, y), image.at(source[1], x, y),
                               image.at(source[2], x, y)};
        }
    }
    return rgb;
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
    view.rgb_diff = display_rgb(difference_image(view.a, view.b, view.result));
    view.heatmap = render_error_heatmap(view.a, view.b, view.result);
    return view;
}

}  // namespace octray::view
