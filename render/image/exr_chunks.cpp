#include "render/image/exr_chunks.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <optional>

namespace octray {
namespace {

std::int64_t pixels(const ExrChunkShape& shape) { return shape.width * shape.height; }

// What a byte count is called in messages.
std::string bytes(std::uint64_t n) { return std::to_string(n) + (n == 1 ? " byte" : " bytes"); }

// The bytes a zlib stream unpacks to, counted without keeping them; stops counting once
// past `limit`. nullopt when the stream is damaged or ends early.
std::optional<std::uint64_t> inflated_size(const unsigned char* data, std::size_t size,
                                           std::uint64_t limit) {
    z_stream stream{};
    if (inflateInit(&stream) != Z_OK) return std::nullopt;
    std::array<unsigned char, 1 << 16> out;
    stream.next_in = const_cast<unsigned char*>(data);
    stream.avail_in = static_cast<uInt>(size);
    std::uint64_t total = 0;
    int status = Z_OK;
    while (status == Z_OK && total <= limit) {
        stream.next_out = out.data();
        stream.avail_out = static_cast<uInt>(out.size());
        status = inflate(&stream, Z_NO_FLUSH);
        total += out.size() - stream.avail_out;
        if (status == Z_BUF_ERROR && stream.avail_in == 0) break;  // input ran out
    }
    inflateEnd(&stream);
    if (total > limit) return total;
    if (status != Z_STREAM_END) return std::nullopt;
    return total;
}

// The same stream unpacked into memory (DWA's RLE section is zlib over RLE); nullopt
// unless it unpacks to exactly `expected` bytes.
std::optional<std::vector<unsigned char>> inflate_exactly(const unsigned char* data,
                                                          std::size_t size,
                                                          std::uint64_t expected) {
    std::vector<unsigned char> out(static_cast<std::size_t>(expected) + 1);
    uLongf length = static_cast<uLongf>(out.size());
    if (uncompress(out.data(), &length, data, static_cast<uLong>(size)) != Z_OK ||
        length != expected)
        return std::nullopt;
    out.resize(length);
    return out;
}

// OpenEXR's RLE: a signed count byte; -n is n literal bytes, n >= 0 is one byte repeated
// n + 1 times. nullopt when a run reaches past the data.
std::optional<std::uint64_t> rle_unpacked_size(const unsigned char* data, std::size_t size,
                                               std::uint64_t limit) {
    std::uint64_t total = 0;
    std::size_t i = 0;
    while (i < size && total <= limit) {
        const auto count = static_cast<signed char>(data[i++]);
        if (count < 0) {
            const auto literal = static_cast<std::size_t>(-count);
            if (size - i < literal) return std::nullopt;
            i += literal;
            total += literal;
        } else {
            if (i == size) return std::nullopt;
            ++i;
            total += static_cast<std::uint64_t>(count) + 1;
        }
    }
    return total;
}

// ---- PIZ -----------------------------------------------------------------------------
// A PIZ chunk: the 16-bit values' bitmap range and bitmap, then a Huffman-coded stream
// of the (wavelet-transformed) 16-bit values. The stream's values are counted by decoding
// its canonical code, as OpenEXR's coder builds it: a 20-byte header (smallest and
// largest symbol, table length, bit count, zero), code lengths packed 6 bits each with
// runs of zeros, then the code; the largest symbol is a run code followed by 8 bits, a
// repeat count of the previous value.

class BitReader {
  public:
    BitReader(const unsigned char* data, std::size_t size) : data_(data), size_(size) {}
    // Up to 32 bits, most significant first; nullopt past the end.
    std::optional<std::uint32_t> bits(int n) {
        std::uint32_t value = 0;
        for (int k = 0; k < n; ++k) {
            if (position_ >= 8 * static_cast<std::uint64_t>(size_)) return std::nullopt;
            const unsigned byte = data_[position_ / 8];
            value = (value << 1) | ((byte >> (7 - position_ % 8)) & 1u);
            ++position_;
        }
        return value;
    }
    // The bytes begun so far (the table ends on a byte boundary).
    std::size_t bytes_used() const { return static_cast<std::size_t>((position_ + 7) / 8); }
    std::uint64_t position() const { return position_; }

