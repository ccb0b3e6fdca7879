#pragma once
// Ctrl-C (SIGINT) and SIGTERM (what Slurm and Kubernetes send before killing a job) during
// a batch render: the first one only raises a flag, so the frame being rendered is
// abandoned at the next tile, nothing half-written is left behind, finished frames stay
// and the run ends with its summary. A second signal kills the process at once (the
// default action); the hidden temporary of a write it interrupts is removed by the next
// run that renders that frame.

#include <atomic>

namespace octray::tools {

class InterruptGuard {
  public:
    InterruptGuard();   // installs the handlers for SIGINT and SIGTERM
    ~InterruptGuard();  // restores the previous ones
    InterruptGuard(const InterruptGuard&) = delete;
    InterruptGuard& operator=(const InterruptGuard&) = delete;

    // Set by the first signal; what the renderers poll between tiles.
    static const std::atomic<bool>& flag();
    // The signal received (SIGINT or SIGTERM), 0 if none.
    static int signal_number();
};

}  // namespace octray::tools
