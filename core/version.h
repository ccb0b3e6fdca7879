#pragma once

namespace octray {

// From project(VERSION) in the top-level CMakeLists.txt, passed down by octray::core.
inline constexpr const char* kVersion = OCTRAY_VERSION_STRING;

}  // namespace octray
