// The one OpenEXR writer, write_exr(path, Image), and the types of an OpenEXR image
// (render/image/image_io.h). Every EXR octray writes goes through write_exr_file() below.

#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfGenericOutputFile.h>
#include <ImfHeader.h>
#include <ImfIntAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfOpaqueAttribute.h>
#include <ImfOutputFile.h>
#include <ImfRational.h>
#include <ImfRationalAttribute.h>
#include <ImfStdIO.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <ImfVersion.h>
#include <emmintrin.h>
#include <half.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <utility>

#include "render/image/deflate.h"
#include "render/image/half_bits.h"
#include "render/image/image_io.h"

namespace octray {
namespace {

// Rgb is handed to OpenEXR as three interleaved float channels, so it must be exactly
// three packed floats.
static_assert(sizeof(Rgb) == 3 * sizeof(float));

std::string window_text(const PixelRect& r) {
    return "(" + std::to_string(r.x0) + ", " + std::to_string(r.y0) + ")-(" +
           std::to_string(r.x1) + ", " + std::to_string(r.y1) + ")";
}

Imf::Compression to_imf(ExrCompression compression) {
    switch (compression) {
        case ExrCompression::none:
            return Imf::NO_COMPRESSION;
        case ExrCompression::rle:
            return Imf::RLE_COMPRESSION;
        case ExrCompression::zips:
            return Imf::ZIPS_COMPRESSION;
        case ExrCompression::zip:
            return Imf::ZIP_COMPRESSION;
        case ExrCompression::piz:
            return Imf::PIZ_COMPRESSION;
        case ExrCompression::pxr24:
            return Imf::PXR24_COMPRESSION;
        case ExrCompression::b44:
            return Imf::B44_COMPRESSION;
        case ExrCompression::b44a:
            return Imf::B44A_COMPRESSION;
        case ExrCompression::dwaa:
            return Imf::DWAA_COMPRESSION;
        case ExrCompression::dwab:
            return Imf::DWAB_COMPRESSION;
    }
    throw std::invalid_argument("unknown EXR compression");
}

constexpr std::array<std::pair<std::string_view, ExrCompression>, 10> kCompressionNames{{
    {"none", ExrCompression::none},
    {"rle", ExrCompression::rle},
    {"zips", ExrCompression::zips},
    {"zip", ExrCompression::zip},
    {"piz", ExrCompression::piz},
    {"pxr24", ExrCompression::pxr24},
    {"b44", ExrCompression::b44},
    {"b44a", ExrCompression::b44a},
    {"dwaa", ExrCompression::dwaa},
    {"dwab", ExrCompression::dwab},
}};

// OpenEXR boxes are inclusive: [x0, x1) becomes min x0, max x1 - 1.
Imath::Box2i to_box(const PixelRect& r) {
    return Imath::Box2i({r.x0, r.y0}, {r.x1 - 1, r.y1 - 1});
}

Imf::PixelType to_imf(PixelFormat type) {
    switch (type) {
        case PixelFormat::uint32:
            return Imf::UINT;
        case PixelFormat::half:
            return Imf::HALF;
        case PixelFormat::float32:
            return Imf::FLOAT;
        case PixelFormat::uint8:
            break;
    }
    throw std::invalid_argument("OpenEXR has no 8-bit samples");
}

// Attributes the writer derives from the image itself; a caller may not set them.
constexpr std::array<std::string_view, 11> kStructuralAttributes{
    "channels", "compression", "dataWindow", "displayWindow", "lineOrder",         "tiles",
    "type",     "name",        "version",    "chunkCount",    "maxSamplesPerPixel"};

void insert_attribute(Imf::Header& header, std::set<std::string>& seen, const std::string& name,
                      const Imf::Attribute& attribute) {
    if (name.empty()) throw std::invalid_argument("an attribute has an empty name");
    for (std::string_view structural : kStructuralAttributes)
        if (name == structural)
            throw std::invalid_argument("attribute '" + name +
                                        "' is set by the writer and cannot be given");
    if (!seen.insert(name).second)
        throw std::invalid_argument("attribute '" + name + "' is given twice");
    // Header::insert throws if the header already holds `name` with another type (the
    // defaults pixelAspectRatio, screenWindowCenter, screenWindowWidth).
    header.insert(name, attribute);
}

void insert_attributes(Imf::Header& header, const ExrAttributes& attributes) {
    std::set<std::string> seen;
    for (const auto& [name, value] : attributes.strings)
        insert_attribute(header, seen, name, Imf::StringAttribute(value));
    for (const auto& [name, value] : attributes.floats)
        insert_attribute(header, seen, name, Imf::FloatAttribute(value));
    for (const auto& [name, value] : attributes.ints)
        insert_attribute(header, seen, name, Imf::IntAttribute(value));
    for (const auto& [name, value] : attributes.doubles)
        insert_attribute(header, seen, name, Imf::DoubleAttribute(value));
    for (const auto& [name, m] : attributes.matrices) {
        const Imath::M44f matrix(m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8], m[9],
                                 m[10], m[11], m[12], m[13], m[14], m[15]);
        insert_attribute(header, seen, name, Imf::M44fAttribute(matrix));
    }
    for (const auto& [name, r] : attributes.rationals)
        insert_attribute(header, seen, name,
                         Imf::RationalAttribute(Imf::Rational(r.numerator, r.denominator)));
    for (const ExrOpaqueAttribute& a : attributes.opaque) {
        // Rebuilt from its stored bytes: a known type as that type (so that OpenEXR checks
        // it), any other as an opaque blob.
        std::unique_ptr<Imf::Attribute> attribute(
            Imf::Attribute::knownType(a.type.c_str())
                ? Imf::Attribute::newAttribute(a.type.c_str())
                : new Imf::OpaqueAttribute(a.type.c_str()));
        Imf::StdISStream in;
        in.str(std::string(a.value.begin(), a.value.end()));
        attribute->readValueFrom(in, static_cast<int>(a.value.size()), Imf::EXR_VERSION);
        insert_attribute(header, seen, a.name, *attribute);
    }
}

// What a file's channel is made of, for the checks: its name, the format of its samples
// and how many bytes of them there are.
struct ChannelFacts {
    const std::string& name;
    PixelFormat format;
    std::size_t bytes;
};

void check_exr_layout(const PixelRect& display_window, const PixelRect& data_window,
                      const std::vector<ChannelFacts>& channels) {
    if (display_window.empty())
        throw std::invalid_argument("the display window " + window_text(display_window) +
                                    " is empty");
    if (data_window.empty())
        throw std::invalid_argument("the data window " + window_text(data_window) +
                                    " is empty");
    if (channels.empty()) throw std::invalid_argument("the image has no channels");
    std::set<std::string> names;
    for (const ChannelFacts& c : channels) {
        if (c.name.empty()) throw std::invalid_argument("a channel has an empty name");
        if (!names.insert(c.name).second)
            throw std::invalid_argument("channel '" + c.name + "' is given twice");
        if (c.format == PixelFormat::uint8)
            throw std::invalid_argument("channel '" + c.name +
                                        "' holds 8-bit samples, which OpenEXR cannot store");
        const std::size_t expected = data_window.pixel_count() * sample_size(c.format);
        if (c.bytes != expected)
            throw std::invalid_argument(
                "channel '" + c.name + "' holds " + std::to_string(c.bytes) +
                " bytes, but the data window " + window_text(data_window) + " needs " +
                std::to_string(expected));
    }
}

void check_exr_image(const Image& image) {
    std::vector<ChannelFacts> facts;
    for (const ImageChannel& c : image.channels)
        facts.push_back({c.name, c.format, c.samples.size()});
    check_exr_layout(image.display_window, image.data_window, facts);
}

Imf::Header make_header(const Image& image) {
    // Line order INCREASING_Y: the file's first scan line is the top row.
    Imf::Header header(to_box(image.display_window), to_box(image.data_window));
    header.compression() = to_imf(image.compression);
    insert_attributes(header, image.attributes);
    for (const ImageChannel& c : image.channels)
        header.channels().insert(c.name, Imf::Channel(to_imf(c.format)));
    return header;
}

// The other compressions: OpenEXR packs and compresses the chunks.
void write_exr_with_openexr(const std::string& path, const Image& image,
                            const Imf::Header& header) {
    const Imath::Box2i window = to_box(image.data_window);
    const std::size_t width = static_cast<std::size_t>(image.data_window.width());
    Imf::FrameBuffer frame_buffer;
    for (const ImageChannel& c : image.channels) {
        // OpenEXR only reads through the frame buffer when writing.
        char* base = reinterpret_cast<char*>(const_cast<unsigned char*>(c.samples.data()));
        const std::size_t element = sample_size(c.format);
        frame_buffer.insert(
            c.name, Imf::Slice::Make(to_imf(c.format), base, window, element, element * width));
    }
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frame_buffer);
    file.writePixels(image.data_window.height());
}

