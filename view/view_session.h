#pragma once
// The renderer behind `octray view`: one scene, a camera the page moves, and a thread that
// renders it — a reduced-resolution preview while the camera moves, then progressive
// passes of 1, 2, 4, ... samples per pixel up to the scene's spp once it stops — and
// publishes each finished picture for the HTTP server (view/view_server.h).

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "kernels/isa.h"
#include "render/image/image.h"
#include "render/packet_renderer.h"
#include "render/render_config.h"
#include "render/render_options.h"
#include "scene/scene.h"

namespace octray::view {

// The order in which a picture's pixels are rendered and shown.
enum class PixelOrder {
    tiled,      // whole pictures: progressive passes (and previews while moving)
    rows,       // as tiled, each tile one row of the picture (row-major within a pass)
    frameless,  // blocks in a fixed random permutation, shown as they land (frameless.h)
};

struct ViewSettings {
    PixelOrder order = PixelOrder::tiled;
    int frameless_block = 8;  // frameless: block side in pixels
    // How it renders (render/render_config.h): the path, the ISA (as asked: automatic is
    // resolved by each render) and the threads (0: every core TBB sees) are read from it;
    // the viewer cuts its own tiles and rows, and the scene carries its overrides.
    RenderConfig render;
    int frame = 0;            // an animated scene's frame shown first
    int preview_divisor = 4;  // a moving camera renders (width / d) x (height / d) at 1 spp
    // After a preview, the passes at full resolution start once the camera has not moved
    // for this long (a page that sends no final "stopped" still gets a sharp picture).
    std::chrono::milliseconds settle{300};
};

// What the page may switch while the viewer runs (POST /api/settings).
struct RenderSwitches {
    // The render's description, as `octray render` takes it (render/render_config.h): the
    // switches change its path, ISA and threads; the rest stays the session's.
    RenderConfig render;
    int spp = 1;
    int max_depth = 1;
    PixelOrder order = PixelOrder::tiled;
    int frame = 0;  // the animation's frame (0 for a still scene)
};

// "tiled", "rows", "frameless"; and the order a name stands for.
const char* to_string(PixelOrder order);
std::optional<PixelOrder> parse_pixel_order(const std::string& name);

// One published picture and how it was made.
struct ViewFrame {
    Image image;  // linear float32 R, G, B planes (make_rgb_image), row 0 on top
    std::uint64_t generation = 0;      // 1, 2, 3, ... in publishing order
    std::uint64_t camera_version = 0;  // which set_camera() call it shows (1: the scene's)
    Camera camera;
    bool preview = false;                // reduced resolution while the camera moves
    int spp = 0;                         // samples per pixel so far
    int target_spp = 0;                  // the scene's spp: the last pass
    int max_depth = 0;                   // the scene's max depth when it was rendered
    int animation_frame = 0;             // the animation's frame (0 for a still scene)
    RenderPath path = RenderPath::simd;  // the renderer that made it,
    Isa isa = Isa::automatic;            // and the ISA asked of the simd path
    double pass_seconds = 0.0;           // this pass
    double frame_seconds = 0.0;          // every pass so far of this camera
    double mrays_per_second = 0.0;       // this pass: rays traced / pass_seconds
    // Frameless: the part of the picture rendered with this camera so far (1: all of it,
    // at the scene's spp; the rest still shows earlier cameras). Tiled: always 1.
    double coverage = 1.0;
    // Tiled: the rays and render time of every pass of this camera so far (what `octray
    // render` writes in its header). Frameless: not counted (zero).
    RayCounts rays;
    double render_seconds = 0.0;
};

class ViewSession {
  public:
    // `scene` must have passed validate_scene(). An animated scene is shown at frame
    // settings.frame (in range), posed as scene_at_frame() poses it; the page's frame
    // switch poses another. Starts rendering at once.
    ViewSession(Scene scene, ViewSettings settings);
    ~ViewSession();  // stop()
    ViewSession(const ViewSession&) = delete;
    ViewSession& operator=(const ViewSession&) = delete;

