// libFuzzer target: frame specs and output patterns of batch renders (render/batch/spec.h) on
// arbitrary strings; see batch_checks.h (check_frame_spec).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "batch_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    octray::fuzz::check_frame_spec(std::string_view(reinterpret_cast<const char*>(data), size));
    return 0;
}
