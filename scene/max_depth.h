#pragma once
// The largest render.max_depth (reflection/refraction bounces): one constant for the
// built-in specs' max_depth=D, `octray render --max-depth` (its check and its help text)
// and, by the same value, scene files' render.max_depth (scene/README.md).

namespace octray {

inline constexpr int kMaxDepthLimit = 64;

}  // namespace octray
