#include "tools/render_batch.h"

#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>
#include <fcntl.h>
#include <oneapi/tbb/global_control.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <new>
#include <system_error>
#include <utility>

#include "core/version.h"
#include "kernels/dispatch.h"
#include "render/aov.h"
#include "render/camera_matrices.h"
#include "render/image/image_read.h"
#include "render/packet_renderer.h"
#include "render/progressive.h"
#include "render/reference.h"
#include "scene/animation.h"
#include "scene/scene_error.h"
#include "tools/claim_owner.h"
#include "tools/commands.h"
#include "tools/interrupt.h"

namespace octray::tools {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// The attribute that marks an image written by a --progressive pass before the last one:
// --skip-existing does not count such a file as a finished frame.
constexpr const char* kSamplesSoFarAttribute = "octray.samplesSoFar";
// The run that writes an unfinished pass: its claim (tools/claim_owner.h).
constexpr const char* kOwnerAttribute = "octray.owner";

enum class FailureKind { none, scene, io, internal, interrupted };

struct FrameResult {
    FrameReport report;
    FailureKind failure = FailureKind::none;
};

RenderResult render_still(const BatchSettings& settings, const Scene& scene,
                          const RenderOptions& options) {
    if (settings.path == RenderPath::scalar) return render_reference(scene, options);
    return render_packet(scene, options, settings.isa);
}

// EXR's capDate convention: "YYYY:MM:DD HH:MM:SS" in local time, with utcOffset holding
// UTC minus local time in seconds.
std::pair<std::string, float> capture_date() {
    const std::time_t now = std::time(nullptr);
    std::tm local{};
    localtime_r(&now, &local);
    char text[32];
    std::strftime(text, sizeof text, "%Y:%m:%d %H:%M:%S", &local);
    return {text, static_cast<float>(-local.tm_gmtoff)};
}

// A finished frame: a non-empty file that is not an unfinished --progressive pass.
// An empty file is a --placeholders claim; an unfinished pass is a claim of its owner
// (tools/claim_owner.h) while that run lives. An OpenEXR file whose chunks do not hold
// what its header implies (cut off, or its header lying about its pixel data) is damaged:
// resuming never takes it for a finished frame, nor renders over what it did not write.
enum class Existing { none, claim, finished, unfinished, damaged };

struct Found {
    Existing kind = Existing::none;
    std::string owner;  // octray.owner of an unfinished pass ("" if it has none)
    std::string error;  // why a damaged file cannot be read
};

bool has_exr_signature(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::array<char, 4> magic{};
    in.read(magic.data(), magic.size());
    return in.gcount() == 4 && magic == std::array<char, 4>{0x76, 0x2f, 0x31, 0x01};
}

Found existing_output(const std::string& path) {
    std::error_code error;
    if (!fs::exists(path, error)) return {Existing::none, {}, {}};
    const auto size = fs::file_size(path, error);
    if (error) return {Existing::finished, {}, {}};  // not a regular file: never overwrite it
    if (size == 0) return {Existing::claim, {}, {}};
    // Not an EXR (a PNG preview target): it exists. An EXR gets the check that `compare` and
    // `assemble` make before decoding (render/image/image_read.h): every chunk against its
    // header. Its pixels are not decoded: resuming a long sequence only needs to know the
    // file is whole.
    if (!has_exr_signature(path)) return {Existing::finished, {}, {}};
    try {
        check_exr_pixel_data(path);
        Imf::InputFile file(path.c_str());
        const Imf::Header& header = file.header();
        if (header.findTypedAttribute<Imf::IntAttribute>(kSamplesSoFarAttribute) != nullptr) {
            const auto* owner =
                header.findTypedAttribute<Imf::StringAttribute>(kOwnerAttribute);
            return {
                Existing::unfinished, owner != nullptr ? owner->value() : std::string(), {}};
        }
    } catch (const IoError& e) {
        return {Existing::damaged, {}, e.what()};
    } catch (const std::exception& e) {  // OpenEXR's own, after the check passed
        return {Existing::damaged, {}, "cannot read '" + path + "': " + e.what()};
    }
    return {Existing::finished, {}, {}};
}

// Takes over a stale unfinished image at `path` for --placeholders: replaces it by an
// empty claim of this run. Two runs may find the same stale image; the one that holds the
// file's lock and still finds it stale under the lock wins, the other finds it changed
// and backs off. False if another run took it (or it cannot be locked).
bool take_over(const std::string& path) {
    int fd = ::open(path.c_str(), O_RDWR | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) return false;
    struct Closer {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) return false;
    const auto same_file = [&] {
        struct stat held {
        }, named{};
        return ::fstat(fd, &held) == 0 && ::stat(path.c_str(), &named) == 0 &&
               held.st_dev == named.st_dev && held.st_ino == named.st_ino;
    };
    if (!same_file()) return false;
    const Found found = existing_output(path);
    if (found.kind != Existing::unfinished || !owner_is_gone(found.owner) || !same_file())
        return false;
    write_file_atomically(path, [](const std::string& tmp) {
        // The temporary is already there, empty: it becomes the claim.
        (void)tmp;
    });
    return true;
}

// Claims `path` with an empty file; false if another run got there first.
bool claim(const std::string& path) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) {
        if (errno == EEXIST) return false;
        throw IoError("cannot claim " + path + " with a placeholder: " + std::strerror(errno));
    }
    ::close(fd);
    return true;
}

