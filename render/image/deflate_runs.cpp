// DEFLATE bands of literals, runs and pixel repeats (deflate.h): a compressor small enough
// to read whole, written for the PNG preview, whose bands are compressed on all threads at
// once.
//
// A band becomes one dynamic-Huffman block (RFC 1951, 3.2.7). Its only matches are at two
// fixed distances: 1, a byte repeated (what zlib's Z_RLE strategy finds), and a pixel's
// size, a pixel's bytes repeated. On filtered pixel rows that is most of what a match
// finder would find (a flat area filters to zeros), and finding them needs no hash table:
// one pass compares each byte with those 1 and `repeat` before it, 32 at a time. What it
// misses are repeats at other distances (a texture, identical objects), which a general
// LZ77 matcher such as igzip's or libdeflate's finds (render/image/README.md, "Compression").
// Three passes over a band: the matches, the histogram, then the codes.

#include <emmintrin.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/image/deflate.h"

namespace octray::detail {
namespace {

constexpr int kMaxCodeBits = 15;       // literal/length and distance codes
constexpr int kMaxCodeLengthBits = 7;  // the code that codes the code lengths
constexpr int kLiteralLengthCodes = 286;
constexpr int kEndOfBlock = 256;
constexpr int kDistanceCodes = 4;  // distances 1 ... 4, the only ones used
constexpr int kMinMatch = 3;
constexpr int kMaxMatch = 258;
constexpr std::size_t kMaxStored = 65535;  // bytes in one stored block

// Length codes 257 ... 285: the first length of each and its extra bits (RFC 1951, 3.2.5).
constexpr std::array<std::uint16_t, 29> kLengthBase = {
    3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
    31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
constexpr std::array<std::uint8_t, 29> kLengthExtra = {
    0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};

// The length code (0 ... 28, for symbols 257 ... 285) of each match length 3 ... 258.
constexpr std::array<std::uint8_t, kMaxMatch + 1> kLengthCode = [] {
    std::array<std::uint8_t, kMaxMatch + 1> code{};
    for (int c = 0; c < 29; ++c)
        for (int length = kLengthBase[c]; length <= kMaxMatch; ++length)
            code[length] = static_cast<std::uint8_t>(c);  // the last code whose base fits
    return code;
}();

// The order in which a dynamic block lists the code lengths of the code-length code.
constexpr std::array<std::uint8_t, 19> kCodeLengthOrder = {16, 17, 18, 0, 8,  7, 9,  6, 10, 5,
                                                           11, 4,  12, 3, 13, 2, 14, 1, 15};

// Bits, least significant first, as DEFLATE packs them (RFC 1951, 3.1.1). put() only
// adds to a 64-bit word; flush() writes its whole bytes, 8 bytes at a time (so the output
// needs 8 bytes of room past its end), and must come before more than 56 bits are added.
class BitWriter {
  public:
    explicit BitWriter(std::uint8_t* out) : out_(out) {}
    void put(std::uint32_t value, int count) {
        bits_ |= std::uint64_t{value} << filled_;
        filled_ += count;
    }
    void flush() {
        std::memcpy(out_, &bits_, 8);  // little-endian host
        out_ += filled_ >> 3;
        bits_ = (filled_ & ~7) == 64 ? 0 : bits_ >> (filled_ & ~7);
        filled_ &= 7;
    }
    void put_flushed(std::uint32_t value, int count) {
        put(value, count);
        flush();
    }
    // Pads with zero bits to the next byte and writes what is left.
    void align() {
        flush();
        if (filled_ > 0) *out_++ = static_cast<std::uint8_t>(bits_);
        filled_ = 0;
        bits_ = 0;
    }
    void put_bytes(const std::uint8_t* data, std::size_t size) {  // after align()
        if (size == 0) return;  // data may be null then (an empty band)
        std::memcpy(out_, data, size);
        out_ += size;
    }
    std::uint8_t* end() const { return out_; }

  private:
    std::uint8_t* out_;
    std::uint64_t bits_ = 0;
    int filled_ = 0;
};

// Code lengths of a prefix code for the symbols of nonzero frequency, none longer than
// `limit`: Huffman's, and when that is too deep, Huffman's of the frequencies halved
// (and made odd, so that none becomes 0) until it fits; the codes a band needs fit at once
// unless a few symbols dominate. At least two symbols must have a nonzero frequency, so
// that the code is complete (a decoder may refuse an incomplete one).
void code_lengths(const std::uint32_t* frequency, int symbols, int limit,
                  std::uint8_t* lengths) {
    std::vector<std::uint32_t> weight(frequency, frequency + symbols);
    std::vector<int> leaves;
    for (int s = 0; s < symbols; ++s)
        if (weight[static_cast<std::size_t>(s)] != 0) leaves.push_back(s);
    const std::size_t n = leaves.size();
    std::fill(lengths, lengths + symbols, 0);
    if (n < 2) {  // not a code; given a length so that a caller's sums stay sound
        for (int s : leaves) lengths[s] = 1;
        return;
    }
    std::vector<std::uint64_t> node_weight(2 * n);
    std::vector<std::size_t> parent(2 * n);
    std::vector<int> depth(2 * n);
    for (;;) {
        std::sort(leaves.begin(), leaves.end(), [&](int a, int b) {
            return weight[static_cast<std::size_t>(a)] != weight[static_cast<std::size_t>(b)]
                       ? weight[static_cast<std::size_t>(a)] <
                             weight[static_cast<std::size_t>(b)]
                       : a < b;
        });
        for (std::size_t i = 0; i < n; ++i)
            node_weight[i] = weight[static_cast<std::size_t>(leaves[i])];
        // Two queues in increasing weight: the leaves, then the nodes as they are made.
        std::size_t leaf = 0, inner = n, made = n;
        const auto lightest = [&]() {
            if (leaf < n && (inner == made || node_weight[leaf] <= node_weight[inner]))
                return leaf++;
            return inner++;
        };
        for (std::size_t k = 0; k + 1 < n; ++k) {
            const std::size_t a = lightest(), b = lightest();
            node_weight[made] = node_weight[a] + node_weight[b];
            parent[a] = parent[b] = made++;
        }
        int deepest = 0;
        depth[made - 1] = 0;
        for (std::size_t i = made - 1; i-- > 0;) {
            depth[i] = depth[parent[i]] + 1;
            deepest = std::max(deepest, depth[i]);
        }
        if (deepest <= limit) break;
        for (std::uint32_t& w : weight)
            if (w != 0) w = (w >> 1) | 1;
    }
    for (std::size_t i = 0; i < n; ++i)
        lengths[leaves[i]] = static_cast<std::uint8_t>(depth[i]);
}

// The low `bits` bits of `code` in reverse order.
std::uint32_t reversed(std::uint32_t code, int bits) {
    std::uint32_t out = 0;
    for (int i = 0; i < bits; ++i, code >>= 1) out = (out << 1) | (code & 1);
    return out;
}

// A prefix code: each symbol's length and its canonical code (RFC 1951, 3.2.2), the code
// bit-reversed, as DEFLATE sends a code's most significant bit first into a stream packed
// least significant bit first.
template <int Symbols>
struct Code {
    std::array<std::uint8_t, Symbols> length{};
    std::array<std::uint32_t, Symbols> bits{};

    Code(const std::uint32_t* frequency, int limit) {
        code_lengths(frequency, Symbols, limit, length.data());
        int count[kMaxCodeBits + 1] = {};
        for (std::uint8_t l : length) ++count[l];
        count[0] = 0;
        std::uint32_t next[kMaxCodeBits + 1] = {};
        for (int l = 1; l <= kMaxCodeBits; ++l) next[l] = (next[l - 1] + count[l - 1]) << 1;
        for (int s = 0; s < Symbols; ++s)
            if (length[s] != 0) bits[s] = reversed(next[length[s]]++, length[s]);
    }
    void put(BitWriter& out, int symbol) const { out.put(bits[symbol], length[symbol]); }
    // Bits to send `frequency[s]` of each symbol s, extra bits not counted.
    std::uint64_t cost(const std::uint32_t* frequency) const {
        std::uint64_t total = 0;
        for (int s = 0; s < Symbols; ++s) total += std::uint64_t{frequency[s]} * length[s];
        return total;
    }
};

// A match: bytes [start, start + length) of a band equal to those `distance` before them.
struct Match {
    std::size_t start;
    std::size_t length;
    std::size_t distance;  // 1 or the repeat distance
};

// Bit k: in[i + k] == in[i + k - distance], for k < 32.
inline std::uint32_t equal_mask(const std::uint8_t* in, std::size_t i, std::size_t distance) {
    const auto* p = reinterpret_cast<const __m128i*>(in + i);
    const auto* q = reinterpret_cast<const __m128i*>(in + i - distance);
    const auto low = static_cast<std::uint32_t>(
        _mm_movemask_epi8(_mm_cmpeq_epi8(_mm_loadu_si128(p), _mm_loadu_si128(q))));
    const auto high = static_cast<std::uint32_t>(
        _mm_movemask_epi8(_mm_cmpeq_epi8(_mm_loadu_si128(p + 1), _mm_loadu_si128(q + 1))));
    return low | high << 16;
}

// How many bytes from `at` on equal those `distance` before them, up to `size`.
std::size_t match_end(const std::uint8_t* in, std::size_t size, std::size_t at,
                      std::size_t distance) {
    std::size_t end = at;
    for (; end + 16 <= size; end += 16) {
        const __m128i now = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + end));
        const __m128i before =
            _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + end - distance));
        const int equal = _mm_movemask_epi8(_mm_cmpeq_epi8(now, before));
        if (equal != 0xFFFF)
            return end +
                   static_cast<std::size_t>(std::countr_one(static_cast<unsigned>(equal)));
    }
    while (end < size && in[end] == in[end - distance]) ++end;
    return end;
}

