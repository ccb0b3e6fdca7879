// `octray view`'s body, linked into octray-view (tools/own_executable.h): load
// the scene, apply the overrides, serve until Ctrl-C, or measure (--bench).

#include <pthread.h>

#include <atomic>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <utility>

#include "core/thread_check.h"
#include "render/batch/frame_loop.h"
#include "render/batch/memory_estimate.h"
#include "render/batch/plan.h"
#include "render/image/image_compare.h"
#include "render/image/image_io.h"
#include "render/render_config.h"
#include "scene/load.h"
#include "tools/cli_checks.h"
#include "tools/commands.h"
#include "tools/view_arguments.h"
#include "view/compare_view.h"
#include "view/jpeg.h"
#include "view/view_bench.h"
#include "view/view_server.h"
#include "view/view_session.h"

namespace octray::tools {
namespace {

// SIGINT and SIGTERM are blocked in every thread (the mask is inherited by the threads
// made after it) and taken by one thread with sigwait(), which then stops the server:
// stopping it from a signal handler would not be async-signal-safe.
class StopOnSignal {
  public:
    StopOnSignal() {
        sigemptyset(&signals_);
        sigaddset(&signals_, SIGINT);
        sigaddset(&signals_, SIGTERM);
        pthread_sigmask(SIG_BLOCK, &signals_, nullptr);
    }
    // The signals stay blocked: the command is about to return and the process to exit,
    // and a late Ctrl-C must not kill it before it has said that it stopped.
    ~StopOnSignal() {
        if (!waiter_.joinable()) return;
        // Wake the waiter if no signal came (the server stopped on its own).
        if (!signalled_) pthread_kill(waiter_.native_handle(), SIGTERM);
        waiter_.join();
    }
    StopOnSignal(const StopOnSignal&) = delete;
    StopOnSignal& operator=(const StopOnSignal&) = delete;

    void watch(view::ViewServer& server) {
        waiter_ = std::thread([this, &server] {
            int received = 0;
            sigwait(&signals_, &received);
            signalled_ = true;
            server.stop();
        });
    }

