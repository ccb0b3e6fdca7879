// `octray man [COMMAND]`: the man page of octray(1) or of one command (octray-render(1),
// ...) as roff, generated from the option definitions the parser itself uses
// (tools/cli_describe.h), like `octray completion`: every option with its whole help text,
// the examples and exit statuses of the command's --help footer. `--directory DIR` writes
// every page (octray.1, octray-<command>.1) into DIR, which is how the build makes the
// pages that `cmake --install` installs.

#include <CLI/CLI.hpp>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "core/version.h"
#include "render/image/image_io.h"
#include "scene/suggest.h"
#include "tools/cli_describe.h"
#include "tools/commands.h"

namespace octray::tools {
namespace {

struct ManArguments {
    std::string command;    // empty: octray(1)
    std::string directory;  // empty: print one page on standard output
};

// Text for roff: backslashes and hyphens escaped (a hyphen in an option name must stay a
// hyphen-minus, `\-`), and a line that would start with a control character made literal.
std::string roff_text(std::string_view text) {
    std::string out;
    for (char c : text) {
        if (c == '\\')
            out += "\\e";
        else if (c == '-')
            out += "\\-";
        else
            out += c;
    }
    if (!out.empty() && (out.front() == '.' || out.front() == '\'')) out.insert(0, "\\&");
    return out;
}

std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> lines;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t end = text.find('\n', start);
        lines.push_back(text.substr(start, end == std::string::npos ? end : end - start));
        if (end == std::string::npos) break;
        start = end + 1;
    }
    while (!lines.empty() && lines.back().empty()) lines.pop_back();
    return lines;
}

// A text in fill mode: each line of it a line of roff (roff joins them into paragraphs).
std::string roff_paragraph(const std::string& text) {
    std::string out;
    for (const std::string& line : lines_of(text)) {
        const std::size_t first = line.find_first_not_of(' ');
        if (first == std::string::npos) continue;
        out += roff_text(line.substr(first)) + "\n";
    }
    return out;
}

// "-o, --output PATTERN" in bold and italics.
std::string option_label(const OptionInfo& o) {
    std::string out;
    for (const std::string& name : o.names)
        out += (out.empty() ? "" : ", ") + std::string("\\fB") + roff_text(name) + "\\fR";
    if (!o.type_name.empty()) out += " \\fI" + roff_text(o.type_name) + "\\fR";
    return out;
}

std::string option_entry(const std::string& label, const OptionInfo& o) {
    std::string out = ".TP\n" + label + "\n" + roff_paragraph(o.description);
    std::string value = o.default_value;
    if (value.size() >= 2 && value.front() == '[' && value.back() == ']')
        value = value.substr(1, value.size() - 2);  // a list: CLI11 writes [a,b]
    if (!value.empty() && o.description.find("[default") == std::string::npos)
        out += ".br\nDefault: \\fB" + roff_text(value) + "\\fR\n";
    return out;
}

// A block of a --help footer: its lines up to a blank line.
using Block = std::vector<std::string>;

std::vector<Block> blocks_of(const std::string& text) {
    std::vector<Block> blocks(1);
    for (const std::string& line : lines_of(text)) {
        if (line.find_first_not_of(' ') == std::string::npos) {
            if (!blocks.back().empty()) blocks.emplace_back();
        } else {
            blocks.back().push_back(line);
        }
    }
    if (blocks.back().empty()) blocks.pop_back();
    return blocks;
}

// "Examples:" or "Exit codes:" on a line of its own: the block's heading.
bool is_heading(const Block& block) {
    const std::string& first = block.front();
    return first.size() > 1 && first.back() == ':' && first.front() != ' ' &&
           first.find(". ") == std::string::npos && first.size() < 60;
}

std::string upper(std::string text) {
    for (char& c : text) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return text;
}

// "  0  success", "130  interrupted ...", "  3, 4  ...": a status and its meaning.
bool split_status(const std::string& line, std::string& status, std::string& meaning) {
    std::size_t i = line.find_first_not_of(' ');
    if (i == std::string::npos || !std::isdigit(static_cast<unsigned char>(line[i])))
        return false;
    const std::size_t gap = line.find("  ", i);
    if (gap == std::string::npos) return false;
    for (std::size_t k = i; k < gap; ++k)
        if (!std::isdigit(static_cast<unsigned char>(line[k])) && line[k] != ',' &&
            line[k] != ' ' && line[k] != '-')
            return false;
    status = line.substr(i, gap - i);
    meaning = line.substr(line.find_first_not_of(' ', gap));
    return true;
}

// An exit-code table: a .TP entry per status, its continuation lines joined to it.
std::string exit_status_section(const Block& block) {
    std::string out = ".SH \"EXIT STATUS\"\n";
    for (std::size_t k = 1; k < block.size(); ++k) {
        std::string status, meaning;
        if (split_status(block[k], status, meaning))
            out += ".TP\n.B " + roff_text(status) + "\n" + roff_paragraph(meaning);
        else if (block[k].front() == ' ')  // the meaning goes on
            out += roff_paragraph(block[k]);
        else  // a note after the table
            out += ".PP\n" + roff_paragraph(block[k]);
    }
    return out;
}