// Gives a claim back after a failed or interrupted frame, if it is still our empty file.
void release_claim(const std::string& path) {
    std::error_code error;
    if (fs::exists(path, error) && fs::file_size(path, error) == 0 && !error)
        fs::remove(path, error);
}

// A frame's work for the progress bar: the pixel samples it traces.
std::uint64_t frame_work(const BatchScene& scene) {
    const ImageSettings& image = scene.scene.image;
    const PixelRect rect = scene.crop.value_or(PixelRect{0, 0, image.width, image.height});
    return rect.pixel_count() * static_cast<std::uint64_t>(image.spp);
}

class BatchRunner {
  public:
    BatchRunner(const std::vector<BatchScene>& scenes, const BatchSettings& settings,
                ProgressReporter& progress)
        : scenes_(scenes), settings_(settings), progress_(progress), owner_(current_owner()) {}

    FrameResult run(std::size_t index, const BatchJob& job);

  private:
    ExrAttributes attributes(const BatchScene& scene, const Scene& posed, int frame,
                             const RenderResult& result, int samples_so_far) const;
    void write_outputs(const BatchScene& scene, const BatchJob& job, const Scene& posed,
                       const RenderResult& result, const AovImages& aovs,
                       int samples_so_far) const;

    const std::vector<BatchScene>& scenes_;
    const BatchSettings& settings_;
    ProgressReporter& progress_;
    std::string owner_;  // octray.owner of this run's unfinished passes
};

ExrAttributes BatchRunner::attributes(const BatchScene& scene, const Scene& posed, int frame,
                                      const RenderResult& result, int samples_so_far) const {
    const auto [date, utc_offset] = capture_date();
    std::string path = std::string(render_path_name(settings_.path));
    if (settings_.path == RenderPath::simd)
        path.append(" (").append(isa_name(settings_.isa)).append(")");
    ExrAttributes a;
    a.strings = {
        {"software", std::string("octray ") + kVersion},
        {"capDate", date},
        {"octray.scene", scene.spec},
        {"octray.sceneSha256", scene.sha256},
        {"octray.path", path},
        // A string keeps all 64 bits of the seed.
        {"octray.seed", std::to_string(posed.render.seed)},
    };
    a.floats = {{"utcOffset", utc_offset}};
    a.ints = {
        {"samplesPerPixel", posed.image.spp},
        {"octray.maxDepth", posed.render.max_depth},
        {"octray.frame", frame},
    };
    if (samples_so_far < posed.image.spp) {
        a.ints.emplace_back(kSamplesSoFarAttribute, samples_so_far);
        a.strings.emplace_back(kOwnerAttribute, owner_);
    }
    // Ray counts are 64-bit; a double holds them exactly up to 2^53 (9e15 rays).
    a.doubles = {
        {"renderTimeSeconds", result.seconds},
        {"octray.time", frame_time(scene.scene, frame)},
        {"octray.rays.primary", static_cast<double>(result.rays.primary)},
        {"octray.rays.shadow", static_cast<double>(result.rays.shadow)},
        {"octray.rays.reflected", static_cast<double>(result.rays.reflected)},
        {"octray.rays.refracted", static_cast<double>(result.rays.refracted)},
        {"octray.rays.total", static_cast<double>(result.rays.total())},
    };
    add_camera_attributes(a, posed);
    const double fps = scene.scene.animation ? scene.scene.animation->fps : kStillFps;
    a.rationals = {{"framesPerSecond", exr_rational(fps)}};
    return a;
}