// ---- The chunks octray packs and compresses itself -------------------------------------
//
// Uncompressed, ZIPS and ZIP files (ZIP is octray's default) are written here: OpenEXR
// 3.1 deflates each chunk with zlib on its thread pool, which cost more than the trace of
// a 1280x720 frame; ISA-L's igzip at level 1 makes zlib streams of the same chunks five to
// ten times as fast as zlib's level 4, about a tenth larger (render/image/README.md,
// "Compression").
// OpenEXR still writes the magic number, version and header; the file reads back through
// any OpenEXR reader (the tests read every compression back, and compare the uncompressed
// file with OpenEXR's byte for byte).

// igzip's level for ZIP and ZIPS chunks (see above): level 0 made files 15-30 % larger
// than level 1 for a fifth less time, levels 2 and 3 were no smaller and slower.
constexpr int kZipLevel = 1;

bool packs_chunks_itself(ExrCompression compression) {
    return compression == ExrCompression::none || compression == ExrCompression::zips ||
           compression == ExrCompression::zip;
}

// The protected member of OpenEXR that writes a file's magic number and version field
// (with the flag for long attribute or channel names).
struct MagicAndVersion : Imf::GenericOutputFile {
    void write(Imf::OStream& os, const Imf::Header& header) {
        writeMagicNumberAndVersionField(os, header);
    }
};

