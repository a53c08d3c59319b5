/*
 * simd.c: the run-time choice of the vector kernels' build (simd.h).
 */
#include "util/simd.h"

#include <stdatomic.h>

static atomic_int avx2_allowed = 1;

int prsm_simd_avx2(void)
{
	if (!atomic_load_explicit(&avx2_allowed, memory_order_relaxed))
		return 0;
#if PRSM_HAVE_AVX2_CLONES
	/* reads the features libgcc's start-up code found with CPUID: a load and a test */
	return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("bmi2");
#else
	return 0;
#endif
}

void prsm_simd_allow_avx2(int allow)
{
	atomic_store_explicit(&avx2_allowed, allow != 0, memory_order_relaxed);
}
