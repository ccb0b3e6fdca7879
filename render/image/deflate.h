#pragma once
// DEFLATE by ISA-L's igzip: zlib streams (RFC 1950) for the ZIP and ZIPS chunks of the EXRs
// octray writes (exr_write.cpp), and bands of one stream for the pixel data of its PNGs
// (png.cpp). igzip compresses three to four times as fast as libdeflate's fastest levels,
// files about a tenth larger (the level each writer uses, and why: render/image/README.md,
// "Compression").

#include <cstddef>
#include <cstdint>

namespace octray::detail {

// Compresses in[0, size) at igzip's `level` (0 fastest ... 3 smallest) into out[0,
// capacity) as one zlib stream and returns its length; 0 when it does not fit in
// `capacity`, so that a caller who gives capacity = size - 1 learns that the data does not
// compress. Each thread keeps its stream state and each level's tables for the life of the
// thread.
std::size_t zlib_compress(int level, const void* in, std::size_t size, void* out,
                          std::size_t capacity);

// ---- Bands of one DEFLATE stream, compressed in parallel ---------------------------------
// zlib_compress makes one whole stream of a buffer, so one PNG's pixels would be
// compressed on one thread. deflate_band compresses a band of them at igzip's `level` into
// raw DEFLATE blocks (RFC 1951) that refer to nothing before the band and end on a byte
// boundary (igzip's full flush: an empty stored block), so that bands compressed on their
// own, in order, make one stream; `last` marks the band that ends it.

// The room deflate_band needs for `size` bytes: data that does not compress is stored.
std::size_t deflate_band_bound(std::size_t size);

// Compresses in[0, size) into out (deflate_band_bound(size) bytes) and returns the length
// written.
std::size_t deflate_band(int level, const std::uint8_t* in, std::size_t size, bool last,
                         std::uint8_t* out);

// ---- Checksums (deflate.cpp) --------------------------------------------------------------
// Adler-32 (a zlib stream's checksum) of data[0, size), continuing from `adler` (1 to
// start), by igzip; and the Adler-32 of A followed by B from A's, B's and B's length,
// by zlib (what joins the bands' sums).
std::uint32_t adler32(std::uint32_t adler, const void* data, std::size_t size);
std::uint32_t adler32_combine(std::uint32_t first, std::uint32_t second,
                              std::size_t second_size);

// CRC-32 (the PNG chunk's) of data[0, size), continuing from `crc` (0 to start), by
// ISA-L.
std::uint32_t crc32(std::uint32_t crc, const void* data, std::size_t size);

}  // namespace octray::detail
