// A deliberate data race through tbb::parallel_for: tests/tsan/run.sh builds this with
// the same flags and TBB as the tsan preset and requires ThreadSanitizer to report it,
// so a TSan setup that has gone blind (a missing flag, a runtime that does not start)
// cannot pass silently.
#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <cstdio>

int main() {
    long shared = 0;  // written by every task without synchronisation: the race
    tbb::task_arena arena(2);
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<int>(0, 1 << 16, 64),
                          [&](const tbb::blocked_range<int>& r) {
                              for (int i = r.begin(); i < r.end(); ++i) shared += i;
                          });
    });
    std::printf("%ld\n", shared);
    return 0;
}
