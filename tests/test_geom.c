/* test_geom.c -- ray/primitive intersection, watertight edges, no self-
 * intersection.
 *
 * Ray/primitive intersection: hits from outside and inside, misses, grazing
 * and parallel rays, watertight shared edges, and self-intersection
 * avoidance at several scene scales. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "check.h"
#include "geom.h"
#include "sampler.h"

static float rnd(uint32_t *state)
{
    *state = smp_hash(*state + 0x9e3779b9u);
    return (float)(*state >> 8) / 16777216.0f;
}

static void test_sphere(void)
{
    fr_sphere s = {v3(0, 0, 10), 2};
    fr_ray r = {v3(0, 0, 0), v3(0, 0, 1), 0.0f};
    CHECK(fabsf(geo_sphere(&s, &r, INFINITY) - 8.0f) < 1e-5f, "sphere hit from outside at t=8");
    r.o = v3(0, 0, 10);
    CHECK(fabsf(geo_sphere(&s, &r, INFINITY) - 2.0f) < 1e-5f, "sphere hit from inside at t=2");
    r.o = v3(0, 0, 20);
    CHECK(geo_sphere(&s, &r, INFINITY) == 0.0f, "sphere behind the ray is missed");
    r.o = v3(0, 2.5f, 0);
    CHECK(geo_sphere(&s, &r, INFINITY) == 0.0f, "ray passing beside the sphere misses");
    r.o = v3(0, 0, 0);
    CHECK(geo_sphere(&s, &r, 7.9f) == 0.0f, "hit beyond tmax is ignored");
    /* Grazing: tangent ray.  Either answer is fine, but it must be finite. */
    r.o = v3(0, 2, 0);
    float t = geo_sphere(&s, &r, INFINITY);
    CHECK(t == 0.0f || fabsf(t - 10.0f) < 1e-2f, "tangent ray: t=%g", t);
    /* A small sphere far away (cancellation-prone) is still hit. */
    fr_sphere far = {v3(0, 0, 1e5f), 0.01f};
    r.o = v3(0, 0.005f, 0);
    t = geo_sphere(&far, &r, INFINITY);
    CHECK(fabsf(t - 1e5f) < 1.0f, "small far sphere hit, t=%g", t);
}

static void test_plane_rect(void)
{
    fr_plane p = {v3(0, 1, 0), v3(0, 1, 0), 0, 0};
    fr_ray r = {v3(0, 5, 0), v3(0, -1, 0), 0.0f};
    CHECK(fabsf(geo_plane(&p, &r, INFINITY) - 4.0f) < 1e-6f, "plane from above");
    r.o = v3(0, -3, 0);
    r.d = v3(0, 1, 0);
    CHECK(fabsf(geo_plane(&p, &r, INFINITY) - 4.0f) < 1e-6f, "plane from below");
    r.d = v3(1, 0, 0);
    CHECK(geo_plane(&p, &r, INFINITY) == 0.0f, "parallel ray misses the plane");

    fr_rect q = geo_rect_make(v3(0, 0, 5), v3(2, 0, 0), v3(0, 1, 0));
    float s, t;
    r.o = v3(1.5f, 0.5f, 0);
    r.d = v3(0, 0, 1);
    CHECK(fabsf(geo_rect(&q, &r, INFINITY, &s, &t) - 5.0f) < 1e-6f && fabsf(s - 0.75f) < 1e-6f &&
              fabsf(t - 0.5f) < 1e-6f, "rect hit with edge coordinates");
    r.o = v3(1.5f, 0.5f, 9);
    r.d = v3(0, 0, -1);
    CHECK(geo_rect(&q, &r, INFINITY, &s, &t) > 0.0f, "rect hit from the back");
    r.o = v3(2.5f, 0.5f, 0);
    r.d = v3(0, 0, 1);
    CHECK(geo_rect(&q, &r, INFINITY, &s, &t) == 0.0f, "ray beside the rect misses");
    r.o = v3(1, 0.5f, 5);
    r.d = v3(1, 0, 0);
    CHECK(geo_rect(&q, &r, INFINITY, &s, &t) == 0.0f, "ray in the rect's plane misses");
}

