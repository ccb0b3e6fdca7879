#include "view/request_json.h"

#include "scene/json_dom.h"
#include "scene/scene_error.h"
#include "view/http_error.h"

namespace octray::view {

nlohmann::json parse_request_json(const std::string& body, const std::string& what) {
    try {
        (void)scene_json::parse_json_dom(body, what);  // the scene files' checks
    } catch (const SceneError& e) {
        throw BadRequest(400, e.what());
    }
    return nlohmann::json::parse(body, nullptr, /*allow_exceptions=*/false);
}

}  // namespace octray::view
