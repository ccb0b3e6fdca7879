#pragma once
// The largest render.max_depth (reflection/refraction bounces): the scene format's limit
// (scene/json_rules.h, which both JSON readers apply), under the name the built-in specs'
// max_depth=D, `octray render --max-depth` (its check and its help text) and the viewer's
// switch use.

#include "scene/json_rules.h"

namespace octray {

inline constexpr int kMaxDepthLimit = scene_json::kMaxDepthLimit;

}  // namespace octray
