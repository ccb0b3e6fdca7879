#include "render/batch/progressive.h"

#include <stdexcept>
#include <string>
#include <utility>

namespace octray::batch {

std::vector<int> progressive_schedule(int spp) {
    if (spp < 1)
        throw std::invalid_argument("progressive rendering needs spp >= 1, not " +
                                    std::to_string(spp));
    std::vector<int> schedule;
    for (long long n = 1; n < spp; n *= 2) schedule.push_back(static_cast<int>(n));
    schedule.push_back(spp);
    return schedule;
}

RenderResult render_progressive(const PassRenderer& render, int spp,
                                const RenderOptions& options, const PassCallback& on_pass) {
    if (options.samples || options.sample_sums != nullptr)
        throw std::invalid_argument(
            "render_progressive sets the sample range itself: options.samples and "
            "options.sample_sums must be unset");
    RayCounts rays;
    double seconds = 0.0, compile_seconds = 0.0, bvh_seconds = 0.0;
    RenderResult result;
    int done = 0;
    for (const int end : progressive_schedule(spp)) {
        RenderOptions pass = options;
        pass.samples = SampleRange{done, end};
        pass.sample_sums = done > 0 ? &result.sample_sums : nullptr;
        RenderResult next = render(pass);
        rays += next.rays;
        seconds += next.seconds;
        compile_seconds += next.compile_seconds;
        bvh_seconds += next.bvh_seconds;
        result = std::move(next);
        done = end;
        if (on_pass) on_pass(result, done);
    }
    result.rays = rays;
    result.seconds = seconds;
    result.compile_seconds = compile_seconds;
    result.bvh_seconds = bvh_seconds;
    result.sample_sums = Image();
    return result;
}

}  // namespace octray::batch