static void test_triangle(void)
{
    vec3 a = v3(0, 0, 3), b = v3(1, 0, 3), c = v3(0, 1, 3);
    fr_ray r = {v3(0.25f, 0.25f, 0), v3(0, 0, 1), 0.0f};
    float b1, b2;
    float t = geo_triangle(a, b, c, &r, INFINITY, &b1, &b2);
    CHECK(fabsf(t - 3.0f) < 1e-6f && fabsf(b1 - 0.25f) < 1e-6f && fabsf(b2 - 0.25f) < 1e-6f,
          "triangle hit and barycentrics (t=%g b=%g,%g)", t, b1, b2);
    r.o = v3(0.25f, 0.25f, 6);
    r.d = v3(0, 0, -1);
    CHECK(geo_triangle(a, b, c, &r, INFINITY, &b1, &b2) > 0.0f, "triangle hit from the back");
    r.o = v3(0.75f, 0.75f, 0);
    r.d = v3(0, 0, 1);
    CHECK(geo_triangle(a, b, c, &r, INFINITY, &b1, &b2) == 0.0f, "ray outside the triangle misses");
    r.o = v3(0.2f, 0.2f, 3);
    r.d = v3(1, 0, 0);
    CHECK(geo_triangle(a, b, c, &r, INFINITY, &b1, &b2) == 0.0f, "ray in the triangle's plane misses");
    CHECK(geo_triangle(a, a, c, &r, INFINITY, &b1, &b2) == 0.0f, "degenerate triangle is never hit");
}

/* Rays through a mesh of triangles sharing edges and a vertex must all hit:
 * a fan of 7 triangles around a centre vertex, aimed at points on the
 * shared edges and at random points. */
static void test_watertight(void)
{
    enum { FAN = 7 };
    vec3 centre = v3(0.3f, -0.2f, 10.0f), rim[FAN];
    for (int i = 0; i < FAN; i++) {
        double ang = 2 * M_PI * i / FAN + 0.1;
        rim[i] = v3((float)(3 * cos(ang)), (float)(3 * sin(ang)), 10.0f + (float)(0.5 * sin(3 * ang)));
    }
    uint32_t st = 1;
    int leaks = 0, rays = 0;
    for (int k = 0; k < 200000; k++) {
        int i = k % FAN;
        float f = rnd(&st);
        /* Points on the shared edge centre-rim[i], and random ones. */
        vec3 target = k % 2 ? v3_add(centre, v3_scale(v3_sub(rim[i], centre), f * 0.95f))
                            : v3_add(centre, v3_add(v3_scale(v3_sub(rim[i], centre), f * 0.6f),
                                                    v3_scale(v3_sub(rim[(i + 1) % FAN], centre), rnd(&st) * 0.3f)));
        vec3 o = v3(rnd(&st) * 4 - 2, rnd(&st) * 4 - 2, -5.0f);
        fr_ray r = {o, v3_sub(target, o), 0.0f};
        int hits = 0;
        for (int j = 0; j < FAN; j++) {
            float b1, b2;
            hits += geo_triangle(centre, rim[j], rim[(j + 1) % FAN], &r, INFINITY, &b1, &b2) > 0.0f;
        }
        rays++;
        leaks += hits == 0;
    }
    CHECK(leaks == 0, "%d of %d rays through shared edges hit no triangle", leaks, rays);
}

/* A random unit direction on the side of unit normal n, from grazing
 * (cosine 1e-4) to along the normal. */