void BatchRunner::write_outputs(const BatchScene& scene, const BatchJob& job,
                                const Scene& posed, const RenderResult& result,
                                const AovImages& aovs, int samples_so_far) const {
    if (settings_.png_output) {
        write_png_preview(job.output, result.image);
        return;
    }
    ExrImage exr = make_exr_image(result, settings_.exr,
                                  attributes(scene, posed, job.frame, result, samples_so_far));
    if (aovs.set.any())
        append_aov_channels(exr, aovs,
                            settings_.exr.float32 ? ExrPixelType::float32 : ExrPixelType::half);
    write_exr(job.output, exr);
    if (!job.png.empty()) write_png_preview(job.png, result.image);
}

FrameResult BatchRunner::run(std::size_t index, const BatchJob& job) {
    const BatchScene& scene = scenes_[job.scene];
    FrameResult out;
    out.report.index = index;
    out.report.scene = scene.name;
    out.report.frame = job.frame;
    out.report.output = job.output;
    out.report.preview = job.png;
    const std::uint64_t work = frame_work(scene);

    const auto skip = [&](FrameOutcome outcome) {
        out.report.outcome = outcome;
        progress_.frame_finished(out.report, work);
        return out;
    };
    // A directory at an output path can never be replaced by an image: the frame fails
    // before any time is spent rendering it, and it never counts as finished or claimed.
    for (const std::string* file : {&job.output, &job.png}) {
        std::error_code error;
        if (file->empty() || !fs::is_directory(*file, error)) continue;
        out.failure = FailureKind::io;
        out.report.outcome = FrameOutcome::failed;
        out.report.message = "I/O error: cannot write " + *file +
                             ": it is a directory; expected an image file (or nothing) there";
        progress_.note("octray: frame " + std::to_string(job.frame) + " of " + scene.spec +
                       " failed: " + out.report.message);
        progress_.frame_finished(out.report, work);
        return out;
    }
    // Resume and claims. A frame is finished only when all its outputs are (the EXR and
    // the --png preview); one missing output makes it render again.
    // An unfinished --progressive image is a claim of the run writing it, rendered over
    // only when that run is provably gone.
    Existing existing = Existing::none;
    Existing preview = Existing::finished;  // no --png: nothing to wait for
    if (settings_.skip_existing || settings_.placeholders) {
        const Found found = existing_output(job.output);
        existing = found.kind;
        Found preview_found{preview, {}, {}};
        if (!job.png.empty()) preview_found = existing_output(job.png);
        preview = preview_found.kind;
        const Found* const outputs[] = {&found, &preview_found};
        for (const Found* damaged : outputs) {
            if (damaged->kind != Existing::damaged) continue;
            out.failure = FailureKind::io;
            out.report.outcome = FrameOutcome::failed;
            out.report.message = "I/O error: " + damaged->error +
                                 "; not a finished frame, and left alone: remove it to "
                                 "render the frame again";
            progress_.note("octray: frame " + std::to_string(job.frame) + " of " + scene.spec +
                           " failed: " + out.report.message);
            progress_.frame_finished(out.report, work);
            return out;
        }
        if (existing == Existing::claim || preview == Existing::claim)
            return skip(FrameOutcome::skipped_claimed);
        if (existing == Existing::finished && preview == Existing::finished)
            return skip(FrameOutcome::skipped_existing);
        if (existing == Existing::unfinished && !owner_is_gone(found.owner))
            return skip(FrameOutcome::skipped_claimed);
    }
    std::string claimed;  // the placeholder this run created, if any
    const auto started = Clock::now();
    try {
        // A missing output is claimed (O_EXCL: one run wins): the EXR, or when only the
        // preview is missing, the preview. A stale unfinished image is taken over.
        if (settings_.placeholders) {
            if (existing == Existing::unfinished) {
                if (!take_over(job.output)) return skip(FrameOutcome::skipped_claimed);
                claimed = job.output;
            } else {
                const std::string* missing = existing == Existing::none  ? &job.output
                                             : preview == Existing::none ? &job.png
                                                                         : nullptr;
                if (missing != nullptr) {
                    if (!claim(*missing)) return skip(FrameOutcome::skipped_claimed);
                    claimed = *missing;
                }
            }
        }
        remove_stale_temporaries(job.output);
        if (!job.png.empty()) remove_stale_temporaries(job.png);
        progress_.frame_started(index, scene.name, job.frame, work, scene.scene.image.spp);

        // A still scene is its own pose: no copy of its (possibly millions of) objects.
        std::optional<Scene> animated;
        if (scene.scene.animation) animated = scene_at_frame(scene.scene, job.frame);
        const Scene& posed = animated ? *animated : scene.scene;
        RenderOptions options = settings_.options;
        options.frame = static_cast<std::uint32_t>(job.frame);
        options.cancel = &InterruptGuard::flag();
        options.pixels_done = &progress_.pixel_counter();
        options.crop = scene.crop;
        // Writing (EXR and PNG encoding) is timed apart from tracing: the frame line and
        // the summary report each, and the rate is rays over trace time alone.
        const auto trace_started = Clock::now();
        const AovImages aovs = compute_aovs(posed, options, settings_.aovs);
        double write_seconds = 0.0;
        const auto timed_write = [&](const RenderResult& r, int samples_so_far) {
            const auto write_started = Clock::now();
            write_outputs(scene, job, posed, r, aovs, samples_so_far);
            write_seconds +=
                std::chrono::duration<double>(Clock::now() - write_started).count();
        };

        RenderResult result;
        if (settings_.progressive) {
            result = render_progressive(
                [&](const RenderOptions& o) { return render_still(settings_, posed, o); },
                posed.image.spp, options,
                [&](const RenderResult& pass, int samples_so_far) {
                    if (samples_so_far < posed.image.spp) timed_write(pass, samples_so_far);
                });
        } else {
            result = render_still(settings_, posed, options);
        }
        out.report.trace_seconds =
            std::chrono::duration<double>(Clock::now() - trace_started).count() - write_seconds;
        timed_write(result, posed.image.spp);
        out.report.write_seconds = write_seconds;
        out.report.load_seconds = scene.load_seconds;
        out.report.compile_seconds = result.compile_seconds;
        out.report.bvh_seconds = result.bvh_seconds;
        out.report.render_seconds =
            result.seconds - result.compile_seconds - result.bvh_seconds;
        if (settings_.stats)  // the scene is loaded once for all its frames: on each line
            std::fprintf(stderr,
                         "stats: %s frame %d: load %.3f s, compile %.3f s, BVH %.3f s, "
                         "render %.3f s, write %.3f s\n",
                         scene.name.c_str(), job.frame, out.report.load_seconds,
                         out.report.compile_seconds, out.report.bvh_seconds,
                         out.report.render_seconds, write_seconds);
        out.report.rays = result.rays.total();
        out.report.outcome = FrameOutcome::rendered;
    } catch (const RenderCancelled&) {
        out.failure = FailureKind::interrupted;
        out.report.outcome = FrameOutcome::failed;
        out.report.message = "interrupted";
    } catch (const SceneError& e) {
        out.failure = FailureKind::scene;
        out.report.outcome = FrameOutcome::failed;
        out.report.message = std::string("scene error: ") + e.what();
    } catch (const IoError& e) {
        out.failure = FailureKind::io;
        out.report.outcome = FrameOutcome::failed;
        out.report.message = std::string("I/O error: ") + e.what();
    } catch (const std::bad_alloc&) {
        out.failure = FailureKind::internal;
        out.report.outcome = FrameOutcome::failed;
        out.report.message = "out of memory";
    } catch (const std::exception& e) {
        out.failure = FailureKind::internal;
        out.report.outcome = FrameOutcome::failed;
        out.report.message = std::string("internal error: ") + e.what();
    }
    if (out.failure != FailureKind::none && !claimed.empty()) release_claim(claimed);
    out.report.seconds = std::chrono::duration<double>(Clock::now() - started).count();
    if (out.failure != FailureKind::interrupted) {
        if (out.failure != FailureKind::none)
            progress_.note("octray: frame " + std::to_string(job.frame) + " of " + scene.spec +
                           " failed: " + out.report.message);
        progress_.frame_finished(out.report, work);
    }
    return out;
}

