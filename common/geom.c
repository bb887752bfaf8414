/* geom.c -- ray/sphere, plane, rectangle and triangle intersection, and hit
 * points (see geom.h). */

#include "geom.h"

#include <string.h>

#include "simd4.h"

/* Inlined where it is called (always_inline: the walk's leaves test
 * spheres without a call). */
__attribute__((always_inline)) inline float geo_sphere(const fr_sphere *s, const fr_ray *r, float tmax)
{
    /* With f = o - c, the discriminant is computed as r^2 - |f - (f.d/d.d) d|^2,
     * which keeps its precision when the sphere is small and far away
     * (Haines et al., Ray Tracing Gems ch. 7). */
    vec3 f = v3_sub(r->o, s->center);
    float a = v3_dot(r->d, r->d);
    float b = -v3_dot(f, r->d);
    vec3 l = v3_add(f, v3_scale(r->d, b / a));
    float disc = s->radius * s->radius - v3_dot(l, l);
    if (disc < 0.0f)
        return 0.0f;
    float q = b + (b >= 0.0f ? 1.0f : -1.0f) * sqrtf(a * disc);
    float ff = v3_dot(f, f), rr = s->radius * s->radius;
    float t0 = q / a, t1 = (ff - rr) / q;
    if (q == 0.0f)
        t0 = t1 = 0.0f;
    if (t0 > t1) { float tmp = t0; t0 = t1; t1 = tmp; }
    /* The root near 0 is (f.f - r^2) / q, whose numerator cancels when the
     * origin is near the surface: its error is at most gamma(6) (f.f + r^2)
     * (f's rounding included); twice that covers q's own error. */
    float err = (ff + rr) * GEO_GAMMA(12) / fabsf(q);
    if (t0 > err && t0 < tmax) return t0;
    if (t1 > err && t1 < tmax) return t1;
    return 0.0f;
}

/* A bound on the error of t = (rel . n) / dn, rel the rounded difference
 * of a point of the plane and the ray origin: the numerator's four
 * roundings (gamma(4) of the sum of |rel_i n_i|), the denominator's and
 * the division's. */
static float plane_error(vec3 rel, vec3 n, float dn)
{
    float sum = fabsf(rel.x * n.x) + fabsf(rel.y * n.y) + fabsf(rel.z * n.z);
    return sum * GEO_GAMMA(6) / fabsf(dn);
}

float geo_plane(const fr_plane *p, const fr_ray *r, float tmax)
{
    float dn = v3_dot(r->d, p->normal);
    if (dn == 0.0f)
        return 0.0f;
    vec3 rel = v3_sub(p->point, r->o);
    float t = v3_dot(rel, p->normal) / dn;
    return t > plane_error(rel, p->normal, dn) && t < tmax ? t : 0.0f;
}

fr_rect geo_rect_make(vec3 origin, vec3 edge_u, vec3 edge_v)
{
    fr_rect q = {origin, edge_u, edge_v, v3_cross(edge_u, edge_v), v3s(0), v3s(0)};
    float uu = v3_dot(edge_u, edge_u), vv = v3_dot(edge_v, edge_v), uv = v3_dot(edge_u, edge_v);
    float det = uu * vv - uv * uv;
    if (det > 0.0f) {
        q.dual_u = v3_scale(v3_sub(v3_scale(edge_u, vv), v3_scale(edge_v, uv)), 1.0f / det);
        q.dual_v = v3_scale(v3_sub(v3_scale(edge_v, uu), v3_scale(edge_u, uv)), 1.0f / det);
    }
    return q;
}

float geo_rect(const fr_rect *q, const fr_ray *r, float tmax, float *s, float *t)
{
    float dn = v3_dot(r->d, q->normal);
    if (dn == 0.0f)
        return 0.0f;
    vec3 rel0 = v3_sub(q->origin, r->o);
    float th = v3_dot(rel0, q->normal) / dn;
    if (!(th > plane_error(rel0, q->normal, dn) && th < tmax))
        return 0.0f;
    /* Coordinates of the hit along the edges, by the dual basis (which
     * handles non-square parallelograms). */
    vec3 rel = v3_sub(v3_madd(r->o, r->d, th), q->origin);
    float a = v3_dot(rel, q->dual_u), b = v3_dot(rel, q->dual_v);
    if (a < 0.0f || a > 1.0f || b < 0.0f || b > 1.0f)
        return 0.0f;
    *s = a;
    *t = b;
    return th;
}

