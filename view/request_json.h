#pragma once
// The JSON bodies of the viewer's requests (settings, camera, save) read by the scene
// files' rules: strict JSON, a duplicate key refused with its path, a syntax error with its
// line and column (scene/json_dom.h). One rule everywhere: what a scene file refuses, a
// request does too.

#include <nlohmann/json.hpp>
#include <string>

namespace octray::view {

// The body as JSON; BadRequest(400) "<what>: <the reason>" where a scene file would be
// refused.
nlohmann::json parse_request_json(const std::string& body, const std::string& what);

}  // namespace octray::view
