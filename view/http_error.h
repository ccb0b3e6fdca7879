#pragma once
// Inside the viewer: a request the client got wrong, answered with `status` (400, 404,
// 409, 413) and the message as plain text (view_server.cpp, view_save.cpp).

#include <stdexcept>
#include <string>

namespace octray::view {

struct BadRequest : std::runtime_error {
    int status;
    BadRequest(int s, const std::string& message) : std::runtime_error(message), status(s) {}
};

}  // namespace octray::view