// The matches of in[0, size) at least kMinMatch long, in order, found greedily: at
// distance 1 (a byte repeated) and at `repeat` (a pixel's bytes repeated; 1 for none).
// A match starts where three bytes in a row equal those one (or `repeat`) before; 32
// bytes are compared at a time, of which the first 30 can start a match whose three bytes
// are all in view.
void find_matches(const std::uint8_t* in, std::size_t size, std::size_t repeat,
                  std::vector<Match>& matches) {
    matches.clear();
    std::size_t i = repeat;
    const auto starts_at = [&](std::size_t at, std::size_t distance) {
        return in[at] == in[at - distance] && in[at + 1] == in[at + 1 - distance] &&
               in[at + 2] == in[at + 2 - distance];
    };
    while (i + kMinMatch <= size) {
        for (; i + 32 <= size; i += 30) {
            std::uint32_t equal = equal_mask(in, i, 1);
            std::uint32_t starts = equal & equal >> 1 & equal >> 2;
            if (repeat != 1) {
                equal = equal_mask(in, i, repeat);
                starts |= equal & equal >> 1 & equal >> 2;
            }
            starts &= 0x3FFFFFFFu;
            if (starts != 0) {
                i += static_cast<std::size_t>(std::countr_zero(starts));
                break;
            }
        }
        if (i + 32 > size)  // the last bytes, one at a time
            while (i + kMinMatch <= size && !starts_at(i, 1) && !starts_at(i, repeat)) ++i;
        if (i + kMinMatch > size) break;
        // The longer of the two (distance 1 when they tie).
        const std::size_t run = starts_at(i, 1) ? match_end(in, size, i, 1) : i;
        const std::size_t pixels =
            repeat != 1 && starts_at(i, repeat) ? match_end(in, size, i, repeat) : i;
        const std::size_t end = std::max(run, pixels);
        matches.push_back({i, end - i, pixels > run ? repeat : 1});
        i = end;
    }
}

