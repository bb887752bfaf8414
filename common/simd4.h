/** @file simd4.h
 * Four-lane float vectors for BVH traversal and construction.
 *
 * Written with the GCC/Clang vector extension, so the same source becomes
 * SSE on x86_64 and NEON on aarch64 (and plain scalar code elsewhere).
 * Only + - * /, comparisons and min/max are used; IEEE 754 rounds each the
 * same way on every machine, so vector and scalar code give the same bits.
 *
 * min/max differ between instruction sets when a lane is NaN, so the two
 * here fix one rule: f4_max_num(a, acc) and f4_min_num(a, acc) return acc
 * in a lane where a is NaN, and acc must never be NaN.  Traversal relies on
 * it: 0 * inf (a ray in the plane of a box face) yields NaN, which must mean
 * "no constraint from this axis" on every host.
 */
#ifndef FRANJA_SIMD4_H
#define FRANJA_SIMD4_H

#include <stdint.h>
#include <string.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#elif defined(__ARM_NEON) && defined(__aarch64__)
#include <arm_neon.h>
#endif

typedef float f4 __attribute__((vector_size(16)));
typedef int32_t i4 __attribute__((vector_size(16)));

/** Unaligned load and store (the binary scene guarantees no alignment to
 * vector loads, only to its 4-byte fields). */
static inline f4 f4_load(const float *p) { f4 v; memcpy(&v, p, sizeof v); return v; }
static inline void f4_store(float *p, f4 v) { memcpy(p, &v, sizeof v); }
static inline f4 f4_set1(float x) { return (f4){x, x, x, x}; }
static inline i4 i4_set1(int32_t x) { return (i4){x, x, x, x}; }

/** Lane-wise |a| (the sign bit cleared). */
static inline f4 f4_abs(f4 a) { return (f4)((i4)a & i4_set1(0x7fffffff)); }

/** Lane-wise max(a, acc), acc where a is NaN (acc: never NaN). */
static inline f4 f4_max_num(f4 a, f4 acc)
{
#if defined(__SSE2__)
    return (f4)_mm_max_ps((__m128)a, (__m128)acc);
#elif defined(__ARM_NEON) && defined(__aarch64__)
    return vmaxnmq_f32(a, acc);
#else
    f4 r;
    for (int i = 0; i < 4; i++) r[i] = a[i] > acc[i] ? a[i] : acc[i];
    return r;
#endif
}

/** Lane-wise min(a, acc), acc where a is NaN (acc: never NaN). */
static inline f4 f4_min_num(f4 a, f4 acc)
{
#if defined(__SSE2__)
    return (f4)_mm_min_ps((__m128)a, (__m128)acc);
#elif defined(__ARM_NEON) && defined(__aarch64__)
    return vminnmq_f32(a, acc);
#else
    f4 r;
    for (int i = 0; i < 4; i++) r[i] = a[i] < acc[i] ? a[i] : acc[i];
    return r;
#endif
}

/** Bit i set when lane i of mask m (a comparison result) is true. */
static inline unsigned i4_bits(i4 m)
{
#if defined(__SSE2__)
    return (unsigned)_mm_movemask_ps((__m128)m);
#elif defined(__ARM_NEON) && defined(__aarch64__)
    const uint32x4_t w = {1, 2, 4, 8};
    return vaddvq_u32(vandq_u32((uint32x4_t)m, w));
#else
    return (unsigned)((m[0] & 1) | (m[1] & 2) | (m[2] & 4) | (m[3] & 8));
#endif
}

#endif