void print_header(const std::vector<BatchScene>& scenes, const std::vector<BatchJob>& jobs,
                  const BatchSettings& settings) {
    for (std::size_t s = 0; s < scenes.size(); ++s) {
        const Scene& scene = scenes[s].scene;
        std::size_t frames = 0;
        for (const BatchJob& job : jobs) frames += job.scene == s ? 1 : 0;
        std::printf(
            "scene    %s (%zu objects, %zu lights%s), %dx%d, %d spp, max depth %d, "
            "seed %llu, %zu frame%s\n",
            scenes[s].spec.c_str(), scene.objects.size(), scene.lights.size(),
            scene.animation ? ", animated" : "", scene.image.width, scene.image.height,
            scene.image.spp, scene.render.max_depth,
            static_cast<unsigned long long>(scene.render.seed), frames, frames == 1 ? "" : "s");
    }
    const std::size_t threads =
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
    std::string path(render_path_name(settings.path));
    if (settings.path == RenderPath::simd)
        path.append(" (").append(isa_name(settings.isa)).append(")");
    std::printf("render   %s path, %zu threads, %dx%d tiles\n", path.c_str(), threads,
                settings.options.tile_width, settings.options.tile_height);
    std::fflush(stdout);
}

}  // namespace

AovSet parse_aov_option(const std::string& text) {
    std::string error;
    const auto set = parse_aov_list(text, &error);
    if (!set) throw UsageError("--aov: " + error);
    return *set;
}

