#include "render/batch/resume.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "render/batch/claim_owner.h"
#include "render/image/image_io.h"
#include "render/image/image_read.h"

namespace octray::batch {
namespace {

namespace fs = std::filesystem;

bool has_exr_signature(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::array<char, 4> magic{};
    in.read(magic.data(), magic.size());
    return in.gcount() == 4 && magic == std::array<char, 4>{0x76, 0x2f, 0x31, 0x01};
}

}  // namespace

Found existing_output(const std::string& path) {
    std::error_code error;
    if (!fs::exists(path, error)) return {Existing::none, {}, {}};
    const auto size = fs::file_size(path, error);
    if (error) return {Existing::finished, {}, {}};  // not a regular file: never overwrite it
    if (size == 0) return {Existing::claim, {}, {}};
    // Not an EXR (a PNG preview target): it exists. An EXR gets the check that `compare` and
    // `assemble` make before decoding (render/image/image_read.h): every chunk against its
    // header. Its pixels are not decoded: resuming a long sequence only needs to know the
    // file is whole.
    if (!has_exr_signature(path)) return {Existing::finished, {}, {}};
    try {
        check_exr_pixel_data(path);
        const ExrAttributes attributes = read_exr_attributes(path);
        if (attributes.find_int(kSamplesSoFarAttribute) != nullptr) {
            const std::string* owner = attributes.find_string(kOwnerAttribute);
            return {Existing::unfinished, owner != nullptr ? *owner : std::string(), {}};
        }
    } catch (const IoError& e) {
        return {Existing::damaged, {}, e.what()};
    }
    return {Existing::finished, {}, {}};
}

bool take_over(const std::string& path) {
    int fd = ::open(path.c_str(), O_RDWR | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) return false;
    struct Closer {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) return false;
    const auto same_file = [&] {
        struct stat held {
        }, named{};
        return ::fstat(fd, &held) == 0 && ::stat(path.c_str(), &named) == 0 &&
               held.st_dev == named.st_dev && held.st_ino == named.st_ino;
    };
    if (!same_file()) return false;
    const Found found = existing_output(path);
    if (found.kind != Existing::unfinished || !owner_is_gone(found.owner) || !same_file())
        return false;
    write_file_atomically(path, [](const std::string& tmp) {
        // The temporary is already there, empty: it becomes the claim.
        (void)tmp;
    });
    return true;
}

bool claim(const std::string& path) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) {
        if (errno == EEXIST) return false;
        throw IoError("cannot claim " + path + " with a placeholder: " + std::strerror(errno));
    }
    ::close(fd);
    return true;
}

void release_claim(const std::string& path) {
    std::error_code error;
    if (fs::exists(path, error) && fs::file_size(path, error) == 0 && !error)
        fs::remove(path, error);
}

}  // namespace octray::batch