// Calls match(length) for the matches that code a run of `length` >= kMinMatch bytes:
// 258 at a time, the last one or two shorter so that none is below kMinMatch.
template <class Match>
void for_each_match(std::size_t length, Match&& match) {
    while (length > 0) {
        std::size_t part = std::min<std::size_t>(length, kMaxMatch);
        if (length - part != 0 && length - part < kMinMatch) part = length - kMinMatch;
        match(static_cast<int>(part));
        length -= part;
    }
}

// Stored blocks of in[0, size) (RFC 1951, 3.2.4): what a band that does not compress costs.
std::size_t stored_bytes(std::size_t size) {
    return size + 5 * std::max<std::size_t>(1, (size + kMaxStored - 1) / kMaxStored);
}

void put_stored(BitWriter& out, const std::uint8_t* in, std::size_t size, bool last) {
    std::size_t done = 0;
    do {
        const std::size_t part = std::min(size - done, kMaxStored);
        const bool final_block = last && done + part == size;
        out.put(final_block ? 1 : 0, 1);
        out.put(0, 2);  // stored
        out.align();
        const std::uint8_t header[4] = {
            static_cast<std::uint8_t>(part), static_cast<std::uint8_t>(part >> 8),
            static_cast<std::uint8_t>(~part), static_cast<std::uint8_t>(~part >> 8)};
        out.put_bytes(header, 4);
        out.put_bytes(in + done, part);
        done += part;
    } while (done < size);
}