static float max2(float a, float b) { return a > b ? a : b; }

static int max_axis(vec3 v)
{
    float x = fabsf(v.x), y = fabsf(v.y), z = fabsf(v.z);
    return x > y ? (x > z ? 0 : 2) : (y > z ? 1 : 2);
}

float geo_triangle(vec3 p0, vec3 p1, vec3 p2, const fr_ray *r, float tmax, float *b1, float *b2)
{
    /* Watertight ray/triangle intersection: shear the vertices into a frame
     * where the ray is the +z axis, then decide with 2D edge functions that
     * are evaluated identically for the two triangles sharing an edge. */
    int kz = max_axis(r->d);
    int kx = kz == 2 ? 0 : kz + 1, ky = kx == 2 ? 0 : kx + 1;
    float dz = v3_get(r->d, kz);
    if (dz < 0.0f) { int tmp = kx; kx = ky; ky = tmp; }
    float sx = v3_get(r->d, kx) / dz, sy = v3_get(r->d, ky) / dz, sz = 1.0f / dz;

    vec3 a = v3_sub(p0, r->o), b = v3_sub(p1, r->o), c = v3_sub(p2, r->o);
    float az = v3_get(a, kz), bz = v3_get(b, kz), cz = v3_get(c, kz);
    float ax = v3_get(a, kx) - sx * az, ay = v3_get(a, ky) - sy * az;
    float bx = v3_get(b, kx) - sx * bz, by = v3_get(b, ky) - sy * bz;
    float cx = v3_get(c, kx) - sx * cz, cy = v3_get(c, ky) - sy * cz;

    float u = cx * by - cy * bx, v = ax * cy - ay * cx, w = bx * ay - by * ax;
    if (u == 0.0f || v == 0.0f || w == 0.0f) {
        /* On an edge in single precision: decide in double, exactly enough
         * that both neighbours agree. */
        u = (float)((double)cx * by - (double)cy * bx);
        v = (float)((double)ax * cy - (double)ay * cx);
        w = (float)((double)bx * ay - (double)by * ax);
    }
    if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f))
        return 0.0f;
    float det = u + v + w;
    if (det == 0.0f)
        return 0.0f;
    float tz = sz * (u * az + v * bz + w * cz);
    float t = tz / det;
    if (!(t > 0.0f && t < tmax))
        return 0.0f;
    /* Within its own rounding error of 0, t might be on either side. */
    if (!(t > GEO_TRI_ERROR(float, fabsf, max2, ax, bx, cx, ay, by, cy, az, bz, cz, u, v, w, sz, det)))
        return 0.0f;
    *b1 = v / det;
    *b2 = w / det;
    return t;
}

/* Inlined where a hit point is made (always_inline), with no vectors
 * passed through the stack. */
__attribute__((always_inline)) inline vec3 geo_triangle_point(vec3 p0, vec3 p1, vec3 p2, float b1, float b2, vec3 *err)
{
    float b0 = 1.0f - b1 - b2;
    vec3 w0 = v3_scale(p0, b0), w1 = v3_scale(p1, b1), w2 = v3_scale(p2, b2);
    /* Products, sums and the rounded b0 (whose error moves the point off
     * the plane in proportion to its distance from the world origin). */
    *err = v3_scale(v3_add(v3_add(v3_abs(w0), v3_abs(w1)), v3_abs(w2)), GEO_GAMMA(7));
    return v3_add(v3_add(w0, w1), w2);
}

vec3 geo_sphere_point(const fr_sphere *s, vec3 n, vec3 *err)
{
    /* |n| is 1 within a few roundings, so c + r n lies on the sphere
     * within those and the two of the sum. */
    vec3 rn = v3_scale(n, s->radius);
    *err = v3_scale(v3_add(v3_abs(s->center), v3_abs(rn)), GEO_GAMMA(6));
    return v3_add(s->center, rn);
}

