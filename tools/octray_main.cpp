// The octray command line's main(), shared by both executables (octray and the viewer's
// octray-view, tools/own_executable.h): parse, call the library, report.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <csignal>
#include <exception>
#include <iostream>
#include <memory>
#include <new>
#include <string>
#include <string_view>
#include <vector>

#include "scene/suggest.h"
#include "tools/cli_checks.h"
#include "tools/commands.h"
#include "tools/own_executable.h"

namespace octray::tools {

namespace {

// The command a command line was given to: the deepest one that parsed ("" for none).
std::string parsed_command(const CLI::App& app) {
    std::string name;
    const CLI::App* command = &app;
    for (;;) {
        const auto parsed = command->get_subcommands();
        if (parsed.empty()) return name;
        command = parsed.front();
        name += (name.empty() ? "" : " ") + command->get_name();
    }
}

// The exit status of a usage error of `command`: compare has its own (kExitCompareUsage).
int usage_status(const std::string& command) {
    return command == "compare" ? kExitCompareUsage : kExitUsage;
}

std::vector<std::string> command_names(const CLI::App& app) {
    std::vector<std::string> names;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
        names.push_back(sub->get_name());
    return names;
}

std::string joined(const std::vector<std::string>& words) {
    std::string out;
    for (const std::string& word : words) out += (out.empty() ? "" : ", ") + word;
    return out;
}

// "unknown command "frobnicate" (did you mean ...?)" or with the list of commands.
std::string unknown_command_message(const CLI::App& app, const std::string& word) {
    const std::vector<std::string> names = command_names(app);
    const std::vector<std::string_view> candidates(names.begin(), names.end());
    if (const auto best = closest_word(word, candidates))
        return "unknown command \"" + word + "\" (did you mean \"" + std::string(*best) +
               "\"?)";
    return "unknown command \"" + word + "\"; the commands are " + joined(names);
}

// `octray help [COMMAND]` is `octray [COMMAND] --help`, as git and cargo have it. Rewrites
// the arguments, or returns the usage error's message.
std::string rewrite_help_command(const CLI::App& app, std::vector<std::string>& args) {
    if (args.size() < 2 || args[1] != "help") return {};
    if (args.size() > 3)
        return "help takes one command name, found " + std::to_string(args.size() - 2) +
               " arguments (octray help COMMAND)";
    if (args.size() == 2 || args[2] == "help") {
        args = {args[0], "--help"};
        return {};
    }
    const std::vector<std::string> names = command_names(app);
    if (std::find(names.begin(), names.end(), args[2]) == names.end())
        return unknown_command_message(app, args[2]);
    args = {args[0], args[2], "--help"};
    return {};
}

}  // namespace

int octray_main(int argc, char** argv) {
    // A write past `ulimit -f` then fails with EFBIG, reported as an I/O error with its
    // temporary removed, instead of SIGXFSZ killing the process mid-file.
    std::signal(SIGXFSZ, SIG_IGN);
    // Likewise a write to a closed pipe (`octray ... | head -1`) fails with EPIPE and is
    // reported as an I/O error (finish_standard_output), instead of SIGPIPE killing the
    // process with status 141.
    std::signal(SIGPIPE, SIG_IGN);

    remember_command_line(argc, argv);  // for the commands in executables of their own
    CommandRunner run;
    const std::unique_ptr<CLI::App> app_owner =
        make_octray_app(run, argc > 1 ? std::string_view(argv[1]) : std::string_view());
    CLI::App& app = *app_owner;

    std::vector<std::string> args(argv, argv + argc);
    if (const std::string error = rewrite_help_command(app, args); !error.empty()) {
        std::cerr << "octray: error: " << error << '\n' << help_hint("") << '\n';
        return kExitUsage;
    }
    std::vector<char*> arguments;
    for (std::string& arg : args) arguments.push_back(arg.data());

    try {
        app.parse(static_cast<int>(arguments.size()), arguments.data());
    } catch (const CLI::ParseError& e) {
        // --help and --version: their output, status 0.
        if (e.get_exit_code() == 0) return finish_standard_output(app.exit(e));
        // Every usage error names the help of the command it was given to.
        const std::string command = parsed_command(app);
        // A mistyped option or command: name the one probably meant, as git and cargo do
        // (the scene loader's "did you mean", scene/suggest.h).
        std::string message = mistyped_argument_hint(app);
        if (message.empty() && command.empty()) {
            for (const std::string& word : app.remaining()) {
                if (word.empty() || word.front() == '-') continue;
                message = unknown_command_message(app, word);
                break;
            }
            // `octray` alone: CLI11's "A subcommand is required" names none of them.
            if (message.empty() && app.remaining().empty() &&
                dynamic_cast<const CLI::RequiredError*>(&e) != nullptr)
                message = "no command given; the commands are " + joined(command_names(app));
        }
        if (message.empty()) message = e.what();
        // CLI11 writes "--warmup: must be an integer >= 0 ..." for the number checks
        // (tools/cli_checks.h); it reads as a sentence without the colon.
        if (const auto colon = message.find(": must be ");
            colon != std::string::npos && message.rfind(' ', colon) == std::string::npos)
            message.erase(colon, 1);
        std::cerr << "octray: error: " << message << '\n' << help_hint(command) << '\n';
        return usage_status(command);
    }
    const std::string command = parsed_command(app);
    if (!run.action) {
        std::cerr << "octray: error: no command given\n" << help_hint("") << '\n';
        return kExitUsage;
    }
    return finish_standard_output(run_command(run.action, command, usage_status(command)));
}

}  // namespace octray::tools
