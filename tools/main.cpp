// octray: the command line. Thin by design: parse, call the library, report.

#include <CLI/CLI.hpp>
#include <csignal>
#include <exception>
#include <iostream>
#include <new>
#include <string>

#include "core/version.h"
#include "render/image_io.h"
#include "scene/scene_error.h"
#include "tools/cli_checks.h"
#include "tools/commands.h"

namespace octray::tools {

std::string exit_code_help() {
    return "Exit codes:\n"
           "  0  success\n"
           "  1  unexpected internal error (a bug, or out of memory)\n"
           "  2  usage error: unknown option, bad value, bad combination of options\n"
           "  3  scene error: the scene file or built-in spec cannot be loaded or is invalid\n"
           "  4  I/O error: an output file cannot be written (nothing partial is left),\n"
           "     or standard output cannot be (a closed pipe: EPIPE, not death by SIGPIPE)\n";
}

int run_command(const std::function<void()>& action) {
    try {
        action();
        return kExitSuccess;
    } catch (const CommandExit& e) {
        return e.status;
    } catch (const UsageError& e) {
        std::cerr << "octray: error: " << e.what()
                  << "\nRun with --help for more information.\n";
        return kExitUsage;
    } catch (const SceneError& e) {
        std::cerr << "octray: scene error: " << e.what() << '\n';
        return kExitScene;
    } catch (const IoError& e) {
        std::cerr << "octray: I/O error: " << e.what() << '\n';
        return kExitIo;
    } catch (const std::bad_alloc&) {
        std::cerr << "octray: out of memory\n";
        return kExitInternal;
    } catch (const std::exception& e) {
        std::cerr << "octray: internal error: " << e.what() << '\n';
        return kExitInternal;
    } catch (...) {
        std::cerr << "octray: internal error: unknown exception\n";
        return kExitInternal;
    }
}

}  // namespace octray::tools

int main(int argc, char** argv) {
    using namespace octray::tools;
    // A write past `ulimit -f` then fails with EFBIG, reported as an I/O error with its
    // temporary removed, instead of SIGXFSZ killing the process mid-file.
    std::signal(SIGXFSZ, SIG_IGN);
    // Likewise a write to a closed pipe (`octray ... | head -1`) fails with EPIPE and is
    // reported as an I/O error (finish_standard_output), instead of SIGPIPE killing the
    // process with status 141.
    std::signal(SIGPIPE, SIG_IGN);

    CLI::App app{"octray renders Whitted-style ray-traced images (OpenEXR, with PNG previews).",
                 "octray"};
    app.set_version_flag("--version", std::string("octray ") + octray::kVersion,
                         "Print the version and exit");
    app.require_subcommand(1);
    // Set before the subcommands are added: they copy it when created.
    app.failure_message([](const CLI::App*, const CLI::Error& e) {
        return std::string("octray: error: ") + e.what() +
               "\nRun with --help for more information.\n";
    });
    app.footer(
        "Examples:\n"
        "  octray render                                  # the built-in whitted scene -> "
        "whitted.exr\n"
        "  octray render whitted -o whitted.exr --png whitted.png\n"
        "  octray render random:1024,width=640,height=360 --spp 4 -o random.exr\n"
        "  octray scene random:16 -o random16.json        # a built-in written as JSON\n"
        "Run 'octray <command> --help' for the options of a command.\n\n" +
        exit_code_help());

    CommandRunner run;
    add_render_command(app, run);
    add_scene_command(app, run);
    add_compare_command(app, run);
    add_bench_command(app, run);
    add_verify_command(app, run);
    add_info_command(app, run);
    add_assemble_command(app, run);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // A mistyped option or command: name the one probably meant, as git and cargo do
        // (the scene loader's "did you mean", scene/suggest.h).
        if (e.get_exit_code() != 0) {
            const std::string hint = mistyped_argument_hint(app);
            if (!hint.empty()) {
                std::cerr << "octray: error: " << hint
                          << "\nRun with --help for more information.\n";
                return kExitUsage;
            }
        }
        // app.exit prints --help / --version output (status 0) or the parse error with a
        // "Run with --help" hint; CLI11's own error numbers all mean "usage error" here.
        const int status = app.exit(e);
        return finish_standard_output(status == 0 ? kExitSuccess : kExitUsage);
    }
    if (!run.action) {
        std::cerr << "octray: error: no command given\nRun with --help for more information.\n";
        return kExitUsage;
    }
    return finish_standard_output(run_command(run.action));
}
