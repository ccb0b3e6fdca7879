// The public API (include/octray/octray.h): a thin facade that converts its plain types to
// the internal ones and calls the libraries the command line uses: scene/ to load and
// validate, render/ for both paths, EXR writing, reading and comparison.

#include "octray/octray.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include "core/version.h"
#include "kernels/dispatch.h"
#include "render/frame_renderer.h"
#include "render/image/image_compare.h"
#include "render/image/image_io.h"
#include "render/image/image_read.h"
#include "render/packet_renderer.h"
#include "render/reference.h"
#include "scene/animation.h"
#include "scene/load.h"
#include "scene/scene.h"

namespace octray::api {

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

octray::Image to_internal(const Image& image) {
    if (image.width < 0 || image.height < 0 ||
        image.rgb.size() != 3 * static_cast<std::size_t>(image.width) *
                                static_cast<std::size_t>(image.height)) {
        throw Error(ErrorKind::invalid_argument,
                    "image: rgb must hold 3 floats for each of width x height pixels");
    }
    octray::Image out(image.width, image.height);
    for (std::size_t k = 0; k < out.pixel_count(); ++k) {
        out.data()[k] = {image.rgb[3 * k], image.rgb[3 * k + 1], image.rgb[3 * k + 2]};
    }
    return out;
}

Image from_internal(const octray::Image& image) {
    Image out;
    out.width = image.width();
    out.height = image.height();
    out.rgb.resize(3 * image.pixel_count());
    for (std::size_t k = 0; k < image.pixel_count(); ++k) {
        out.rgb[3 * k] = image.data()[k].r;
        out.rgb[3 * k + 1] = image.data()[k].g;
        out.rgb[3 * k + 2] = image.data()[k].b;
    }
    return out;
}

ChannelImage to_channels(const Image& image) {
    const octray::Image rgb = to_internal(image);
    ChannelImage out(image.width, image.height, {"R", "G", "B"});
    for (int y = 0; y < image.height; ++y) {
        for (int x = 0; x < image.width; ++x) {
            out.at(0, x, y) = rgb.at(x, y).r;
            out.at(1, x, y) = rgb.at(x, y).g;
            out.at(2, x, y) = rgb.at(x, y).b;
        }
    }
    return out;
}

CompareResult compare_channels(const ChannelImage& a, const ChannelImage& b,
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

// Runs `run` (a render with options `o`) on a thread of its own while this thread calls
// options.progress with the pixels done, and stops it when the callback says so.
template <typename Run>
octray::RenderResult render_reporting(const Run& run, octray::RenderOptions& o,
                                      const octray::Scene& scene,
                                      const RenderOptions& options) {
    Progress progress;
    progress.pixels_total = static_cast<std::uint64_t>(scene.image.width) *
                            static_cast<std::uint64_t>(scene.image.height);
    const auto ask = [&] {
        try {
            return options.progress(progress);
        } catch (...) {
            throw CallbackFailure{std::current_exception()};
        }
    };
    if (!ask()) throw Error(ErrorKind::cancelled, "render cancelled by the progress callback");
    std::atomic<bool> cancel{false};
    std::atomic<std::uint64_t> pixels{0};
    o.cancel = &cancel;
    o.pixels_done = &pixels;

    std::mutex mutex;
    std::condition_variable finished_cv;
    bool finished = false;
    octray::RenderResult result;
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
            progress.pixels_done = std::min(pixels.load(), progress.pixels_total);
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
    progress.pixels_done = progress.pixels_total;
    static_cast<void>(ask());  // done: its answer changes nothing
    return result;
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

std::vector<Isa> supported_isas() {
    std::vector<Isa> out;
    for (octray::Isa isa : octray::supported_isas()) out.push_back(from_internal(isa));
    return out;
}

// The render options checked, and the scene they apply to, once per Renderer.
struct Renderer::Impl {
    RenderOptions options;
    octray::Scene source;  // the overrides applied, validated
    octray::RenderOptions internal;
    octray::Isa isa = octray::Isa::automatic;  // resolved (simd path)
    // The frames of `source`, posed and prepared once (render/frame_renderer.h).
    std::unique_ptr<octray::FrameRenderer> renderer;

    Impl(const Scene& scene, const RenderOptions& o) : options(o) {
        // The command line's limits (render --help): a thread count beyond them would ask
        // the OS for that many threads (INT_MAX crashed TBB), a negative size or spp was
        // silently ignored.
        if (options.threads < 0 || options.threads > kMaxRenderThreads)
            throw std::invalid_argument("render: threads must be from 0 to " +
                                        std::to_string(kMaxRenderThreads) + ", not " +
                                        std::to_string(options.threads));
        if (options.width < 0 || options.height < 0 || options.spp < 0)
            throw std::invalid_argument(
                "render: width, height and spp must be >= 0 (0 keeps the scene's)");
        if (options.tile_width < 1 || options.tile_height < 1)
            throw std::invalid_argument("render: tiles must be at least 1x1");
        source = SceneAccess::get(scene);
        if (options.width > 0) source.image.width = options.width;
        if (options.height > 0) source.image.height = options.height;
        if (options.spp > 0) source.image.spp = options.spp;
        validate_scene(source);
        internal.threads = options.threads;
        internal.tile_width = options.tile_width;
        internal.tile_height = options.tile_height;
        if (options.path != Path::scalar) isa = resolve_isa(to_internal(options.isa));
        renderer = std::make_unique<octray::FrameRenderer>(
            source, options.path == Path::scalar ? RenderPath::scalar : RenderPath::simd, isa,
            octray::Accel::automatic, options.threads);
    }

    RenderResult render(int frame) {
        if (frame < 0) throw std::invalid_argument("render: frame must be >= 0");
        const octray::Scene& scene = renderer->prepare(frame);
        octray::RenderOptions o = internal;
        o.frame = static_cast<std::uint32_t>(frame);
        // With a progress callback, on a thread of its own (render_reporting).
        const auto run = [&] { return renderer->render(o); };
        const octray::RenderResult r =
            options.progress ? render_reporting(run, o, scene, options) : run();
        RenderResult out;
        out.path = options.path == Path::scalar
                       ? std::string("scalar")
                       : std::string("simd (") + octray::isa_name(isa) + ")";
        out.image = from_internal(r.image);
        out.rays = {r.rays.primary, r.rays.shadow, r.rays.reflected, r.rays.refracted};
        out.seconds = r.seconds;
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
        octray::write_exr(path, to_internal(image), o, attributes);
    });
}

Image read_image(const std::string& path) {
    return translate_errors([&] {
        const ChannelImage c = octray::read_image(path);
        const int r = c.find_channel("R"), g = c.find_channel("G"), b = c.find_channel("B");
        if (r < 0 || g < 0 || b < 0) {
            throw IoError(path + ": no R, G and B channels");
        }
        Image out;
        out.width = c.width;
        out.height = c.height;
        out.rgb.resize(3 * c.pixel_count());
        for (int y = 0; y < c.height; ++y) {
            for (int x = 0; x < c.width; ++x) {
                const std::size_t k = static_cast<std::size_t>(y) * c.width + x;
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
        [&] { return compare_channels(to_channels(a), to_channels(b), options); });
}

CompareResult compare_files(const std::string& a, const std::string& b,
                            const CompareOptions& options) {
    return translate_errors([&] {
        return compare_channels(octray::read_image(a), octray::read_image(b), options);
    });
}

}  // namespace octray::api
