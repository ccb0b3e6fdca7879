#include "render/batch/output_paths.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <set>
#include <system_error>

#include "render/image/image_io.h"

namespace octray::batch {
namespace {

namespace fs = std::filesystem;

// Creates the missing directories above an output (as Blender does), top down, adding each
// one created to `created`; fails before the render when one cannot be created or the
// directory clearly cannot be written, rather than after hours of rendering. (The writes
// themselves still report anything this misses.)
void prepare_output_directory(const fs::path& file, std::vector<std::string>& created) {
    fs::path dir = file.parent_path();
    if (dir.empty()) dir = ".";
    struct stat info {};
    if (::stat(dir.c_str(), &info) != 0 && errno == ENOENT) {
        std::vector<fs::path> missing;  // deepest first
        for (fs::path up = dir; !up.empty(); up = up.parent_path()) {
            if (::stat(up.c_str(), &info) == 0 || errno != ENOENT) break;
            missing.push_back(up);
            if (up == up.parent_path()) break;
        }
        // "x.exr/../y.exr": creating x.exr only to leave it again would leave a stray
        // directory behind (and what ".." means then depends on symlinks): refused.
        for (const fs::path& up : missing)
            if (up.filename() == "..")
                throw IoError("cannot write " + file.string() + ": " +
                              up.parent_path().string() +
                              " does not exist, and the path goes up (..) out of it; name "
                              "the output without the missing directory");
        for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
            if (::mkdir(it->c_str(), 0777) == 0) {
                created.push_back(it->string());
            } else if (errno != EEXIST) {  // EEXIST: a concurrent shard made it first
                const int error = errno;
                if (error == ENOTDIR) break;  // a file in the way: named below
                throw IoError("cannot write " + file.string() + ": cannot create directory " +
                              it->string() + ": " + std::strerror(error));
            }
        }
    }
    if (::stat(dir.c_str(), &info) != 0) {
        const int error = errno;
        // A file in the way is the reason, not a missing directory: name it.
        if (error == ENOTDIR) {
            for (fs::path up = dir.parent_path(); !up.empty(); up = up.parent_path()) {
                if (::stat(up.c_str(), &info) == 0) {
                    if (!S_ISDIR(info.st_mode))
                        throw IoError("cannot write " + file.string() + ": " + up.string() +
                                      " is a file, not a directory");
                    break;
                }
            }
        }
        throw IoError("cannot write " + file.string() + ": " + dir.string() + ": " +
                      std::strerror(error));
    }
    if (!S_ISDIR(info.st_mode))
        throw IoError("cannot write " + file.string() + ": " + dir.string() +
                      " is a file, not a directory");
    if (::access(dir.c_str(), W_OK | X_OK) != 0)
        throw IoError("cannot write " + file.string() + ": directory " + dir.string() +
                      " is not writable");
}

}  // namespace

std::string directory_identity(const std::string& dir) {
    const std::string path = dir.empty() ? "." : dir;
    struct stat info {};
    if (::stat(path.c_str(), &info) == 0 && S_ISDIR(info.st_mode))
        return "device " + std::to_string(info.st_dev) + ", inode " +
               std::to_string(info.st_ino) + ": ";
    std::error_code error;
    const fs::path absolute = fs::absolute(path, error);
    return "path " + (error ? fs::path(path) : absolute).lexically_normal().string() + "/";
}

std::string output_identity(const std::string& path) {
    const fs::path file(path);
    return directory_identity(file.parent_path().string()) + file.filename().string();
}

std::vector<std::string> prepare_output_directories(const std::vector<BatchJob>& jobs) {
    std::set<std::string> directories;
    std::vector<std::string> created;
    for (const BatchJob& job : jobs) {
        for (const std::string* file : {&job.output, &job.png}) {
            if (file->empty()) continue;
            check_output_target(*file);  // a device or FIFO would be replaced: refused
            const fs::path path(*file);
            if (directories.insert(path.parent_path().string()).second)
                prepare_output_directory(path, created);
        }
    }
    return created;
}

}  // namespace octray::batch
