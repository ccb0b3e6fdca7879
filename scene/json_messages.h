#pragma once
// The pieces of the diagnosing reader's messages (scene/README.md, "Error messages"): numbers,
// vectors and colors as the file would write them, JSON values described for "found ...",
// JSON paths, quoted (and cut short) keys and "did you mean" suggestions. Shared by the
// diagnosing reader (scene/json_reader.h, scene/read_scene.cpp, scene/read_animation.cpp)
// and validate_scene (scene/validate.cpp), so that both write the same words.

#include <cstddef>
#include <nlohmann/json_fwd.hpp>
#include <span>
#include <string>
#include <string_view>

#include "core/color.h"
#include "core/vec3.h"

namespace octray::scene_json {

// ordered_json keeps members in file order: named materials are indexed in the order the
// file lists them, and errors are reported in reading order.
using Json = nlohmann::ordered_json;

std::string format_float(float v);
std::string format_vec(Vec3 v);
std::string format_rgb(Rgb c);

// Keys, names and words longer than this are cut short in messages: a 100 MB key must
// not make a 100 MB message.
inline constexpr std::size_t kMaxQuotedLength = 64;

// The message for a NUL byte ("invalid JSON: a NUL byte ..."; the SceneError carries its
// line and column): the diagnosing reader's, and the file reader's, which stops at the
// first one rather than reading a sparse 2 GB file to its end.
std::string nul_byte_message();

std::string abbreviated(std::string_view s);
std::string quote_text(std::string_view s);

// A short description of a JSON value for "found ..." in messages.
std::string describe(const Json& v);

// A path segment: .key for identifier-like keys, ["odd key"] otherwise.
std::string child_path(const std::string& path, std::string_view key);
std::string index_path(const std::string& path, std::size_t i);

// " (did you mean "x"?)" when one candidate is close (scene/suggest.h), else "".
std::string suggestion(std::string_view word, std::span<const std::string_view> candidates);

std::string join_quoted(std::span<const std::string_view> words);

}  // namespace octray::scene_json