// OpenEXR stores the channels of a line sorted by name, byte by byte (its ChannelList is
// ordered by strcmp), each line's samples of one channel together, little-endian.
static_assert(std::endian::native == std::endian::little,
              "the samples are copied as they lie in memory into a little-endian file");

// The channels in file order (OpenEXR sorts them by name), each from its samples.
std::vector<ExrChannelSource> channels_in_file_order(std::vector<ExrChannelSource> channels) {
    std::sort(channels.begin(), channels.end(),
              [](const ExrChannelSource& a, const ExrChannelSource& b) {
                  return a.samples->name < b.samples->name;
              });
    return channels;
}

// An Image's channels as sources of themselves.
std::vector<ExrChannelSource> sources_of(const Image& image) {
    std::vector<ExrChannelSource> channels;
    for (const ImageChannel& c : image.channels) channels.push_back({&c, c.format});
    return channels;
}

// The byte pairs at in[0, 2 * pairs) split into their first bytes, to even, and their
// second bytes, to odd. SSE2 (every x86-64) 16 pairs at a time.
void split_even_odd(const unsigned char* in, std::size_t pairs, unsigned char* even,
                    unsigned char* odd) {
    std::size_t i = 0;
    const __m128i low = _mm_set1_epi16(0x00ff);
    for (; i + 16 <= pairs; i += 16) {
        const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + 2 * i));
        const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + 2 * i + 16));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(even + i),
                         _mm_packus_epi16(_mm_and_si128(a, low), _mm_and_si128(b, low)));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(odd + i),
                         _mm_packus_epi16(_mm_srli_epi16(a, 8), _mm_srli_epi16(b, 8)));
    }
    for (; i < pairs; ++i) {
        even[i] = in[2 * i];
        odd[i] = in[2 * i + 1];
    }
}