static vec3 leave(uint32_t *st, vec3 n)
{
    vec3 t, b;
    v3_basis(n, &t, &b);
    float c = rnd(st) < 0.3f ? 1e-4f + rnd(st) * 1e-2f : rnd(st), sn = sqrtf(1.0f - c * c);
    float a = 6.2831853f * rnd(st);
    return v3_norm(v3_from_local(v3(sn * (float)cos(a), sn * (float)sin(a), c), t, b, n));
}

/* A quad as two triangles p0 p1 p2 and p0 p2 p3, as a scene's quad is. */
static float quad_hit(const vec3 q[4], const fr_ray *r, vec3 *p, vec3 *err, vec3 *ng)
{
    float b1, b2, t = geo_triangle(q[0], q[1], q[2], r, INFINITY, &b1, &b2);
    if (t > 0.0f) {
        *p = geo_triangle_point(q[0], q[1], q[2], b1, b2, err);
        *ng = v3_norm(v3_cross(v3_sub(q[1], q[0]), v3_sub(q[2], q[0])));
        return t;
    }
    t = geo_triangle(q[0], q[2], q[3], r, INFINITY, &b1, &b2);
    if (t > 0.0f) {
        *p = geo_triangle_point(q[0], q[2], q[3], b1, b2, err);
        *ng = v3_norm(v3_cross(v3_sub(q[2], q[0]), v3_sub(q[3], q[0])));
    }
    return t;
}

/* A ray leaving a surface from geo_offset must hit neither that surface
 * nor, for a quad, its other triangle: rays from the hit point of a ray
 * coming from either side, leaving to either side at any angle down to
 * grazing.  Walls at coordinate 0 with vertices hundreds of units away
 * (the Cornell box's), the same moved far from the origin, and shapes at
 * scales from 1e-2 to 1e5. */
