#pragma once
// zlib streams (RFC 1950) made by libdeflate, for the files octray compresses itself: the
// ZIP and ZIPS chunks of its EXRs (exr_write.cpp) and the pixel data of its PNGs
// (png.cpp). libdeflate compresses a whole buffer at once, faster than zlib at the same
// size (the level each writer uses, and why: render/image/README.md, "Compression").

#include <cstddef>
#include <cstdint>

namespace octray::detail {

// Compresses in[0, size) at `level` (1 fastest ... 12 smallest) into out[0, capacity) as
// one zlib stream and returns its length; 0 when it does not fit in `capacity`, so that a
// caller who gives capacity = size - 1 learns that the data does not compress. Each
// thread keeps one compressor per level for the life of the thread.
std::size_t zlib_compress(int level, const void* in, std::size_t size, void* out,
                          std::size_t capacity);

// The most bytes zlib_compress can need for `size` bytes at `level`.
std::size_t zlib_compress_bound(int level, std::size_t size);

// CRC-32 (the PNG chunk's) of data[0, size), continuing from `crc` (0 to start).
std::uint32_t crc32(std::uint32_t crc, const void* data, std::size_t size);

}  // namespace octray::detail