  private:
    const unsigned char* data_;
    std::size_t size_;
    std::uint64_t position_ = 0;
};

std::uint32_t read_u32_le(const unsigned char* p) {
    return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 |
           std::uint32_t{p[3]} << 24;
}

// The 16-bit values a PIZ Huffman stream decodes to, or a description of the damage.
struct Count {
    std::uint64_t values = 0;
    std::string problem;
};

Count huffman_value_count(const unsigned char* data, std::size_t size, std::uint64_t limit) {
    constexpr std::uint32_t encoding_size = (1u << 16) + 1;
    constexpr int max_length = 58;
    if (size < 20) return {0, size == 0 ? "" : "a cut-off PIZ code header"};
    const std::uint32_t smallest = read_u32_le(data);
    const std::uint32_t largest = read_u32_le(data + 4);
    const std::uint32_t bit_count = read_u32_le(data + 12);
    if (smallest >= encoding_size || largest >= encoding_size || smallest > largest)
        return {0, "a PIZ code table with an invalid symbol range"};
    // Code lengths, smallest..largest.
    std::vector<std::uint8_t> length(encoding_size, 0);
    BitReader table(data + 20, size - 20);
    for (std::uint32_t s = smallest; s <= largest; ++s) {
        const auto l = table.bits(6);
        if (!l) return {0, "a cut-off PIZ code table"};
        if (*l >= 59) {  // a run of zero lengths: 59..62 short, 63 long (8 more bits)
            std::uint32_t run = *l - 59 + 2;
            if (*l == 63) {
                const auto more = table.bits(8);
                if (!more) return {0, "a cut-off PIZ code table"};
                run = *more + 6;
            }
            if (s + run > largest + 1) return {0, "a PIZ code table longer than its range"};
            s += run - 1;  // those lengths stay 0
        } else {
            length[s] = static_cast<std::uint8_t>(*l);
        }
    }
    // Canonical codes, as OpenEXR assigns them: the longest codes take the smallest
    // values; codes of one length are consecutive, in symbol order.
    std::array<std::uint64_t, max_length + 1> count{}, first{};
    for (std::uint32_t s = smallest; s <= largest; ++s) ++count[length[s]];
    std::uint64_t c = 0;
    for (int l = max_length; l > 0; --l) {
        first[static_cast<std::size_t>(l)] = c;
        c = (c + count[static_cast<std::size_t>(l)]) >> 1;
    }
    const int run_length = length[largest];
    std::uint64_t run_code = first[static_cast<std::size_t>(run_length)];
    for (std::uint32_t s = smallest; s < largest; ++s)
        if (length[s] == run_length) ++run_code;

    const std::size_t start = table.bytes_used();
    const std::size_t code_bytes = (static_cast<std::uint64_t>(bit_count) + 7) / 8;
    if (code_bytes > size - 20 - start)
        return {0, "a PIZ code stream that runs past the chunk"};
    BitReader code(data + 20 + start, code_bytes);
    std::uint64_t values = 0;
    std::uint64_t value = 0;
    int l = 0;
    while (code.position() < bit_count && values <= limit) {
        value = (value << 1) | *code.bits(1);
        ++l;
        if (l > max_length) return {0, "an invalid PIZ code"};
        const auto ul = static_cast<std::size_t>(l);
        if (count[ul] == 0 || value < first[ul]) continue;
        if (value - first[ul] >= count[ul]) return {0, "an invalid PIZ code"};
        if (l == run_length && value == run_code) {
            if (values == 0) return {0, "a PIZ run with no value to repeat"};
            if (bit_count - code.position() < 8) return {0, "a cut-off PIZ run"};
            values += *code.bits(8);
        } else {
            ++values;
        }
        value = 0;
        l = 0;
    }
    if (values <= limit && l != 0) return {0, "a PIZ code stream that ends inside a code"};
    return {values, ""};
}

// ---- DWA -----------------------------------------------------------------------------
// A DWAA/DWAB chunk: eleven little-endian 64-bit sizes, then (version 2) the rules that
// sort channels into lossy DCT, RLE and "unknown" (zlib) by name suffix and type, then
// the four sections. DCT data does not depend on the channel's declared type; the RLE and
// unknown sections hold every sample in its type's size, and their sizes are in the
// chunk's header.

enum class DwaScheme { unknown = 0, lossy_dct = 1, rle = 2 };

struct DwaRule {
    std::string suffix;
    DwaScheme scheme = DwaScheme::unknown;
    bool case_insensitive = false;
    PixelFormat type = PixelFormat::half;
};

std::uint64_t read_u64_le(const unsigned char* p) {
    std::uint64_t v = 0;
    for (int k = 7; k >= 0; --k) v = (v << 8) | p[k];
    return v;
}

std::string lower(std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

bool matches(const DwaRule& rule, const ExrChunkChannel& channel) {
    if (rule.type != channel.type) return false;
    const std::size_t dot = channel.name.rfind('.');
    const std::string suffix =
        dot == std::string::npos ? channel.name : channel.name.substr(dot + 1);
    return rule.case_insensitive ? lower(suffix) == lower(rule.suffix) : suffix == rule.suffix;
}

// OpenEXR's pixel type numbers, as the rules store them.
std::optional<PixelFormat> pixel_type(unsigned value) {
    switch (value) {
        case 0:
            return PixelFormat::uint32;
        case 1:
            return PixelFormat::half;
        case 2:
            return PixelFormat::float32;
        default:
            return std::nullopt;
    }
}

std::string dwa_problem(const ExrChunkShape& shape, const unsigned char* data,
                        std::size_t size) {
    constexpr std::size_t header_size = 11 * 8;
    if (size < header_size) return "holds a cut-off DWA header";
    std::array<std::uint64_t, 11> field{};
    for (std::size_t k = 0; k < field.size(); ++k) field[k] = read_u64_le(data + 8 * k);
    const std::uint64_t version = field[0], unknown_raw = field[1], unknown_packed = field[2],
                        ac_packed = field[3], dc_packed = field[4], rle_packed = field[5],
                        rle_unpacked = field[6], rle_raw = field[7], dc_count = field[9];
    const std::uint64_t sections = unknown_packed + ac_packed + dc_packed + rle_packed;
    for (std::uint64_t s : {unknown_packed, ac_packed, dc_packed, rle_packed})
        if (s > size) return "holds DWA sections larger than the chunk";
    if (version > 2) return "holds DWA data of unknown version " + std::to_string(version);
    std::size_t offset = header_size;
    std::vector<DwaRule> rules;
    if (version == 2) {
        if (size - offset < 2) return "holds a cut-off DWA rule table";
        const std::size_t rules_size = data[offset] | std::size_t{data[offset + 1]} << 8;
        if (rules_size < 2 || rules_size > size - offset)
            return "holds a damaged DWA rule table";
        const std::size_t end = offset + rules_size;
        offset += 2;
        while (offset < end) {
            const auto nul = std::find(data + offset, data + end, 0);
            if (nul == data + end || end - static_cast<std::size_t>(nul - data) < 3)
                return "holds a damaged DWA rule table";
            DwaRule rule;
            rule.suffix.assign(reinterpret_cast<const char*>(data + offset),
                               static_cast<std::size_t>(nul - (data + offset)));
            const unsigned flags = nul[1];
            const auto type = pixel_type(nul[2]);
            const unsigned scheme = (flags >> 2) & 3u;
            if (!type || scheme > 2) return "holds a damaged DWA rule table";
            rule.scheme = static_cast<DwaScheme>(scheme);
            rule.case_insensitive = (flags & 1u) != 0;
            rule.type = *type;
            rules.push_back(rule);
            offset = static_cast<std::size_t>(nul - data) + 3;
        }
    }
    if (sections > size - offset)
        return "holds DWA sections of " + bytes(sections) + " where the chunk has " +
               bytes(size - offset) + " after its header";
    const unsigned char* unknown_data = data + offset;
    const unsigned char* rle_data = unknown_data + unknown_packed + ac_packed + dc_packed;

    // Version 1 files sort channels by rules built into the codec; only version 2 (every
    // OpenEXR since 2.2.1 writes it) carries the rules that tell which sizes to expect.
    if (version == 2) {
        std::uint64_t expect_unknown = 0, expect_rle = 0, dct_channels = 0;
        for (const ExrChunkChannel& channel : shape.channels) {
            DwaScheme scheme = DwaScheme::unknown;
            for (const DwaRule& rule : rules)  // the last matching rule wins, as in OpenEXR
                if (matches(rule, channel)) scheme = rule.scheme;
            const std::uint64_t raw =
                static_cast<std::uint64_t>(pixels(shape)) * sample_size(channel.type);
            if (scheme == DwaScheme::unknown) expect_unknown += raw;
            if (scheme == DwaScheme::rle) expect_rle += raw;
            if (scheme == DwaScheme::lossy_dct) ++dct_channels;
        }
        if (unknown_raw != expect_unknown)
            return "holds " + bytes(unknown_raw) +
                   " of zlib-coded DWA channels where the header's channels need " +
                   bytes(expect_unknown);
        if (rle_raw != expect_rle)
            return "holds " + bytes(rle_raw) +
                   " of RLE-coded DWA channels where the header's channels need " +
                   bytes(expect_rle);
        const std::uint64_t blocks = static_cast<std::uint64_t>((shape.width + 7) / 8) *
                                     static_cast<std::uint64_t>((shape.height + 7) / 8);
        if (dc_count != dct_channels * blocks)
            return "holds " + std::to_string(dc_count) +
                   " DWA DC values where the header's channels need " +
                   std::to_string(dct_channels * blocks);
    }
    if (unknown_packed > 0) {
        const auto n = inflated_size(unknown_data, unknown_packed, unknown_raw);
        if (!n || *n != unknown_raw) return "holds a damaged zlib-coded DWA section";
    }
    if (rle_packed > 0) {
        if (rle_unpacked > exr_unpacked_size(shape) * 2 + 1024)
            return "holds an RLE-coded DWA section larger than its channels";
        const auto unpacked = inflate_exactly(rle_data, rle_packed, rle_unpacked);
        if (!unpacked) return "holds a damaged RLE-coded DWA section";
        const auto n = rle_unpacked_size(unpacked->data(), unpacked->size(), rle_raw);
        if (!n || *n != rle_raw) return "holds a damaged RLE-coded DWA section";
    }
    return {};
}

// ---- B44 -----------------------------------------------------------------------------
// HALF channels in 4x4 blocks of 14 bytes, or 3 bytes for a flat block (its third byte
// >= 13 << 2); other channels raw. The blocks and raw samples must fill the chunk.
std::string b44_problem(const ExrChunkShape& shape, const unsigned char* data,
                        std::size_t size) {
    std::size_t at = 0;
    for (const ExrChunkChannel& channel : shape.channels) {
        if (channel.type != PixelFormat::half) {
            const std::uint64_t raw = static_cast<std::uint64_t>(pixels(shape)) * 4;
            if (raw > size - at) return "holds B44 data that ends inside its channels";
            at += static_cast<std::size_t>(raw);
            continue;
        }
        const std::uint64_t blocks = static_cast<std::uint64_t>((shape.width + 3) / 4) *
                                     static_cast<std::uint64_t>((shape.height + 3) / 4);
        for (std::uint64_t b = 0; b < blocks; ++b) {
            if (size - at < 3) return "holds B44 data that ends inside its channels";
            const std::size_t block = data[at + 2] >= (13 << 2) ? 3 : 14;
            if (size - at < block) return "holds B44 data that ends inside its channels";
            at += block;
        }
    }
    if (at != size)
        return "holds " + bytes(size) + " of B44 data, " + bytes(size - at) +
               " more than the header's channels need";
    return {};
}

std::string unpacks_to(std::size_t size, std::string_view codec, std::uint64_t got,
                       std::uint64_t expected, std::uint64_t limit) {
    return "holds " + bytes(size) + " of " + std::string(codec) + " data that unpack to " +
           (got > limit ? "more than " + bytes(limit) : bytes(got)) +
           ", where the header's channels need " + bytes(expected);
}

std::string codec_name(ExrCompression c) {
    std::string name(to_string(c));
    for (char& ch : name) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
    return name;
}

}  // namespace

std::uint64_t exr_unpacked_size(const ExrChunkShape& shape) {
    std::uint64_t per_pixel = 0;
    for (const ExrChunkChannel& channel : shape.channels)
        per_pixel += sample_size(channel.type);
    return static_cast<std::uint64_t>(pixels(shape)) * per_pixel;
}

std::string exr_chunk_problem(const ExrChunkShape& shape, const unsigned char* data,
                              std::size_t size) {
    const std::uint64_t expected = exr_unpacked_size(shape);
    if (size == expected) return {};  // stored raw
    if (size > expected)
        return "holds " + bytes(size) + ", more than the " + bytes(expected) +
               " the header's channels need even uncompressed";
    const std::string codec = codec_name(shape.compression);
    switch (shape.compression) {
        case ExrCompression::none:
            return "holds " + bytes(size) + " of uncompressed data where the header's " +
                   "channels need " + bytes(expected);
        case ExrCompression::rle: {
            const auto n = rle_unpacked_size(data, size, expected);
            if (!n) return "holds RLE data with a run past the chunk's end";
            return *n == expected ? std::string()
                                  : unpacks_to(size, codec, *n, expected, expected);
        }
        case ExrCompression::zips:
        case ExrCompression::zip: {
            const auto n = inflated_size(data, size, expected);
            if (!n) return "holds damaged or cut-off " + codec + " (zlib) data";
            return *n == expected ? std::string()
                                  : unpacks_to(size, codec, *n, expected, expected);
        }
        case ExrCompression::pxr24: {
            // PXR24 keeps 24 bits of a FLOAT, all of a HALF or UINT, then deflates.
            std::uint64_t packed = 0;
            for (const ExrChunkChannel& channel : shape.channels)
                packed += channel.type == PixelFormat::float32 ? 3 : sample_size(channel.type);
            packed *= static_cast<std::uint64_t>(pixels(shape));
            const auto n = inflated_size(data, size, packed);
            if (!n) return "holds damaged or cut-off PXR24 (zlib) data";
            return *n == packed ? std::string() : unpacks_to(size, codec, *n, packed, packed);
        }
        case ExrCompression::piz: {
            // Minimum and maximum non-zero bitmap bytes, the bitmap, the code's length.
            if (size < 4) return "holds a cut-off PIZ header";
            const unsigned low = data[0] | unsigned{data[1]} << 8;
            const unsigned high = data[2] | unsigned{data[3]} << 8;
            std::size_t at = 4;
            if (low <= high) {
                if (high >= 8192) return "holds a PIZ bitmap out of range";
                at += high - low + 1;
            }
            if (size < at + 4) return "holds a cut-off PIZ header";
            const std::uint32_t length = read_u32_le(data + at);
            at += 4;
            if (length > size - at) return "holds a PIZ code longer than the chunk";
            const std::uint64_t wanted = expected / 2;  // PIZ codes 16-bit values
            const Count n = huffman_value_count(data + at, length, wanted);
            if (!n.problem.empty()) return "holds " + n.problem;
            if (n.values == wanted) return {};
            return "holds PIZ data that decode to " +
                   (n.values > wanted ? "more than " + std::to_string(wanted)
                                      : std::to_string(n.values)) +
                   " 16-bit values, where the header's channels need " + std::to_string(wanted);
        }
        case ExrCompression::b44:
        case ExrCompression::b44a:
            return b44_problem(shape, data, size);
        case ExrCompression::dwaa:
        case ExrCompression::dwab:
            return dwa_problem(shape, data, size);
    }
    return {};
}

}  // namespace octray
