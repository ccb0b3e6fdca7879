# Shared compile flags as INTERFACE targets: link them, never copy them.

# Warnings are errors everywhere in our own code.
add_library(octray_warnings INTERFACE)
add_library(octray::warnings ALIAS octray_warnings)
target_compile_options(octray_warnings INTERFACE -Wall -Wextra -Werror)

# The floating-point model both render paths rely on. GCC contracts a*b+c into an FMA
# whenever the target has one (-ffp-contract=fast is its default in GNU mode), which would
# make the AVX2 translation unit round differently from the SSE2 one and from the scalar
# reference. We turn contraction off so every ISA computes the same IEEE operations in the
# same order; the kernels use FMA only where they ask for it explicitly.
add_library(octray_fp_model INTERFACE)
add_library(octray::fp_model ALIAS octray_fp_model)
target_compile_options(octray_fp_model INTERFACE -ffp-contract=off -fno-math-errno)

# Optimisation for the hot code, whatever the build type (a Debug build of the kernels is
# still usable for the tests). Never -march=native: the ISA is picked at run time.
add_library(octray_optimize INTERFACE)
add_library(octray::optimize ALIAS octray_optimize)
target_compile_options(octray_optimize INTERFACE $<$<NOT:$<CONFIG:Debug>>:-O2>)
