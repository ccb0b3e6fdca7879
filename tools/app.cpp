// The `octray` application: its commands and what they share (tools/commands.h).

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <memory>
#include <new>
#include <string>
#include <string_view>
#include <utility>

#include "core/thread_check.h"
#include "core/version.h"
#include "render/image/image_io.h"
#include "scene/scene_error.h"
#include "tools/cli_checks.h"
#include "tools/commands.h"

namespace octray::tools {

std::string exit_code_help() {
    return "Exit codes:\n"
           "  0  success\n"
           "  1  unexpected internal error (a bug, or out of memory; also too little memory\n"
           "     or too many processes allowed to start the worker threads)\n"
           "  2  usage error: unknown option, bad value, bad combination of options\n"
           "     (octray compare: 5, as 2 is its FAIL verdict; see its --help)\n"
           "  3  scene error: the scene file or built-in spec cannot be loaded or is invalid\n"
           "  4  I/O error: an output file cannot be written (nothing partial is left),\n"
           "     or standard output cannot be (a closed pipe: EPIPE, not death by SIGPIPE)\n";
}

void end_command(int status) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
    throw CommandExit{status};
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer) || __has_feature(leak_sanitizer)
    throw CommandExit{status};
#endif
#endif
    // As after any command (octray_main): a standard output that could not be written is
    // an I/O error.
    status = finish_standard_output(status);
    std::cerr.flush();
    std::fflush(nullptr);
    std::_Exit(status);
}

std::string help_hint(const std::string& command) {
    return "Run 'octray " + (command.empty() ? std::string() : command + " ") +
           "--help' for more information.";
}

int run_command(const std::function<void()>& action, const std::string& command,
                int usage_status) {
    try {
        action();
        return kExitSuccess;
    } catch (const CommandExit& e) {
        return e.status;
    } catch (const UsageError& e) {
        std::cerr << "octray: error: " << e.what() << '\n' << help_hint(command) << '\n';
        return usage_status;
    } catch (const SceneError& e) {
        std::cerr << "octray: scene error: " << e.what() << '\n';
        return kExitScene;
    } catch (const IoError& e) {
        std::cerr << "octray: I/O error: " << e.what() << '\n';
        return kExitIo;
    } catch (const std::bad_alloc&) {
        std::cerr << "octray: out of memory\n";
        return kExitInternal;
    } catch (const ThreadStartError& e) {
        // As out of memory: the machine's limits, not the command line, are in the way.
        std::cerr << "octray: error: " << e.what() << "; use fewer --threads\n";
        return kExitInternal;
    } catch (const std::exception& e) {
        std::cerr << "octray: internal error: " << e.what() << '\n';
        return kExitInternal;
    } catch (...) {
        std::cerr << "octray: internal error: unknown exception\n";
        return kExitInternal;
    }
}

std::unique_ptr<CLI::App> make_octray_app(CommandRunner& run, std::string_view only) {
    auto app = std::make_unique<CLI::App>(
        "octray renders Whitted-style ray-traced images (OpenEXR, with PNG previews).",
        "octray");
    app->set_version_flag("-V,--version", std::string("octray ") + octray::kVersion,
                          "Print the version and exit");
    app->require_subcommand(1);
    app->footer(
        "Examples:\n"
        "  octray render                                  # the built-in whitted scene -> "
        "whitted.exr\n"
        "  octray render whitted -o whitted.exr --png whitted.png\n"
        "  octray render random:1024,width=640,height=360 --spp 4 -o random.exr\n"
        "  octray scene random:16 -o random16.json        # a built-in written as JSON\n"
        "Run 'octray help <command>' (or 'octray <command> --help') for the options of a\n"
        "command.\n\n" +
        exit_code_help());

    // In the order --help lists them; man and completion last (commands.h).
    using Add = void (*)(CLI::App&, CommandRunner&);
    static constexpr std::pair<std::string_view, Add> kCommands[] = {
        {"render", add_render_command},     {"scene", add_scene_command},
        {"compare", add_compare_command},   {"bench", add_bench_command},
        {"verify", add_verify_command},     {"info", add_info_command},
        {"assemble", add_assemble_command}, {"view", add_view_command}};
    for (const auto& [name, add] : kCommands) {
        if (name != only) continue;
        add(*app, run);
        return app;
    }
    for (const auto& [name, add] : kCommands) add(*app, run);
    add_man_command(*app, run);
    add_completion_command(*app, run);
    return app;
}

}  // namespace octray::tools
