// The image's channels: sample sizes, values as floats, channels made from floats (half
// through half_bits.h's conversion, OpenEXR's rounding) and lookups by name.

#include "render/image/image.h"

#include <half.h>

#include <cstring>
#include <stdexcept>

#include "render/image/half_bits.h"

namespace octray {

std::string_view to_string(PixelFormat format) {
    switch (format) {
        case PixelFormat::uint8:
            return "uint8";
        case PixelFormat::uint32:
            return "uint";
        case PixelFormat::half:
            return "half";
        case PixelFormat::float32:
            return "float";
    }
    return "unknown";
}

std::size_t sample_size(PixelFormat format) {
    switch (format) {
        case PixelFormat::uint8:
            return 1;
        case PixelFormat::half:
            return 2;
        case PixelFormat::float32:
        case PixelFormat::uint32:
            return 4;
    }
    return 4;
}

float ImageChannel::value(std::size_t k) const {
    const unsigned char* p = samples.data() + k * sample_size(format);
    switch (format) {
        case PixelFormat::uint8:
            return static_cast<float>(*p);
        case PixelFormat::half: {
            half h;
            std::uint16_t bits;
            std::memcpy(&bits, p, sizeof bits);
            h.setBits(bits);
            return static_cast<float>(h);
        }
        case PixelFormat::float32: {
            float f;
            std::memcpy(&f, p, sizeof f);
            return f;
        }
        case PixelFormat::uint32: {
            std::uint32_t u;
            std::memcpy(&u, p, sizeof u);
            return static_cast<float>(u);
        }
    }
    return 0.0f;
}

std::uint32_t ImageChannel::uint_value(std::size_t k) const {
    if (format == PixelFormat::uint32) {
        std::uint32_t u;
        std::memcpy(&u, samples.data() + k * sizeof u, sizeof u);
        return u;
    }
    const float f = value(k);
    // NaN and negatives give 0, values past the range the largest uint32.
    if (!(f > 0.0f)) return 0;
    if (f >= 4294967296.0f) return 0xffffffffu;
    return static_cast<std::uint32_t>(f);
}

ImageChannel make_channel(std::string name, PixelFormat format, const float* values,
                          std::size_t count, std::size_t stride, SampleBytes storage) {
    if (format != PixelFormat::half && format != PixelFormat::float32)
        throw std::invalid_argument("make_channel: floats make half or float channels");
    // Storage of another size is not kept: its capacity would outlast this channel.
    if (storage.size() != count * sample_size(format)) storage = {};
    storage.resize(count * sample_size(format));  // every byte is written below
    ImageChannel c{std::move(name), format, std::move(storage)};
    unsigned char* out = c.samples.data();
    if (format == PixelFormat::half) {
        // The samples are bytes; std::vector's storage is aligned for any scalar type.
        floats_to_half_bits(values, count, stride, reinterpret_cast<std::uint16_t*>(out));
        return c;
    }
    for (std::size_t k = 0; k < count; ++k) {
        const float v = values[k * stride];
        std::memcpy(out + 4 * k, &v, sizeof v);
    }
    return c;
}

ImageChannel make_channel(std::string name, const std::vector<std::uint32_t>& values) {
    ImageChannel c{std::move(name), PixelFormat::uint32,
                   SampleBytes(values.size() * sizeof(std::uint32_t))};  // written below
    if (!values.empty()) std::memcpy(c.samples.data(), values.data(), c.samples.size());
    return c;
}

ImageChannel make_channel(std::string name, const std::vector<std::uint8_t>& values) {
    return ImageChannel{std::move(name), PixelFormat::uint8,
                        SampleBytes(values.begin(), values.end())};
}

Image::Image(int width, int height, const std::vector<std::string>& names) {
    display_window = data_window = PixelRect{0, 0, width, height};
    const std::size_t bytes = pixel_count() * sizeof(float);
    for (const std::string& name : names)
        channels.push_back(ImageChannel{name, PixelFormat::float32, SampleBytes(bytes, 0)});
}

Image make_rgb_image(PixelRect data_window, PixelRect display_window, Image spare) {
    Image image;
    image.data_window = data_window;
    image.display_window = display_window;
    const std::size_t bytes = data_window.pixel_count() * sizeof(float);
    const char* const names[3] = {"R", "G", "B"};
    for (std::size_t c = 0; c < 3; ++c) {
        SampleBytes samples;
        if (c < spare.channels.size() && spare.channels[c].samples.size() == bytes)
            samples = std::move(spare.channels[c].samples);
        image.channels.push_back(ImageChannel{names[c], PixelFormat::float32, {}});
        image.channels.back().samples = std::move(samples);
    }
    spare = Image();  // whatever was not taken is freed before the new storage is mapped
    for (ImageChannel& c : image.channels)
        if (c.samples.size() != bytes) c.samples.resize(bytes);  // unwritten
    return image;
}

bool fits_rgb_storage(const Image& spare, PixelRect data_window) {
    const std::size_t bytes = data_window.pixel_count() * sizeof(float);
    if (spare.channels.size() < 3) return false;
    for (std::size_t c = 0; c < 3; ++c)
        if (spare.channels[c].samples.size() != bytes) return false;
    return true;
}

bool is_rgb_image(const Image& image) {
    if (image.channels.size() != 3) return false;
    const char* const names[3] = {"R", "G", "B"};
    for (std::size_t c = 0; c < 3; ++c) {
        const ImageChannel& channel = image.channels[c];
        if (channel.name != names[c] || channel.format != PixelFormat::float32 ||
            channel.size() != image.pixel_count())
            return false;
    }
    return true;
}

const ImageChannel* Image::find_channel(std::string_view name) const {
    for (const ImageChannel& c : channels)
        if (c.name == name) return &c;
    return nullptr;
}

int Image::channel_index(std::string_view name) const {
    for (std::size_t c = 0; c < channels.size(); ++c)
        if (channels[c].name == name) return static_cast<int>(c);
    return -1;
}

std::vector<std::string> Image::channel_names() const {
    std::vector<std::string> names;
    for (const ImageChannel& c : channels) names.push_back(c.name);
    return names;
}

bool Image::all_float32() const {
    for (const ImageChannel& c : channels)
        if (c.format != PixelFormat::float32) return false;
    return true;
}

std::vector<Rgb> rgb_pixels(const Image& image) {
    std::vector<Rgb> out(image.pixel_count());
    for (std::size_t k = 0; k < out.size(); ++k)
        out[k] = Rgb(image.plane(0)[k], image.plane(1)[k], image.plane(2)[k]);
    return out;
}

bool same_pixels(const Image& a, const Image& b) {
    return a.data_window == b.data_window && a.display_window == b.display_window &&
           a.channels == b.channels;
}

Image to_float32(const Image& image) {
    Image out;
    out.display_window = image.display_window;
    out.data_window = image.data_window;
    out.compression = image.compression;
    out.attributes = image.attributes;
    out.file_format = image.file_format;
    for (const ImageChannel& c : image.channels) {
        if (c.format == PixelFormat::float32) {
            out.channels.push_back(c);
            continue;
        }
        ImageChannel f{c.name, PixelFormat::float32, SampleBytes(c.size() * sizeof(float))};
        float* values = f.floats();
        for (std::size_t k = 0; k < c.size(); ++k) values[k] = c.value(k);
        out.channels.push_back(std::move(f));
    }
    return out;
}

}  // namespace octray
