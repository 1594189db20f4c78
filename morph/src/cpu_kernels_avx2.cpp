// The CPU row loops compiled for AVX2 + FMA (CMake adds -mavx2 -mfma
// -ffp-contract=fast to this file only); chosen at run time when the
// processor has both.
#define EMOFACE_CPU_KERNELS_IMPL cpu_avx2
#include "cpu_kernels.h"