// The code lengths of a dynamic block's two codes, as the code-length alphabet codes them:
// 0 ... 15 a length, 16 the previous length 3-6 times, 17 and 18 zero 3-10 and 11-138
// times, with their extra bits.
struct LengthToken {
    std::uint8_t symbol;
    std::uint8_t extra;
};

std::vector<LengthToken> length_tokens(const std::uint8_t* lengths, int count) {
    std::vector<LengthToken> tokens;
    for (int i = 0; i < count;) {
        const std::uint8_t value = lengths[i];
        int repeat = 1;
        while (i + repeat < count && lengths[i + repeat] == value) ++repeat;
        i += repeat;
        if (value == 0) {
            while (repeat >= 11) {
                const int n = std::min(repeat, 138);
                tokens.push_back({18, static_cast<std::uint8_t>(n - 11)});
                repeat -= n;
            }
            if (repeat >= 3) {
                tokens.push_back({17, static_cast<std::uint8_t>(repeat - 3)});
                repeat = 0;
            }
        } else {
            tokens.push_back({value, 0});
            --repeat;
            while (repeat >= 3) {
                const int n = std::min(repeat, 6);
                tokens.push_back({16, static_cast<std::uint8_t>(n - 3)});
                repeat -= n;
            }
        }
        for (; repeat > 0; --repeat) tokens.push_back({value, 0});
    }
    return tokens;
}

constexpr int kLengthExtraBits[19] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 3, 7};

}  // namespace

std::size_t deflate_band_bound(std::size_t size) {
    // The smaller of the two forms is written, so the stored form bounds it; 5 bytes more
    // for the empty stored block that ends a band that is not the last, and 8 for the
    // bit writer's last 8-byte store.
    return stored_bytes(size) + 5 + 8;
}

