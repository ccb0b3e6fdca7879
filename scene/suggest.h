#pragma once
// "Did you mean ...?": the known word closest to a mistyped one. The scene loader uses it
// for unknown JSON keys and names, the command line for unknown options and commands.

#include <cstddef>
#include <optional>
#include <span>
#include <string_view>

namespace octray {

// Edit distance counting a swap of neighbours as one edit (optimal string alignment), so
// that "widht" is one typo away from "width".
std::size_t edit_distance(std::string_view a, std::string_view b);

// The candidate closest to `word` when it is close enough to be a typo of it: at most a
// third of the word's length away (at least one edit, at most two), and not `word` itself.
// The first of equally close candidates wins. Words longer than 64 characters get none.
std::optional<std::string_view> closest_word(std::string_view word,
                                             std::span<const std::string_view> candidates);

}  // namespace octray
