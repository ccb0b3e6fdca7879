#pragma once
// Where a JSON path is written in a scene file's text, so that every scene error can point
// at its line and column (scene/scene_error.h), not only a syntax error.

#include <optional>
#include <string_view>

#include "scene/scene_error.h"

namespace octray::scene_json {

// The position of the value at `path` (written as child_path and index_path write paths,
// "objects[1].radius") in `json_text`: its key for an object member, its first byte for an
// array element or the root. A path the text lacks (a missing key) gives its deepest
// parent that is there. Several members of one name (a duplicate key): the last. nullopt
// where the text stops being JSON before anything of the path is found.
std::optional<SourcePosition> json_path_position(std::string_view json_text,
                                                 std::string_view path);

// The line and column of byte `offset` of `text` (a column counts bytes).
SourcePosition text_position(std::string_view text, std::size_t offset);

}  // namespace octray::scene_json
