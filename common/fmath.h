/** @file fmath.h
 * The transcendental functions of the render path.
 *
 * libm's sin, cos, exp, log ... differ in their last bits between C
 * libraries (glibc 2.31 and 2.36 disagree on some sin/cos inputs;
 * tests/bench/README.md, "libm across C libraries"), so
 * a slab rendered on one host would not match the same slab rendered on
 * another.  These versions use only + - * / and sqrt, which IEEE 754 rounds
 * exactly, so they give the same bits on every machine and C library.
 *
 * Accuracy (measured by tests/test_fmath.c against libm in double precision,
 * rounded to float, over grids, random points and a walk through all float
 * bit patterns): every function is within 1 ulp of the correctly rounded
 * float result over its whole domain, subnormal results included, and
 * correctly rounded for all but a few inputs in a million.  NaN in gives NaN
 * out; infinities and signed zeros follow C's rules.
 */
#ifndef FRANJA_FMATH_H
#define FRANJA_FMATH_H

#define FM_PI      3.14159265358979323846f
#define FM_INV_PI  0.31830988618379067154f
#define FM_INV_2PI 0.15915494309189533577f

float fm_sinf(float x);            /**< any finite x (exact reduction mod pi/2) */
float fm_cosf(float x);            /**< as fm_sinf */
void fm_sincosf(float x, float *s, float *c); /**< one reduction for both */
float fm_tanf(float x);            /**< any finite x */
float fm_expf(float x);            /**< 0 below -103.98, +inf above 88.73 */
float fm_logf(float x);            /**< x > 0; -inf at 0, NaN below */
float fm_powf(float x, float y);   /**< C's rules: x < 0 needs an integer y, else NaN */
float fm_atan2f(float y, float x); /**< in [-pi,pi]; atan2(+-0,+0) = +-0, atan2(+-0,-0) = +-pi */
float fm_acosf(float x);           /**< x clamped to [-1,1] */
float fm_asinf(float x);           /**< x clamped to [-1,1] */

#endif
