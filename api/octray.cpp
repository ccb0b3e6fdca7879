// The public API (include/octray/octray.h): a thin facade that converts its plain types to
// the internal ones and calls the libraries the command line uses: scene/ to load and
// validate, render/ for both paths, EXR writing, reading and comparison.

#include "octray/octray.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <filesystem>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include "core/version.h"
#include "kernels/dispatch.h"
#include "render/batch/digest.h"
#include "render/batch/frame_loop.h"
#include "render/batch/memory_estimate.h"
#include "render/batch/output_paths.h"
#include "render/batch/plan.h"
#include "render/batch/spec.h"
#include "render/frame_renderer.h"
#include "render/image/image_compare.h"
#include "render/image/image_io.h"
#include "render/image/image_read.h"
#include "render/packet_renderer.h"
#include "render/reference.h"
#include "render/render_config.h"
#include "scene/animation.h"
#include "scene/load.h"
#include "scene/scene.h"

namespace octray::api {

// The API's default tile is the renderer's (core/pixel_rect.h), so a render through the
// API runs as `octray render` does.
static_assert(kDefaultTileSide == TileSize{}.width && kDefaultTileSide == TileSize{}.height);

struct Scene::Impl {
    octray::Scene scene;
};

struct SceneAccess {
    static const octray::Scene& get(const Scene& s) { return s.impl_->scene; }
    static octray::Scene& get(Scene& s) { return s.impl_->scene; }
};

namespace {

octray::Vec3 to_internal(Vec3 v) { return {v.x, v.y, v.z}; }
octray::Rgb to_internal(Rgb c) { return {c.r, c.g, c.b}; }

// Runs `f`, turning the internal libraries' exceptions into api::Error.
template <typename F>
auto translate_errors(F&& f) -> decltype(f()) {
    try {
        return f();
    } catch (const Error&) {
        throw;
    } catch (const SceneError& e) {
        throw Error(ErrorKind::scene, e.what());
    } catch (const IoError& e) {
        throw Error(ErrorKind::io, e.what());
    } catch (const std::bad_alloc&) {
        throw;
    } catch (const std::exception& e) {
        // ImageMismatch, std::invalid_argument, an unsupported forced ISA, ...
        throw Error(ErrorKind::invalid_argument, e.what());
    }
}

octray::Isa to_internal(Isa isa) {
    switch (isa) {
        case Isa::sse2:
            return octray::Isa::sse2;
        case Isa::sse4_1:
            return octray::Isa::sse4_1;
        case Isa::avx2:
            return octray::Isa::avx2;
        case Isa::avx512:
            return octray::Isa::avx512;
        case Isa::automatic:
            break;
    }
    return octray::Isa::automatic;
}

Isa from_internal(octray::Isa isa) {
    switch (isa) {
        case octray::Isa::sse2:
            return Isa::sse2;
        case octray::Isa::sse4_1:
            return Isa::sse4_1;
        case octray::Isa::avx2:
            return Isa::avx2;
        case octray::Isa::avx512:
            return Isa::avx512;
        case octray::Isa::automatic:
            break;
    }
    return Isa::automatic;
}

// The API's interleaved RGB image as octray's: float32 planes R, G, B (a render's image,
// render/image/image.h), its data window its display window.
octray::Image image_to_internal(const Image& image) {
    if (image.width < 0 || image.height < 0 ||
        image.rgb.size() != 3 * static_cast<std::size_t>(image.width) *
                                static_cast<std::size_t>(image.height)) {
        throw Error(ErrorKind::invalid_argument,
                    "image: rgb must hold 3 floats for each of width x height pixels");
    }
    const octray::PixelRect window{0, 0, image.width, image.height};
    octray::Image out = octray::make_rgb_image(window, window);
    const std::size_t n = out.pixel_count();
    for (int c = 0; c < 3; ++c) {
        float* plane = out.plane(c);
        for (std::size_t k = 0; k < n; ++k)
            plane[k] = image.rgb[3 * k + static_cast<std::size_t>(c)];
    }
    return out;
}

// A render's image (float32 R, G, B planes) as the API's interleaved RGB.
Image image_from_internal(const octray::Image& image) {
    Image out;
    out.width = image.width();
    out.height = image.height();
    const std::size_t n = image.pixel_count();
    out.rgb.resize(3 * n);
    for (int c = 0; c < 3; ++c) {
        const float* plane = image.plane(c);
        for (std::size_t k = 0; k < n; ++k)
            out.rgb[3 * k + static_cast<std::size_t>(c)] = plane[k];
    }
    return out;
}

CompareResult compare_channels(const octray::Image& a, const octray::Image& b,
                               const CompareOptions& options) {
    octray::CompareOptions o;
    o.fail_threshold = options.fail_threshold;
    o.fail_percent = options.fail_percent;
    o.warn_threshold = options.warn_threshold;
    o.warn_percent = options.warn_percent;
    const octray::CompareResult r = compare_images(a, b, o);
    CompareResult out;
    out.verdict = static_cast<Verdict>(static_cast<int>(r.verdict));
    out.max_abs_error = r.overall.max_abs_error;
    out.mean_abs_error = r.overall.mean_abs_error;
    out.rmse = r.overall.rmse;
    out.psnr = r.overall.psnr;
    out.fail_pixels = r.overall.fail_pixels;
    out.warn_pixels = r.overall.warn_pixels;
    out.nonfinite_pixels = r.overall.nonfinite_pixels;
    out.reason = r.reason;
    return out;
}

// An exception the progress callback threw, carried past translate_errors (it is no
// std::exception) to reach the caller as it was thrown.
struct CallbackFailure {
    std::exception_ptr error;
};

// Runs `run` on a thread of its own while this thread calls options.progress with
// done() of pixels_total pixels, and sets `cancel` (which `run` polls) when the callback
// says stop. A run stopped that way throws RenderCancelled, which becomes
// Error(cancelled); with `cancel_throws` false a stop before the run starts does not throw
// either (the run sees `cancel` set and returns what it has).
template <typename Run, typename Done>
auto run_reporting(const Run& run, const Done& done, std::atomic<bool>& cancel,
                   std::uint64_t pixels_total, const RenderOptions& options,
                   bool cancel_throws = true) -> decltype(run()) {
    Progress progress;
    progress.pixels_total = pixels_total;
    const auto ask = [&] {
        try {
            return options.progress(progress);
        } catch (...) {
            throw CallbackFailure{std::current_exception()};
        }
    };
    if (!ask()) {
        if (cancel_throws)
            throw Error(ErrorKind::cancelled, "render cancelled by the progress callback");
        cancel = true;
    }

    std::mutex mutex;
    std::condition_variable finished_cv;
    bool finished = false;
    decltype(run()) result{};
    std::exception_ptr failure;
    std::thread worker([&] {
        try {
            result = run();
        } catch (...) {
            failure = std::current_exception();
        }
        std::lock_guard lock(mutex);
        finished = true;
        finished_cv.notify_one();
    });
    std::exception_ptr callback_failure;
    const auto interval = std::chrono::milliseconds(std::max(options.progress_interval_ms, 1));
    {
        std::unique_lock lock(mutex);
        while (!finished_cv.wait_for(lock, interval, [&] { return finished; })) {
            if (cancel.load() || callback_failure) continue;  // waiting for the stop
            progress.pixels_done = std::min(done(), progress.pixels_total);
            lock.unlock();
            try {
                if (!options.progress(progress)) cancel = true;
            } catch (...) {
                callback_failure = std::current_exception();
                cancel = true;
            }
            lock.lock();
        }
    }
    worker.join();
    if (callback_failure) throw CallbackFailure{callback_failure};
    if (failure) {
        try {
            std::rethrow_exception(failure);
        } catch (const RenderCancelled&) {
            throw Error(ErrorKind::cancelled, "render cancelled by the progress callback");
        }
    }
    if (!cancel.load()) {
        progress.pixels_done = progress.pixels_total;
        static_cast<void>(ask());  // done: its answer changes nothing
    }
    return result;
}

// The one description of a render (render/render_config.h) that the API's options give,
// checked.
octray::RenderConfig to_config(const RenderOptions& options) {
    if (options.width < 0 || options.height < 0 || options.spp < 0)
        throw std::invalid_argument(
            "render: width, height and spp must be >= 0 (0 keeps the scene's)");
    octray::RenderConfig config;
    config.path = options.path == Path::scalar ? RenderPath::scalar : RenderPath::simd;
    config.isa = to_internal(options.isa);
    config.threads = options.threads;
    config.tile = {options.tile_width, options.tile_height};
    if (options.width > 0) config.overrides.width = options.width;
    if (options.height > 0) config.overrides.height = options.height;
    if (options.spp > 0) config.overrides.spp = options.spp;
    if (options.crop) {
        const Crop& c = *options.crop;
        config.crop = PixelRect{c.x0, c.y0, c.x1, c.y1};
    }
    config.aovs = {options.aovs.depth, options.aovs.normal, options.aovs.albedo,
                   options.aovs.id};
    config.check();
    return config;
}

// The scene with the options' overrides applied, validated, and the crop checked against
// it; the ISA resolved.
octray::Scene configured_scene(const Scene& scene, octray::RenderConfig& config) {
    octray::Scene source = SceneAccess::get(scene);
    apply_overrides(source, config.overrides);
    validate_scene(source);
    config.check_crop(source.image.width, source.image.height);
    config.resolve_isa();
    return source;
}

// The AOV image's channels (render/aov.h) as the API's vectors: Z, N.* and albedo.*
// interleaved three to a pixel, id.
// Refuses (SceneError: Error(scene)) a render whose memory estimate exceeds `limit`, or
// this machine's memory when `limit` is 0, as `octray render` does before it starts.
void check_memory(const octray::Scene& scene, const batch::RenderMemoryParams& params,
                  std::uint64_t limit) {
    if (limit == 0) limit = batch::machine_memory_bytes();  // 0 if unknown: no limit
    if (limit > 0) batch::check_memory_limit(scene, limit, params);
}

Aovs from_internal(const octray::Image& a) {
    Aovs out;
    const auto floats = [&](const char* name) {
        const octray::ImageChannel* c = a.find_channel(name);
        return c == nullptr ? nullptr : c->floats();
    };
    const auto interleave = [&](std::vector<float>& v, const char* x, const char* y,
                                const char* z) {
        const float* p[3] = {floats(x), floats(y), floats(z)};
        if (p[0] == nullptr) return;
        v.resize(3 * a.pixel_count());
        for (std::size_t k = 0; k < a.pixel_count(); ++k)
            for (std::size_t c = 0; c < 3; ++c) v[3 * k + c] = p[c][k];
    };
    if (const float* z = floats("Z")) out.depth.assign(z, z + a.pixel_count());
    interleave(out.normal, "N.X", "N.Y", "N.Z");
    interleave(out.albedo, "albedo.R", "albedo.G", "albedo.B");
    if (const octray::ImageChannel* id = a.find_channel("id")) {
        out.id.resize(a.pixel_count());
        for (std::size_t k = 0; k < a.pixel_count(); ++k) out.id[k] = id->uint_value(k);
    }
    return out;
}

}  // namespace

const char* version() { return OCTRAY_VERSION_STRING; }

// ---- Scene ------------------------------------------------------------------------------

Scene::Scene() : impl_(std::make_unique<Impl>()) { impl_->scene.source = "<api>"; }
Scene::~Scene() = default;
Scene::Scene(const Scene& other) : impl_(std::make_unique<Impl>(*other.impl_)) {}
Scene& Scene::operator=(const Scene& other) {
    if (this != &other) impl_ = std::make_unique<Impl>(*other.impl_);
    return *this;
}
Scene::Scene(Scene&& other) noexcept = default;
Scene& Scene::operator=(Scene&& other) noexcept = default;

Scene Scene::load(const std::string& spec) {
    Scene s;
    SceneAccess::get(s) = translate_errors([&] { return load_scene(spec); });
    return s;
}

Scene Scene::from_json(std::string_view json, const std::string& source) {
    Scene s;
    SceneAccess::get(s) = translate_errors([&] { return parse_scene_json(json, source); });
    return s;
}

Scene& Scene::set_image(int width, int height, int spp) {
    impl_->scene.image = {width, height, spp};
    return *this;
}

Scene& Scene::set_camera(const Camera& camera) {
    octray::Camera& c = impl_->scene.camera;
    c.type = static_cast<octray::CameraType>(static_cast<int>(camera.type));
    c.eye = to_internal(camera.eye);
    c.lookat = to_internal(camera.lookat);
    c.up = to_internal(camera.up);
    c.fov = camera.fov;
    c.width = camera.width;
    c.aperture = camera.aperture;
    c.focus_distance = camera.focus_distance;
    return *this;
}

Scene& Scene::set_background(Rgb color) {
    impl_->scene.background = {};
    impl_->scene.background.type = BackgroundType::constant;
    impl_->scene.background.color = to_internal(color);
    return *this;
}

Scene& Scene::set_background(Rgb bottom, Rgb top) {
    impl_->scene.background = {};
    impl_->scene.background.type = BackgroundType::gradient;
    impl_->scene.background.bottom = to_internal(bottom);
    impl_->scene.background.top = to_internal(top);
    return *this;
}

Scene& Scene::set_ambient(Rgb ambient) {
    impl_->scene.ambient = to_internal(ambient);
    return *this;
}

Scene& Scene::set_max_depth(int max_depth) {
    impl_->scene.render.max_depth = max_depth;
    return *this;
}

Scene& Scene::set_seed(std::uint64_t seed) {
    impl_->scene.render.seed = seed;
    return *this;
}

std::uint32_t Scene::add_material(const Material& material, const std::string& name) {
    octray::Material m;
    m.color = to_internal(material.color);
    m.kd = material.kd;
    m.ks = material.ks;
    m.shininess = material.shininess;
    m.reflect = to_internal(material.reflect);
    m.transmit = material.transmit;
    m.ior = material.ior;
    if (material.checker)
        m.checker = Checker{to_internal(material.checker_color), material.checker_size};
    impl_->scene.materials.push_back({name, m});
    return static_cast<std::uint32_t>(impl_->scene.materials.size() - 1);
}

Scene& Scene::add_sphere(Vec3 center, float radius, std::uint32_t material,
                         const std::string& name) {
    Object o;
    o.type = ObjectType::sphere;
    o.name = name;
    o.material = material;
    o.center = to_internal(center);
    o.radius = radius;
    impl_->scene.objects.push_back(std::move(o));
    return *this;
}

Scene& Scene::add_plane(Vec3 point, Vec3 normal, std::uint32_t material) {
    Object o;
    o.type = ObjectType::plane;
    o.material = material;
    o.point = to_internal(point);
    // Normalised as the JSON loader does (in double, a unit normal kept bit for bit), so a
    // scene built here renders as the same scene read from a file; a zero normal stays
    // zero and validate() refuses it.
    const double x = normal.x, y = normal.y, z = normal.z;
    const double len2 = x * x + y * y + z * z;
    o.normal = to_internal(normal);
    if (len2 > 0.0 && std::fabs(len2 - 1.0) > 1e-6) {
        const double len = std::sqrt(len2);
        o.normal = {static_cast<float>(x / len), static_cast<float>(y / len),
                    static_cast<float>(z / len)};
    }
    impl_->scene.objects.push_back(std::move(o));
    return *this;
}

Scene& Scene::add_point_light(Vec3 position, Rgb color, bool inverse_square) {
    Light l;
    l.type = LightType::point;
    l.position = to_internal(position);
    l.color = to_internal(color);
    l.inverse_square = inverse_square;
    impl_->scene.lights.push_back(l);
    return *this;
}

Scene& Scene::add_directional_light(Vec3 direction, Rgb color) {
    Light l;
    l.type = LightType::directional;
    l.direction = to_internal(direction);
    l.color = to_internal(color);
    impl_->scene.lights.push_back(l);
    return *this;
}

int Scene::width() const { return impl_->scene.image.width; }
int Scene::height() const { return impl_->scene.image.height; }
int Scene::spp() const { return impl_->scene.image.spp; }
std::size_t Scene::object_count() const { return impl_->scene.objects.size(); }
std::size_t Scene::light_count() const { return impl_->scene.lights.size(); }

void Scene::validate() const {
    translate_errors([&] { validate_scene(impl_->scene); });
}

std::string Scene::to_json() const {
    return translate_errors([&] {
        validate_scene(impl_->scene);
        return scene_to_json(impl_->scene);
    });
}

// ---- Rendering ---------------------------------------------------------------------------

const char* isa_name(Isa isa) { return octray::isa_name(to_internal(isa)); }

Isa parse_isa(const std::string& name) {
    return translate_errors([&] {
        octray::RenderConfig config;
        config.set_isa(name);
        return from_internal(config.isa);
    });
}

AovSelection parse_aovs(const std::string& list) {
    return translate_errors([&] {
        octray::RenderConfig config;
        config.set_aovs(list);
        return AovSelection{config.aovs.depth, config.aovs.normal, config.aovs.albedo,
                            config.aovs.id};
    });
}

std::vector<Isa> supported_isas() {
    std::vector<Isa> out;
    for (octray::Isa isa : octray::supported_isas()) out.push_back(from_internal(isa));
    return out;
}

// The render options checked, and the scene they apply to, once per Renderer.
struct Renderer::Impl {
    RenderOptions options;
    octray::RenderConfig config;  // checked, the ISA resolved
    octray::Scene source;         // the overrides applied, validated
    // The frames of `source`, posed and prepared once (render/frame_renderer.h).
    std::unique_ptr<octray::FrameRenderer> renderer;