// OpenEXR's predictor: out[0] = in[0], out[i] = in[i] - in[i - 1] + 128 (mod 256).
void predict(const unsigned char* in, std::size_t size, unsigned char* out) {
    out[0] = in[0];
    std::size_t i = 1;
    const __m128i bias = _mm_set1_epi8(static_cast<char>(128));
    for (; i + 16 <= size; i += 16) {
        const __m128i now = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + i));
        const __m128i before = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + i - 1));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i),
                         _mm_add_epi8(_mm_sub_epi8(now, before), bias));
    }
    for (; i < size; ++i) out[i] = static_cast<unsigned char>(in[i] - in[i - 1] + 128);
}

// Packs, and for ZIP and ZIPS compresses, one chunk of scan lines.
class ChunkEncoder {
  public:
    ChunkEncoder(std::vector<ExrChannelSource> channels, const PixelRect& data_window,
                 ExrCompression compression)
        : channels_(channels_in_file_order(std::move(channels))),
          width_(static_cast<std::size_t>(data_window.width())),
          height_(data_window.height()),
          lines_per_chunk_(exr_lines_per_chunk(compression)),
          compression_(compression) {
        for (const ExrChannelSource& c : channels_)
            line_bytes_ += width_ * sample_size(c.format);
    }

    int chunk_count() const { return (height_ + lines_per_chunk_ - 1) / lines_per_chunk_; }
    int first_line(int chunk) const { return chunk * lines_per_chunk_; }
    std::size_t raw_bytes(int chunk) const {
        const int lines = std::min(lines_per_chunk_, height_ - first_line(chunk));
        return static_cast<std::size_t>(lines) * line_bytes_;
    }

    // Chunk `chunk`'s data as the file stores it after its y and size: compressed when
    // that makes it smaller, as OpenEXR's reader expects (it reads a chunk whose size is
    // its raw size as raw).
    // `out` is uninitialised storage: only the bytes written are touched (resizing a
    // std::vector to the raw size zeroed 5.5 MB for a 1280x720 half RGB frame, page
    // faults included, for ~0.7 MB of compressed chunks).
    void encode(int chunk, SampleBytes& out) const {
        const std::size_t raw = raw_bytes(chunk);
        if (compression_ == ExrCompression::none) {
            out.resize(raw);
            pack(chunk, out.data());
            return;
        }
        // OpenEXR's ZIP predictor: the chunk's bytes split into the even ones then the odd
        // ones (the low and high bytes of the samples), then each byte replaced by its
        // difference from the one before, plus 128. Every line of every channel holds an
        // even number of bytes, so each is split on its own.
        thread_local std::vector<unsigned char> split, predicted;
        split.resize(raw);
        predicted.resize(raw);
        unsigned char* even = split.data();
        unsigned char* odd = split.data() + raw / 2;
        for_each_line(chunk, [&](const unsigned char* line, std::size_t bytes) {
            split_even_odd(line, bytes / 2, even, odd);
            even += bytes / 2;
            odd += bytes / 2;
        });
        predict(split.data(), raw, predicted.data());
        out.resize(raw);
        const std::size_t size =
            detail::zlib_compress(kZipLevel, predicted.data(), raw, out.data(), raw - 1);
        if (size != 0) {
            out.resize(size);
        } else {
            pack(chunk, out.data());  // it does not compress: stored raw
        }
    }

  private:
    // Each line of each channel of the chunk, in file order, as the file's bytes: a float32
    // line stored as half is converted into this thread's line buffer first.
    template <class Visit>
    void for_each_line(int chunk, Visit&& visit) const {
        thread_local std::vector<std::uint16_t> half_line;
        const int y0 = first_line(chunk);
        const int y1 = std::min(height_, y0 + lines_per_chunk_);
        for (int y = y0; y < y1; ++y)
            for (const ExrChannelSource& c : channels_) {
                const std::size_t line = static_cast<std::size_t>(y) * width_;
                if (c.format == c.samples->format) {
                    const std::size_t bytes = width_ * sample_size(c.format);
                    visit(c.samples->samples.data() + line * sample_size(c.format), bytes);
                    continue;
                }
                half_line.resize(width_);
                floats_to_half_bits(c.samples->floats() + line, width_, 1, half_line.data());
                visit(reinterpret_cast<const unsigned char*>(half_line.data()),
                      width_ * sizeof(std::uint16_t));
            }
    }

