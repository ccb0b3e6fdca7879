// The AVX2 build of the user-geometry sphere callbacks: 8 lanes at a time, compiled with
// -mavx2 -mfma (bench/CMakeLists.txt); packets narrower than 8 go to the scalar build.

#define OCTRAY_EMBREE_CALLBACK_NAMESPACE avx2
#define OCTRAY_EMBREE_CALLBACK_ARCH xsimd::fma3<xsimd::avx2>
#define OCTRAY_EMBREE_CALLBACK_NARROWER scalar
#include "bench/embree_user_spheres_simd.h"