    Impl(const Scene& scene, const RenderOptions& o)
        : options(o), config(to_config(o)), source(configured_scene(scene, config)) {
        check_memory(source, batch::memory_params(config), o.max_memory);
        renderer = std::make_unique<octray::FrameRenderer>(source, config.path, config.isa,
                                                           config.accel, config.threads);
    }

    RenderResult render(int frame) {
        if (frame < 0) throw std::invalid_argument("render: frame must be >= 0");
        octray::RenderOptions o = config.render_options();
        o.frame = static_cast<std::uint32_t>(frame);
        struct Rendered {
            octray::RenderResult result;
            octray::Image aovs;
        };
        // Preparing the frame (compiling the scene and building its BVH for the first
        // frame) is part of the run the progress callback reports.
        const auto run = [&] {
            Rendered r;
            renderer->prepare(frame);
            r.result = renderer->render(o);
            if (config.aovs.any()) r.aovs = renderer->aovs(o, config.aovs);
            return r;
        };
        Rendered r;
        if (options.progress) {
            std::atomic<bool> cancel{false};
            std::atomic<std::uint64_t> pixels{0};
            o.cancel = &cancel;
            o.pixels_done = &pixels;
            const std::uint64_t total =
                config.crop ? config.crop->pixel_count()
                            : static_cast<std::uint64_t>(source.image.width) *
                                  static_cast<std::uint64_t>(source.image.height);
            r = run_reporting(
                run, [&] { return pixels.load(); }, cancel, total, options);
        } else {
            r = run();
        }
        RenderResult out;
        out.path = config.path_label();
        out.image = image_from_internal(r.result.image);
        out.rays = {r.result.rays.primary, r.result.rays.shadow, r.result.rays.reflected,
                    r.result.rays.refracted};
        out.seconds = r.result.seconds;
        if (config.aovs.any()) out.aovs = from_internal(r.aovs);
        const octray::PixelRect& window = r.result.image.data_window;
        out.window = {window.x0, window.y0, window.x1, window.y1};
        out.full_width = r.result.image.display_window.width();
        out.full_height = r.result.image.display_window.height();
        return out;
    }
};

Renderer::Renderer(const Scene& scene, const RenderOptions& options) {
    translate_errors([&] { impl_ = std::make_unique<Impl>(scene, options); });
}
Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

RenderResult Renderer::render(int frame) try {
    if (!impl_) throw Error(ErrorKind::invalid_argument, "render: the Renderer was moved from");
    return translate_errors([&] { return impl_->render(frame); });
} catch (const CallbackFailure& failure) {
    std::rethrow_exception(failure.error);
}

int Renderer::frame_count() const {
    if (!impl_) return 0;
    return impl_->source.animation ? std::max(impl_->source.animation->frames, 1) : 1;
}

RenderResult render(const Scene& scene, const RenderOptions& options) {
    if (options.frame < 0)
        throw Error(ErrorKind::invalid_argument, "render: frame must be >= 0");
    return Renderer(scene, options).render(options.frame);
}

// ---- Images ------------------------------------------------------------------------------

void write_exr(const std::string& path, const Image& image, const ExrOptions& options) {
    translate_errors([&] {
        ExrWriteOptions o;
        o.float32 = options.float32;
        ExrAttributes attributes;
        attributes.strings.emplace_back("software", std::string("octray ") + version());
        octray::write_exr(path, image_to_internal(image), o, attributes);
    });
}

Image read_image(const std::string& path) {
    return translate_errors([&] {
        const octray::Image c = octray::read_image(path);
        const int r = c.channel_index("R"), g = c.channel_index("G"), b = c.channel_index("B");
        if (r < 0 || g < 0 || b < 0) {
            throw IoError(path + ": no R, G and B channels");
        }
        Image out;
        out.width = c.width();
        out.height = c.height();
        out.rgb.resize(3 * c.pixel_count());
        for (int y = 0; y < c.height(); ++y) {
            for (int x = 0; x < c.width(); ++x) {
                const std::size_t k = static_cast<std::size_t>(y) * c.width() + x;
                out.rgb[3 * k] = c.at(r, x, y);
                out.rgb[3 * k + 1] = c.at(g, x, y);
                out.rgb[3 * k + 2] = c.at(b, x, y);
            }
        }
        return out;
    });
}

CompareResult compare(const Image& a, const Image& b, const CompareOptions& options) {
    return translate_errors(
        [&] { return compare_channels(image_to_internal(a), image_to_internal(b), options); });
}

CompareResult compare_files(const std::string& a, const std::string& b,
                            const CompareOptions& options) {
    return translate_errors([&] {
        return compare_channels(octray::read_image(a), octray::read_image(b), options);
    });
}

// ---- Frames to files ---------------------------------------------------------------------

namespace {

// The frame loop's reports as FrameFiles, and its pixels done over the whole run: the
// frames started before (each whole, however it ended) plus the one rendering.
class FrameFilesObserver : public batch::BatchObserver {
  public:
    explicit FrameFilesObserver(const std::vector<batch::BatchInput>& scenes,
                                const std::vector<batch::BatchJob>& jobs)
        : scenes_(scenes), jobs_(jobs) {}