    void pack(int chunk, unsigned char* out) const {
        for_each_line(chunk, [&](const unsigned char* line, std::size_t bytes) {
            std::memcpy(out, line, bytes);
            out += bytes;
        });
    }

    std::vector<ExrChannelSource> channels_;
    std::size_t width_;
    int height_;
    int lines_per_chunk_;
    ExrCompression compression_;
    std::size_t line_bytes_ = 0;
};

// A file written with stdio; every failure throws with the OS's reason.
class OutputBytes {
  public:
    explicit OutputBytes(const std::string& path) : file_(std::fopen(path.c_str(), "wb")) {
        if (file_ == nullptr) throw std::runtime_error(std::strerror(errno));
    }
    ~OutputBytes() {
        if (file_ != nullptr) std::fclose(file_);
    }
    OutputBytes(const OutputBytes&) = delete;
    OutputBytes& operator=(const OutputBytes&) = delete;

    void write(const void* data, std::size_t size) {
        errno = 0;
        if (size != 0 && std::fwrite(data, 1, size, file_) != size) fail();
        position_ += size;
    }
    template <class T>
    void write_le(T value) {  // the host is little-endian (static_assert above)
        write(&value, sizeof value);
    }
    void seek(std::uint64_t position) {
        if (std::fseek(file_, static_cast<long>(position), SEEK_SET) != 0) fail();
        position_ = position;
    }
    std::uint64_t position() const { return position_; }
    // A full disk may only show when buffered data is flushed, so the close is checked.
    void close() {
        const bool failed = std::ferror(file_) != 0;
        std::FILE* file = std::exchange(file_, nullptr);
        errno = 0;
        if (std::fclose(file) != 0 || failed) fail();
    }

  private:
    [[noreturn]] void fail() const {
        throw std::runtime_error(std::strerror(errno != 0 ? errno : EIO));
    }
    std::FILE* file_;
    std::uint64_t position_ = 0;
};

// The chunks are encoded in parallel, a group at a time (so that a huge image never holds
// all of its compressed chunks at once), and each goes to the file as soon as every chunk
// before it is there: the writes overlap the encoding of the chunks after them instead of
// following it, and a written chunk's storage is free for the next one. With an
// exr_thread_count() of 0 or 1 the calling thread encodes them alone.
constexpr std::size_t kRawBytesPerGroup = std::size_t{16} << 20;

void write_exr_with_own_chunks(const std::string& path, const ChunkEncoder& encoder,
                               int first_line, const Imf::Header& header,
                               const std::function<void()>& on_read) {
    header.sanityCheck();
    Imf::StdOSStream head;
    MagicAndVersion().write(head, header);
    header.writeTo(head);
    const std::string head_bytes = head.str();

    const int chunks = encoder.chunk_count();
    OutputBytes file(path);
    file.write(head_bytes.data(), head_bytes.size());
    // The chunk offset table, filled in once the chunks are written.
    const std::uint64_t table_position = file.position();
    std::vector<std::uint64_t> offsets(static_cast<std::size_t>(chunks), 0);
    file.write(offsets.data(), offsets.size() * sizeof(std::uint64_t));

    // In the caller's arena, whose threads the frame's other work (its PNG) shares: a
    // task arena of its own here would wait for a worker the PNG holds.
    const bool parallel = Imf::globalThreadCount() > 1;
    for (int first = 0; first < chunks;) {
        int last = first;
        for (std::size_t bytes = 0;
             last < chunks && (last == first || bytes < kRawBytesPerGroup); ++last)
            bytes += encoder.raw_bytes(last);
        const auto count = static_cast<std::size_t>(last - first);
        std::vector<SampleBytes> encoded(count);
        const auto ready = std::make_unique<std::atomic<bool>[]>(count);
        std::mutex writing;        // held by the thread writing chunks to the file
        std::atomic<int> next{0};  // the group's next chunk to write (changed under writing)
        const auto write_chunk = [&](int g) {
            SampleBytes& data = encoded[static_cast<std::size_t>(g)];
            const int k = first + g;
            offsets[static_cast<std::size_t>(k)] = file.position();
            file.write_le<std::int32_t>(first_line + encoder.first_line(k));
            file.write_le<std::int32_t>(static_cast<std::int32_t>(data.size()));
            file.write(data.data(), data.size());
            data = SampleBytes();
        };
        // Writes the encoded chunks from `next` on, in order, unless another thread is
        // writing (it looks again once it lets go, and the loop below writes what is left).
        const auto write_ready = [&] {
            for (;;) {
                std::unique_lock lock(writing, std::try_to_lock);
                if (!lock.owns_lock()) return;
                for (int g = next.load(); g < last - first && ready[g].load(); next = ++g)
                    write_chunk(g);
                lock.unlock();
                const int g = next.load();
                if (g == last - first || !ready[g].load()) return;
            }
        };
        const auto encode_range = [&](const tbb::blocked_range<int>& range) {
            for (int k = range.begin(); k != range.end(); ++k) {
                encoder.encode(k, encoded[static_cast<std::size_t>(k - first)]);
                ready[k - first].store(true);
                write_ready();
            }
        };
        if (parallel)
            tbb::parallel_for(tbb::blocked_range<int>(first, last), encode_range);
        else
            encode_range(tbb::blocked_range<int>(first, last));
        // Every chunk encoded: the sources are read no more.
        if (last == chunks && on_read) on_read();
        for (int g = next.load(); g < last - first; ++g) write_chunk(g);
        first = last;
    }
    file.seek(table_position);
    file.write(offsets.data(), offsets.size() * sizeof(std::uint64_t));
    file.close();
}

