#pragma once
// Commands in executables of their own. `octray view` links an HTTP server library
// (Debian's cpp-httplib, built with OpenSSL and brotli) and a JPEG encoder; `octray bench`
// links Embree. Loading and initialising them cost every other command about 2 ms of a
// ~43 ms README render (docs/performance-log.md, "Commands in executables of their
// own"). So `octray` registers those commands (their options, --help, man pages and
// completions) but, once the command line has parsed, replaces itself (execv) with
// octray-<command>: the same command line with that command's libraries linked in, which
// parses the command line again and runs it. The executables lie beside octray in the
// build tree, in <prefix>/libexec/octray once installed (tools/README.md).

#include <string>
#include <string_view>
#include <vector>

namespace octray::tools {

// The command line as main() received it, for exec_own_executable.
void remember_command_line(int argc, char** argv);

// Where octray looks for octray-<command>, first to last: beside `self` (octray's own
// path), then in `relative` to it (the install's bin -> libexec/octray).
std::vector<std::string> own_executable_candidates(const std::string& self,
                                                   const std::string& relative,
                                                   std::string_view command);

// execv of octray-<command> with the command line remembered; returns only by throwing
// std::runtime_error (an internal error, exit 1) that names where it looked and why each
// failed.
[[noreturn]] void exec_own_executable(std::string_view command);

// A command whose body is linked into its own executable only. That executable's main()
// sets the body; elsewhere run() hands the whole command line over to it.
template <class Arguments>
class OwnExecutable {
  public:
    using Body = void (*)(const Arguments&);
    static void set_body(Body body) { body_ = body; }
    static void run(std::string_view command, const Arguments& args) {
        if (body_ == nullptr) exec_own_executable(command);
        body_(args);
    }

  private:
    static inline Body body_ = nullptr;
};

}  // namespace octray::tools
