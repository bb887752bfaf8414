/** @file vec.h
 * Three-component float vectors, used for points, directions and
 * linear RGB colours alike.
 *
 * Everything here is inline and uses only + - * / and sqrt, so results are
 * the same bits on every IEEE 754 machine (the render path is compiled with
 * -ffp-contract=off so no fused multiply-add changes a rounding).
 */
#ifndef FRANJA_VEC_H
#define FRANJA_VEC_H

#include <math.h>
#include <stdint.h>
#include <string.h>

typedef struct { float x, y, z; } vec3;
typedef struct { float u, v; } vec2;

static inline vec3 v3(float x, float y, float z) { vec3 r = {x, y, z}; return r; }
static inline vec3 v3s(float s) { return v3(s, s, s); }
static inline vec3 v3_add(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3 v3_sub(vec3 a, vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vec3 v3_mul(vec3 a, vec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline vec3 v3_scale(vec3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline vec3 v3_abs(vec3 a) { return v3(fabsf(a.x), fabsf(a.y), fabsf(a.z)); }
static inline vec3 v3_neg(vec3 a) { return v3(-a.x, -a.y, -a.z); }
static inline float v3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 v3_cross(vec3 a, vec3 b) {
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float v3_len2(vec3 a) { return v3_dot(a, a); }
static inline float v3_len(vec3 a) { return sqrtf(v3_dot(a, a)); }
static inline vec3 v3_norm(vec3 a) { return v3_scale(a, 1.0f / v3_len(a)); }
/** a + b*s, written out so the compiler cannot fuse it */
static inline vec3 v3_madd(vec3 a, vec3 b, float s) { return v3_add(a, v3_scale(b, s)); }
static inline float v3_max(vec3 a) { float m = a.x > a.y ? a.x : a.y; return m > a.z ? m : a.z; }
static inline float v3_min(vec3 a) { float m = a.x < a.y ? a.x : a.y; return m < a.z ? m : a.z; }
static inline vec3 v3_vmin(vec3 a, vec3 b) {
    return v3(a.x < b.x ? a.x : b.x, a.y < b.y ? a.y : b.y, a.z < b.z ? a.z : b.z);
}
static inline vec3 v3_vmax(vec3 a, vec3 b) {
    return v3(a.x > b.x ? a.x : b.x, a.y > b.y ? a.y : b.y, a.z > b.z ? a.z : b.z);
}
static inline float v3_get(vec3 a, int axis) { return axis == 0 ? a.x : axis == 1 ? a.y : a.z; }
/** All three coordinates == 0 (either sign), by their bits: a float
 * compares equal to 0 exactly where its bits but the sign are 0. */
static inline int v3_is_zero(vec3 a)
{
    uint32_t x, y, z;
    memcpy(&x, &a.x, 4);
    memcpy(&y, &a.y, 4);
    memcpy(&z, &a.z, 4);
    return ((x | y | z) & 0x7fffffffu) == 0;
}
/** Rec. 709 luminance of a linear RGB colour */
static inline float v3_luma(vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

/** An orthonormal basis (t, b, n) around unit vector n, without branches on
 * near-parallel cases (Duff et al. 2017, "Building an orthonormal basis,
 * revisited"), nor on the sign of n.z (n is often a random direction). */
static inline void v3_basis(vec3 n, vec3 *t, vec3 *b) {
    float sign = 1.0f - 2.0f * (float)!(n.z >= 0.0f);
    float a = -1.0f / (sign + n.z);
    float c = n.x * n.y * a;
    *t = v3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
    *b = v3(c, sign + n.y * n.y * a, -n.y);
}
/** Local frame (x along t, y along b, z along n) to world */
static inline vec3 v3_from_local(vec3 l, vec3 t, vec3 b, vec3 n) {
    return v3_add(v3_add(v3_scale(t, l.x), v3_scale(b, l.y)), v3_scale(n, l.z));
}
static inline vec3 v3_reflect(vec3 d, vec3 n) { return v3_sub(d, v3_scale(n, 2.0f * v3_dot(d, n))); }

#endif
