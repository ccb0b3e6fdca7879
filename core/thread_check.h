#pragma once
// Whether this process can start the worker threads a render asks for, checked before
// oneTBB is asked for them. oneTBB starts its workers from inside its own threads and
// cannot report a failed pthread_create to anyone: it calls std::terminate ("pthread_create
// has failed", exit 134) when a limit on memory (ulimit -v) or processes (ulimit -u) stops
// it. So the caller checks first and refuses the render with the reason:
// - under an address-space limit, that the workers fit in what is left of it: each a 4 MiB
//   stack, and each up to glibc's arena limit (8 per core) a malloc arena, which reserves
//   64 MiB of address space (a worker gets one on its first malloc). Which thread wins the
//   race for the last megabytes differs from run to run, so this is counted, not tried;
// - that threads - 1 threads can be started at once (the process limit), by starting them.

#include <pthread.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace octray {

// The threads could not be started: the message says how many and why.
class ThreadStartError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// oneTBB's default worker stack (global_control::thread_stack_size on 64-bit systems), and
// the address space glibc reserves for a thread's malloc arena (HEAP_MAX_SIZE on 64-bit).
inline constexpr std::uint64_t kWorkerStackBytes = std::uint64_t{4} << 20;
inline constexpr std::uint64_t kMallocArenaBytes = std::uint64_t{64} << 20;

// Throws ThreadStartError unless `threads` threads (0: one per core) can run at once: the
// caller and threads - 1 workers. Proven counts are remembered, so a render after the
// first costs a lock.
inline void check_threads_can_start(int threads) {
    static std::mutex mutex;
    static int proven = 1;
    const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    const int wanted = threads > 0 ? threads : cores;
    const std::lock_guard<std::mutex> lock(mutex);
    if (wanted <= proven) return;

    constexpr std::uint64_t kMiB = std::uint64_t{1} << 20;
    struct rlimit limit {};
    if (::getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
        std::uint64_t pages = 0;
        std::FILE* statm = std::fopen("/proc/self/statm", "r");
        if (statm != nullptr) {
            unsigned long long size = 0;
            if (std::fscanf(statm, "%llu", &size) == 1) pages = size;
            std::fclose(statm);
        }
        const std::uint64_t used = pages * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
        const std::uint64_t arenas = static_cast<std::uint64_t>(std::min(wanted, 8 * cores));
        const std::uint64_t need = static_cast<std::uint64_t>(wanted - 1) * kWorkerStackBytes +
                                   arenas * kMallocArenaBytes;
        const std::uint64_t left = limit.rlim_cur > used ? limit.rlim_cur - used : 0;
        if (need > left)
            throw ThreadStartError("cannot start " + std::to_string(wanted) +
                                   " threads within the address-space limit (ulimit -v) of " +
                                   std::to_string(limit.rlim_cur / kMiB) +
                                   " MiB: they take about " + std::to_string(need / kMiB) +
                                   " MiB (a 4 MiB stack each and " + std::to_string(arenas) +
                                   " malloc arenas of 64 MiB), and " +
                                   std::to_string(left / kMiB) + " MiB are left");
    }

    struct Gate {
        pthread_mutex_t mutex = PTHREAD_MUTEX_INITIALIZER;
        pthread_cond_t open = PTHREAD_COND_INITIALIZER;
        bool released = false;
    } gate;
    const auto worker = [](void* arg) -> void* {
        auto* g = static_cast<Gate*>(arg);
        pthread_mutex_lock(&g->mutex);
        while (!g->released) pthread_cond_wait(&g->open, &g->mutex);
        pthread_mutex_unlock(&g->mutex);
        return nullptr;
    };
    pthread_attr_t attributes;
    pthread_attr_init(&attributes);
    pthread_attr_setstacksize(&attributes, kWorkerStackBytes);
    std::vector<pthread_t> started;
    int error = 0;
    for (int i = 1; i < wanted && error == 0; ++i) {
        pthread_t thread;
        error = pthread_create(&thread, &attributes, worker, &gate);
        if (error == 0) started.push_back(thread);
    }
    pthread_attr_destroy(&attributes);
    pthread_mutex_lock(&gate.mutex);
    gate.released = true;
    pthread_cond_broadcast(&gate.open);
    pthread_mutex_unlock(&gate.mutex);
    for (pthread_t thread : started) pthread_join(thread, nullptr);
    if (error != 0)
        throw ThreadStartError(
            "cannot start " + std::to_string(wanted) + " threads: thread " +
            std::to_string(started.size() + 2) + " failed (" + std::strerror(error) +
            "; a limit on processes or memory, such as ulimit -u, is in the way)");
    proven = wanted;
}

}  // namespace octray
