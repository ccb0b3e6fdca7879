// write_file_atomically() and remove_stale_temporaries() (render/image/image_io.h): how
// every image file is replaced, whole or not at all.

#include <dirent.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <random>
#include <stdexcept>
#include <string_view>
#include <system_error>

#include "render/image/image_io.h"

namespace octray {
namespace {

namespace fs = std::filesystem;

std::string errno_message(int error) { return std::generic_category().message(error); }

// "<dir>/.<name>.<kind>.<pid>.<random>": hidden, in the target's directory so that the
// final rename stays on one file system (and so stays atomic), and unique per process and
// call. The kind is "new" while the file is being created and locked, "tmp" after.
std::string temporary_path_for(const fs::path& target, const char* kind, std::uint64_t salt) {
    fs::path dir = target.parent_path();
    if (dir.empty()) dir = ".";
    char suffix[80];
    std::snprintf(suffix, sizeof suffix, ".%s.%ld.%016llx", kind, static_cast<long>(::getpid()),
                  static_cast<unsigned long long>(salt));
    return (dir / ("." + target.filename().string() + suffix)).string();
}

// A temporary file, held by its writer: the open descriptor carries an exclusive flock(2)
// from before the file has its ".tmp." name until after it was renamed over the target.
// The lock ends with the descriptor, so also when the writer is killed: a ".tmp." file
// nobody holds the lock of is stale (remove_stale_temporaries).
struct HeldTemporary {
    std::string path;
    int fd = -1;
    HeldTemporary() = default;
    HeldTemporary(const HeldTemporary&) = delete;
    HeldTemporary& operator=(const HeldTemporary&) = delete;
    ~HeldTemporary() {
        if (fd >= 0) ::close(fd);
    }
};

// Creates the temporary file exclusively (O_EXCL: never clobber another writer's file),
// locks it, then gives it its ".tmp." name. The writer callback then truncates and fills
// it. Mode 0666 lets the umask decide the final permissions, as for any file the user
// creates.
void create_temporary_file(const fs::path& target, HeldTemporary& held) {
    std::random_device entropy;
    std::mt19937_64 generator((static_cast<std::uint64_t>(entropy()) << 32) ^ entropy());
    for (int attempt = 0; attempt < 16; ++attempt) {
        const std::uint64_t salt = generator();
        const std::string fresh = temporary_path_for(target, "new", salt);
        const int fd = ::open(fresh.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0) {
            if (errno != EEXIST) throw std::runtime_error(errno_message(errno));
            continue;
        }
        held.fd = fd;
        // Where locks do not work (some network file systems), the file is only not
        // provably stale: other runs leave it alone.
        (void)::flock(fd, LOCK_EX | LOCK_NB);
        const std::string tmp = temporary_path_for(target, "tmp", salt);
        if (std::rename(fresh.c_str(), tmp.c_str()) != 0) {
            const int error = errno;
            std::remove(fresh.c_str());
            throw std::runtime_error(errno_message(error));
        }
        held.path = tmp;
        return;
    }
    throw std::runtime_error("could not create a unique temporary file next to it");
}

// What a file of this mode is, for a message: "a character device".
const char* file_kind(mode_t mode) {
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a regular file";
}

}  // namespace

void check_output_target(const std::string& path) {
    // stat follows symlinks: a symlink to a regular file is written as before (the link is
    // replaced by the new file), one to a device is refused like the device. A directory
    // is left to the rename, which cannot replace it (EISDIR): a batch fails that frame
    // alone and renders the others.
    struct stat info {};
    if (::stat(path.c_str(), &info) != 0 || S_ISREG(info.st_mode) || S_ISDIR(info.st_mode))
        return;
    throw IoError("cannot write " + path + ": it exists and is " + file_kind(info.st_mode) +
                  ", not a regular file; octray writes a new file and renames it over the "
                  "target, which would replace it, so it leaves it alone");
}

void write_file_atomically(const std::string& path,
                           const std::function<void(const std::string& tmp_path)>& write) {
    check_output_target(path);
    HeldTemporary tmp;
    try {
        create_temporary_file(fs::path(path), tmp);
        write(tmp.path);
        if (std::rename(tmp.path.c_str(), path.c_str()) != 0)
            throw std::runtime_error(errno_message(errno));
    } catch (const std::exception& e) {
        if (!tmp.path.empty()) std::remove(tmp.path.c_str());
        throw IoError("cannot write " + path + ": " + e.what());
    } catch (...) {
        if (!tmp.path.empty()) std::remove(tmp.path.c_str());
        throw IoError("cannot write " + path + ": unknown error");
    }
}

std::vector<std::string> remove_stale_temporaries(const std::vector<std::string>& targets) {
    // Each directory is read once for all of its targets, a name compared without a
    // path or string made of it: an animation's directory grows by a frame (and a
    // preview) at a time, and every frame reads it again.
    std::map<std::string, std::vector<std::string>> prefixes;  // directory -> prefixes
    for (const std::string& target : targets) {
        const fs::path path(target);
        fs::path dir = path.parent_path();
        if (dir.empty()) dir = ".";
        prefixes[dir.string()].push_back("." + path.filename().string() + ".tmp.");
    }
    std::vector<std::string> removed;
    for (const auto& [dir, names] : prefixes) {
        DIR* stream = ::opendir(dir.c_str());
        if (stream == nullptr) continue;
        while (const dirent* entry = ::readdir(stream)) {
            const std::string_view name(entry->d_name);
            if (std::none_of(names.begin(), names.end(), [&](const std::string& prefix) {
                    return name.starts_with(prefix);
                }))
                continue;
            const std::string file = (fs::path(dir) / name).string();
            // O_NONBLOCK: a FIFO planted under such a name must not block the open.
            int fd = ::open(file.c_str(), O_RDWR | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
            if (fd < 0)
                fd = ::open(file.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
            if (fd < 0) continue;
            // The lock is free only when no writer holds it: its writer is gone. (Names
            // are never reused, so if the writer renamed it away meanwhile, the unlink
            // finds nothing.)
            if (::flock(fd, LOCK_EX | LOCK_NB) == 0 && ::unlink(file.c_str()) == 0)
                removed.push_back(file);
            ::close(fd);
        }
        ::closedir(stream);
    }
    return removed;
}

}  // namespace octray
