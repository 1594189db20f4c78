#pragma once
// EMOFACE_HD marks a function that compiles as plain C++ and as CUDA
// host+device code, so a kernel body is written once for both backends
// (the way pbrt-v4's PBRT_CPU_GPU does).
#if defined(__CUDACC__)
#define EMOFACE_HD __host__ __device__
#define EMOFACE_INLINE __forceinline__
#else
#define EMOFACE_HD
#define EMOFACE_INLINE inline
#endif
