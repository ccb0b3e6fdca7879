#include "render/batch/frame_loop.h"

#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/parallel_invoke.h>
#include <oneapi/tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <ctime>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <system_error>
#include <thread>
#include <utility>

#include "core/version.h"
#include "kernels/dispatch.h"
#include "render/batch/camera_matrices.h"
#include "render/batch/claim_owner.h"
#include "render/batch/progressive.h"
#include "render/batch/resume.h"
#include "render/frame_renderer.h"
#include "render/image/image_io.h"
#include "scene/animation.h"
#include "scene/scene_error.h"

namespace octray::batch {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

enum class FailureKind { none, scene, io, internal, interrupted };

struct FrameResult {
    FrameReport report;
    FailureKind failure = FailureKind::none;
};

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

// A frame's work for the progress bar: the pixel samples it traces.
std::uint64_t frame_work(const BatchInput& scene) {
    const ImageSettings& image = scene.scene.image;
    const PixelRect rect = scene.crop.value_or(PixelRect{0, 0, image.width, image.height});
    return rect.pixel_count() * static_cast<std::uint64_t>(image.spp);
}

// The reason a frame failed, from what its render or write threw.
void record_failure(FrameResult& out, const std::exception_ptr& error) {
    out.report.outcome = FrameOutcome::failed;
    try {
        std::rethrow_exception(error);
    } catch (const RenderCancelled&) {
        out.failure = FailureKind::interrupted;
        out.report.message = "interrupted";
    } catch (const SceneError& e) {
        out.failure = FailureKind::scene;
        out.report.message = std::string("scene error: ") + e.what();
    } catch (const IoError& e) {
        out.failure = FailureKind::io;
        out.report.message = std::string("I/O error: ") + e.what();
    } catch (const std::bad_alloc&) {
        out.failure = FailureKind::internal;
        out.report.message = "out of memory";
    } catch (const std::exception& e) {
        out.failure = FailureKind::internal;
        out.report.message = std::string("internal error: ") + e.what();
    }
}

// A frame's files, ready to write: where the EXR and the preview of its pixels go, and
// how the EXR stores them. The EXR is written from the frame's own float32 pixels and its
// AOVs (write_exr of ExrSources converts each line to half as it packs the chunks): no
// converted copy of either is made.
struct FrameFiles {
    std::string exr_path, png_path;  // either may be empty
    ExrWriteOptions exr_options;
    ExrAttributes exr_attributes;
    std::shared_ptr<const Image> aovs;  // null: none

    void write_exr_file(const Image& pixels, const std::function<void()>& on_read) const {
        ExrSources sources = exr_sources(pixels, exr_options, exr_attributes);
        if (aovs)
            append_aov_sources(sources, *aovs,
                               exr_options.float32 ? PixelFormat::float32 : PixelFormat::half);
        sources.on_read = on_read;
        write_exr(exr_path, sources);
    }
    // Both are written atomically, each on its own; the frame counts as finished only
    // when both are (resume.h). `spent` (the run's last frame, whose storage serves no
    // next frame; the same image as `pixels`) is freed as soon as both files have read
    // the pixels, by a task of the arena while the files are finished (closed, renamed):
    // freeing a 1280x720 frame took 0.9 ms after its files, with the other core idle.
    void write(const Image& pixels, Image* spent = nullptr) const {
        std::atomic<int> readers{(exr_path.empty() ? 0 : 1) + (png_path.empty() ? 0 : 1)};
        tbb::task_group freeing;
        std::function<void()> on_read;
        if (spent != nullptr)
            on_read = [&] {
                if (--readers == 0) freeing.run([spent] { *spent = Image(); });
            };
        if (exr_path.empty()) {
            write_png_preview(png_path, pixels, on_read);
        } else if (png_path.empty()) {
            write_exr_file(pixels, on_read);
        } else {
            // The preview is encoded while the EXR's chunks are compressed: on 2 cores the
            // two files take the time of the longer one.
            tbb::parallel_invoke([&] { write_exr_file(pixels, on_read); },
                                 [&] { write_png_preview(png_path, pixels, on_read); });
        }
        freeing.wait();  // (a write that throws waits for it in the destructor)
    }
};

// A rendered frame whose files a thread of its own writes while the next frame renders.
struct PendingWrite {
    FrameResult result;  // the frame's report, but for its outcome and write time
    std::uint64_t work = 0;
    std::string claimed;  // its placeholder, released if the write fails
    Clock::time_point started;
    FrameFiles files;
    Image pixels;       // the render's R, G, B (the preview's source)
    bool last = false;  // the run's last frame: `pixels` go once the files have read them
    double seconds = 0.0;
    std::exception_ptr report_error;  // what reporting it threw, rethrown when joined
    std::thread writer;
};

class BatchRunner {
  public:
    using Account = std::function<void(const FrameResult&)>;