static void test_offset(void)
{
    uint32_t st = 7;
    int acne = 0, total = 0;
    /* Quads: the Cornell box's green wall (x = 0), its floor (y = 0), both
     * moved by (1000, 1000, 0), and tilted quads at several scales. */
    vec3 quads[][4] = {
        {v3(0, 0, 559.2f), v3(0, 0, 0), v3(0, 548.8f, 0), v3(0, 548.8f, 559.2f)},
        {v3(0, 0, 0), v3(0, 548.8f, 0), v3(0, 548.8f, 559.2f), v3(0, 0, 559.2f)},
        {v3(552.8f, 0, 0), v3(0, 0, 0), v3(0, 0, 559.2f), v3(552.8f, 0, 559.2f)},
        {v3(1000, 1000, 559.2f), v3(1000, 1000, 0), v3(1000, 1548.8f, 0), v3(1000, 1548.8f, 559.2f)},
        {v3(1552.8f, 1000, 0), v3(1000, 1000, 0), v3(1000, 1000, 559.2f), v3(1552.8f, 1000, 559.2f)},
    };
    int nq = sizeof quads / sizeof quads[0];
    for (int qi = 0; qi < nq + 4; qi++) {
        vec3 q[4];
        if (qi < nq) {
            for (int k = 0; k < 4; k++)
                q[k] = quads[qi][k];
        } else {
            /* A planar tilted parallelogram, size and position by scale. */
            float sc = qi == nq ? 1e-2f : qi == nq + 1 ? 1.0f : qi == nq + 2 ? 500.0f : 1e5f;
            vec3 o = v3_scale(v3(rnd(&st) * 8 - 4, rnd(&st) * 8 - 4, rnd(&st) * 8 - 4), sc);
            vec3 e1 = v3_scale(v3(1, 0.3f, -0.2f), sc), e2 = v3_scale(v3(-0.1f, 0.8f, 0.45f), sc);
            q[0] = o; q[1] = v3_add(o, e1); q[2] = v3_add(q[1], e2); q[3] = v3_add(o, e2);
        }
        vec3 n = v3_norm(v3_cross(v3_sub(q[1], q[0]), v3_sub(q[2], q[0])));
        float size = v3_len(v3_sub(q[2], q[0]));
        for (int k = 0; k < 4000; k++) {
            float f = rnd(&st), g = rnd(&st);
            /* Targets spread over the quad, a third of them on its diagonal. */
            if (k % 3 == 0) g = f;
            vec3 tgt = v3_add(q[0], v3_add(v3_scale(v3_sub(q[1], q[0]), f), v3_scale(v3_sub(q[3], q[0]), g)));
            vec3 side = k & 1 ? n : v3_neg(n);
            vec3 o = v3_add(tgt, v3_scale(v3_add(side, v3_scale(leave(&st, side), 0.9f)), size));
            fr_ray r = {o, v3_sub(tgt, o), 0.0f};
            vec3 p, err, ng;
            if (!(quad_hit(q, &r, &p, &err, &ng) > 0.0f))
                continue;
            for (int back = 0; back < 2; back++) {
                vec3 out = leave(&st, back ? v3_neg(side) : side);
                fr_ray r2 = {geo_offset(p, err, ng, out), out, 0.0f};
                vec3 p2, e2, n2;
                total++;
                acne += quad_hit(q, &r2, &p2, &e2, &n2) > 0.0f;
            }
        }
    }
    CHECK(acne == 0, "%d of %d offset rays hit their own quad again", acne, total);

    acne = total = 0;
    float scales[] = {1e-2f, 1.0f, 500.0f, 1e5f};
    for (int si = 0; si < 4; si++) {
        float sc = scales[si];
        fr_sphere s = {v3(sc * 3, sc * -2, sc * 5), sc};
        fr_sphere s0 = {v3(sc, 0, 0), sc};     /* touching the origin */
        fr_rect rc = geo_rect_make(v3(0, sc * 2, sc), v3(sc, sc * 0.1f, 0), v3(sc * 0.2f, sc * 0.3f, sc * 2));
        fr_plane pl = {v3(sc * 7, 0, sc * 3), v3_norm(v3(0.3f, 1, -0.2f)), 0, 0};
        for (int k = 0; k < 20000; k++) {
            /* Spheres: hit from outside, leave outward or inward. */
            const fr_sphere *sp = k & 1 ? &s : &s0;
            vec3 o = v3_add(sp->center, v3_scale(v3(rnd(&st) - 0.5f, rnd(&st) - 0.5f, rnd(&st) - 0.5f), sc * 8));
            fr_ray r = {o, v3_norm(v3_sub(v3_add(sp->center, v3_scale(v3(rnd(&st), rnd(&st), rnd(&st)), sc * 0.5f)), o)), 0.0f};
            float t = geo_sphere(sp, &r, INFINITY);
            if (t > 0.0f) {
                vec3 err, n = v3_norm(v3_sub(v3_madd(r.o, r.d, t), sp->center));
                vec3 p = geo_sphere_point(sp, n, &err);
                for (int side = 0; side < 2; side++) {
                    vec3 out = leave(&st, side ? v3_neg(n) : n);
                    fr_ray r2 = {geo_offset(p, err, n, out), out, 0.0f};
                    float t2 = geo_sphere(sp, &r2, INFINITY);
                    /* Outward: nothing; inward: only the far side. */
                    acne += side ? t2 > 0.0f && t2 < sc * 1e-3f : t2 > 0.0f;
                    total++;
                }
            }
            /* Rectangle and plane: hit from a random side, leave to either. */
            float s1, s2;
            vec3 side = rnd(&st) < 0.5f ? v3_norm(rc.normal) : v3_neg(v3_norm(rc.normal));
            vec3 tgt = v3_add(rc.origin, v3_add(v3_scale(rc.edge_u, rnd(&st)), v3_scale(rc.edge_v, rnd(&st))));
            o = v3_add(tgt, v3_scale(v3_add(side, leave(&st, side)), sc * 3));
            r = (fr_ray){o, v3_sub(tgt, o), 0.0f};
            if (geo_rect(&rc, &r, INFINITY, &s1, &s2) > 0.0f) {
                vec3 err, p = geo_rect_point(&rc, s1, s2, &err), ng = v3_norm(rc.normal);
                for (int back = 0; back < 2; back++) {
                    vec3 out = leave(&st, back ? v3_neg(side) : side);
                    fr_ray r2 = {geo_offset(p, err, ng, out), out, 0.0f};
                    acne += geo_rect(&rc, &r2, INFINITY, &s1, &s2) > 0.0f;
                    total++;
                }
            }
            side = rnd(&st) < 0.5f ? pl.normal : v3_neg(pl.normal);
            o = v3_add(pl.point, v3_scale(v3(rnd(&st) - 0.5f, rnd(&st) - 0.5f, rnd(&st) - 0.5f), sc * 20));
            r = (fr_ray){o, leave(&st, v3_dot(v3_sub(pl.point, o), pl.normal) > 0.0f ? pl.normal : v3_neg(pl.normal)), 0.0f};
            t = geo_plane(&pl, &r, INFINITY);
            if (t > 0.0f) {
                vec3 err, p = geo_plane_point(&pl, &r, t, &err);
                for (int back = 0; back < 2; back++) {
                    vec3 out = leave(&st, back ? v3_neg(side) : side);
                    fr_ray r2 = {geo_offset(p, err, pl.normal, out), out, 0.0f};
                    acne += geo_plane(&pl, &r2, INFINITY) > 0.0f;
                    total++;
                }
            }
        }
    }
    CHECK(acne == 0, "%d of %d offset rays hit their own sphere, rectangle or plane again", acne, total);
    CHECK(total > 200000, "only %d offset rays tested", total);
}

