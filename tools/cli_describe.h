#pragma once
// The commands and options of the `octray` command line as data, read from the CLI11
// definitions the parser itself uses (main.cpp and each cmd_<name>.cpp), so that the
// generated documents — the shell completions (`octray completion`) and the man pages
// (`octray man`) — can never miss or misdescribe an option.

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace octray::tools {

struct OptionInfo {
    std::vector<std::string> names;  // "-o", "--output"; empty for a positional argument
    std::string positional;          // a positional's name ("scenes"), else empty
    std::string type_name;           // "PATTERN", "N", "SCENE..."; empty for a flag
    std::string description;         // the whole help text, '\n' where --help breaks it
    std::string default_value;       // CLI11's captured default, if any
    bool takes_value = false;        // false for a flag
    bool required = false;
    // The words the value completes to (tools/cli_checks.h, one_of and completes): the
    // choices of --path, the built-in scenes of a SCENE argument; empty for any value.
    std::vector<std::string> values;
};

struct CommandInfo {
    std::string name;                 // "render"; "octray" for the program itself
    std::string description;          // the whole description
    std::string footer;               // the --help footer: notes, "Examples:", "Exit codes:"
    std::vector<OptionInfo> options;  // named options, in --help order
    std::vector<OptionInfo> positionals;  // positional arguments, in order
};

// The program itself (its own options: --help, --version).
CommandInfo describe_program(const CLI::App& app);

// Every subcommand of `app`, in the order they were added.
std::vector<CommandInfo> describe_commands(const CLI::App& app);

// The first line of a (description) text.
std::string first_line(const std::string& text);

}  // namespace octray::tools
