#pragma once
// octray's public C++ API: the one installed header (docs/embedding.md).
//
// A thin facade over the renderer's internal libraries: build a scene in code or load one
// (a JSON file or a built-in such as "whitted"), render it with either path, get the
// linear RGB image (or a crop of it), its AOVs and the ray counts, write it as OpenEXR,
// render an animation's frames to files as `octray render` does, compare two images.
// Nothing here exposes an internal header, so the API stays the same when the internals
// change.
//
//   #include <octray/octray.h>
//   octray::api::Scene scene = octray::api::Scene::load("whitted");
//   octray::api::RenderResult r = octray::api::render(scene, {.threads = 2});
//   octray::api::write_exr("whitted.exr", r.image);
//
// CMake: find_package(octray CONFIG REQUIRED) and
// target_link_libraries(app PRIVATE octray::octray).
//
// Every function reports failure by throwing octray::api::Error.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace octray::api {

// The library's version, "MAJOR.MINOR.PATCH" (the same as `octray --version`).
const char* version();

// ---- Errors ------------------------------------------------------------------------

enum class ErrorKind {
    scene,             // a scene that cannot be loaded or is invalid (the CLI's exit code 3)
    io,                // a file that cannot be read or written (exit code 4)
    invalid_argument,  // a bad option: an ISA the CPU lacks, images of different sizes, ...
    cancelled,         // RenderOptions::progress returned false: the render was stopped
};

class Error : public std::runtime_error {
  public:
    Error(ErrorKind kind, const std::string& message)
        : std::runtime_error(message), kind_(kind) {}
    ErrorKind kind() const { return kind_; }

  private:
    ErrorKind kind_;
};

// ---- Scenes --------------------------------------------------------------------------
// The types mirror the scene format (docs/scene-format.md); every default is the format's.

struct Vec3 {
    float x = 0.0f, y = 0.0f, z = 0.0f;
};

struct Rgb {  // linear RGB
    float r = 0.0f, g = 0.0f, b = 0.0f;
};

enum class CameraType { pinhole, orthographic, thinlens, fisheye };

struct Camera {
    CameraType type = CameraType::pinhole;
    Vec3 eye{0.0f, 0.0f, 5.0f};
    Vec3 lookat{0.0f, 0.0f, 0.0f};
    Vec3 up{0.0f, 1.0f, 0.0f};
    float fov = 50.0f;            // degrees across the image width (pinhole, thinlens, fisheye)
    float width = 2.0f;           // film width in world units (orthographic)
    float aperture = 0.0f;        // lens radius (thinlens)
    float focus_distance = 1.0f;  // distance to the plane in focus (thinlens)
};

struct Material {
    Rgb color{0.8f, 0.8f, 0.8f};  // diffuse color Cd
    float kd = 1.0f;              // diffuse weight
    float ks = 0.0f;              // Phong highlight weight
    float shininess = 32.0f;      // Phong exponent
    Rgb reflect{};                // mirror weight kr
    float transmit = 0.0f;        // refraction weight kt
    float ior = 1.5f;             // index of refraction
    // A checker (planes only): checker_color on the odd squares of size checker_size.
    bool checker = false;
    Rgb checker_color{};
    float checker_size = 1.0f;
};

// An authored scene. Scene() is the format's defaults: 640x480, 1 spp, the default
// pinhole camera, a black constant background, no objects and no lights. A scene is
// checked (validate()) before it renders; the setters themselves accept anything.
class Scene {
  public:
    Scene();
    ~Scene();
    Scene(const Scene& other);
    Scene& operator=(const Scene& other);
    Scene(Scene&& other) noexcept;
    Scene& operator=(Scene&& other) noexcept;

    // A JSON scene file or a built-in ("whitted", "random:1024,spp=4", "sphereflake:3").
    static Scene load(const std::string& spec);
    // A JSON scene from memory; `source` names it in error messages.
    static Scene from_json(std::string_view json, const std::string& source = "<memory>");

    Scene& set_image(int width, int height, int spp = 1);
    Scene& set_camera(const Camera& camera);
    Scene& set_background(Rgb color);            // constant
    Scene& set_background(Rgb bottom, Rgb top);  // vertical gradient
    Scene& set_ambient(Rgb ambient);
    Scene& set_max_depth(int max_depth);  // bounces; 0 traces primary rays only
    Scene& set_seed(std::uint64_t seed);  // seed of the sample jitter

