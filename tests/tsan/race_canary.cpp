// A deliberate data race: tests/tsan/run.sh builds this with the same compiler and
// -fsanitize=thread as the tsan preset and requires ThreadSanitizer to report it, so a
// TSan setup that has gone blind (a missing flag, a runtime that does not start) cannot
// pass silently.
//
// The race must not depend on scheduling. Both writes below are unordered by
// happens-before (the thread is started before the main thread's write and joined after
// it), so TSan reports them whichever runs first, on any number of cores. An earlier
// canary raced inside tbb::parallel_for; on a slow CI machine the main thread ran every
// chunk before a worker woke up, no second thread touched the variable, and TSan rightly
// stayed silent.
#include <cstdio>
#include <thread>

int main() {
    long shared = 0;
    std::thread other([&] { shared += 1; });
    shared += 2;
    other.join();
    std::printf("%ld\n", shared);
    return 0;
}
