// `octray scene`: write the scene a spec describes (a built-in, or a file normalised) as JSON.

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>

#include "render/image/image_io.h"
#include "scene/load.h"
#include "tools/cli_checks.h"
#include "tools/commands.h"

namespace octray::tools {
namespace {

struct SceneArguments {
    std::string scene;
    std::string output;  // empty: standard output
    bool quiet = false;
};

void write_text(const std::string& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(std::generic_category().message(errno));
    out << text;
    out.close();  // flushes: a full disk shows up here
    if (!out) throw std::runtime_error(std::generic_category().message(errno));
}

void run_scene(const SceneArguments& args) {
    const Scene scene = load_scene(args.scene);
    print_scene_warnings(scene, args.quiet);
    std::string json = scene_to_json(scene);
    if (json.empty() || json.back() != '\n') json += '\n';
    if (args.output.empty()) {
        std::cout << json << std::flush;
        if (!std::cout)
            throw IoError(std::string("cannot write the scene to standard output: ") +
                          std::strerror(errno));
        return;
    }
    write_file_atomically(args.output, [&](const std::string& tmp) { write_text(tmp, json); });
    std::cerr << "wrote " << args.output << '\n';
}

}  // namespace

void add_scene_command(CLI::App& app, CommandRunner& run) {
    auto args = std::make_shared<SceneArguments>();
    CLI::App* cmd = app.add_subcommand(
        "scene",
        "Write a scene (built-in or file) as JSON; rendering that file gives the "
        "identical image");
    cmd->add_option("scene", args->scene,
                    "Scene: a built-in (whitted, random:N, sphereflake:L, with optional\n"
                    ",width=W,height=H,spp=N,seed=S,max_depth=D) or a JSON file")
        ->type_name("SCENE")
        ->check(completes(builtin_scene_words()))
        ->required();
    cmd->add_option("-o,--output", args->output,
                    "Output JSON file, written atomically [default: standard output]")
        ->type_name("FILE");
    cmd->add_flag("-q,--quiet", args->quiet, kQuietHelp);
    cmd->footer(
        "Examples:\n"
        "  octray scene random:16 -o random16.json\n"
        "  octray scene whitted                   # print the default scene\n"
        "  octray scene my.json -o normalised.json\n\n" +
        exit_code_help());
    cmd->callback([args, &run] { run.action = [args] { run_scene(*args); }; });
}

}  // namespace octray::tools