    BatchRunner(const std::vector<BatchInput>& scenes, std::size_t jobs,
                const BatchSettings& settings, BatchObserver& observer,
                const std::atomic<bool>* cancel, Account account)
        : scenes_(scenes),
          jobs_(jobs),
          settings_(settings),
          observer_(observer),
          cancel_(cancel),
          account_(std::move(account)),
          owner_(current_owner()) {}
    BatchRunner(const BatchRunner&) = delete;
    BatchRunner& operator=(const BatchRunner&) = delete;
    // A frame still being written when the run ends by an exception is waited for, not
    // reported.
    ~BatchRunner() {
        if (pending_) pending_->writer.join();
    }

    // Renders and writes one job; every frame that ends (this one, or the one written
    // behind it) goes to the observer and the account. Returns false when the cancel flag
    // stopped this frame mid-render (it is not reported).
    bool run(std::size_t index, const BatchJob& job);
    // Waits for the frame being written behind, if any, and reports it.
    void finish_pending();
    // Frees the prepared scene (compiled arrays, BVH) and the spare frame: after the last
    // frame, while its files are written behind, rather than after them.
    void release_renderer() {
        renderer_.reset();
        spare_frame_ = Image();
    }

  private:
    ExrAttributes attributes(const BatchInput& scene, const FrameRenderer::Pose& pose,
                             int frame, const RenderResult& result, int samples_so_far) const;
    FrameFiles files(const BatchInput& scene, const BatchJob& job,
                     const FrameRenderer::Pose& pose, const RenderResult& result,
                     const std::shared_ptr<const Image>& aovs, int samples_so_far);
    void finish(const FrameResult& out, std::uint64_t work);
    void write_behind(PendingWrite& p);

    const std::vector<BatchInput>& scenes_;
    std::size_t jobs_;  // the run's job count: job `jobs_` (1-based) is the last
    const BatchSettings& settings_;
    BatchObserver& observer_;
    const std::atomic<bool>* cancel_;
    Account account_;
    std::string owner_;  // octray.owner of this run's unfinished passes
    // The last frame written: the next frame renders into its storage (RenderOptions::
    // spare_image), so only a run's first frame maps fresh pages for its pixels.
    Image spare_frame_;
    // The frames of scene renderer_index_, posed and prepared once (FrameRenderer).
    // (A pointer: g++ 12 takes an optional holding an optional for maybe-uninitialized.)
    std::unique_ptr<FrameRenderer> renderer_;
    std::size_t renderer_index_ = 0;
    // The frame being written behind (settings_.write_behind), at most one; its writer
    // reports it, so the observer and the account are called under report_mutex_.
    std::unique_ptr<PendingWrite> pending_;
    std::mutex report_mutex_;
};

}  // namespace