void write_exr_file(const std::string& path, const Image& image) {
    const Imf::Header header = make_header(image);
    if (packs_chunks_itself(image.compression)) {
        const ChunkEncoder encoder(sources_of(image), image.data_window, image.compression);
        write_exr_with_own_chunks(path, encoder, image.data_window.y0, header, {});
    } else {
        write_exr_with_openexr(path, image, header);
    }
}

void require_render_image(const Image& image) {
    if (!is_rgb_image(image))
        throw std::invalid_argument(
            "the image is not a render's (float32 channels R, G and B, one sample a pixel)");
    if (image.width() <= 0 || image.height() <= 0)
        throw std::invalid_argument("the image is empty (" + std::to_string(image.width()) +
                                    "x" + std::to_string(image.height()) + ")");
}

// The image `sources` describe: each float32 source converted (or copied) by make_channel
// into storage taken from `spare` in turn where there is some, any other copied.
Image exr_image_of(const ExrSources& sources, std::vector<ImageChannel> spare = {}) {
    Image image;
    image.display_window = sources.display_window;
    image.data_window = sources.data_window;
    image.compression = sources.compression;
    image.attributes = sources.attributes;
    for (std::size_t k = 0; k < sources.channels.size(); ++k) {
        const ImageChannel& c = *sources.channels[k].samples;
        if (c.format != PixelFormat::float32) {
            image.channels.push_back(c);
            continue;
        }
        SampleBytes storage = k < spare.size() ? std::move(spare[k].samples) : SampleBytes();
        image.channels.push_back(make_channel(c.name, sources.channels[k].format, c.floats(),
                                              c.size(), 1, std::move(storage)));
    }
    return image;
}

}  // namespace

std::optional<ExrCompression> parse_exr_compression(std::string_view name) {
    for (const auto& [text, value] : kCompressionNames)
        if (text == name) return value;
    return std::nullopt;
}

int exr_lines_per_chunk(ExrCompression compression) {
    switch (compression) {
        case ExrCompression::none:
        case ExrCompression::rle:
        case ExrCompression::zips:
            return 1;
        case ExrCompression::zip:
        case ExrCompression::pxr24:
            return 16;
        case ExrCompression::piz:
        case ExrCompression::b44:
        case ExrCompression::b44a:
        case ExrCompression::dwaa:
            return 32;
        case ExrCompression::dwab:
            return 256;
    }
    return 256;
}

std::string_view to_string(ExrCompression compression) {
    for (const auto& [text, value] : kCompressionNames)
        if (value == compression) return text;
    return "unknown";
}

