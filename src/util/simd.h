/*
 * simd.h: which build of the Monte Carlo engine's vector kernels runs (docs/speed.md, "Engine
 * overhead").
 *
 * The build targets baseline x86-64 (SSE2, two doubles a vector) and takes no -march flag, so
 * that one binary runs on any x86-64. The few loops that carry the engine's sampling (the normal
 * quantile's central region and tails, the uniform's chunk, the Philox generator and its
 * conversion to doubles) are compiled a
 * second time for AVX2 (four doubles a vector) and BMI2 (mulx: PRSM_TARGET_AVX2) and chosen at
 * run time. Either
 * build gives the same bits: the integer arithmetic is exact, and the floating-point operations
 * are the same IEEE additions, multiplications and divisions lane by lane in the same order (no
 * FMA: AVX2 does not imply it, and -std=c11 forbids contracting a * b + c anyway).
 */
#ifndef PRSM_UTIL_SIMD_H
#define PRSM_UTIL_SIMD_H

#if defined(__x86_64__) && defined(__GNUC__)
#define PRSM_HAVE_AVX2_CLONES 1
#define PRSM_TARGET_AVX2 __attribute__((target("avx2,bmi2")))
#else
#define PRSM_HAVE_AVX2_CLONES 0
#define PRSM_TARGET_AVX2
#endif

/* 1 when the AVX2 builds of the kernels may run: the processor has AVX2 and BMI2 (every processor
 * with AVX2 but a few has both; the Philox rounds take BMI2's mulx) and the tests have not turned
 * them off. */
int prsm_simd_avx2(void);

/* For the tests, which run both builds of a kernel against the scalar reference: 0 turns the AVX2
 * builds off, 1 lets the processor decide again. Not for use while kernels run on other threads. */
void prsm_simd_allow_avx2(int allow);

#endif