// A block's lines from `from` on: runs of indented lines (examples) shown as they are, with
// no filling or adjusting; other lines (notes between them) as paragraphs.
std::string literal_lines(const Block& block, std::size_t from) {
    std::string out;
    bool literal = false;
    for (std::size_t k = from; k < block.size(); ++k) {
        const std::size_t first = block[k].find_first_not_of(' ');
        const bool indented = first > 0;
        if (indented != literal || k == from)
            out += literal && !indented ? ".fi\n.RE\n.PP\n"
                   : indented           ? ".PP\n.RS 4\n.nf\n"
                                        : ".PP\n";
        literal = indented;
        out += roff_text(block[k].substr(std::min<std::size_t>(first, 2))) + "\n";
    }
    return literal ? out + ".fi\n.RE\n" : out;
}

// The sections a --help footer makes: its paragraphs (DESCRIPTION, after the command's
// own description), EXAMPLES and EXIT STATUS; any other heading becomes its own section.
struct FooterSections {
    std::string description, examples, exit_status, others;
};

FooterSections footer_sections(const std::string& footer) {
    FooterSections s;
    for (const Block& block : blocks_of(footer)) {
        if (!is_heading(block) && block.front().rfind("Exit codes: ", 0) == 0) {
            // "Exit codes: 0 within the thresholds ..., 1 otherwise; ...": in prose.
            std::string text;
            for (const std::string& line : block) text += line + "\n";
            s.exit_status += ".SH \"EXIT STATUS\"\n" + roff_paragraph(text.substr(12));
            continue;
        }
        if (!is_heading(block)) {
            std::string text;
            for (const std::string& line : block) text += line + "\n";
            const bool literal = block.front().rfind("  ", 0) == 0;
            s.description += literal ? literal_lines(block, 0) : ".PP\n" + roff_paragraph(text);
            continue;
        }
        const std::string heading = block.front().substr(0, block.front().size() - 1);
        if (heading == "Examples")
            s.examples += ".SH EXAMPLES\n" + literal_lines(block, 1);
        else if (heading.rfind("Exit codes", 0) == 0)  // "Exit codes (compare's own...)"
            s.exit_status += exit_status_section(block);
        else
            s.others += ".SH \"" + roff_text(upper(heading)) + "\"\n" + literal_lines(block, 1);
    }
    return s;
}

std::string page_name(const std::string& command) {
    return command.empty() ? "octray" : "octray-" + command;
}

std::string header(const std::string& name, const std::string& summary) {
    return ".\\\" Generated by `octray man` from the options octray's parser uses; do not "
           "edit.\n"
           ".TH " +
           roff_text(upper(name)) + " 1 \"\" \"octray " + roff_text(kVersion) +
           "\" \"octray manual\"\n"
           ".nh\n.ad l\n"  // option names and paths must not be hyphenated
           ".SH NAME\n" +
           roff_text(name) + " \\- " + roff_text(summary) + "\n";
}

std::string see_also(const std::string& self, const std::vector<CommandInfo>& commands) {
    std::vector<std::string> pages{"octray"};
    for (const CommandInfo& c : commands) pages.push_back(page_name(c.name));
    std::string out = ".SH \"SEE ALSO\"\n";
    bool first = true;
    for (const std::string& page : pages) {
        if (page == self) continue;
        out += std::string(first ? "" : ",\n") + ".BR " + roff_text(page) + " (1)";
        first = false;
    }
    return out + "\n";
}

// The summary on the NAME line: the description's first sentence, without its period.
std::string summary_of(const std::string& description) {
    std::string line = first_line(description);
    if (const std::size_t stop = line.find(". "); stop != std::string::npos) line.resize(stop);
    if (!line.empty() && line.back() == '.') line.pop_back();
    if (!line.empty())
        line[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(line[0])));
    return line;
}

// A description as a sentence: ending with a period.
std::string sentence(std::string text) {
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    if (!text.empty() && text.back() != '.') text += '.';
    return text;
}

std::string options_section(const std::vector<OptionInfo>& options) {
    std::string out = ".SH OPTIONS\n";
    for (const OptionInfo& o : options) out += option_entry(option_label(o), o);
    return out;
}

std::string command_page(const CommandInfo& c, const std::vector<CommandInfo>& commands) {
    const std::string name = page_name(c.name);
    std::string out = header(name, summary_of(c.description));
    out += ".SH SYNOPSIS\n.B octray " + roff_text(c.name) + "\n";
    if (!c.options.empty()) out += "[\\fIOPTIONS\\fR]\n";
    for (const OptionInfo& p : c.positionals) {
        const std::string label = "\\fI" + roff_text(p.type_name) + "\\fR";
        out += p.required ? label + "\n" : "[" + label + "]\n";
    }
    const FooterSections footer = footer_sections(c.footer);
    out += ".SH DESCRIPTION\n" + roff_paragraph(c.description) + footer.description;
    if (!c.positionals.empty()) {
        out += ".SH ARGUMENTS\n";
        for (const OptionInfo& p : c.positionals)
            out += option_entry("\\fI" + roff_text(p.type_name) + "\\fR", p);
    }
    out += options_section(c.options) + footer.others + footer.examples;
    out += footer.exit_status.empty() ? exit_status_section(blocks_of(exit_code_help()).front())
                                      : footer.exit_status;
    return out + see_also(name, commands);
}

