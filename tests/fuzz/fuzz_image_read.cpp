// libFuzzer target: read_image (OpenEXR and PNG, behind `octray compare`) on arbitrary
// bytes, written to one temporary file per process; see fuzz_checks.h (check_image_bytes).
#include <cstddef>
#include <cstdint>

#include "fuzz_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    octray::fuzz::check_image_bytes(data, size);
    return 0;
}