vec3 geo_rect_point(const fr_rect *q, float s, float t, vec3 *err)
{
    vec3 us = v3_scale(q->edge_u, s), vt = v3_scale(q->edge_v, t);
    vec3 p = v3_add(q->origin, v3_add(us, vt));
    /* The rectangle's test takes its plane through `origin` across the
     * rounded normal, which tilts from the plane of the edges by the
     * cross product's error (gamma(2) per term): a point s, t along the
     * edges is off it by up to (s |edge_u| + t |edge_v|) . that error / |n|. */
    vec3 eu = v3_abs(q->edge_u), ev = v3_abs(q->edge_v);
    vec3 ce = v3(eu.y * ev.z + eu.z * ev.y, eu.z * ev.x + eu.x * ev.z, eu.x * ev.y + eu.y * ev.x);
    float tilt = (fabsf(s) * v3_dot(eu, ce) + fabsf(t) * v3_dot(ev, ce)) * GEO_GAMMA(3) / v3_len(q->normal);
    *err = v3_add(v3_scale(v3_add(v3_add(v3_abs(q->origin), v3_abs(us)), v3_abs(vt)), GEO_GAMMA(4)), v3s(tilt));
    return p;
}

vec3 geo_plane_point(const fr_plane *p, const fr_ray *r, float t, vec3 *err)
{
    /* The point along the ray: t's error (plane_error, relative to the
     * numerator, at most gamma(11) of sum |rel_i n_i| across the normal)
     * and the two roundings of o + t d. */
    vec3 dt = v3_scale(r->d, t), rel = v3_sub(p->point, r->o);
    float sum = fabsf(rel.x * p->normal.x) + fabsf(rel.y * p->normal.y) + fabsf(rel.z * p->normal.z);
    *err = v3_add(v3s(sum * GEO_GAMMA(11)), v3_scale(v3_add(v3_abs(r->o), v3_abs(dt)), GEO_GAMMA(2)));
    return v3_add(r->o, dt);
}

/* Inlined where they are called (always_inline), so that their vectors
 * are not passed through the stack. */
__attribute__((always_inline)) inline vec3 geo_offset(vec3 p, vec3 err, vec3 ng, vec3 dir)
{
    return geo_offset_side(p, err, ng, v3_dot(ng, dir) < 0.0f);
}

__attribute__((always_inline)) inline vec3 geo_offset_side(vec3 p, vec3 err, vec3 ng, int below)
{
    float d = fabsf(ng.x) * err.x + fabsf(ng.y) * err.y + fabsf(ng.z) * err.z;
    /* A degenerate surface's NaN normal or error: no push (and no NaN). */
    if (!(d < INFINITY))
        return p;
    if (below)
        d = -d;
    /* Each coordinate: p + step, then one float further along the sign of
     * step (next_up or next_down of the sum; the sum itself when step is
     * 0).  Done on the bit patterns, three coordinates at once, with masks
     * instead of branches, since the step's sign follows the ray's random
     * direction: moving away from zero adds one to the pattern, toward
     * zero takes one; a zero becomes the smallest subnormal of the step's
     * sign, an infinity moving outward stays, and a NaN loses one as
     * next_up's general case does. */
    f4 step = (f4){ng.x, ng.y, ng.z, 0.0f} * f4_set1(d);
    f4 o = (f4){p.x, p.y, p.z, 0.0f} + step;
    i4 i = (i4)o, zero4 = i4_set1(0);
    i4 mag = i & i4_set1(0x7fffffff);
    i4 up = step > f4_set1(0.0f), down = step < f4_set1(0.0f), move = up | down;
    /* The common case, every coordinate that moves finite and not zero:
     * +1 where the sum and the step have the same sign (away from zero),
     * -1 where they differ (the sign of a step that moves is its bit
     * pattern's), nothing where the step is 0 (on a surface along an axis
     * plane through the origin, with no error to push off: d = 0). */
    i4 plain = ((mag > zero4) & (mag < i4_set1(0x7f800000))) | ~move;
    if ((i4_bits(plain) & 7) == 7) {
        i4 delta = ((i ^ (i4)step) >> 31) | i4_set1(1);
        f4 q = (f4)(i + (delta & move));
        return v3(q[0], q[1], q[2]);
    }
    i4 neg = i < zero4;
    i4 out = (neg & down) | (~neg & up);                       /* away from zero */
    i4 nan = mag > i4_set1(0x7f800000), stay = (mag == i4_set1(0x7f800000)) & out;
    i4 delta = ((out & ~nan) & i4_set1(2)) - i4_set1(1);       /* +1 or -1 */
    delta &= move & ~stay;
    i4 zero = (mag == zero4) & move;
    i4 r = ((i + delta) & ~zero) | (((down & i4_set1(INT32_MIN)) | i4_set1(1)) & zero);
    f4 q = (f4)r;
    return v3(q[0], q[1], q[2]);
}
