#pragma once
// populate_pages (core/aligned.h) over a large buffer on every thread of the caller's TBB
// arena: the fresh pages of a frame before its tiles write them (render/packet_renderer.cpp),
// of a built-in scene's objects before one thread fills them (scene/builtin.cpp). The
// kernel's zeroing of the pages is then spread over the cores instead of falling, a fault
// at a time, on the thread that writes first.

#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "core/aligned.h"

namespace octray {

// Maps the whole pages inside [p, p + bytes), a 2 MiB piece per task.
inline void populate_pages_parallel(void* p, std::size_t bytes) {
    constexpr std::uintptr_t kPage = 4096, kPiece = kHugePageBytes;
    const auto at = reinterpret_cast<std::uintptr_t>(p);
    const std::uintptr_t begin = (at + kPage - 1) & ~(kPage - 1);
    const std::uintptr_t end = (at + bytes) & ~(kPage - 1);
    if (end <= begin) return;
    tbb::parallel_for(std::uintptr_t{0}, (end - begin + kPiece - 1) / kPiece,
                      [&](std::uintptr_t k) {
                          const std::uintptr_t b = begin + k * kPiece;
                          populate_pages(reinterpret_cast<void*>(b), std::min(kPiece, end - b));
                      });
}

}  // namespace octray
