#pragma once
// The one error type for bad scene input. Its message always says where (file, and the
// JSON path such as objects[3].radius when there is one) and what was expected.

#include <stdexcept>
#include <string>

namespace octray {

class SceneError : public std::runtime_error {
  public:
    // what() reads "<file>: <json_path>: <message>" (parts left out when empty).
    SceneError(std::string file, std::string json_path, const std::string& message)
        : std::runtime_error(compose(file, json_path, message)),
          file_(std::move(file)),
          json_path_(std::move(json_path)) {}

    const std::string& file() const { return file_; }
    const std::string& json_path() const { return json_path_; }

  private:
    static std::string compose(const std::string& file, const std::string& path,
                               const std::string& message) {
        std::string out;
        if (!file.empty()) out += file + ": ";
        if (!path.empty()) out += path + ": ";
        return out + message;
    }

    std::string file_;
    std::string json_path_;
};

}  // namespace octray