Accel parse_accel_option(const std::string& text) {
    const auto accel = parse_accel(text);
    if (!accel) throw UsageError("--accel: expected auto, bvh or none, not " + text);
    return *accel;
}

std::vector<BatchJob> select_jobs(const std::vector<BatchJob>& jobs, batch::Shard shard) {
    std::vector<BatchJob> selected;
    for (std::size_t k = 0; k < jobs.size(); ++k)
        if (k % static_cast<std::size_t>(shard.count) == static_cast<std::size_t>(shard.index))
            selected.push_back(jobs[k]);
    return selected;
}

int run_batch(const std::vector<BatchScene>& scenes, const std::vector<BatchJob>& jobs,
              const BatchSettings& settings) {
    // Limit TBB for the whole run; 0 keeps its default (every core it may use).
    std::optional<tbb::global_control> thread_limit;
    if (settings.options.threads > 0)
        thread_limit.emplace(tbb::global_control::max_allowed_parallelism,
                             static_cast<std::size_t>(settings.options.threads));
    // OpenEXR compresses the blocks of scan lines of a frame on a pool of its own: as many
    // threads as the render's (none for one thread: the caller compresses). The file's
    // bytes are the same for any count; a 1920x1080 ZIP frame is written about twice as
    // fast on 2 threads (tools/README.md, "Time to image").
    const std::size_t exr_threads =
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
    Imf::setGlobalThreadCount(
        exr_threads > 1 ? static_cast<int>(std::min<std::size_t>(exr_threads, 64)) : 0);
    if (settings.progress != ProgressMode::json && settings.progress != ProgressMode::none)
        print_header(scenes, jobs, settings);

    std::uint64_t total_work = 0;
    for (const BatchJob& job : jobs) total_work += frame_work(scenes[job.scene]);

    InterruptGuard interrupt;
    ProgressReporter progress(settings.progress, jobs.size(), total_work);
    BatchRunner runner(scenes, settings, progress);
    BatchSummary summary;
    bool scene_failure = false, io_failure = false, internal_failure = false;
    const auto started = Clock::now();
    for (std::size_t k = 0; k < jobs.size(); ++k) {
        if (InterruptGuard::flag().load()) {
            summary.not_started = jobs.size() - k;
            break;
        }
        const FrameResult result = runner.run(k + 1, jobs[k]);
        switch (result.report.outcome) {
            case FrameOutcome::rendered:
                ++summary.rendered;
                summary.rays += result.report.rays;
                summary.trace_seconds += result.report.trace_seconds;
                summary.write_seconds += result.report.write_seconds;
                break;
            case FrameOutcome::skipped_existing:
            case FrameOutcome::skipped_claimed:
                ++summary.skipped;
                break;
            case FrameOutcome::failed:
                if (result.failure == FailureKind::interrupted) {
                    summary.not_started = jobs.size() - k;  // this one included: not done
                    k = jobs.size();
                } else {
                    ++summary.failed;
                }
                break;
        }
        scene_failure |= result.failure == FailureKind::scene;
        io_failure |= result.failure == FailureKind::io;
        internal_failure |= result.failure == FailureKind::internal;
    }
    summary.interrupted = InterruptGuard::flag().load();
    summary.seconds = std::chrono::duration<double>(Clock::now() - started).count();
    progress.finish(summary);

    if (summary.interrupted) return 128 + InterruptGuard::signal_number();
    if (scene_failure) return kExitScene;
    if (io_failure) return kExitIo;
    if (internal_failure) return kExitInternal;
    return kExitSuccess;
}

}  // namespace octray::tools
