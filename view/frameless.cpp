#include "view/frameless.h"

#include <algorithm>
#include <random>
#include <stdexcept>

namespace octray::view {

std::vector<PixelRect> frameless_blocks(int width, int height, int block, std::uint64_t seed) {
    if (width < 1 || height < 1 || block < 1)
        throw std::invalid_argument("frameless_blocks: width, height and block must be >= 1");
    std::vector<PixelRect> blocks;
    for (int y = 0; y < height; y += block)
        for (int x = 0; x < width; x += block)
            blocks.push_back({x, y, std::min(x + block, width), std::min(y + block, height)});
    // Fisher-Yates with std::mt19937_64, whose sequence the standard fixes (unlike
    // std::shuffle's use of it), so the order is the same on every platform.
    std::mt19937_64 random(seed);
    for (std::size_t i = blocks.size(); i > 1; --i) {
        const std::size_t j = static_cast<std::size_t>(random() % i);
        std::swap(blocks[i - 1], blocks[j]);
    }
    return blocks;
}

}  // namespace octray::view
