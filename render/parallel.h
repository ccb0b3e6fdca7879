#pragma once
// What every parallel loop of the renderers shares: running on RenderOptions::threads,
// and a tile loop's cancellation and progress (RenderOptions::cancel, ::pixels_done).

#include <oneapi/tbb/task_arena.h>

#include <atomic>
#include <cstdint>

#include "core/thread_check.h"
#include "render/render_options.h"

namespace octray {

// Runs f() on `threads` worker threads (0: every core TBB sees). Throws ThreadStartError
// (core/thread_check.h) rather than let oneTBB abort when they cannot be started.
template <class F>
void run_with_threads(int threads, const F& f) {
    check_threads_can_start(threads);
    if (threads > 0)
        tbb::task_arena(threads).execute(f);
    else
        f();
}

// Per render: ask proceed() before a tile and report done(pixels) after it; finish()
// throws RenderCancelled when a tile was skipped, so a cancelled render returns no image.
class TileControl {
  public:
    explicit TileControl(const RenderOptions& options) : options_(options) {}

    bool proceed() {
        if (options_.cancel == nullptr || !options_.cancel->load(std::memory_order_relaxed))
            return true;
        cancelled_.store(true, std::memory_order_relaxed);
        return false;
    }
    void done(std::uint64_t pixels) {
        if (options_.pixels_done != nullptr)
            options_.pixels_done->fetch_add(pixels, std::memory_order_relaxed);
    }
    void finish() const {
        if (cancelled_.load()) throw RenderCancelled();
    }

  private:
    const RenderOptions& options_;
    std::atomic<bool> cancelled_{false};
};

}  // namespace octray
