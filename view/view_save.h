#pragma once
// POST /api/save of `octray view` (view/README.md): the refined picture written as
// `octray render` writes it, with the command line that renders it again.

#include <nlohmann/json.hpp>
#include <string>

#include "view/view_server.h"
#include "view/view_session.h"

namespace octray::view {

// Writes the session's latest picture as settings.directory/NAME, NAME from the JSON
// body {"name": "view.exr", "overwrite": false}; a moved camera's scene goes beside it as
// NAME.json. Answers {"file", "command", "camera_moved", "scene_file"}. Throws BadRequest
// (http_error.h): 400 for a bad body or name, 409 for existing files (naming each) unless
// overwrite, for a file that is the scene being viewed (never overwritten), or for a
// picture that is still refining or frameless; IoError when a file cannot be written.
nlohmann::json save_view(ViewSession& session, const SaveSettings& settings,
                         const std::string& body);

}  // namespace octray::view
