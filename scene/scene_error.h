#pragma once
// The one error type for bad scene input. Its message always says where (file, and the
// JSON path such as objects[3].radius when there is one) and what was expected; an error in
// a scene file also says the line and column, in the form editors and compilers use
// ("shot.json:12:7: objects[1].raduis: unknown key ...").

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>

namespace octray {

// A place in a text: 1-based line and column (in bytes); line 0 means none.
struct SourcePosition {
    std::size_t line = 0;
    std::size_t column = 0;
};

class SceneError : public std::runtime_error {
  public:
    // what() reads "<file>: <json_path>: <message>" (parts left out when empty).
    SceneError(std::string file, std::string json_path, const std::string& message)
        : SceneError(std::move(file), SourcePosition{}, std::move(json_path), message) {}
    // what() reads "<file>:<line>:<column>: <json_path>: <message>".
    SceneError(std::string file, SourcePosition at, std::string json_path,
               const std::string& message)
        : std::runtime_error(compose(file, at, json_path, message)),
          file_(std::move(file)),
          json_path_(std::move(json_path)),
          message_(message),
          at_(at) {}

    const std::string& file() const { return file_; }
    const std::string& json_path() const { return json_path_; }
    // The message without the file, position and path.
    const std::string& message() const { return message_; }
    // Where in the file, when known (line 0: not known, or not from a file).
    SourcePosition position() const { return at_; }

  private:
    static std::string compose(const std::string& file, SourcePosition at,
                               const std::string& path, const std::string& message) {
        std::string out;
        if (!file.empty()) {
            out += file;
            if (at.line > 0)
                out += ":" + std::to_string(at.line) + ":" + std::to_string(at.column);
            out += ": ";
        }
        if (!path.empty()) out += path + ": ";
        return out + message;
    }

    std::string file_;
    std::string json_path_;
    std::string message_;
    SourcePosition at_;
};

}  // namespace octray
