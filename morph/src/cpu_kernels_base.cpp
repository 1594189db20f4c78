// The CPU row loops for the baseline instruction set of the target (SSE2 on
// x86-64): what runs where AVX2 is missing, and on other architectures.
#define EMOFACE_CPU_KERNELS_IMPL cpu_base
#include "cpu_kernels.h"