    std::atomic<std::uint64_t>* pixel_counter() override { return &pixels_; }
    void frame_started(std::size_t index, const std::string&, int, std::uint64_t,
                       int) override {
        done_ += current_;
        current_ = frame_pixels(index);
        started_.push_back(index);
        pixels_ = 0;
    }
    void frame_finished(const batch::FrameReport& report, std::uint64_t) override {
        if (std::find(started_.begin(), started_.end(), report.index) == started_.end())
            done_ += frame_pixels(report.index);  // skipped, or failed before rendering
        FrameFile f;
        f.frame = report.frame;
        f.output = report.output;
        f.png = report.preview;
        f.status = report.outcome == batch::FrameOutcome::rendered ? FrameStatus::rendered
                   : report.outcome == batch::FrameOutcome::failed ? FrameStatus::failed
                                                                   : FrameStatus::skipped;
        f.message = report.message;
        f.rays = report.rays;
        f.seconds = report.seconds;
        const std::lock_guard lock(mutex_);
        files_.push_back(std::move(f));
    }

    std::uint64_t frame_pixels(std::size_t index) const {
        const batch::BatchInput& scene = scenes_[jobs_[index - 1].scene];
        return scene.crop ? scene.crop->pixel_count()
                          : static_cast<std::uint64_t>(scene.scene.image.width) *
                                static_cast<std::uint64_t>(scene.scene.image.height);
    }
    std::uint64_t total_pixels() const {
        std::uint64_t total = 0;
        for (std::size_t i = 1; i <= jobs_.size(); ++i) total += frame_pixels(i);
        return total;
    }
    std::uint64_t done() const { return done_.load() + pixels_.load(); }
    std::vector<FrameFile> take_files() {
        const std::lock_guard lock(mutex_);
        std::sort(files_.begin(), files_.end(), [&](const FrameFile& a, const FrameFile& b) {
            return index_of(a) < index_of(b);
        });
        return std::move(files_);
    }