    // The scene as loaded (an animation posed at the current frame; its camera is the
    // initial one, not the page's), with the switches applied.
    Scene scene() const;
    RenderSwitches switches() const;
    // The animation's frame count (1 for a still scene) and frames per second (its fps,
    // kStillFps for a still scene). They never change.
    int frame_count() const { return frame_count_; }
    double frames_per_second() const { return fps_; }
    // Applies new switches: the render in flight is abandoned, the render thread restarts
    // with them and renders the current camera again (a new camera version). A new frame
    // of an animation whose camera is animated takes that frame's camera. Throws
    // SceneError for values the scene rules refuse (spp, max depth out of range, a pose
    // that cannot be rendered), std::out_of_range for a frame outside the animation and
    // std::runtime_error for an ISA this CPU lacks; nothing changes then. Returns the
    // camera version of the pictures made with the new switches.
    std::uint64_t reconfigure(const RenderSwitches& switches);

    // The latest picture, nullptr before the first one.
    std::shared_ptr<const ViewFrame> latest() const;
    // Waits up to `timeout` for a picture newer than `generation` (or stop()); returns the
    // latest (possibly still the old one, or nullptr).
    std::shared_ptr<const ViewFrame> wait_newer(std::uint64_t generation,
                                                std::chrono::milliseconds timeout) const;

    // Moves the camera: the picture being rendered is abandoned at its next tile, except a
    // preview when `moving` (the preview is finished and published, then the latest camera
    // is rendered: abandoning every preview for the next move would show nothing while the
    // moves come faster than a preview renders). `moving`: more moves follow soon, so
    // render a preview first. Throws SceneError (with what is
    // wrong) for a camera the scene cannot have: non-finite numbers, eye on the look-at
    // point, up along the view, a fov out of range. Returns the new camera version.
    std::uint64_t set_camera(const Camera& camera, bool moving);
    Camera camera() const;

    // Why the latest camera could not be rendered (a render that threw, such as out of
    // memory), empty if it could; cleared by the next camera.
    std::string error() const;

    // Ends the render thread (the pass in flight is abandoned) and wakes every waiter.
    void stop();
    bool stopped() const;

  private:
    void run();
    void run_frameless();
    // A picture of `camera`; the simd path renders `prepared_scene`, prepared for the
    // first picture of the current switches (run() keeps it, reconfigure() drops it).
    void render_preview(const Camera& camera, std::uint64_t version,
                        std::optional<PreparedScene>& prepared_scene);
    bool render_passes(const Camera& camera, std::uint64_t version,
                       std::optional<PreparedScene>& prepared_scene);
    PreparedScene& prepared(std::optional<PreparedScene>& prepared) const;
    void publish(ViewFrame frame);

    // Options of every render of the current switches: threads, the cancel flag, the
    // frame counter of the sample hash, and for the rows order one tile per row.
    RenderOptions render_options(int width) const;
    ViewFrame frame_of(std::uint64_t version, const Camera& camera) const;

    // An animated scene as loaded (its poses come from it), absent for a still one.
    const std::optional<Scene> animated_;
    const int frame_count_;
    const double fps_;
    // Changed only by reconfigure(), while the render thread is stopped; read by other
    // threads under mutex_ (scene(), switches()).
    Scene scene_;
    ViewSettings settings_;
    std::mutex reconfigure_mutex_;  // one reconfigure() or stop() at a time
    bool restart_ = false;          // the render thread is to return for reconfigure()

    mutable std::mutex mutex_;
    mutable std::condition_variable changed_;  // camera set, picture published, or stop
    Camera camera_;
    std::uint64_t camera_version_ = 1;
    bool moving_ = false;
    // A preview is being rendered: a newer moving camera does not abandon it (it is
    // rendered next), so that previews reach the screen however fast the camera moves.
    bool previewing_ = false;
    bool stop_ = false;
    std::uint64_t generation_ = 0;
    std::shared_ptr<const ViewFrame> latest_;
    std::string error_;
    std::atomic<bool> cancel_{false};  // what the renderers poll between tiles

    std::thread thread_;
};

}  // namespace octray::view
