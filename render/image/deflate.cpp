// zlib streams by libdeflate, and the checksums of zlib streams and PNG chunks (deflate.h).

#include "render/image/deflate.h"

#include <libdeflate.h>
#include <zlib.h>

#include <array>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>

namespace octray::detail {
namespace {

struct FreeCompressor {
    void operator()(libdeflate_compressor* c) const { libdeflate_free_compressor(c); }
};
using Compressor = std::unique_ptr<libdeflate_compressor, FreeCompressor>;

// This thread's compressor for `level`, made on first use: one costs a few hundred KB of
// tables, too much to make per chunk.
libdeflate_compressor* compressor(int level) {
    if (level < 1 || level > 12)
        throw std::invalid_argument("deflate level " + std::to_string(level) +
                                    " is outside 1 ... 12");
    thread_local std::array<Compressor, 13> compressors;
    Compressor& c = compressors[static_cast<std::size_t>(level)];
    if (!c) {
        c.reset(libdeflate_alloc_compressor(level));
        if (!c) throw std::bad_alloc();
    }
    return c.get();
}

}  // namespace

std::size_t zlib_compress(int level, const void* in, std::size_t size, void* out,
                          std::size_t capacity) {
    return libdeflate_zlib_compress(compressor(level), in, size, out, capacity);
}

std::uint32_t adler32(std::uint32_t adler, const void* data, std::size_t size) {
    return libdeflate_adler32(adler, data, size);
}

std::uint32_t adler32_combine(std::uint32_t first, std::uint32_t second,
                              std::size_t second_size) {
    return static_cast<std::uint32_t>(
        ::adler32_combine(first, second, static_cast<z_off_t>(second_size)));
}

std::uint32_t crc32(std::uint32_t crc, const void* data, std::size_t size) {
    return libdeflate_crc32(crc, data, size);
}

}  // namespace octray::detail
