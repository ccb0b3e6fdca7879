// Baseline code (no ISA flags): it runs before we know what the CPU has.

#include "kernels/dispatch.h"

#include <stdexcept>
#include <xsimd/xsimd.hpp>

namespace octray {

const char* isa_name(Isa isa) {
    switch (isa) {
        case Isa::automatic:
            return "auto";
        case Isa::sse2:
            return "sse2";
        case Isa::sse4_1:
            return "sse4.1";
        case Isa::avx2:
            return "avx2";
        case Isa::avx512:
            return "avx512";
    }
    return "?";
}

std::optional<Isa> parse_isa(std::string_view name) {
    for (Isa isa : {Isa::automatic, Isa::sse2, Isa::sse4_1, Isa::avx2, Isa::avx512})
        if (name == isa_name(isa)) return isa;
    return std::nullopt;
}

CpuSupport cpu_support() {
    const auto arch = xsimd::available_architectures();
    CpuSupport s;
    s.sse2 = arch.sse2;
    s.sse4_1 = arch.sse4_1;
    s.avx2 = arch.avx2;
    s.fma = arch.fma3_avx2;  // xsimd: AVX2 and the FMA3 CPUID bit
    // libgcc's CPU model counts AVX-512 only where the OS saves the ZMM state (XCR0).
    s.avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
               __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
    return s;
}

bool isa_supported(Isa isa) {
    const CpuSupport s = cpu_support();
    switch (isa) {
        case Isa::automatic:
            return true;
        case Isa::sse2:
            return s.sse2;
        case Isa::sse4_1:
            return s.sse4_1;
        case Isa::avx2:
            return s.avx2 && s.fma;
        case Isa::avx512:
            return s.avx2 && s.fma && s.avx512;
    }
    return false;
}

std::vector<Isa> compiled_isas() { return {Isa::sse2, Isa::sse4_1, Isa::avx2, Isa::avx512}; }

std::vector<Isa> supported_isas() {
    std::vector<Isa> out;
    for (Isa isa : compiled_isas())
        if (isa_supported(isa)) out.push_back(isa);
    return out;
}

Isa resolve_isa(Isa requested) {
    if (requested != Isa::automatic) {
        if (!isa_supported(requested))
            throw std::runtime_error(std::string("this CPU does not support --isa ") +
                                     isa_name(requested));
        return requested;
    }
    const std::vector<Isa> supported = supported_isas();
    if (supported.empty()) throw std::runtime_error("this CPU lacks even SSE2");
    return supported.back();
}

const kernels::KernelTable& kernel_table(Isa isa) {
    switch (isa) {
        case Isa::sse2:
            return kernels::kKernelsSse2;
        case Isa::sse4_1:
            return kernels::kKernelsSse41;
        case Isa::avx2:
            return kernels::kKernelsAvx2;
        case Isa::avx512:
            return kernels::kKernelsAvx512;
        case Isa::automatic:
            break;
    }
    throw std::logic_error("kernel_table() needs a resolved ISA");
}

}  // namespace octray
