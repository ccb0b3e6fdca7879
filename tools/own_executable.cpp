// Commands in executables of their own (tools/own_executable.h).

#include "tools/own_executable.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#ifndef OCTRAY_OWN_EXECUTABLES_RELATIVE_DIR
#error "OCTRAY_OWN_EXECUTABLES_RELATIVE_DIR: their folder relative to octray's, once installed"
#endif

namespace octray::tools {
namespace {

std::vector<std::string>& command_line() {
    static std::vector<std::string> arguments;
    return arguments;
}

}  // namespace

void remember_command_line(int argc, char** argv) { command_line().assign(argv, argv + argc); }

std::vector<std::string> own_executable_candidates(const std::string& self,
                                                   const std::string& relative,
                                                   std::string_view command) {
    const std::filesystem::path dir = std::filesystem::path(self).parent_path();
    const std::string name = "octray-" + std::string(command);
    return {(dir / name).string(), (dir / relative / name).lexically_normal().string()};
}

void exec_own_executable(std::string_view command) {
    const std::string name = "octray-" + std::string(command);
    std::error_code error;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
    if (error)
        throw std::runtime_error(
            std::string(command) + ": cannot find octray's own executable " +
            "(/proc/self/exe: " + error.message() + "), beside which " + name + " lies");
    std::vector<char*> argv;
    for (std::string& arg : command_line()) argv.push_back(arg.data());
    argv.push_back(nullptr);
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    std::string tried;
    for (const std::string& candidate : own_executable_candidates(
             self.string(), OCTRAY_OWN_EXECUTABLES_RELATIVE_DIR, command)) {
        ::execv(candidate.c_str(), argv.data());  // returns only when it failed
        tried += (tried.empty() ? "" : "; ") + candidate + ": " + std::strerror(errno);
    }
    throw std::runtime_error(
        std::string(command) + ": cannot run " + name + ", which octray runs for octray " +
        std::string(command) +
        " (it is built beside octray and installed in libexec/octray): " + tried);
}

}  // namespace octray::tools