/* The offset is small: a ray leaving a surface still finds a surface just
 * in front of it.  A point of the wall at x = 0 is exact in x (a weighted
 * sum of zeros), so it needs no push across the wall at all: the tests'
 * own error bounds keep the ray from the wall. */
static void test_offset_small(void)
{
    vec3 q[4] = {v3(0, 0, 559.2f), v3(0, 0, 0), v3(0, 548.8f, 0), v3(0, 548.8f, 559.2f)};
    fr_ray r = {v3(300, 200, 100), v3(-1, 0.1f, 0.2f), 0.0f};
    vec3 p, err, ng;
    float t = quad_hit(q, &r, &p, &err, &ng);
    CHECK(t > 0.0f, "the wall is hit");
    vec3 o = geo_offset(p, err, ng, v3(1, 0, 0));
    CHECK(p.x == 0.0f && o.x == 0.0f && o.y == p.y && o.z == p.z, "offset from the wall at x=0: (%g %g %g)", o.x,
          o.y - p.y, o.z - p.z);
    /* A parallel wall 0.01 in front is hit from the offset point. */
    vec3 q2[4] = {v3(0.01f, 0, 559.2f), v3(0.01f, 0, 0), v3(0.01f, 548.8f, 0), v3(0.01f, 548.8f, 559.2f)};
    fr_ray r2 = {o, v3_norm(v3(1, 0.2f, 0.1f)), 0.0f};
    vec3 p2, e2, n2;
    CHECK(quad_hit(q2, &r2, &p2, &e2, &n2) > 0.0f, "a wall 0.01 away is found");
    /* A degenerate normal gives no NaN origin. */
    vec3 bad = geo_offset(p, err, v3(NAN, NAN, NAN), v3(1, 0, 0));
    CHECK(bad.x == p.x && bad.y == p.y && bad.z == p.z, "NaN normal: origin unchanged");
}


/* geo_offset's push, written on the bit pattern without branches, against
 * its definition: the sum, then next_up or next_down of it by the step's
 * sign (both written the plain way here), bit for bit, on random points of
 * every magnitude and on zeros, subnormals, the largest floats and
 * infinities, for steps of either sign and none. */