  private:
    sigset_t signals_{};
    std::atomic<bool> signalled_{false};
    std::thread waiter_;
};

void print_bench(const Scene& scene, const view::ViewSettings& settings,
                 const view::ViewBenchResult& r) {
    std::printf("octray view --bench: %s, %s path, %d threads (0 = all)\n",
                scene.source.c_str(), render_path_name(settings.render.path),
                settings.render.threads);
    std::printf("first picture: %dx%d at %d spp after %.3f s\n", r.first_width, r.first_height,
                r.first_spp, r.first_picture_seconds);
    std::printf(
        "orbit: %d updates of %dx%d in %.3f s: %.1f updates/s, %.1f Mrays/s, "
        "%.0f bytes each as sent (JPEG)\n",
        r.updates, r.update_width, r.update_height, r.seconds, r.updates_per_second,
        r.mrays_per_second, r.sent_bytes);
    std::printf(
        "last picture, one thread: tone map %.2f ms; then PNG %.2f ms (%.0f bytes), JPEG q%d "
        "%.2f ms (%.0f bytes), RGBA8 %.2f ms (%.0f bytes)\n",
        r.tone_map_ms, r.png_ms, r.last_png_bytes, view::kStreamJpegQuality, r.jpeg_ms,
        r.jpeg_bytes, r.rgba_ms, r.rgba_bytes);
    std::fflush(stdout);
}

// Serves until Ctrl-C (or SIGTERM); `what` says what is served, for the first line.
void serve(view::ViewServer& server, StopOnSignal& stop_on_signal, const std::string& what) {
    server.start();
    stop_on_signal.watch(server);
    std::cout << "octray view: " << what << " at\n"
              << "  " << server.url() << "\n"
              << "Open that URL in a browser (it carries the access token); Ctrl-C stops.\n"
              << std::flush;
    server.wait();
}

std::unique_ptr<view::ViewServer> make_server(const ViewArguments& args, auto& source,
                                              std::optional<view::SaveSettings> save = {}) {
    view::ServerOptions options;
    options.bind = args.bind;
    options.port = args.port;
    options.save = std::move(save);
    try {
        return std::make_unique<view::ViewServer>(source, options);
    } catch (const std::runtime_error& e) {
        throw UsageError(std::string("--bind/--port: ") + e.what());
    }
}

// `octray view A B`: the two images as `octray compare A B` reads and compares them, with
// its exit codes for images that cannot be read (4) or compared (3).
void run_compare_view(const ViewArguments& args) {
    if (args.width > 0 || args.height > 0 || args.spp > 0 || args.max_depth > 0 ||
        args.bench > 0 || args.order != "tiled")
        throw UsageError(
            "--width, --height, --spp, --max-depth, --order and --bench apply to a scene; "
            "with two images (A B) the viewer compares them");
    StopOnSignal stop_on_signal;  // before any thread is made
    const std::string& a = args.inputs[0];
    const std::string& b = args.inputs[1];
    view::CompareView images;
    try {
        images = view::load_compare_view(a, b);
    } catch (const ImageMismatch& e) {
        std::cerr << "octray: view: " << e.what() << " (A = " << a << ", B = " << b << ")";
        if (std::string_view(e.what()).starts_with("channel mismatch"))
            std::cerr << "; the viewer compares every channel: compare common ones with "
                         "octray compare A B --channels LIST";
        std::cerr << '\n';
        throw CommandExit{3};  // as `octray compare`
    }
    const auto server = make_server(args, images);
    serve(*server, stop_on_signal,
          a + " against " + b + " (" + std::to_string(images.result.width) + "x" +
              std::to_string(images.result.height) + ", " +
              std::string(to_string(images.result.verdict)) + ")");
    std::cout << "octray view: stopped\n" << std::flush;
}

// How the viewer renders at first (render/render_config.h): the path, ISA, threads and
// the scene's overrides its options give; the page's switches change them later.
RenderConfig view_config(const ViewArguments& args) {
    RenderConfig config;
    try {
        config.set_path(args.path);
        config.set_isa(args.isa);
        config.threads = args.threads;
        if (args.width > 0) config.overrides.width = args.width;
        if (args.height > 0) config.overrides.height = args.height;
        if (args.spp > 0) config.overrides.spp = args.spp;
        if (args.max_depth > 0) config.overrides.max_depth = args.max_depth;
        config.check();
        RenderConfig resolved = config;  // each render resolves "auto" again
        resolved.resolve_isa();
    } catch (const ConfigError& e) {
        throw UsageError("--" + e.setting() + ": " + e.detail());
    }
    return config;
}

// The viewer holds what a progressive `render --png` holds (the picture, the sums of its
// passes, a PNG of it) and more threads' scratch: refused by the same estimate as `render`
// when it exceeds the limit (--max-memory, else this machine's memory), rather than
// starting and failing on its first picture with std::bad_alloc.
void check_view_memory(const Scene& scene, const RenderConfig& config,
                       const ViewArguments& args) {
    const std::uint64_t limit = max_memory_limit(args.max_memory);  // 0: no limit
    if (limit == 0) return;
    batch::RenderMemoryParams memory = batch::memory_params(config);
    memory.progressive = true;
    memory.png_preview = true;
    try {
        batch::check_memory_limit(scene, limit, memory);
    } catch (const SceneError& e) {
        throw UsageError(e.what() + (args.max_memory.empty()
                                         ? std::string(" (the limit is this machine's memory; "
                                                       "--max-memory sets another)")
                                         : " (--max-memory " + args.max_memory + ")"));
    }
}

}  // namespace

void run_view(const ViewArguments& args) {
    if (args.inputs.size() == 2) {
        run_compare_view(args);
        return;
    }
    std::optional<StopOnSignal> stop_on_signal;
    if (args.bench == 0) stop_on_signal.emplace();  // before any thread is made (TBB's too)
    check_threads_can_start(args.threads);          // before oneTBB starts a worker (ulimit -v)
    const std::string spec = args.inputs.empty() ? std::string("whitted") : args.inputs[0];
    // The digest names the scene in the header of a saved picture, as in `octray render`'s.
    // An animation is shown at frame 0; the page's slider poses the others.
    const RenderConfig config = view_config(args);
    auto [scene, sha256] = batch::load_scene_and_digest(spec, args.threads);
    apply_overrides(scene, config.overrides);
    validate_scene(scene);
    check_view_memory(scene, config, args);

    view::ViewSettings settings;
    settings.render = config;
    settings.preview_divisor = args.preview_divisor;
    settings.frameless_block = args.frameless_block;
    settings.order = view::parse_pixel_order(args.order).value_or(view::PixelOrder::tiled);

    if (args.bench > 0) {
        print_bench(scene, settings, view::bench_orbit(scene, settings, args.bench));
        return;
    }

    view::ViewSession session(scene, settings);
    view::SaveSettings save;
    save.spec = spec;
    save.sha256 = sha256;
    const auto server = make_server(args, session, save);
    serve(*server, *stop_on_signal,
          scene.source + " (" + std::to_string(scene.image.width) + "x" +
              std::to_string(scene.image.height) + ", " + std::to_string(scene.image.spp) +
              " spp)");
    session.stop();
    std::cout << "octray view: stopped\n" << std::flush;
}

}  // namespace octray::tools
