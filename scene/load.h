#pragma once
// Scenes from the command line: a JSON file (docs/scene-format.md) or a built-in
// generator spec ("whitted", "random:1024,width=640", "sphereflake:4").

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "scene/scene.h"
#include "scene/scene_error.h"

namespace octray {

// The fast JSON reader reads up to this many bytes past the end of its text (simdjson
// loads 64-byte blocks); text without them is copied first.
inline constexpr std::size_t kJsonPadding = 64;

// Parses a JSON scene. `source` names the file in error messages. Throws SceneError.
// The fast reader (simdjson) reads the text; where it declines (on anything it would have
// to report, and on nothing else it does not handle) the diagnosing reader (nlohmann)
// reads it again and writes the message: scene/README.md, "Two readers". `readable` is how
// many bytes from json_text.data() may be read: at least json_text.size() + kJsonPadding
// (a string from read_scene_file and its capacity()) spares the fast reader a copy.
Scene parse_scene_json(std::string_view json_text, const std::string& source,
                       std::size_t readable = 0);

// The two readers behind parse_scene_json, for the tests and fuzzers that check that they
// agree. The fast one returns no scene where it declines; every scene it returns has passed
// validate_scene and is the one the diagnosing reader builds. The diagnosing one throws
// SceneError with the file, line and column or JSON path, and what was expected.
std::optional<Scene> parse_scene_json_fast(std::string_view json_text,
                                           const std::string& source, std::size_t readable = 0);
Scene parse_scene_json_diagnosing(std::string_view json_text, const std::string& source);

// The bytes of a scene file, with kJsonPadding bytes of spare capacity after them for the
// fast reader. Refuses anything but a regular file (a directory, a device such as
// /dev/zero, a FIFO) before reading, so a read always ends. Throws SceneError.
std::string read_scene_file(const std::string& path);
// The same, handing each chunk to `on_chunk` as it is read (while it is in cache): a
// caller hashes the file's bytes in the same single read.
std::string read_scene_file(const std::string& path,
                            const std::function<void(std::string_view)>& on_chunk);

// Reads and parses a JSON scene file. Throws SceneError (unreadable file included).
Scene load_scene_file(const std::string& path);

// A built-in spec if `spec` names one (a word before an optional ':'), else a file path.
// Throws SceneError.
Scene load_scene(const std::string& spec);

// Checks the whole scene (camera frame, radii, normals, materials, image size, ...).
// The loaders call it; call it again after changing a scene. Throws SceneError.
void validate_scene(const Scene& scene);

// Writes the scene as JSON that parse_scene_json reads back to an identical scene
// (floats printed round-trip exact), so rendering it gives a bit-identical image.
std::string scene_to_json(const Scene& scene);

}  // namespace octray
