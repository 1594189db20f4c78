#pragma once
// EMOFACE_HD marks a function that compiles as plain C++ and as CUDA
// host+device code, so a kernel body is written once for both backends
// (the way pbrt-v4's PBRT_CPU_GPU does).
//
// EMOFACE_INLINE forces inlining on both sides: the small functions of a
// kernel body are called in its innermost loops, where a call the compiler
// chose to keep (plain `inline` allows that on the host) stops it from
// vectorising or keeping the sums in registers.
#if defined(__CUDACC__)
#define EMOFACE_HD __host__ __device__
#define EMOFACE_INLINE __forceinline__
#elif defined(__GNUC__)
#define EMOFACE_HD
#define EMOFACE_INLINE inline __attribute__((always_inline))
#else
#define EMOFACE_HD
#define EMOFACE_INLINE inline
#endif
