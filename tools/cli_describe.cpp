// The command line as data: tools/cli_describe.h.

#include "tools/cli_describe.h"

#include <CLI/CLI.hpp>

#include "tools/cli_checks.h"

namespace octray::tools {
namespace {

CommandInfo describe_one(const CLI::App& app, const std::string& name) {
    CommandInfo c{name, app.get_description(), app.get_footer(), {}, {}};
    for (const CLI::Option* option : app.get_options()) {
        if (option->get_group().empty()) continue;  // hidden from --help
        OptionInfo o;
        for (const std::string& n : option->get_snames()) o.names.push_back("-" + n);
        for (const std::string& n : option->get_lnames()) o.names.push_back("--" + n);
        o.type_name = option->get_type_name();
        o.description = option->get_description();
        o.default_value = option->get_default_str();
        o.takes_value = option->get_expected_max() > 0;  // flags expect none
        o.required = option->get_required();
        if (!o.takes_value) o.type_name.clear();
        o.values = completion_words(*option);
        if (o.names.empty()) {
            o.positional = option->get_name(true);
            c.positionals.push_back(std::move(o));
        } else {
            c.options.push_back(std::move(o));
        }
    }
    return c;
}

}  // namespace

std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

CommandInfo describe_program(const CLI::App& app) { return describe_one(app, app.get_name()); }

std::vector<CommandInfo> describe_commands(const CLI::App& app) {
    std::vector<CommandInfo> commands;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
        commands.push_back(describe_one(*sub, sub->get_name()));
        // CLI11 gives a subcommand without a footer of its own the program's.
        if (commands.back().footer == app.get_footer()) commands.back().footer.clear();
    }
    return commands;
}

}  // namespace octray::tools
