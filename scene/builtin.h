#pragma once
// The built-in scenes of docs/scene-format.md.

#include <optional>
#include <string>

#include "scene/scene.h"

namespace octray {

// True if the spec's name (text before ':' or ',') is a built-in: whitted, random,
// sphereflake.
bool is_builtin_scene(const std::string& spec);

// The built-in spec that `spec` is probably a typo of ("sphereflak:3" -> "sphereflake:3"):
// its name one or two edits from a built-in's, the rest as given; nullopt when none is
// close.
std::optional<std::string> builtin_suggestion(const std::string& spec);

// Builds "whitted", "random:N", "sphereflake:L", each optionally followed by
// ",key=value" overrides (width, height, spp, seed, max_depth). Throws SceneError.
Scene make_builtin_scene(const std::string& spec);

// The splitmix64 generator that random:N is specified with.
class SplitMix64 {
  public:
    explicit SplitMix64(std::uint64_t state) : state_(state) {}
    std::uint64_t next();
    float next_float();  // (next() >> 40) * 2^-24, in [0, 1)
    // Skips n outputs in O(1) (the state advances by a constant per output): a block of
    // spheres is generated from its own copy, in parallel, with the serial values.
    void discard(std::uint64_t n);

  private:
    std::uint64_t state_;
};

}  // namespace octray