    // Returns the material's index, for add_sphere / add_plane. A non-empty name must be
    // unique; an unnamed material is written inline by to_json().
    std::uint32_t add_material(const Material& material, const std::string& name = {});
    // A non-empty name must be unique (it is what animations refer to).
    Scene& add_sphere(Vec3 center, float radius, std::uint32_t material,
                      const std::string& name = {});
    Scene& add_plane(Vec3 point, Vec3 normal, std::uint32_t material);
    Scene& add_point_light(Vec3 position, Rgb color, bool inverse_square = false);
    Scene& add_directional_light(Vec3 direction, Rgb color);  // the way the light travels

    int width() const;
    int height() const;
    int spp() const;
    std::size_t object_count() const;
    std::size_t light_count() const;

    // Throws Error(ErrorKind::scene) naming the first problem.
    void validate() const;
    // The scene as JSON that Scene::from_json reads back to an identical scene (the format
    // of docs/scene-format.md). Validates first: throws Error(ErrorKind::scene).
    std::string to_json() const;

  private:
    friend struct SceneAccess;
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// ---- Rendering -----------------------------------------------------------------------

enum class Path {
    simd,    // 8-ray packets through the per-ISA kernels (the default)
    scalar,  // the scalar reference renderer; the same image bit for bit
};

enum class Isa {
    automatic,  // the best this CPU supports
    sse2,
    sse4_1,
    avx2,
    avx512,  // AVX-512 F/VL/BW/DQ
};

// "auto", "sse2", "sse4.1", "avx2", "avx512".
const char* isa_name(Isa isa);
// The ISA of a name isa_name() gives; Error(invalid_argument) for any other.
Isa parse_isa(const std::string& name);
// The ISAs this CPU can run, best last (never Isa::automatic).
std::vector<Isa> supported_isas();

// How far a render is: pixels of the image finished (tile by tile) of all of them.
struct Progress {
    std::uint64_t pixels_done = 0;
    std::uint64_t pixels_total = 0;
    double fraction() const {
        return pixels_total ? static_cast<double>(pixels_done) / pixels_total : 1.0;
    }
};

// Arbitrary output variables rendered alongside the image (`octray render --aov`): each
// pixel's first surface along its sample-0 camera ray, the same values on either path and
// bit for bit what `octray render --aov` writes into its EXR.
struct AovSelection {
    bool depth = false;   // distance along the unit camera ray to the first hit
    bool normal = false;  // the hit's world-space unit normal, facing the ray
    bool albedo = false;  // the diffuse color Cd at the hit (checker included)
    bool id = false;      // the hit object's index + 1 (spheres and planes in the order added)
    bool any() const { return depth || normal || albedo || id; }
};

// "depth,normal,albedo,id" (any of them, each once, comma-separated) as a selection;
// Error(invalid_argument) naming an unknown, empty or repeated item.
AovSelection parse_aovs(const std::string& list);

// A rectangle of pixels of the full image: columns x0 .. x1-1, rows y0 .. y1-1, row 0 on
// top (`octray render --crop x0,y0,x1,y1`).
struct Crop {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    int width() const { return x1 - x0; }
    int height() const { return y1 - y0; }
};

// The side of a render's square tiles unless RenderOptions says otherwise: the octray
// command's `--tile` default (api/octray.cpp checks that the two agree).
inline constexpr int kDefaultTileSide = 32;

struct RenderOptions {
    Path path = Path::simd;
    Isa isa = Isa::automatic;  // simd path only; a forced ISA the CPU lacks is an Error
    int threads = 0;           // worker threads; 0 uses every core
    int spp = 0;               // samples per pixel; 0 keeps the scene's
    int width = 0;             // image size; 0 keeps the scene's
    int height = 0;
    int frame = 0;  // frame number (>= 0) of an animated scene: its pose and jitter
    // Threads, tile size (sides 1 .. 4096) and ISA never change the image: only its speed.
    int tile_width = kDefaultTileSide;
    int tile_height = kDefaultTileSide;
    // Called on the thread that called render(): once before the render starts, then about
    // every progress_interval_ms while it runs, and once at the end (all pixels done; its
    // answer then changes nothing). Returning false stops the render at its next tile (it
    // waits for the tiles in flight, milliseconds): render() then throws
    // Error(ErrorKind::cancelled) and returns no image. Empty: no calls.
    // Preparing a frame (on the simd path, a scene's first frame compiles it and builds
    // its BVH) is part of the render: the first call comes before it, and the calls go on
    // while it runs (pixels_done 0) and can stop the render after it.
    std::function<bool(const Progress&)> progress = nullptr;
    int progress_interval_ms = 100;
    // Only this window of the image (width x height after the overrides): RenderResult's
    // image (and AOVs) are crop-sized, each pixel bit for bit the same pixel of the whole
    // image. Empty or outside the image: Error(invalid_argument). Unset: the whole image.
    std::optional<Crop> crop = std::nullopt;
    // The AOVs to render alongside the image (RenderResult::aovs); none by default.
    AovSelection aovs{};
    // A render (or render_frames) whose memory estimate — `octray render`'s, framebuffer,
    // tile scratch, BVH, AOVs and outputs — exceeds this many bytes is refused before
    // anything is allocated: Error(scene) with the estimate and its terms, as `octray render
    // --max-memory` refuses it. 0: this machine's memory (no limit where it is unknown).
    std::uint64_t max_memory = 0;
};

// Linear RGB floats, row 0 on top: pixel (x, y) is rgb[3 * (y * width + x) + {0, 1, 2}].
struct Image {
    int width = 0;
    int height = 0;
    std::vector<float> rgb;
};

struct RayCounts {
    std::uint64_t primary = 0;
    std::uint64_t shadow = 0;
    std::uint64_t reflected = 0;
    std::uint64_t refracted = 0;
    std::uint64_t total() const { return primary + shadow + reflected + refracted; }
};

// The AOVs of RenderOptions::aovs, pixel (x, y) of the image at index y * width + x (three
// floats per pixel for normal and albedo, as Image::rgb); a vector is empty unless its AOV
// was asked for. Background pixels (no hit) hold +inf depth, a zero normal and albedo,
// id 0.
struct Aovs {
    std::vector<float> depth{};
    std::vector<float> normal{};  // x, y, z
    std::vector<float> albedo{};  // r, g, b (linear)
    std::vector<std::uint32_t> id{};
};

struct RenderResult {
    Image image;
    RayCounts rays;
    double seconds = 0.0;  // wall-clock time of the render
    std::string path;      // "scalar", or "simd (avx2)" with the ISA used
    Aovs aovs{};           // the AOVs asked for, the size of `image`
    // Which pixels of the full_width x full_height image `image` holds: the crop, or the
    // whole image.
    Crop window{};
    int full_width = 0;
    int full_height = 0;
};

// Renders the scene (or its animation frame options.frame) with the options' overrides
// applied and the result validated. Throws Error. The same as
// Renderer(scene, options).render(options.frame).
RenderResult render(const Scene& scene, const RenderOptions& options = {});

// A scene prepared once and rendered frame after frame. The constructor copies the scene,
// applies the options' overrides and validates it; on the simd path the first frame
// compiles it and builds its BVH, and the next frames reuse them: a still scene's frames,
// and a camera-only animation's, only take their camera; an animation of moving spheres
// updates the compiled spheres in place and refits the BVH (or rebuilds it when the refit
// tree has grown too costly). render(f) is, bit for bit, render(scene, options) with
// .frame = f, whatever the frames rendered before it and their order. The scalar path
// renders each frame from its posed scene. One render at a time per Renderer.
//
//   octray::api::Renderer renderer(octray::api::Scene::load("anim.json"), {.threads = 2});
//   for (int f = 0; f < renderer.frame_count(); ++f) save(renderer.render(f).image);
class Renderer {
  public:
    explicit Renderer(const Scene& scene, const RenderOptions& options = {});
    ~Renderer();
    Renderer(Renderer&&) noexcept;
    Renderer& operator=(Renderer&&) noexcept;

