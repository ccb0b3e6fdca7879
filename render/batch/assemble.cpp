// Assembling crops: checks first (display windows, channels, overlaps, gaps), then each
// part's samples copied byte for byte into the full image, channel by channel.

#include "render/batch/assemble.h"

#include <cstring>
#include <limits>
#include <stdexcept>

#include "render/crop.h"
#include "render/image/image_read.h"

namespace octray::batch {
namespace {

// A bound on the assembled image (as read_exr_image's): 2^30 samples in all channels.
constexpr std::size_t kMaxSamples = std::size_t{1} << 30;

std::string quoted(const std::string& name) { return "'" + name + "'"; }

std::string channel_list(const Image& image) {
    std::string s;
    for (const ImageChannel& c : image.channels) {
        if (!s.empty()) s += ", ";
        s += c.name;
        s += " (";
        s += to_string(c.format);
        s += ")";
    }
    return s;
}

bool same_channels(const Image& a, const Image& b) {
    if (a.channels.size() != b.channels.size()) return false;
    for (const ImageChannel& c : a.channels) {
        const ImageChannel* other = b.find_channel(c.name);
        if (other == nullptr || other->format != c.format) return false;
    }
    return true;
}

// The largest uncovered rectangle that starts at the first uncovered pixel (row-major):
// its row run, extended downwards while the whole run stays uncovered.
PixelRect first_gap(const std::vector<unsigned char>& covered, const PixelRect& display,
                    std::size_t& uncovered) {
    const int w = display.width(), h = display.height();
    const auto is_covered = [&](int x, int y) {
        return covered[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) +
                       static_cast<std::size_t>(x)] != 0;
    };
    uncovered = 0;
    for (unsigned char c : covered) uncovered += c == 0 ? 1 : 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (is_covered(x, y)) continue;
            int x1 = x + 1;
            while (x1 < w && !is_covered(x1, y)) ++x1;
            int y1 = y + 1;
            for (; y1 < h; ++y1) {
                bool row_free = true;
                for (int k = x; k < x1 && row_free; ++k) row_free = !is_covered(k, y1);
                if (!row_free) break;
            }
            return PixelRect{display.x0 + x, display.y0 + y, display.x0 + x1, display.y0 + y1};
        }
    return PixelRect{};
}

}  // namespace

Image assemble_parts(const std::vector<Image>& parts, const std::vector<std::string>& names) {
    if (parts.empty()) throw std::invalid_argument("assemble: no parts");
    if (names.size() != parts.size())
        throw std::invalid_argument("assemble: one name per part is needed");
    const Image& first = parts.front();
    const PixelRect display = first.display_window;

    for (std::size_t k = 0; k < parts.size(); ++k) {
        const Image& p = parts[k];
        if (!(p.display_window == display))
            throw AssembleError("part " + quoted(names[k]) + " has the display window " +
                                to_string(p.display_window) + ", but " + quoted(names[0]) +
                                " has " + to_string(display) +
                                ": the parts are not crops of one image");
        if (!same_channels(p, first))
            throw AssembleError("part " + quoted(names[k]) + " has the channels " +
                                channel_list(p) + ", but " + quoted(names[0]) + " has " +
                                channel_list(first));
        if (!display.contains(p.data_window))
            throw AssembleError("part " + quoted(names[k]) + " has the data window " +
                                to_string(p.data_window) +
                                ", which is not inside the display window " +
                                to_string(display));
        for (std::size_t e = 0; e < k; ++e) {
            const PixelRect both = intersection(parts[e].data_window, p.data_window);
            if (!both.empty())
                throw AssembleError("parts " + quoted(names[e]) + " " +
                                    to_string(parts[e].data_window) + " and " +
                                    quoted(names[k]) + " " + to_string(p.data_window) +
                                    " overlap in " + to_string(both));
        }
    }
    const std::size_t pixels = display.pixel_count();
    if (pixels > kMaxSamples / first.channels.size())
        throw AssembleError("the display window " + to_string(display) +
                            " is too large to assemble");

    // Coverage: no overlaps (checked above), so the parts cover the display window iff
    // their pixel counts add up to it; find and name a gap otherwise.
    std::size_t covered_pixels = 0;
    for (const Image& p : parts) covered_pixels += p.data_window.pixel_count();
    if (covered_pixels != pixels) {
        std::vector<unsigned char> covered(pixels, 0);
        for (const Image& p : parts)
            for (int y = p.data_window.y0; y < p.data_window.y1; ++y)
                std::memset(covered.data() +
                                static_cast<std::size_t>(y - display.y0) * display.width() +
                                (p.data_window.x0 - display.x0),
                            1, static_cast<std::size_t>(p.data_window.width()));
        std::size_t uncovered = 0;
        const PixelRect gap = first_gap(covered, display, uncovered);
        throw AssembleError("no part covers pixel (" + std::to_string(gap.x0) + ", " +
                            std::to_string(gap.y0) + "): the parts leave " +
                            std::to_string(uncovered) + " of the " + std::to_string(pixels) +
                            " pixels of " + to_string(display) + " uncovered, among them " +
                            to_string(gap));
    }

    Image out;
    out.display_window = display;
    out.data_window = display;
    out.compression = first.compression;
    out.attributes = first.attributes;
    for (const ImageChannel& c : first.channels)
        out.channels.push_back(
            ImageChannel{c.name, c.format, SampleBytes(pixels * sample_size(c.format), 0)});
    const std::size_t width = static_cast<std::size_t>(display.width());
    for (const Image& p : parts) {
        const PixelRect& r = p.data_window;
        for (ImageChannel& c : out.channels) {
            const ImageChannel& source = *p.find_channel(c.name);
            const std::size_t size = sample_size(c.format);
            const std::size_t row_bytes = static_cast<std::size_t>(r.width()) * size;
            for (int y = r.y0; y < r.y1; ++y) {
                const std::size_t to = (static_cast<std::size_t>(y - display.y0) * width +
                                        static_cast<std::size_t>(r.x0 - display.x0)) *
                                       size;
                const std::size_t from = static_cast<std::size_t>(y - r.y0) * row_bytes;
                std::memcpy(c.samples.data() + to, source.samples.data() + from, row_bytes);
            }
        }
    }
    return out;
}

AssembleSummary assemble_files(const std::vector<std::string>& part_paths,
                               const std::string& output) {
    if (part_paths.empty()) throw std::invalid_argument("assemble: no parts");
    std::vector<Image> parts;
    parts.reserve(part_paths.size());
    for (const std::string& path : part_paths) parts.push_back(read_exr_image(path));
    const Image image = assemble_parts(parts, part_paths);
    parts.clear();
    write_exr(output, image);

    AssembleSummary summary;
    summary.display_window = image.display_window;
    summary.parts = part_paths.size();
    for (const ImageChannel& c : image.channels)
        summary.channels.push_back(c.name + " (" + std::string(to_string(c.format)) + ")");
    return summary;
}

}  // namespace octray::batch
