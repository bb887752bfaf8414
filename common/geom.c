#include "geom.h"

#include <string.h>

float geo_sphere(const fr_sphere *s, const fr_ray *r, float tmax)
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
    float t0 = q / a, t1 = (v3_dot(f, f) - s->radius * s->radius) / q;
    if (q == 0.0f)
        t0 = t1 = 0.0f;
    if (t0 > t1) { float tmp = t0; t0 = t1; t1 = tmp; }
    if (t0 > 0.0f && t0 < tmax) return t0;
    if (t1 > 0.0f && t1 < tmax) return t1;
    return 0.0f;
}

float geo_plane(const fr_plane *p, const fr_ray *r, float tmax)
{
    float dn = v3_dot(r->d, p->normal);
    if (dn == 0.0f)
        return 0.0f;
    float t = v3_dot(v3_sub(p->point, r->o), p->normal) / dn;
    return t > 0.0f && t < tmax ? t : 0.0f;
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
    float th = v3_dot(v3_sub(q->origin, r->o), q->normal) / dn;
    if (!(th > 0.0f && th < tmax))
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
    *b1 = v / det;
    *b2 = w / det;
    return t;
}

static float bits_to_float(int32_t i) { float f; memcpy(&f, &i, 4); return f; }
static int32_t float_to_bits(float f) { int32_t i; memcpy(&i, &f, 4); return i; }

static float offset_coord(float p, float n)
{
    /* Far from the origin, step a fixed number of ulps (scaled by the
     * normal's component); near it, where ulps vanish, a tiny absolute
     * step. */
    const float origin = 1.0f / 32.0f, float_scale = 1.0f / 65536.0f, int_scale = 256.0f;
    if (fabsf(p) < origin)
        return p + float_scale * n;
    /* n is a unit normal's component; a degenerate surface's NaN normal
     * gives no step (and no out-of-range float-to-int conversion). */
    float step = int_scale * n;
    int32_t di = step >= -int_scale && step <= int_scale ? (int32_t)step : 0;
    int32_t bits = float_to_bits(p);
    return bits_to_float(bits + ((p < 0.0f) ? -di : di));
}

vec3 geo_offset(vec3 p, vec3 ng, vec3 dir)
{
    if (v3_dot(ng, dir) < 0.0f)
        ng = v3_neg(ng);
    return v3(offset_coord(p.x, ng.x), offset_coord(p.y, ng.y), offset_coord(p.z, ng.z));
}
