#include "view/view_save.h"

#include <cctype>
#include <filesystem>
#include <fstream>
#include <string_view>
#include <system_error>
#include <vector>

#include "kernels/dispatch.h"
#include "render/batch/digest.h"
#include "render/batch/frame_loop.h"
#include "render/image/image_io.h"
#include "scene/builtin.h"
#include "scene/load.h"
#include "view/http_error.h"
#include "view/request_json.h"
#include "view/view_switches.h"

namespace octray::view {
namespace {

using nlohmann::json;

// A file name for POST /api/save: letters, digits, '.', '_', '-', '+' only (so no '/',
// no space, nothing a shell would read), not starting with '.' or '-', no "..", ending
// in .exr.
void check_save_name(const std::string& name) {
    const auto bad = [&](const std::string& why) {
        return BadRequest(400, "save: file name \"" + name + "\" " + why +
                                   " (a plain name such as view.exr, written in the "
                                   "directory octray view was started in)");
    };
    if (name.empty() || name.size() > 200) throw bad("must have 1 to 200 characters");
    if (name.find('/') != std::string::npos || name.find("..") != std::string::npos)
        throw bad("must not contain '/' or '..'");
    for (const char c : name) {
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-' &&
            c != '+')
            throw bad("may only hold letters, digits, '.', '_', '-' and '+'");
    }
    if (name[0] == '.' || name[0] == '-') throw bad("must not start with '.' or '-'");
    std::string lower = name;
    for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (lower.size() < 5 || lower.compare(lower.size() - 4, 4, ".exr") != 0)
        throw bad("must end in .exr");
}

// `text` as one shell word: as it is when it holds only safe characters, else quoted.
std::string shell_word(const std::string& text) {
    bool safe = !text.empty();
    for (const char c : text) {
        if (!std::isalnum(static_cast<unsigned char>(c)) &&
            std::string_view("._-+/:=,").find(c) == std::string_view::npos)
            safe = false;
    }
    if (safe) return text;
    std::string quoted = "'";
    for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return quoted + "'";
}

bool same_camera(const Camera& a, const Camera& b) {
    const auto same = [](const Vec3& u, const Vec3& v) {
        return u.x == v.x && u.y == v.y && u.z == v.z;
    };
    return same(a.eye, b.eye) && same(a.lookat, b.lookat) && same(a.up, b.up) && a.fov == b.fov;
}

}  // namespace

// POST /api/save: the refined picture as `octray render` writes it (view/README.md).
nlohmann::json save_view(ViewSession& session, const SaveSettings& settings,
                         const std::string& body) {
    const json request = parse_request_json(body, "save");
    if (request.is_discarded() || !request.is_object() || !request.contains("name") ||
        !request["name"].is_string())
        throw BadRequest(400, "save: expected {\"name\": \"view.exr\", \"overwrite\": false}");
    bool overwrite = false;
    for (const auto& [key, value] : request.items()) {
        if (key == "overwrite") {
            if (!value.is_boolean())
                throw BadRequest(400, "save.overwrite: expected true or false");
            overwrite = value.get<bool>();
        } else if (key != "name") {
            throw BadRequest(400,
                             "save: unknown key \"" + key + "\" (expected name, overwrite)");
        }
    }
    const std::string name = request["name"].get<std::string>();
    check_save_name(name);
    const auto frame = session.latest();
    Scene posed = session.scene();
    const int animation_frame = session.switches().frame;
    if (!frame || frame->preview || frame->spp < frame->target_spp ||
        frame->target_spp != posed.image.spp || frame->max_depth != posed.render.max_depth ||
        frame->animation_frame != animation_frame)
        throw BadRequest(409, "save: the picture is still refining; save once it has all " +
                                  std::to_string(posed.image.spp) + " spp");
    if (frame->rays.total() == 0)
        throw BadRequest(409, "save: needs the tiled order (frameless pictures are not saved)");
    namespace fs = std::filesystem;
    const fs::path directory(settings.directory);
    // A moved camera is a new scene: written beside the image as JSON (`octray scene`'s
    // writer), named in the header and the command line instead of the original.
    const Camera scene_camera = posed.camera;
    const bool moved = !same_camera(frame->camera, scene_camera);
    const std::string scene_file = moved ? name.substr(0, name.size() - 4) + ".json" : "";
    std::vector<std::string> files{name};
    if (moved) files.push_back(scene_file);
    // The scene being viewed is never replaced, overwrite or not (an animated scene would
    // lose its animation to the frame's still pose); every other existing file is named.
    std::vector<std::string> existing;
    for (const std::string& file : files) {
        std::error_code error;
        if (!is_builtin_scene(settings.spec) &&
            fs::equivalent(directory / file, settings.spec, error) && !error)
            throw BadRequest(409, "save: " + file + " is the scene being viewed (" +
                                      settings.spec +
                                      "), which a save never overwrites; choose another name");
        if (fs::exists(directory / file, error)) existing.push_back(file);
    }
    if (!overwrite && !existing.empty()) {
        std::string names;
        for (std::size_t i = 0; i < existing.size(); ++i)
            names += (i == 0 ? "" : " and ") + existing[i];
        throw BadRequest(409, "save: " + names + (existing.size() == 1 ? " exists" : " exist") +
                                  "; ask to overwrite " +
                                  (existing.size() == 1 ? "it" : "them") +
                                  " (\"overwrite\": true)");
    }

    posed.camera = frame->camera;
    batch::BatchInput identity;
    identity.spec = settings.spec;
    identity.sha256 = settings.sha256;
    identity.scene = posed;
    // The header's time and frame rate are the animation's (render_exr_attributes reads
    // only its frame count and fps from the scene it identifies).
    if (session.frame_count() > 1) {
        identity.scene.animation.emplace();
        identity.scene.animation->frames = session.frame_count();
        identity.scene.animation->fps = session.frames_per_second();
    }
    if (moved) {
        const std::string text = scene_to_json(posed);
        write_file_atomically((directory / scene_file).string(), [&](const std::string& tmp) {
            std::ofstream out(tmp, std::ios::binary);
            out << text;
            out.close();
            if (!out) throw IoError("cannot write " + tmp);
        });
        identity.spec = scene_file;
        identity.sha256 = batch::sha256_hex(text);
    }
    RenderResult result;
    result.image = frame->image;
    result.rays = frame->rays;
    result.seconds = frame->render_seconds;
    const ExrAttributes attributes = batch::render_exr_attributes(
        identity, posed, posed.camera, animation_frame, result,
        path_label(frame->path, frame->isa), posed.image.spp, std::string());
    write_exr((directory / name).string(), result.image, ExrWriteOptions{}, attributes);

    std::string command = "octray render " + shell_word(identity.spec) + " --width " +
                          std::to_string(posed.image.width) + " --height " +
                          std::to_string(posed.image.height) + " --spp " +
                          std::to_string(posed.image.spp) + " --max-depth " +
                          std::to_string(posed.render.max_depth);
    if (frame->path == RenderPath::scalar) command += " --path scalar";
    if (frame->path == RenderPath::simd && frame->isa != Isa::automatic)
        command += std::string(" --isa ") + isa_name(frame->isa);
    if (session.frame_count() > 1) command += " --frames " + std::to_string(animation_frame);
    command += " -o " + name;
    json answer{{"file", name}, {"command", command}, {"camera_moved", moved}};
    answer["scene_file"] = moved ? json(scene_file) : json(nullptr);
    return answer;
}

}  // namespace octray::view
