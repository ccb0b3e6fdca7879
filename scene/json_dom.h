#pragma once
// JSON text to a DOM for the diagnosing reader: strict JSON (the whole text: a NUL byte is
// an error, not an end), syntax errors with their line and column, duplicate keys and
// number overflow with their JSON path, nesting bounded.

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "scene/json_messages.h"

namespace octray::scene_json {

// The DOM of `json_text`, in file order. Throws SceneError (file: `source`) with the
// position or path of the first error.
Json parse_json_dom(std::string_view json_text, const std::string& source);

}  // namespace octray::scene_json
