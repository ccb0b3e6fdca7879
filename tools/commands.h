#pragma once
// The `octray` subcommands. Each lives in its own cmd_<name>.cpp and registers itself with
// one add_<name>_command() call in app.cpp, so a new command is a new file and one line.
//
// A command's parse callback only records what to do (CommandRunner::action); main() runs
// it after the whole command line has parsed, so every command shares one mapping from
// exceptions to exit codes (run_command below).

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

namespace CLI {
class App;
}

namespace octray::tools {

// The exit status of every command; --help and README.md list the same table.
enum ExitCode : int {
    kExitSuccess = 0,
    kExitInternal = 1,  // an unexpected failure (a bug, or out of memory)
    kExitUsage = 2,     // a bad command line: unknown option, bad value, bad combination
    kExitScene = 3,     // the scene cannot be loaded or is invalid (octray::SceneError)
    kExitIo = 4,        // a file cannot be written (octray::IoError)
};

// `octray compare` keeps idiff's 0..4 (2 is its FAIL verdict), so its usage errors need a
// status of their own: a CI script can then tell a typo from a regression.
constexpr int kExitCompareUsage = 5;

// The exit-code table as help text, for the --help footers.
std::string exit_code_help();

// A command-line mistake only found once the command runs (an option combination, a path
// that is not available yet): exits with kExitUsage like a parse error.
class UsageError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// A command's own outcome with its own exit status, already reported (`octray compare`:
// 1 warn, 2 fail, 3 mismatch): run_command prints nothing and returns `status`.
struct CommandExit {
    int status;
};

// Ends a command that has finished its work (every file written and closed, every line
// reported) with `status` (kExitIo where standard output could not be written, as
// finish_standard_output says), without destroying what it built: the process's memory goes
// back to the system at once, where freeing a million-sphere scene object by object took
// 5-10 ms after the last frame (docs/performance-log.md, "A million spheres prepared
// faster"). Standard output and error are flushed first. Under a sanitizer, whose leak
// and race reports run at a normal exit, it throws CommandExit{status} instead, which
// run_command returns as the exit status.
[[noreturn]] void end_command(int status);

struct CommandRunner {
    std::function<void()> action;  // set by the subcommand the user chose
};

// The hint after a usage error: "Run 'octray render --help' for more information." for
// `command` ("" for octray itself).
std::string help_hint(const std::string& command);

// Runs `action` of `command`, reports any exception on stderr and returns the exit code for
// it; a usage error names the command's own help and exits with `usage_status`.
int run_command(const std::function<void()>& action, const std::string& command,
                int usage_status);

// main() of the executables octray, octray-view and octray-bench (tools/own_executable.h):
// parses the command line with the application make_octray_app makes for its first word and
// runs the chosen command; the exit status.
int octray_main(int argc, char** argv);

// The `octray` application, its commands registered (with `run`) as main() parses with
// it; tests walk its options. Every command, or with `only` the name of one (main passes
// its first argument), that command alone: a command line that starts with a command's
// name parses within that command, and registering all of them took 0.35 ms of every
// run (tools/README.md, "Commands in executables of their own"). man and completion,
// which describe every command, and any other word get every command.
std::unique_ptr<CLI::App> make_octray_app(CommandRunner& run, std::string_view only = {});

void add_render_command(CLI::App& app, CommandRunner& run);
void add_scene_command(CLI::App& app, CommandRunner& run);
void add_compare_command(CLI::App& app, CommandRunner& run);
void add_bench_command(CLI::App& app, CommandRunner& run);
void add_verify_command(CLI::App& app, CommandRunner& run);
void add_info_command(CLI::App& app, CommandRunner& run);
void add_assemble_command(CLI::App& app, CommandRunner& run);
void add_view_command(CLI::App& app, CommandRunner& run);
// man and completion describe every command (tools/cli_describe.h) when they run, after
// all are registered; they come last so that --help lists them after the commands they
// document.
void add_man_command(CLI::App& app, CommandRunner& run);
void add_completion_command(CLI::App& app, CommandRunner& run);

}  // namespace octray::tools
