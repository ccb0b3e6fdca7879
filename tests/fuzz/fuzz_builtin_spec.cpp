// libFuzzer target: the built-in scene spec parser and generators (make_builtin_scene) on
// arbitrary strings, with a cap on generated scene size; see fuzz_checks.h
// (check_builtin_spec).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    (void)octray::fuzz::check_builtin_spec(
        std::string(reinterpret_cast<const char*>(data), size));
    return 0;
}