const int* ExrAttributes::find_int(std::string_view name) const {
    for (const auto& [key, value] : ints)
        if (key == name) return &value;
    return nullptr;
}

const std::string* ExrAttributes::find_string(std::string_view name) const {
    for (const auto& [key, value] : strings)
        if (key == name) return &value;
    return nullptr;
}

ExrRational exr_rational(double value) {
    const Imf::Rational r(value);
    return {r.n, r.d};
}

Image make_exr_image(const Image& render, const ExrWriteOptions& options,
                     const ExrAttributes& attributes, std::vector<ImageChannel> spare) {
    return exr_image_of(exr_sources(render, options, attributes), std::move(spare));
}

void write_exr(const std::string& path, const Image& image) {
    try {
        check_exr_image(image);
    } catch (const std::exception& e) {
        throw IoError("cannot write " + path + ": " + e.what());
    }
    write_file_atomically(path, [&](const std::string& tmp) { write_exr_file(tmp, image); });
}

ExrSources exr_sources(const Image& render, const ExrWriteOptions& options,
                       const ExrAttributes& attributes) {
    ExrSources exr;
    exr.display_window = render.display_window;
    exr.data_window = render.data_window;
    exr.compression = options.compression;
    exr.attributes = attributes;
    const PixelFormat type = options.float32 ? PixelFormat::float32 : PixelFormat::half;
    for (const ImageChannel& c : render.channels) {
        if (c.format != PixelFormat::float32)
            throw std::invalid_argument("exr_sources: channel " + c.name + " is " +
                                        std::string(to_string(c.format)) +
                                        ", not a render's float32");
        exr.channels.push_back({&c, type});
    }
    return exr;
}

void write_exr(const std::string& path, const Image& render, const ExrWriteOptions& options,
               const ExrAttributes& attributes) {
    try {
        require_render_image(render);
    } catch (const std::exception& e) {
        throw IoError("cannot write " + path + ": " + e.what());
    }
    write_exr(path, exr_sources(render, options, attributes));
}

void write_exr(const std::string& path, const ExrSources& sources) {
    // The file's image without samples: its header, and the checks write_exr(path, Image)
    // makes, on the sources' own samples.
    Image shape;
    shape.display_window = sources.display_window;
    shape.data_window = sources.data_window;
    shape.compression = sources.compression;
    shape.attributes = sources.attributes;
    try {
        std::vector<ChannelFacts> facts;
        for (const ExrChannelSource& c : sources.channels) {
            if (c.format != c.samples->format &&
                !(c.format == PixelFormat::half && c.samples->format == PixelFormat::float32))
                throw std::invalid_argument("channel '" + c.samples->name + "' holds " +
                                            std::string(to_string(c.samples->format)) +
                                            " samples, which are not " + "written as " +
                                            std::string(to_string(c.format)));
            shape.channels.push_back({c.samples->name, c.format, {}});
            facts.push_back({c.samples->name, c.samples->format, c.samples->samples.size()});
        }
        check_exr_layout(sources.display_window, sources.data_window, facts);
    } catch (const std::exception& e) {
        throw IoError("cannot write " + path + ": " + e.what());
    }
    if (!packs_chunks_itself(sources.compression)) {
        // OpenEXR packs these: the image is made, converted, and written as it is.
        const Image image = exr_image_of(sources);
        if (sources.on_read) sources.on_read();
        write_exr(path, image);
        return;
    }
    write_file_atomically(path, [&](const std::string& tmp) {
        const ChunkEncoder encoder(sources.channels, sources.data_window, sources.compression);
        write_exr_with_own_chunks(tmp, encoder, sources.data_window.y0, make_header(shape),
                                  sources.on_read);
    });
}

void set_exr_thread_count(int threads) { Imf::setGlobalThreadCount(threads); }

int exr_thread_count() { return Imf::globalThreadCount(); }

void detail::write_exr_by_openexr(const std::string& path, const Image& image) {
    check_exr_image(image);
    write_exr_with_openexr(path, image, make_header(image));
}

}  // namespace octray
