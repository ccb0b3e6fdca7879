// libFuzzer target: the JSON scene loader (parse_scene_json) and its validation, on
// arbitrary bytes; invariants in fuzz_checks.h (check_scene_json).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    octray::fuzz::check_scene_json(std::string_view(reinterpret_cast<const char*>(data), size));
    return 0;
}
