#include "render/batch/plan.h"

#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/parallel_invoke.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <string_view>
#include <tuple>

#include "render/batch/digest.h"
#include "render/batch/output_paths.h"
#include "render/batch/spec.h"
#include "scene/animation.h"
#include "scene/builtin.h"
#include "scene/load.h"
#include "scene/scene_error.h"

namespace octray::batch {
namespace {

namespace fs = std::filesystem;

// The frames of one scene: `spec`, else the scene's own (0..frames-1, or 0 for a still).
std::vector<int> frames_of(const Scene& scene, const std::string& spec) {
    if (spec.empty()) return default_frames(scene);
    try {
        return parse_frame_spec(spec);
    } catch (const SpecError& e) {
        throw RequestError(std::string("--frames: ") + e.what());
    }
}

std::string default_pattern(bool sequence) {
    return sequence ? "{scene}.####.exr" : "{scene}.exr";
}

// How to keep two jobs that would write one file apart: what the pattern lacks, or, when
// it has {scene}, which scenes share a name (scene files named alike in two folders).
std::string collision_advice(const BatchInput& a, const BatchInput& b,
                             const std::string& pattern, bool different_frames) {
    if (&a == &b)
        return different_frames ? "put #### or {frame:04d} in the pattern"
                                : "the frame is listed twice";
    if (a.spec == b.spec) return "the scene " + a.spec + " is given twice";
    if (pattern.find("{scene}") == std::string::npos) return "put {scene} in the pattern";
    if (a.name == b.name)
        return "{scene} is \"" + a.name + "\" for both: it is a scene file's name without " +
               "its folder and extension, so " + a.spec + " and " + b.spec +
               " cannot be told apart by it; render them in separate runs, each with an -o " +
               "of its own (-o " + (fs::path(a.spec).parent_path() / "{scene}").string() +
               ".{frame:04d}.exr), or rename one of the files";
    return "{scene} is \"" + a.name + "\" and \"" + b.name +
           "\", and the rest of the pattern makes the names equal";
}
}  // namespace

// The scene's identity for the EXR: hashing a built-in's spec costs nothing where
// serializing random:1048576 to JSON and hashing that took seconds. The hash takes about a
// third of the parse's time, so the two run as two TBB tasks (one
// after the other with one thread).
std::pair<Scene, std::string> load_scene_and_digest(const std::string& spec, int threads) {
    if (is_builtin_scene(spec)) return {make_builtin_scene(spec), sha256_hex(spec)};
    const std::string text = read_scene_file(spec);
    std::optional<tbb::global_control> thread_limit;
    if (threads > 0) {
        thread_limit.emplace(tbb::global_control::max_allowed_parallelism,
                             static_cast<std::size_t>(threads));
    }
    Scene scene;
    std::string digest;
    tbb::parallel_invoke(
        [&] {
            Sha256 file_digest;
            file_digest.update(text);
            digest = file_digest.hex_digest();
        },
        [&] { scene = parse_scene_json(text, spec, text.capacity()); });
    return {std::move(scene), std::move(digest)};
}

BatchInput load_batch_input(const std::string& spec, const BatchRequest& request) {
    BatchInput loaded;
    loaded.spec = spec;
    loaded.name = scene_display_name(spec);
    const auto load_start = std::chrono::steady_clock::now();
    std::string digest;
    std::tie(loaded.scene, digest) = load_scene_and_digest(spec, request.threads);
    loaded.load_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();
    Scene& scene = loaded.scene;
    const SceneOverrides& o = request.overrides;
    apply_overrides(scene, o);
    if (o.any()) {
        // The scene itself was valid when loaded, so a failure now is the overrides' fault.
        try {
            validate_scene(scene);
        } catch (const SceneError& e) {
            throw RequestError(std::string("the options make the scene invalid: ") + e.what());
        }
    }
    loaded.sha256 = std::move(digest);
    return loaded;
}

std::vector<BatchJob> plan_jobs(const std::vector<BatchInput>& scenes,
                                const BatchRequest& request) {
    std::vector<BatchJob> jobs;
    std::size_t total = 0;
    std::vector<std::vector<int>> frames(scenes.size());
    for (std::size_t s = 0; s < scenes.size(); ++s) {
        frames[s] = frames_of(scenes[s].scene, request.frames);
        total += frames[s].size();
    }
    const std::string pattern =
        request.output.empty() ? default_pattern(total > scenes.size()) : request.output;
    try {
        for (std::size_t s = 0; s < scenes.size(); ++s) {
            if (frames[s].size() > 1 && !pattern_has_frame_field(pattern))
                throw RequestError("-o " + pattern +
                                   " has no frame field (#### or {frame:04d}) but " +
                                   std::to_string(frames[s].size()) + " frames of " +
                                   scenes[s].spec + " are to be rendered");
            if (!request.png.empty() && frames[s].size() > 1 &&
                !pattern_has_frame_field(request.png))
                throw RequestError(
                    "--png " + request.png + " has no frame field (#### or {frame:04d}) but " +
                    std::to_string(frames[s].size()) + " frames are to be rendered");
            for (const int frame : frames[s]) {
                BatchJob job;
                job.scene = s;
                job.frame = frame;
                job.output = expand_output_pattern(pattern, frame, scenes[s].name);
                if (!request.png.empty())
                    job.png = expand_output_pattern(request.png, frame, scenes[s].name);
                jobs.push_back(std::move(job));
            }
        }
    } catch (const SpecError& e) {
        throw RequestError(std::string("output pattern: ") + e.what());
    }

    // Two frames must never share a file (several scenes without {scene}, say). Files are
    // told apart by what a write replaces, the directory entry (device and inode of the
    // directory plus the name), so no spelling ("./", "..", a symlink) hides a clash.
    std::map<std::string, std::size_t> owner;
    std::map<std::string, std::string> directories;  // each directory looked up once
    const auto identity = [&directories](const std::string& file) {
        const fs::path path(file);
        const std::string dir = path.parent_path().string();
        auto it = directories.find(dir);
        if (it == directories.end())
            it = directories.emplace(dir, directory_identity(dir)).first;
        return it->second + path.filename().string();
    };
    for (std::size_t j = 0; j < jobs.size(); ++j) {
        if (!jobs[j].png.empty() && identity(jobs[j].png) == identity(jobs[j].output))
            throw RequestError("-o and --png name the same file: " + jobs[j].output + " and " +
                               jobs[j].png);
        for (const std::string* file : {&jobs[j].output, &jobs[j].png}) {
            if (file->empty()) continue;
            const std::string key = identity(*file);
            const auto [it, inserted] = owner.emplace(key, j);
            if (!inserted) {
                const BatchJob& other = jobs[it->second];
                throw RequestError("two frames would write the same file " + *file + ": " +
                                   scenes[other.scene].spec + " frame " +
                                   std::to_string(other.frame) + " and " +
                                   scenes[jobs[j].scene].spec + " frame " +
                                   std::to_string(jobs[j].frame) + " (" +
                                   collision_advice(scenes[other.scene], scenes[jobs[j].scene],
                                                    pattern, other.frame != jobs[j].frame) +
                                   ")");
            }
        }
    }
    return jobs;
}

}  // namespace octray::batch
