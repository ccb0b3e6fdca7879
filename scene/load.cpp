// Scenes from the command line (scene/load.h): reading a scene file, the choice between
// the fast reader (scene/load_fast.cpp) and the diagnosing one (scene/read_scene.cpp), and
// built-in specs. validate_scene is scene/validate.cpp.

#include "scene/load.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

#include "core/aligned.h"
#include "scene/builtin.h"
#include "scene/json_messages.h"
#include "scene/json_positions.h"

namespace octray {

Scene parse_scene_json(std::string_view json_text, const std::string& source,
                       std::size_t readable) {
    if (std::optional<Scene> scene = parse_scene_json_fast(json_text, source, readable)) {
        return std::move(*scene);
    }
    return parse_scene_json_diagnosing(json_text, source);
}

std::string read_scene_file(const std::string& path) { return read_scene_file(path, {}); }

std::string read_scene_file(const std::string& path,
                            const std::function<void(std::string_view)>& on_chunk) {
    // O_NONBLOCK: opening a FIFO must not wait for a writer; it is refused below anyway.
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        const int error = errno;
        std::string message =
            "cannot open scene file: " + std::generic_category().message(error);
        // A missing file spelled like a built-in is a typo of one ("sphereflak:3").
        if (error == ENOENT) {
            if (const std::optional<std::string> builtin = builtin_suggestion(path))
                message += "; nor is it a built-in (did you mean \"" + *builtin +
                           "\"?): the built-ins are whitted, random:N and sphereflake:L";
        }
        throw SceneError(path, "", message);
    }
    const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(::fdopen(fd, "rb"),
                                                               &std::fclose);
    if (!file) {
        const int error = errno;
        ::close(fd);
        throw SceneError(path, "",
                         "cannot read scene file: " + std::generic_category().message(error));
    }
    // Only a regular file has an end: /dev/zero, /dev/urandom or a pipe would be read
    // forever (or block), so they are refused before the first byte is read.
    struct stat info {};
    if (::fstat(fd, &info) != 0) {
        throw SceneError(path, "",
                         "cannot read scene file: " + std::generic_category().message(errno));
    }
    if (S_ISDIR(info.st_mode)) {
        throw SceneError(path, "",
                         "cannot read scene file: " + std::generic_category().message(EISDIR) +
                             "; expected a regular file");
    }
    if (!S_ISREG(info.st_mode)) {
        const char* kind = S_ISCHR(info.st_mode)    ? "a character device"
                           : S_ISBLK(info.st_mode)  ? "a block device"
                           : S_ISFIFO(info.st_mode) ? "a pipe (FIFO)"
                           : S_ISSOCK(info.st_mode) ? "a socket"
                                                    : "not a plain file";
        throw SceneError(path, "",
                         std::string("cannot read scene file: it is ") + kind +
                             "; expected a regular file (a JSON scene)");
    }
    // Read straight into the string (no bounce buffer), a chunk at a time so that the
    // caller's hash sees each chunk while it is in cache. The string holds the size fstat
    // gave plus the padding; it grows only if the file grows while it is read.
    constexpr std::size_t kChunk = std::size_t{1} << 20;
    std::string text;
    text.reserve(static_cast<std::size_t>(info.st_size) + kJsonPadding);
    offer_huge_pages(text.data(), text.capacity());  // fewer page faults while filled
    std::size_t size = 0;
    for (;;) {
        const std::size_t room = text.capacity() - kJsonPadding - size;
        if (room == 0) {
            // Full: at the end of the file, unless it grew since fstat.
            char byte = 0;
            if (std::fread(&byte, 1, 1, file.get()) == 0) break;
            text.reserve(text.capacity() * 2);
            text.push_back(byte);
            if (on_chunk) on_chunk(std::string_view(&text[size], 1));
            ++size;
            continue;
        }
        const std::size_t want = std::min(kChunk, room);
        text.resize(size + want);
        const std::size_t n = std::fread(text.data() + size, 1, want, file.get());
        // JSON text never holds a NUL byte: the first one is the error, whatever follows
        // (a sparse 2 GB file of them is not read to its end first).
        if (const void* nul = std::memchr(text.data() + size, '\0', n)) {
            const auto offset =
                static_cast<std::size_t>(static_cast<const char*>(nul) - text.data());
            throw SceneError(path, scene_json::text_position(text, offset), "",
                             scene_json::nul_byte_message());
        }
        if (on_chunk && n > 0) on_chunk(std::string_view(text.data() + size, n));
        size += n;
        text.resize(size);
        if (n < want) break;
    }
    if (std::ferror(file.get())) {
        throw SceneError(path, "",
                         "cannot read scene file: " + std::generic_category().message(errno));
    }
    // Zeroed padding: the fast reader's blocks past the end read defined bytes.
    text.append(kJsonPadding, '\0');
    text.resize(size);
    return text;
}

Scene load_scene_file(const std::string& path) {
    const std::string text = read_scene_file(path);
    return parse_scene_json(text, path, text.capacity());
}

Scene load_scene(const std::string& spec) {
    if (is_builtin_scene(spec)) return make_builtin_scene(spec);
    return load_scene_file(spec);
}

}  // namespace octray
