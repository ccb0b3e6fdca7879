#pragma once
// The fixture and helpers of the end-to-end tests of the `octray` executable
// (cli_test.cpp, cli_render_test.cpp): a directory per test to run octray in, and
// readers of what it leaves there.

#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfStringAttribute.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <png.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "run_octray.h"

namespace octray::testing {

namespace fs = std::filesystem;

class CliTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::path(OCTRAY_TEST_TMPDIR) / "cli" /
               (std::string(info->test_suite_name()) + "." + info->name() + "." +
                std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        if (!HasFailure()) fs::remove_all(dir_);
    }

    RunResult octray(const std::vector<std::string>& args, bool capture_stderr = true) {
        return run_octray(args, dir_, capture_stderr);
    }

    std::vector<std::string> entries() const {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(dir_))
            names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }

    std::string path(const std::string& name) const { return (dir_ / name).string(); }

    fs::path dir_;
};

// EXR's capDate format, "YYYY:MM:DD HH:MM:SS". (Checked by hand: std::regex trips a false
// -Wmaybe-uninitialized in GCC 12 under the sanitizer build.)
inline bool is_exr_date(const std::string& text) {
    const std::string pattern = "dddd:dd:dd dd:dd:dd";
    if (text.size() != pattern.size()) return false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const bool digit = text[i] >= '0' && text[i] <= '9';
        if (pattern[i] == 'd' ? !digit : text[i] != pattern[i]) return false;
    }
    return true;
}

inline bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

struct ExrPixels {
    int width = 0, height = 0;
    std::vector<float> rgb;  // as stored; FLOAT channels are read back bit for bit
};

inline ExrPixels read_exr_pixels(const std::string& file_path) {
    Imf::InputFile file(file_path.c_str());
    const Imath::Box2i window = file.header().dataWindow();
    ExrPixels out;
    out.width = window.max.x - window.min.x + 1;
    out.height = window.max.y - window.min.y + 1;
    out.rgb.resize(static_cast<std::size_t>(out.width) * out.height * 3);
    char* base = reinterpret_cast<char*>(out.rgb.data()) -
                 (static_cast<std::ptrdiff_t>(window.min.x) +
                  static_cast<std::ptrdiff_t>(window.min.y) * out.width) *
                     static_cast<std::ptrdiff_t>(3 * sizeof(float));
    const std::size_t xs = 3 * sizeof(float), ys = xs * static_cast<std::size_t>(out.width);
    Imf::FrameBuffer fb;
    fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
    fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
    fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
    file.setFrameBuffer(fb);
    file.readPixels(window.min.y, window.max.y);
    return out;
}

inline bool same_bits(const ExrPixels& a, const ExrPixels& b) {
    return a.width == b.width && a.height == b.height && a.rgb.size() == b.rgb.size() &&
           std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0;
}

inline bool any_nonzero(const ExrPixels& p) {
    return std::any_of(p.rgb.begin(), p.rgb.end(), [](float v) { return v != 0.0f; });
}

// The first `n` bytes of a file ("" if it cannot be read).
inline std::string file_head(const fs::path& file, std::size_t n) {
    std::ifstream in(file, std::ios::binary);
    std::string bytes(n, '\0');
    in.read(bytes.data(), static_cast<std::streamsize>(n));
    bytes.resize(static_cast<std::size_t>(in.gcount()));
    return bytes;
}

inline std::string file_bytes(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline bool is_png_file(const fs::path& file) {
    return file_head(file, 8) == std::string("\x89PNG\r\n\x1a\n", 8);
}

inline bool is_exr_file(const fs::path& file) {
    return file_head(file, 4) == std::string("\x76\x2f\x31\x01", 4);
}

struct ClosedStdoutRun {
    int wait_status = 0;
    std::string stderr_text;
};

// Runs `octray <args...>` in `cwd` with its standard output a pipe whose reading end is
// already closed (as `octray ... | head -0` leaves it), SIGPIPE at its default action.
inline ClosedStdoutRun run_with_closed_stdout(const std::vector<std::string>& args,
                                              const fs::path& cwd) {
    ClosedStdoutRun result;
    int fds[2];
    if (::pipe(fds) != 0) return result;
    ::close(fds[0]);
    const fs::path err = cwd / ".stderr.txt";
    const pid_t pid = ::fork();
    if (pid == 0) {
        std::signal(SIGPIPE, SIG_DFL);
        if (::chdir(cwd.c_str()) != 0) ::_exit(120);
        ::dup2(fds[1], STDOUT_FILENO);
        const int err_fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        ::dup2(err_fd, STDERR_FILENO);
        std::vector<char*> argv;
        std::string exe = OCTRAY_EXE;
        argv.push_back(exe.data());
        std::vector<std::string> copies = args;
        for (std::string& a : copies) argv.push_back(a.data());
        argv.push_back(nullptr);
        ::execv(exe.c_str(), argv.data());
        ::_exit(121);
    }
    ::close(fds[1]);
    ::waitpid(pid, &result.wait_status, 0);
    result.stderr_text = file_bytes(err);
    fs::remove(err);
    return result;
}

}  // namespace octray::testing