static float ref_next_up(float x)
{
    if (x == INFINITY)
        return x;
    if (x == 0.0f)
        return 0x1p-149f;
    uint32_t i;
    memcpy(&i, &x, 4);
    i = x > 0.0f ? i + 1 : i - 1;
    memcpy(&x, &i, 4);
    return x;
}

static float ref_push(float p, float step)
{
    float o = p + step;
    return step > 0.0f ? ref_next_up(o) : step < 0.0f ? -ref_next_up(-o) : o;
}

static vec3 ref_offset(vec3 p, vec3 err, vec3 ng, vec3 dir)
{
    float d = fabsf(ng.x) * err.x + fabsf(ng.y) * err.y + fabsf(ng.z) * err.z;
    if (!(d < INFINITY))
        return p;
    if (v3_dot(ng, dir) < 0.0f)
        d = -d;
    return v3(ref_push(p.x, ng.x * d), ref_push(p.y, ng.y * d), ref_push(p.z, ng.z * d));
}

static int same_bits(float a, float b) { return memcmp(&a, &b, 4) == 0; }

static void test_offset_bits(void)
{
    const float special[] = {0.0f, -0.0f, 0x1p-149f, -0x1p-149f, 0x1p-126f, -0x1p-126f, 1.0f, -1.0f,
                             0x1.fffffep127f, -0x1.fffffep127f, INFINITY, -INFINITY, 548.8f, -559.2f, NAN, -NAN};
    const int ns = (int)(sizeof special / sizeof special[0]);
    uint32_t st = 11;
    int bad = 0, n = 0;
    for (int k = 0; k < 200000; k++) {
        vec3 p, err, ng, dir;
        float c[12];
        for (int j = 0; j < 12; j++) {
            float u = rnd(&st), e = (float)((int)(rnd(&st) * 80.0f) - 40);
            c[j] = (u < 0.5f ? -1.0f : 1.0f) * rnd(&st) * ldexpf(1.0f, (int)e);
        }
        p = v3(c[0], c[1], c[2]);
        if (k % 4 == 1)
            p = v3(special[k % ns], special[(k / 3) % ns], special[(k / 7) % ns]);
        err = v3(fabsf(c[3]) * 1e-3f, fabsf(c[4]) * 1e-3f, fabsf(c[5]) * 1e-3f);
        if (k % 5 == 2)
            err = v3(0.0f, 0x1p-149f, 1e-30f);
        ng = v3_norm(v3(c[6], c[7], c[8]));
        if (k % 6 == 3)
            ng = v3(0.0f, k % 12 == 3 ? 1.0f : -1.0f, 0.0f);
        dir = v3(c[9], c[10], c[11]);
        if (k % 7 == 4) {
            /* A sum that comes out zero: p.y is minus the step. */
            float e = fabsf(c[4]) + 0x1p-140f, sgn = dir.y < 0.0f ? -1.0f : 1.0f;
            ng = v3(0.0f, 1.0f, 0.0f);
            err = v3(0.0f, e, 0.0f);
            p.y = -sgn * e;
        }
        vec3 a = geo_offset(p, err, ng, dir), b = ref_offset(p, err, ng, dir);
        n++;
        if (!same_bits(a.x, b.x) || !same_bits(a.y, b.y) || !same_bits(a.z, b.z)) {
            if (bad++ < 5)
                CHECK(0, "offset of (%a %a %a) by err (%a %a %a) along (%a %a %a): (%a %a %a), expected (%a %a %a)",
                      p.x, p.y, p.z, err.x, err.y, err.z, ng.x, ng.y, ng.z, a.x, a.y, a.z, b.x, b.y, b.z);
        }
    }
    CHECK(bad == 0, "geo_offset differs from its definition on %d of %d points", bad, n);
}

int main(void)
{
    test_sphere();
    test_plane_rect();
    test_triangle();
    test_watertight();
    test_offset();
    test_offset_small();
    test_offset_bits();
    return check_done();
}