ExrAttributes render_exr_attributes(const BatchInput& scene, const Scene& posed,
                                    const Camera& camera, int frame, const RenderResult& result,
                                    const std::string& path_label, int samples_so_far,
                                    const std::string& owner) {
    const auto [date, utc_offset] = capture_date();
    ExrAttributes a;
    a.strings = {
        {"software", std::string("octray ") + kVersion},
        {"capDate", date},
        {"octray.scene", scene.spec},
        {"octray.sceneSha256", scene.sha256},
        {"octray.path", path_label},
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
        a.strings.emplace_back(kOwnerAttribute, owner);
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
    add_camera_attributes(a, posed, camera);
    const double fps = scene.scene.animation ? scene.scene.animation->fps : kStillFps;
    a.rationals = {{"framesPerSecond", exr_rational(fps)}};
    return a;
}

namespace {

ExrAttributes BatchRunner::attributes(const BatchInput& scene, const FrameRenderer::Pose& pose,
                                      int frame, const RenderResult& result,
                                      int samples_so_far) const {
    return render_exr_attributes(scene, pose.scene, pose.camera, frame, result,
                                 render_path_label(settings_), samples_so_far, owner_);
}

FrameFiles BatchRunner::files(const BatchInput& scene, const BatchJob& job,
                              const FrameRenderer::Pose& pose, const RenderResult& result,
                              const std::shared_ptr<const Image>& aovs, int samples_so_far) {
    FrameFiles f;
    if (settings_.png_output) {
        f.png_path = job.output;
        return f;
    }
    f.exr_path = job.output;
    f.png_path = job.png;
    f.exr_options = settings_.exr;
    f.exr_attributes = attributes(scene, pose, job.frame, result, samples_so_far);
    if (!aovs->channels.empty()) f.aovs = aovs;
    return f;
}

void BatchRunner::finish(const FrameResult& out, std::uint64_t work) {
    const std::lock_guard lock(report_mutex_);
    if (out.failure != FailureKind::interrupted) observer_.frame_finished(out.report, work);
    account_(out);
}

// On the writer's thread: writes the frame's files, then reports the frame at once (a
// farm manager reading the lines sees every frame on disk, even when the run is killed
// while the next frame renders).
void BatchRunner::write_behind(PendingWrite& p) {
    const auto write_started = Clock::now();
    std::exception_ptr error;
    try {
        p.files.write(p.pixels, p.last ? &p.pixels : nullptr);
    } catch (...) {
        error = std::current_exception();
    }
    FrameResult& out = p.result;
    out.report.write_seconds +=
        p.seconds + std::chrono::duration<double>(Clock::now() - write_started).count();
    try {
        if (error) {
            record_failure(out, error);
            if (!p.claimed.empty()) release_claim(p.claimed);
        }
        out.report.seconds = std::chrono::duration<double>(Clock::now() - p.started).count();
        finish(out, p.work);
    } catch (...) {
        p.report_error = std::current_exception();
    }
}

void BatchRunner::finish_pending() {
    if (!pending_) return;
    const std::unique_ptr<PendingWrite> p = std::move(pending_);
    p->writer.join();
    // Its storage serves the frame after the next.
    spare_frame_ = std::move(p->pixels);
    if (p->report_error) std::rethrow_exception(p->report_error);
}

bool BatchRunner::run(std::size_t index, const BatchJob& job) {
    const BatchInput& scene = scenes_[job.scene];
    FrameResult out;
    out.report.index = index;
    out.report.scene = scene.name;
    out.report.scene_spec = scene.spec;
    out.report.frame = job.frame;
    out.report.output = job.output;
    out.report.preview = job.png;
    const std::uint64_t work = frame_work(scene);

    // A frame that ends before it renders: the one written behind is reported first.
    const auto end_early = [&] {
        finish_pending();
        finish(out, work);
        return true;
    };
    const auto skip = [&](FrameOutcome outcome) {
        out.report.outcome = outcome;
        return end_early();
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
        return end_early();
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
            return end_early();
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
        remove_stale_temporaries(job.png.empty()
                                     ? std::vector<std::string>{job.output}
                                     : std::vector<std::string>{job.output, job.png});
        {
            const std::lock_guard lock(report_mutex_);  // the writer may be reporting
            observer_.frame_started(index, scene.name, job.frame, work, scene.scene.image.spp);
        }

        // The frame posed and prepared (frame_renderer.h): a scene's first frame compiles
        // it and builds its BVH (simd path); a next frame of a still or camera-only
        // animation only takes its camera, one whose spheres move updates them in place
        // and refits the BVH. One scene's renderer at a time (the memory estimate counts
        // one prepared scene).
        if (!renderer_ || renderer_index_ != job.scene) {
            renderer_.reset();
            const RenderConfig& c = settings_.render;
            renderer_ =
                std::make_unique<FrameRenderer>(scene.scene, c.path, c.isa, c.accel, c.threads);
            renderer_index_ = job.scene;
        }
        FrameRenderer::Timing prepared;
        const FrameRenderer::Pose pose = renderer_->prepare(job.frame, &prepared);
        const Scene& posed = pose.scene;
        out.report.compile_seconds = prepared.compile_seconds;
        out.report.bvh_seconds = prepared.bvh_seconds;  // or the spheres' update and refit
        out.report.prepare_seconds = prepared.seconds();
        RenderOptions options = settings_.render.render_options();
        options.frame = static_cast<std::uint32_t>(job.frame);
        options.cancel = cancel_;
        options.pixels_done = observer_.pixel_counter();
        options.crop = scene.crop;
        // A spare frame of another size would only add to this frame's memory (the
        // estimate counts one frame): it goes before this one renders.
        const std::uint64_t pixels = scene.crop
                                         ? scene.crop->pixel_count()
                                         : static_cast<std::uint64_t>(posed.image.width) *
                                               static_cast<std::uint64_t>(posed.image.height);
        if (spare_frame_.pixel_count() != pixels) spare_frame_ = Image();
        options.spare_image = &spare_frame_;
        // Writing (EXR and PNG encoding) is timed apart from tracing: the frame line and
        // the summary report each, and the rate is rays over trace time alone.
        const auto trace_started = Clock::now();

        const auto render_pass = [&](const RenderOptions& o) { return renderer_->render(o); };
        const auto aovs =
            std::make_shared<const Image>(renderer_->aovs(options, settings_.render.aovs));
        double write_seconds = 0.0;
        const auto timed_write = [&](const RenderResult& r, int samples_so_far,
                                     Image* spent = nullptr) {
            const auto write_started = Clock::now();
            FrameFiles f = files(scene, job, pose, r, aovs, samples_so_far);
            f.write(r.image, spent);
            write_seconds +=
                std::chrono::duration<double>(Clock::now() - write_started).count();
        };

        RenderResult result;
        if (settings_.progressive) {
            result = render_progressive(render_pass, posed.image.spp, options,
                                        [&](const RenderResult& pass, int samples_so_far) {
                                            if (samples_so_far < posed.image.spp)
                                                timed_write(pass, samples_so_far);
                                        });
        } else {
            result = render_pass(options);
        }
        // trace: the render (and AOVs) alone; preparing (compile, BVH) and writing are
        // reported apart.
        out.report.trace_seconds =
            std::chrono::duration<double>(Clock::now() - trace_started).count() - write_seconds;
        out.report.load_seconds = scene.load_seconds;
        out.report.render_seconds =
            result.seconds - result.compile_seconds - result.bvh_seconds;
        out.report.rays = result.rays.total();
        // The frame written behind this one is on disk before this one's files start:
        // at most one frame in flight.
        finish_pending();
        if (settings_.write_behind && !settings_.progressive) {
            auto p = std::make_unique<PendingWrite>();
            const auto write_started = Clock::now();
            p->files = files(scene, job, pose, result, aovs, posed.image.spp);
            p->seconds = std::chrono::duration<double>(Clock::now() - write_started).count();
            p->pixels = std::move(result.image);
            p->last = index == jobs_;
            out.report.write_seconds = write_seconds;
            p->result = std::move(out);
            p->work = work;
            p->claimed = claimed;
            p->started = started;
            p->writer = std::thread([this, w = p.get()] { write_behind(*w); });
            pending_ = std::move(p);
            return true;
        }
        // The run's last frame serves no next one as its storage.
        timed_write(result, posed.image.spp, index == jobs_ ? &result.image : nullptr);
        spare_frame_ = std::move(result.image);
        out.report.write_seconds = write_seconds;
        out.report.outcome = FrameOutcome::rendered;
    } catch (...) {
        record_failure(out, std::current_exception());
    }
    if (out.failure != FailureKind::none) {
        finish_pending();  // the frame before this one is reported first
        if (!claimed.empty()) release_claim(claimed);
    }
    out.report.seconds = std::chrono::duration<double>(Clock::now() - started).count();
    finish(out, work);
    return out.failure != FailureKind::interrupted;
}

}  // namespace

std::string render_path_label(const BatchSettings& settings) {
    return settings.render.path_label();
}

BatchSummary run_batch(const std::vector<BatchInput>& scenes, const std::vector<BatchJob>& jobs,
                       const BatchSettings& settings, BatchObserver& observer,
                       const std::atomic<bool>* cancel) {
    // Limit TBB for the whole run; 0 keeps its default (every core it may use).
    std::optional<tbb::global_control> thread_limit;
    if (settings.render.threads > 0)
        thread_limit.emplace(tbb::global_control::max_allowed_parallelism,
                             static_cast<std::size_t>(settings.render.threads));
    // OpenEXR compresses the blocks of scan lines of a frame on a pool of its own: as many
    // threads as the render's (none for one thread: the caller compresses). The file's
    // bytes are the same for any count, and the write is faster with more threads
    // (measured: docs/performance-log.md, "Time to image on a Zen 3 VM").
    const std::size_t threads =
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
    set_exr_thread_count(threads > 1 ? static_cast<int>(std::min<std::size_t>(threads, 64))
                                     : 0);

    std::uint64_t total_work = 0;
    for (const BatchJob& job : jobs) total_work += frame_work(scenes[job.scene]);
    observer.run_started({scenes, jobs, render_path_label(settings), threads,
                          settings.render.tile.width, settings.render.tile.height, total_work});

    const auto cancelled = [cancel] { return cancel != nullptr && cancel->load(); };
    BatchSummary summary;
    const auto account = [&summary](const FrameResult& result) {
        switch (result.report.outcome) {
            case FrameOutcome::rendered:
                ++summary.rendered;
                summary.rays += result.report.rays;
                summary.prepare_seconds += result.report.prepare_seconds;
                summary.trace_seconds += result.report.trace_seconds;
                summary.write_seconds += result.report.write_seconds;
                break;
            case FrameOutcome::skipped_existing:
            case FrameOutcome::skipped_claimed:
                ++summary.skipped;
                break;
            case FrameOutcome::failed:
                if (result.failure == FailureKind::interrupted)
                    summary.interrupted_frames = 1;  // abandoned mid-render
                else
                    ++summary.failed;
                break;
        }
        summary.scene_failure |= result.failure == FailureKind::scene;
        summary.io_failure |= result.failure == FailureKind::io;
        summary.internal_failure |= result.failure == FailureKind::internal;
    };
    const auto started = Clock::now();
    {
        BatchRunner runner(scenes, jobs.size(), settings, observer, cancel, account);
        for (std::size_t k = 0; k < jobs.size(); ++k) {
            if (cancelled()) {
                summary.not_started = jobs.size() - k;
                break;
            }
            if (!runner.run(k + 1, jobs[k])) {
                summary.not_started = jobs.size() - k - 1;
                break;
            }
        }
        // The last frame is written behind while its scene's memory goes back: freeing a
        // million spheres' BVH and arrays took 3-8 ms, the last write 3-6 ms.
        runner.release_renderer();
        runner.finish_pending();
    }
    summary.interrupted = cancelled();
    // The run's time counts its scenes' loading (done before it, once per scene).
    double load_seconds = 0.0;
    for (const BatchInput& scene : scenes) load_seconds += scene.load_seconds;
    summary.seconds =
        load_seconds + std::chrono::duration<double>(Clock::now() - started).count();
    observer.run_finished(summary);
    return summary;
}

}  // namespace octray::batch
