#pragma once
// Checking one block ("chunk") of an OpenEXR file's pixel data against the file's header.
//
// A header names each channel's pixel type, and the type fixes how many bytes a chunk
// unpacks to. OpenEXR 3.1 does not always check that a chunk really unpacks to that many:
// a header declaring FLOAT channels over ZIP-compressed HALF data reads without an error,
// as garbage. These checks find such lying files for every codec OpenEXR 3.1 has, without
// decoding pixel values: the stored size, and the size the codec's own framing says the
// data unpacks to (zlib's stream end, RLE's runs, PIZ's Huffman code count, B44's blocks,
// DWA's section sizes), must match what the header implies.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "render/image/image_io.h"

namespace octray {

struct ExrChunkChannel {
    std::string name;
    PixelFormat type = PixelFormat::half;
};

// One chunk as the header describes it: the codec, the channels in the file's order
// (alphabetical) and the chunk's pixel rectangle (a scan-line block or a tile, clipped to
// the data window).
struct ExrChunkShape {
    ExrCompression compression = ExrCompression::none;
    std::vector<ExrChunkChannel> channels;
    std::int64_t width = 0;
    std::int64_t height = 0;
};

// The bytes the chunk unpacks to: every sample of every channel in its type's size.
std::uint64_t exr_unpacked_size(const ExrChunkShape& shape);

// Empty when the `size` stored bytes at `data` are a chunk of `shape`: either exactly its
// unpacked size (stored raw, as every OpenEXR writer does when a codec does not shrink
// the data) or fewer bytes that the codec's framing unpacks to exactly that size.
// Otherwise what is wrong, as a phrase ("holds 2368 bytes of ZIP data that unpack to 4736
// bytes, where the header's channels need 9472").
std::string exr_chunk_problem(const ExrChunkShape& shape, const unsigned char* data,
                              std::size_t size);

}  // namespace octray
