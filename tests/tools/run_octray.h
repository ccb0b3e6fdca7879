#pragma once
// Runs the built `octray` executable through the shell, as a user (and CI) would: in a
// given directory, with stdin closed, capturing stdout (and stderr when asked).

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace octray::testing {

struct RunResult {
    int status = -1;     // the exit code, or -1 if the process did not exit normally
    std::string output;  // stdout, and stderr too when asked
};

// Single-quotes an argument for /bin/sh.
inline std::string shell_quote(const std::string& arg) {
    std::string quoted = "'";
    for (char c : arg) {
        if (c == '\'')
            quoted.append("'\\''");
        else
            quoted.push_back(c);
    }
    quoted.push_back('\'');
    return quoted;
}

// Runs `octray <args...>` in `cwd`.
inline RunResult run_octray(const std::vector<std::string>& args,
                            const std::filesystem::path& cwd, bool capture_stderr = true) {
    // Built with append(): GCC 12's -O3 warns falsely (-Wrestrict) on chains of operator+.
    std::string command = "cd ";
    command.append(shell_quote(cwd.string())).append(" && ").append(shell_quote(OCTRAY_EXE));
    for (const std::string& a : args) command.append(" ").append(shell_quote(a));
    command.append(" </dev/null");
    command.append(capture_stderr ? " 2>&1" : " 2>/dev/null");
    RunResult result;
    FILE* pipe = ::popen(command.c_str(), "r");
    if (pipe == nullptr) return result;
    std::array<char, 4096> buffer;
    std::size_t n = 0;
    while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
        result.output.append(buffer.data(), n);
    const int status = ::pclose(pipe);
    if (status != -1 && WIFEXITED(status)) result.status = WEXITSTATUS(status);
    return result;
}

}  // namespace octray::testing
