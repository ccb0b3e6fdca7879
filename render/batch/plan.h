#pragma once
// Planning a batch render from a plain request (BatchRequest: what `octray render` reads
// from its options, or what any other caller fills in): loading each scene with its
// digest and the request's overrides, and the run's list of jobs, one per frame, with
// their output files. The frame loop (frame_loop.h) renders the jobs.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/pixel_rect.h"
#include "render/render_config.h"
#include "scene/scene.h"

namespace octray::batch {

// A request that cannot be carried out as asked (a bad frame spec or output pattern, a
// pattern without a frame field for several frames, two frames writing one file, options
// that make a scene invalid): the caller's mistake, found before anything renders. The
// message names the option of `octray render` that the request's field stands for.
class RequestError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// A scene's settings that the request replaces; unset: the scene's own (one struct for
// every caller: render/render_config.h).
using octray::SceneOverrides;

struct BatchRequest {
    SceneOverrides overrides;
    int threads = 0;     // loading's hash and parse run side by side; 0: every core
    std::string frames;  // a frame spec (spec.h); empty: each scene's own frames
    // An output pattern (spec.h); empty: {scene}.exr, or {scene}.####.exr when the run has
    // more frames than scenes.
    std::string output;
    std::string png;  // the PNG previews' pattern; empty: no preview
};

// One input of a batch run: a scene as the run takes it (loaded once, overrides applied)
// and what the run says of it. Not another shape of a scene: the Scene is `scene`
// (render/README.md, "Scene shapes").
struct BatchInput {
    std::string spec;               // as given on the command line
    std::string name;               // {scene} in output patterns
    std::string sha256;             // octray.sceneSha256
    Scene scene;                    // loaded, overrides applied, validated
    std::optional<PixelRect> crop;  // --crop, checked against the image
    double load_seconds = 0.0;      // reading (and hashing) and parsing it, for --stats
};

struct BatchJob {
    std::size_t scene = 0;  // index into the scenes
    int frame = 0;
    std::string output;
    std::string png;  // empty: no preview
};

// The scene of `spec` (a built-in or a JSON file) and its identity for the EXR: the
// SHA-256 of the file's bytes (what `sha256sum` prints), or for a built-in, of its spec
// string as given (`printf %s SPEC | sha256sum`). A file is read once; its bytes are
// hashed and parsed side by side on at most `threads` threads (0: every core). Throws
// SceneError.
std::pair<Scene, std::string> load_scene_and_digest(const std::string& spec, int threads);

// The scene of `spec` with its name, digest, load time and the request's overrides,
// validated again when any applies (RequestError when they make it invalid). Throws
// SceneError for a scene that cannot be loaded.
BatchInput load_batch_input(const std::string& spec, const BatchRequest& request);

// The frame list of the whole run, in order: each scene's frames (request.frames, else
// its animation's 0..frames-1, or 0 for a still), scene after scene, with the output and
// preview files of each. RequestError for a bad frame spec or pattern, a pattern without
// a frame field for several frames, -o and --png naming one file, or two frames that
// would write one file, however spelled (output_paths.h, output_identity).
std::vector<BatchJob> plan_jobs(const std::vector<BatchInput>& scenes,
                                const BatchRequest& request);

}  // namespace octray::batch