std::string program_page(const CommandInfo& program, const std::vector<CommandInfo>& commands) {
    // "octray renders Whitted-style ..." names the program once: "octray - renders ...".
    std::string summary = summary_of(program.description);
    if (summary.rfind("octray ", 0) == 0) summary.erase(0, 7);
    std::string out = header("octray", summary);
    out +=
        ".SH SYNOPSIS\n"
        ".B octray\n"
        "\\fICOMMAND\\fR [\\fIOPTIONS\\fR] [\\fIARGUMENTS\\fR]\n"
        ".br\n"
        ".B octray help\n"
        "[\\fICOMMAND\\fR]\n"
        ".br\n"
        ".B octray\n"
        "\\fB\\-V\\fR | \\fB\\-\\-version\\fR | \\fB\\-h\\fR | \\fB\\-\\-help\\fR\n";
    const FooterSections footer = footer_sections(program.footer);
    out += ".SH DESCRIPTION\n" + roff_paragraph(program.description) + footer.description;
    out += ".SH COMMANDS\n";
    for (const CommandInfo& c : commands)
        out += ".TP\n.B " + roff_text(c.name) + "\n" + roff_paragraph(sentence(c.description)) +
               "See\n.BR " + roff_text(page_name(c.name)) + " (1).\n";
    out +=
        ".TP\n.BI help \" COMMAND\"\n"
        "Print the help of a command: the same as \\fBoctray \\fICOMMAND\\fB \\-\\-help\\fR.\n";
    out += options_section(program.options) + footer.others + footer.examples;
    out += footer.exit_status.empty() ? exit_status_section(blocks_of(exit_code_help()).front())
                                      : footer.exit_status;
    return out + see_also("octray", commands);
}

void write_text(const std::string& path, const std::string& text) {
    write_file_atomically(path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        out << text;
        out.close();  // flushes: a full disk shows up here
        if (!out) throw IoError("cannot write " + tmp);
    });
}

void run_man(const ManArguments& args, const CLI::App& app) {
    const CommandInfo program = describe_program(app);
    const std::vector<CommandInfo> commands = describe_commands(app);
    std::vector<std::pair<std::string, std::string>> pages;  // (file name, roff)
    if (args.command.empty()) pages.emplace_back("octray.1", program_page(program, commands));
    for (const CommandInfo& c : commands)
        if (args.command == c.name || (args.command.empty() && !args.directory.empty()))
            pages.emplace_back(page_name(c.name) + ".1", command_page(c, commands));
    if (pages.empty()) {
        std::vector<std::string_view> names;
        for (const CommandInfo& c : commands) names.push_back(c.name);
        const auto best = closest_word(args.command, names);
        throw UsageError("unknown command \"" + args.command + "\"" +
                         (best ? " (did you mean \"" + std::string(*best) + "\"?)" : ""));
    }
    if (args.directory.empty()) {
        std::cout << pages.front().second;
        return;
    }
    std::error_code error;
    std::filesystem::create_directories(args.directory, error);
    if (error)
        throw IoError("cannot create the directory " + args.directory + ": " + error.message());
    for (const auto& [file, text] : pages) {
        const std::string path = (std::filesystem::path(args.directory) / file).string();
        write_text(path, text);
        std::cerr << "wrote " << path << '\n';
    }
}

}  // namespace

void add_man_command(CLI::App& app, CommandRunner& run) {
    auto args = std::make_shared<ManArguments>();
    CLI::App* cmd = app.add_subcommand(
        "man",
        "Print the man page of octray or of one of its commands (roff), generated from "
        "its options");
    cmd->add_option("command", args->command,
                    "The command whose page to print (octray-COMMAND(1))\n"
                    "[default: octray(1), the program and its list of commands]")
        ->type_name("COMMAND");
    cmd->add_option("-d,--directory", args->directory,
                    "Write the pages into DIR instead (created if missing): octray.1 and\n"
                    "octray-COMMAND.1 for every command, or only COMMAND's page")
        ->type_name("DIR");
    cmd->footer(
        "Examples:\n"
        "  octray man render | man -l -              # read octray-render(1)\n"
        "  octray man -d ~/.local/share/man/man1     # every page, for man octray-render\n\n" +
        exit_code_help());
    const CLI::App* top = &app;
    cmd->callback([args, top, &run] { run.action = [args, top] { run_man(*args, *top); }; });
}

}  // namespace octray::tools