std::size_t deflate_band(const std::uint8_t* in, std::size_t size, std::size_t repeat,
                         bool last, std::uint8_t* out) {
    if (repeat < 1 || repeat > kDistanceCodes)
        throw std::invalid_argument("deflate_band: repeat distance " + std::to_string(repeat) +
                                    " is outside 1 ... 4");
    BitWriter bits(out);
    if (size == 0) {
        if (last) put_stored(bits, in, 0, true);
        return static_cast<std::size_t>(bits.end() - out);
    }
    thread_local std::vector<Match> matches;
    find_matches(in, size, repeat, matches);

    // Symbol frequencies: the literals between the runs (four tables, so that bytes in a
    // row rarely wait on one counter), and the matches that code each run.
    std::uint32_t literal[4][256] = {};
    const auto count_literals = [&](std::size_t from, std::size_t to) {
        for (; from + 4 <= to; from += 4) {
            ++literal[0][in[from]];
            ++literal[1][in[from + 1]];
            ++literal[2][in[from + 2]];
            ++literal[3][in[from + 3]];
        }
        for (; from < to; ++from) ++literal[0][in[from]];
    };
    std::uint32_t frequency[kLiteralLengthCodes] = {};
    frequency[kEndOfBlock] = 1;
    // Distances 1 ... 4 are codes 0 ... 3, without extra bits.
    std::uint32_t distance_frequency[kDistanceCodes] = {};
    std::uint64_t extra_bits = 0;
    std::size_t at = 0;
    for (const Match& match : matches) {
        count_literals(at, match.start);
        at = match.start + match.length;
        for_each_match(match.length, [&](int length) {
            const int code = kLengthCode[static_cast<std::size_t>(length)];
            ++frequency[257 + code];
            extra_bits += kLengthExtra[static_cast<std::size_t>(code)];
            ++distance_frequency[match.distance - 1];
        });
    }
    count_literals(at, size);
    for (int b = 0; b < 256; ++b)
        frequency[b] = literal[0][b] + literal[1][b] + literal[2][b] + literal[3][b];
    const Code<kLiteralLengthCodes> code(frequency, kMaxCodeBits);
    // Every distance code counted once more, so that the code is complete (a decoder may
    // refuse an incomplete one) whichever distances the band uses.
    std::uint32_t distance_weight[kDistanceCodes];
    for (int d = 0; d < kDistanceCodes; ++d) distance_weight[d] = distance_frequency[d] + 1;
    const Code<kDistanceCodes> distance(distance_weight, kMaxCodeBits);

    // The block's header: both codes' lengths, coded by the code-length code.
    int literal_codes = kLiteralLengthCodes;
    while (code.length[static_cast<std::size_t>(literal_codes - 1)] == 0) --literal_codes;
    std::uint8_t lengths[kLiteralLengthCodes + kDistanceCodes];
    std::copy_n(code.length.begin(), literal_codes, lengths);
    std::copy_n(distance.length.begin(), kDistanceCodes, lengths + literal_codes);
    const std::vector<LengthToken> tokens =
        length_tokens(lengths, literal_codes + kDistanceCodes);
    std::uint32_t token_frequency[19] = {};
    for (const LengthToken& t : tokens) ++token_frequency[t.symbol];
    // At least two symbols, so that the code-length code is complete.
    if (std::count_if(token_frequency, token_frequency + 19,
                      [](std::uint32_t f) { return f; }) < 2)
        ++token_frequency[token_frequency[0] != 0 ? 1 : 0];
    const Code<19> length_code(token_frequency, kMaxCodeLengthBits);
    int length_codes = 19;
    while (length_codes > 4 &&
           length_code.length[kCodeLengthOrder[static_cast<std::size_t>(length_codes - 1)]] ==
               0)
        --length_codes;

    // Whichever is smaller: the Huffman block, or the band stored.
    std::uint64_t header_bits = 3 + 5 + 5 + 4 + 3 * static_cast<std::uint64_t>(length_codes);
    for (const LengthToken& t : tokens)
        header_bits += length_code.length[t.symbol] + kLengthExtraBits[t.symbol];
    const std::uint64_t huffman_bits =
        header_bits + code.cost(frequency) + extra_bits + distance.cost(distance_frequency);
    const bool stored = huffman_bits / 8 + 1 >= stored_bytes(size);
    if (stored) {
        put_stored(bits, in, size, last);
    } else {
        bits.put(last ? 1 : 0, 1);
        bits.put(2, 2);  // dynamic Huffman codes
        bits.put(static_cast<std::uint32_t>(literal_codes - 257), 5);
        bits.put(kDistanceCodes - 1, 5);
        bits.put_flushed(static_cast<std::uint32_t>(length_codes - 4), 4);
        for (int k = 0; k < length_codes; ++k)
            bits.put_flushed(length_code.length[kCodeLengthOrder[static_cast<std::size_t>(k)]],
                             3);
        for (const LengthToken& t : tokens) {
            length_code.put(bits, t.symbol);
            bits.put_flushed(t.extra, kLengthExtraBits[t.symbol]);
        }
        // Three codes of at most 15 bits between flushes, which leave at most 7 bits.
        at = 0;
        const auto literals_to = [&](std::size_t end) {
            for (; at + 3 <= end; at += 3) {
                code.put(bits, in[at]);
                code.put(bits, in[at + 1]);
                code.put(bits, in[at + 2]);
                bits.flush();
            }
            for (; at < end; ++at) {
                code.put(bits, in[at]);
                bits.flush();
            }
        };
        for (const Match& match : matches) {
            literals_to(match.start);
            for_each_match(match.length, [&](int length) {
                const auto c =
                    static_cast<std::size_t>(kLengthCode[static_cast<std::size_t>(length)]);
                code.put(bits, 257 + static_cast<int>(c));
                bits.put(static_cast<std::uint32_t>(length - kLengthBase[c]), kLengthExtra[c]);
                distance.put(bits, static_cast<int>(match.distance) - 1);
                bits.flush();
            });
            at = match.start + match.length;
        }
        literals_to(size);
        code.put(bits, kEndOfBlock);
        bits.flush();
    }
    // A band that is not the last ends on a byte boundary, with an empty stored block (as
    // zlib's Z_SYNC_FLUSH does), so that the next band's bytes can follow it.
    // (Stored blocks end on one already.)
    if (!last && !stored) put_stored(bits, in, 0, false);
    bits.align();
    return static_cast<std::size_t>(bits.end() - out);
}

}  // namespace octray::detail