  private:
    std::size_t index_of(const FrameFile& f) const {
        for (std::size_t i = 0; i < jobs_.size(); ++i)
            if (jobs_[i].output == f.output) return i;
        return jobs_.size();
    }

    const std::vector<batch::BatchInput>& scenes_;
    const std::vector<batch::BatchJob>& jobs_;
    std::atomic<std::uint64_t> pixels_{0};
    std::atomic<std::uint64_t> done_{0};
    std::uint64_t current_ = 0;
    std::vector<std::size_t> started_;
    std::mutex mutex_;
    std::vector<FrameFile> files_;
};

// Whether an output name chooses PNG (else OpenEXR); any other extension is refused.
bool png_output(const std::string& what, const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".png") return true;
    if (ext == ".exr") return false;
    throw std::invalid_argument(what + " \"" + path +
                                "\": the extension chooses the format: .exr or .png");
}

}  // namespace

FrameFilesResult render_frames(const Scene& scene, const RenderOptions& options,
                               const FrameFilesOptions& files) try {
    return translate_errors([&] {
        const auto started = std::chrono::steady_clock::now();
        octray::RenderConfig config = to_config(options);
        batch::BatchInput loaded;
        loaded.scene = configured_scene(scene, config);
        loaded.spec = loaded.scene.source;
        loaded.name = loaded.spec == "<api>" ? std::string("scene")
                                             : batch::scene_display_name(loaded.spec);
        loaded.sha256 = batch::sha256_hex(scene_to_json(loaded.scene));
        loaded.crop = config.crop;
        const std::vector<batch::BatchInput> scenes{std::move(loaded)};

        batch::BatchRequest request;
        request.threads = config.threads;
        request.frames = files.frames;
        request.output = files.output;
        request.png = files.png;
        batch::BatchSettings settings;
        settings.render = config;
        settings.exr.float32 = files.exr.float32;
        settings.png_output = !files.output.empty() && png_output("output", files.output);
        if (!files.png.empty() && png_output("png", files.png) == false)
            throw std::invalid_argument("png \"" + files.png + "\": a preview is a .png");
        if (settings.png_output &&
            (config.aovs.any() || files.exr.float32 || !files.png.empty()))
            throw std::invalid_argument("output \"" + files.output +
                                        "\" is an 8-bit PNG, which holds R, G, B only: AOVs, "
                                        "float32 and a png preview need an .exr output");
        settings.skip_existing = files.skip_existing;
        std::vector<batch::BatchJob> jobs;
        try {
            jobs = batch::plan_jobs(scenes, request);
        } catch (const batch::RequestError& e) {
            throw std::invalid_argument(e.what());
        } catch (const batch::SpecError& e) {
            throw std::invalid_argument(e.what());
        }
        // A frame is written while the next renders, as `octray render` does, when the
        // memory estimate of two frames in flight fits this machine's memory.
        batch::RenderMemoryParams memory = batch::memory_params(config);
        memory.float32_output = files.exr.float32;
        memory.png_preview = !files.png.empty();
        check_memory(scenes[0].scene, memory, options.max_memory);
        memory.write_behind = true;
        const std::uint64_t machine = batch::machine_memory_bytes();
        settings.write_behind =
            jobs.size() > 1 &&
            (machine == 0 ||
             batch::estimate_render_memory(scenes[0].scene, memory).total <= machine);
        batch::prepare_output_directories(jobs);

        FrameFilesObserver observer(scenes, jobs);
        std::atomic<bool> cancel{false};
        const auto run = [&] {
            return batch::run_batch(scenes, jobs, settings, observer, &cancel);
        };
        const batch::BatchSummary summary =
            options.progress ? run_reporting(
                                   run, [&] { return observer.done(); }, cancel,
                                   observer.total_pixels(), options, /*cancel_throws=*/false)
                             : run();
        FrameFilesResult out;
        out.frames = observer.take_files();
        out.rendered = static_cast<int>(summary.rendered);
        out.skipped = static_cast<int>(summary.skipped);
        out.failed = static_cast<int>(summary.failed);
        out.cancelled = summary.interrupted;
        out.seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
        return out;
    });
} catch (const CallbackFailure& failure) {
    std::rethrow_exception(failure.error);
}

}  // namespace octray::api
