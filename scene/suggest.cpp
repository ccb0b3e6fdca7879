// The "did you mean" helper (scene/suggest.h).

#include "scene/suggest.h"

#include <algorithm>
#include <limits>
#include <vector>

namespace octray {
namespace {

// The edit distance costs |word| x |candidate| time and memory; beyond a few dozen
// characters a typo is unlikely and two long names would make it quadratic.
constexpr std::size_t kMaxWordLength = 64;

}  // namespace

std::size_t edit_distance(std::string_view a, std::string_view b) {
    const std::size_t w = b.size() + 1;
    std::vector<std::size_t> d((a.size() + 1) * w);
    for (std::size_t i = 0; i <= a.size(); ++i) d[i * w] = i;
    for (std::size_t j = 0; j <= b.size(); ++j) d[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
            std::size_t best = std::min(
                {d[(i - 1) * w + j] + 1, d[i * w + j - 1] + 1, d[(i - 1) * w + j - 1] + cost});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
                best = std::min(best, d[(i - 2) * w + j - 2] + 1);
            }
            d[i * w + j] = best;
        }
    }
    return d[a.size() * w + b.size()];
}

std::optional<std::string_view> closest_word(std::string_view word,
                                             std::span<const std::string_view> candidates) {
    if (word.size() > kMaxWordLength) return std::nullopt;
    const std::size_t limit = std::clamp<std::size_t>(word.size() / 3, 1, 2);
    std::string_view best;
    std::size_t best_distance = std::numeric_limits<std::size_t>::max();
    for (std::string_view c : candidates) {
        // The distance is at least the difference in length.
        if (c.size() > word.size() + limit || word.size() > c.size() + limit) continue;
        const std::size_t d = edit_distance(word, c);
        if (d < best_distance) {
            best = c;
            best_distance = d;
        }
    }
    // Up to a third of the word may be wrong (at least one edit, at most two).
    if (best_distance == 0 || best_distance > limit) return std::nullopt;
    return best;
}

}  // namespace octray
