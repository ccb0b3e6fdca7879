#pragma once
// Run-time choice of the kernel ISA (xsimd's dispatch pattern, embree's per-ISA
// libraries): every ISA is compiled into its own translation unit and the table for the
// one picked is looked up here, in baseline code.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "kernels/isa.h"
#include "kernels/kernel_table.h"

namespace octray {

// "auto", "sse2", "sse4.1", "avx2" or "avx512".
const char* isa_name(Isa isa);
std::optional<Isa> parse_isa(std::string_view name);

// What the CPU running us supports (CPUID via xsimd::available_architectures()).
struct CpuSupport {
    bool sse2 = false;
    bool sse4_1 = false;
    bool avx2 = false;
    bool fma = false;
    bool avx512 = false;  // F, VL, BW and DQ, with the OS saving the ZMM state
};
CpuSupport cpu_support();

// Whether the kernels for `isa` can run here (avx2 needs AVX2 and FMA; avx512 those and
// AVX-512 F, VL, BW and DQ).
bool isa_supported(Isa isa);

// Every ISA compiled into this binary, best last.
std::vector<Isa> compiled_isas();

// Every compiled ISA the CPU can run, best last.
std::vector<Isa> supported_isas();

// Isa::automatic becomes the best supported ISA; a forced ISA the CPU lacks throws
// std::runtime_error naming it.
Isa resolve_isa(Isa requested);

// The kernel table of a resolved ISA (never Isa::automatic).
const kernels::KernelTable& kernel_table(Isa isa);

}  // namespace octray
