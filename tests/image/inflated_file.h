#pragma once
// What an EXR or PNG file holds once its DEFLATE streams are inflated, for tests that hold
// two writes of the same pixels to each other.
//
// Comparing the files byte for byte asks more than octray can promise: igzip, which
// compresses the ZIP chunks and the PNG's stream (render/image/deflate.h), now and then
// encodes the same bytes differently (a chunk of 230 KB came out 1-4 bytes longer or
// shorter, about one compression in 10,000 to 20,000) when octray's writer runs on two
// CPUs, never with the process pinned to one; docs/performance-log.md, "igzip's output is
// not always the same". Both encodings inflate to the same bytes, so these helpers compare
// what the files say: every byte that is not compressed data, and the compressed data
// inflated.

#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace octray::test {

inline std::string whole_file(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// `in` inflated as one whole zlib stream into `out`; false when it is not one (a chunk
// stored raw, or PIZ's, RLE's or DWA's own encoding).
inline bool inflate_zlib(const std::string& in, std::string& out) {
    z_stream z{};
    if (inflateInit(&z) != Z_OK) return false;
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
    z.avail_in = static_cast<uInt>(in.size());
    char buffer[1 << 16];
    int status = Z_OK;
    while (status == Z_OK) {
        z.next_out = reinterpret_cast<Bytef*>(buffer);
        z.avail_out = sizeof buffer;
        status = inflate(&z, Z_NO_FLUSH);
        out.append(buffer, sizeof buffer - z.avail_out);
    }
    const bool whole = status == Z_STREAM_END && z.avail_in == 0;
    inflateEnd(&z);
    return whole;
}

template <class T>
T read_le(const std::string& bytes, std::size_t at) {
    T value{};
    if (at + sizeof value <= bytes.size()) std::memcpy(&value, bytes.data() + at, sizeof value);
    return value;
}

// A single-part scan-line EXR: its bytes up to the chunk offset table (magic number,
// version, header), then each chunk's first line and its data, inflated where the data is
// a zlib stream. A file that is not such an EXR comes back whole, as it is.
inline std::string exr_inflated(const std::filesystem::path& path) {
    const std::string file = whole_file(path);
    std::size_t at = 8;  // magic number and version
    for (;;) {           // attributes: name, type, size, value; an empty name ends the header
        if (at >= file.size()) return file;
        if (file[at] == '\0') break;
        const std::size_t name_end = file.find('\0', at);
        const std::size_t type_end = file.find('\0', name_end + 1);
        if (name_end == std::string::npos || type_end == std::string::npos) return file;
        at = type_end + 1 + 4 +
             static_cast<std::size_t>(read_le<std::int32_t>(file, type_end + 1));
    }
    const std::size_t table = at + 1;
    const auto first = read_le<std::uint64_t>(file, table);
    if (first <= table || first > file.size() || (first - table) % 8 != 0) return file;
    std::string said = file.substr(0, table);
    for (std::size_t k = 0; k < (first - table) / 8; ++k) {
        const auto offset = read_le<std::uint64_t>(file, table + 8 * k);
        const auto size = read_le<std::int32_t>(file, offset + 4);
        if (offset + 8 > file.size() || size < 0 || offset + 8 + size > file.size())
            return file;
        const std::string data = file.substr(offset + 8, static_cast<std::size_t>(size));
        std::string inflated;
        said += "\nchunk at line " + std::to_string(read_le<std::int32_t>(file, offset)) + ":";
        said += inflate_zlib(data, inflated) ? "inflated " + inflated : "as stored " + data;
    }
    return said;
}

// A PNG: every chunk but IDAT (type and data), then the IDAT chunks' one zlib stream
// inflated. A file that is not a PNG comes back whole, as it is.
inline std::string png_inflated(const std::filesystem::path& path) {
    const std::string file = whole_file(path);
    std::string said = file.substr(0, 8);  // the signature
    std::string stream;
    for (std::size_t at = 8; at < file.size();) {
        if (at + 12 > file.size()) return file;
        const auto* b = reinterpret_cast<const unsigned char*>(file.data() + at);
        const std::size_t length = std::size_t{b[0]} << 24 | std::size_t{b[1]} << 16 |
                                   std::size_t{b[2]} << 8 | std::size_t{b[3]};
        if (at + 12 + length > file.size()) return file;
        const std::string type = file.substr(at + 4, 4);
        if (type == "IDAT")
            stream += file.substr(at + 8, length);
        else
            said += type + file.substr(at + 8, length);
        at += 12 + length;
    }
    std::string inflated;
    if (!inflate_zlib(stream, inflated)) return file;
    return said + "IDAT inflated " + inflated;
}

}  // namespace octray::test
