/** @file lanes.h
 * Three-component vectors (vec.h) in the first three lanes of a four-lane
 * float vector (simd4.h), for code that repeats vec.h's operations on
 * whole points and normals at once.  Lane-wise + - * / round as the scalar
 * operations do, so such code gives the bits of its scalar form when it
 * keeps the form's order of operations (and -ffp-contract=off keeps
 * products and sums apart).
 */
#ifndef FRANJA_LANES_H
#define FRANJA_LANES_H

#include "simd4.h"
#include "vec.h"

/** v in lanes 0-2, 0 in lane 3. */
static inline f4 ln_from(vec3 v) { return (f4){v.x, v.y, v.z, 0.0f}; }
/** Lanes 0-2 of v as a vector. */
static inline vec3 ln_vec(f4 v) { return v3(v[0], v[1], v[2]); }
/** The lanes turned: (y, z, x) and (z, x, y), lane 3 kept.  Clang (the
 * fuzz build) spells GCC's lane shuffle otherwise; both move the same
 * lanes. */
#ifdef __clang__
static inline f4 ln_yzx(f4 v) { return __builtin_shufflevector(v, v, 1, 2, 0, 3); }
static inline f4 ln_zxy(f4 v) { return __builtin_shufflevector(v, v, 2, 0, 1, 3); }
#else
static inline f4 ln_yzx(f4 v) { return __builtin_shuffle(v, (i4){1, 2, 0, 3}); }
static inline f4 ln_zxy(f4 v) { return __builtin_shuffle(v, (i4){2, 0, 1, 3}); }
#endif
/** v3_cross of lanes 0-2. */
static inline f4 ln_cross(f4 a, f4 b) { return ln_yzx(a) * ln_zxy(b) - ln_zxy(a) * ln_yzx(b); }
/** v3_norm of lanes 0-2: scaled by 1 / sqrt(x x + y y + z z). */
static inline f4 ln_norm(f4 a)
{
    f4 a2 = a * a;
    return a * f4_set1(1.0f / sqrtf(a2[0] + a2[1] + a2[2]));
}

#endif
