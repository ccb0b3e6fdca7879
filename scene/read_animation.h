#pragma once
// The diagnosing reader's "animation" block (scene/read_animation.cpp).

#include "scene/json_reader.h"
#include "scene/scene.h"

namespace octray::scene_json {

// The animation block of `scene`'s file, its object names resolved against scene.objects
// (read before it). JSON types, key names and object names here; the rules on values in
// validate_scene. Throws SceneError.
Animation read_animation(const Reader& r, const Json& j, const Scene& scene);

}  // namespace octray::scene_json
