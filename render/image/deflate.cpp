// DEFLATE by ISA-L's igzip, and the checksums of zlib streams and PNG chunks (deflate.h).

#include "render/image/deflate.h"

#include <isa-l/crc.h>
#include <isa-l/igzip_lib.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace octray::detail {
namespace {

// This thread's stream state and the tables of each level, made on first use: the state is
// about 100 KB of history and hash heads, a level's buffer a few hundred KB, too much to
// make per chunk or to put on a worker's stack.
struct Igzip {
    isal_zstream stream;
    std::array<std::vector<std::uint8_t>, 4> level_buffers;  // levels 1 ... 3
};

Igzip& igzip() {
    thread_local const std::unique_ptr<Igzip> state = std::make_unique<Igzip>();
    return *state;
}

std::size_t level_buffer_size(int level) {
    switch (level) {
        case 1:
            return ISAL_DEF_LVL1_DEFAULT;
        case 2:
            return ISAL_DEF_LVL2_DEFAULT;
        case 3:
            return ISAL_DEF_LVL3_DEFAULT;
        default:
            return ISAL_DEF_LVL0_DEFAULT;
    }
}

// One call of isal_deflate_stateless at `level` on this thread's state: in[0, size) into
// out[0, capacity) as a zlib stream (IGZIP_ZLIB) or raw DEFLATE blocks (IGZIP_DEFLATE),
// ended (end_of_stream) or byte-aligned and independent of what follows (FULL_FLUSH).
// Returns the length written, or 0 when it does not fit in `capacity`.
std::size_t igzip_stateless(int level, std::uint16_t format, bool end_of_stream, const void* in,
                            std::size_t size, void* out, std::size_t capacity,
                            const char* caller) {
    if (level < 0 || level > 3)
        throw std::invalid_argument(std::string(caller) + ": deflate level " +
                                    std::to_string(level) + " is outside 0 ... 3");
    // One call takes at most 4 GiB in and out (the fields are 32 bits); a chunk or band
    // octray compresses is far smaller.
    if (size > UINT32_MAX)
        throw std::length_error(std::string(caller) + ": " + std::to_string(size) +
                                " bytes exceed one call's 4 GiB");
    Igzip& state = igzip();
    isal_zstream& s = state.stream;
    isal_deflate_stateless_init(&s);
    s.level = static_cast<std::uint32_t>(level);
    if (level > 0) {
        std::vector<std::uint8_t>& buffer =
            state.level_buffers[static_cast<std::size_t>(level)];
        if (buffer.empty()) buffer.resize(level_buffer_size(level));
        s.level_buf = buffer.data();
        s.level_buf_size = static_cast<std::uint32_t>(buffer.size());
    }
    s.gzip_flag = format;
    s.end_of_stream = end_of_stream ? 1 : 0;
    s.flush = end_of_stream ? NO_FLUSH : FULL_FLUSH;
    s.next_in = static_cast<std::uint8_t*>(const_cast<void*>(in));
    s.avail_in = static_cast<std::uint32_t>(size);
    s.next_out = static_cast<std::uint8_t*>(out);
    s.avail_out = static_cast<std::uint32_t>(std::min<std::size_t>(capacity, UINT32_MAX));
    const int status = isal_deflate_stateless(&s);
    if (status == STATELESS_OVERFLOW) return 0;  // it does not fit in `capacity`
    if (status != COMP_OK)
        throw std::runtime_error(std::string(caller) + ": igzip failed with status " +
                                 std::to_string(status));
    return s.total_out;
}

}  // namespace

std::size_t zlib_compress(int level, const void* in, std::size_t size, void* out,
                          std::size_t capacity) {
    return igzip_stateless(level, IGZIP_ZLIB, true, in, size, out, capacity, "zlib_compress");
}

std::size_t deflate_band_bound(std::size_t size) {
    // Stored: 5 bytes a block of at most 65535, the empty stored block of a flush, and
    // room for igzip's own header and the bits before a flush.
    return size + 5 * (size / 65535 + 2) + 64;
}

std::size_t deflate_band(int level, const std::uint8_t* in, std::size_t size, bool last,
                         std::uint8_t* out) {
    const std::size_t written = igzip_stateless(level, IGZIP_DEFLATE, last, in, size, out,
                                                deflate_band_bound(size), "deflate_band");
    if (written == 0)
        throw std::logic_error("deflate_band: " + std::to_string(size) +
                               " bytes did not fit in deflate_band_bound's room");
    return written;
}

std::uint32_t adler32(std::uint32_t adler, const void* data, std::size_t size) {
    return isal_adler32(adler, static_cast<const unsigned char*>(data), size);
}

std::uint32_t adler32_combine(std::uint32_t first, std::uint32_t second,
                              std::size_t second_size) {
    return static_cast<std::uint32_t>(
        ::adler32_combine(first, second, static_cast<z_off_t>(second_size)));
}

std::uint32_t crc32(std::uint32_t crc, const void* data, std::size_t size) {
    return crc32_gzip_refl(crc, static_cast<const unsigned char*>(data), size);
}

}  // namespace octray::detail