    // Frame `frame` (>= 0; frames past an animation's end hold its last pose); the
    // options' frame is not used. Throws Error.
    RenderResult render(int frame);
    // The animation's frame count; 1 for a still scene (0 for a moved-from Renderer, whose
    // render() throws).
    int frame_count() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// ---- Images ---------------------------------------------------------------------------

struct ExrOptions {
    bool float32 = false;  // 32-bit float channels instead of half
};

// Writes R, G, B channels (ZIP-compressed), atomically: the file is complete or absent.
void write_exr(const std::string& path, const Image& image, const ExrOptions& options = {});
// Reads the R, G and B channels of an OpenEXR or PNG file (PNG values are not linearised).
Image read_image(const std::string& path);

// idiff's thresholds and verdicts (octray compare --help).
struct CompareOptions {
    double fail_threshold = 1e-6;  // a pixel fails when a channel differs by more
    double fail_percent = 0.0;     // FAIL when more than this % of the pixels fail
    double warn_threshold = 1e-6;
    double warn_percent = 0.0;
};

enum class Verdict { pass = 0, warn = 1, fail = 2 };

struct CompareResult {
    Verdict verdict = Verdict::pass;
    double max_abs_error = 0.0;
    double mean_abs_error = 0.0;
    double rmse = 0.0;
    double psnr = 0.0;  // infinite for identical images
    std::uint64_t fail_pixels = 0;
    std::uint64_t warn_pixels = 0;
    std::uint64_t nonfinite_pixels = 0;  // NaN or Inf in either image
    std::string reason;                  // one line: the verdict and why
};

// Compares b against a; images of different sizes are an Error (invalid_argument).
CompareResult compare(const Image& a, const Image& b, const CompareOptions& options = {});
// The same for two files (every channel, as `octray compare`).
CompareResult compare_files(const std::string& a, const std::string& b,
                            const CompareOptions& options = {});

// ---- Frames to files ----------------------------------------------------------------
// An animation's frames (or a still) rendered to files by the frame loop of `octray render`
// (the same library): each frame's EXR (with AOV channels, a crop's data window and the
// header attributes of `octray render --help`) and optional PNG preview written
// atomically, complete or absent; a frame that fails is reported and the others go on.

struct FrameFilesOptions {
    // The files: `#` runs or {frame:04d} become the frame number, {scene} the scene's name
    // (a loaded scene's file stem or built-in name, "scene" for one built in code); .exr,
    // or .png for the 8-bit sRGB preview alone. Empty: {scene}.exr for one frame, else
    // {scene}.####.exr. Missing directories are created.
    std::string output{};
    // The frames: "5", "1-100", "1-100:2", "1-10,20,30-40:5" (`octray render --frames`).
    // Empty: the animation's frames 0 .. frame_count()-1, or frame 0 of a still.
    std::string frames{};
    std::string png{};  // also an 8-bit sRGB PNG preview per frame, a pattern as `output`
    ExrOptions exr{};
    bool skip_existing = false;  // leave frames whose files all exist (resume)
};

enum class FrameStatus { rendered, skipped, failed };

struct FrameFile {
    int frame = 0;
    std::string output;
    std::string png;  // empty: no preview
    FrameStatus status = FrameStatus::rendered;
    std::string message;     // failed: why
    std::uint64_t rays = 0;  // rays traced (a rendered frame)
    double seconds = 0.0;    // the frame's time: prepare, render and write
};

struct FrameFilesResult {
    std::vector<FrameFile> frames;  // in frame-list order; the interrupted one is absent
    int rendered = 0, skipped = 0, failed = 0;
    bool cancelled = false;  // the progress callback stopped the run
    double seconds = 0.0;
};

// Renders the frames of `scene` with `options` (path, ISA, threads, tiles, size, spp,
// crop, AOVs; its frame is not used) to files. options.progress is called with the
// pixels of the whole run (every frame) done, on the calling thread; returning false
// abandons the frame in progress at its next tile, deletes nothing finished, starts no
// other frame and returns with `cancelled` set (no Error). Throws Error(invalid_argument)
// for bad options (a frame spec or pattern, two frames writing one file, a crop outside
// the image), Error(io) when an output directory cannot be made; a frame that fails to
// render or write is in the result, `failed`.
FrameFilesResult render_frames(const Scene& scene, const RenderOptions& options,
                               const FrameFilesOptions& files);

}  // namespace octray::api
