// libFuzzer target: crop rectangles and shard specs of batch renders (render/batch/spec.h) on
// arbitrary strings; see batch_checks.h (check_crop_spec).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "batch_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    octray::fuzz::check_crop_spec(std::string_view(reinterpret_cast<const char*>(data), size));
    return 0;
}
