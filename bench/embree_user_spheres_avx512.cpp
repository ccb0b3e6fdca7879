// The AVX-512 build of the user-geometry sphere callbacks: 16 lanes at a time, as an
// Embree user on AVX-512 writes them for rtcIntersect16, compiled with -mavx512f
// -mavx512vl -mavx512bw -mavx512dq -mavx2 -mfma (bench/CMakeLists.txt); packets of 8 or
// fewer go to the AVX2 build.

#define OCTRAY_EMBREE_CALLBACK_NAMESPACE avx512
#define OCTRAY_EMBREE_CALLBACK_ARCH xsimd::avx512bw
#define OCTRAY_EMBREE_CALLBACK_NARROWER avx2
#include "bench/embree_user_spheres_simd.h"
