/* Ray/primitive intersection: hits from outside and inside, misses, grazing
 * and parallel rays, watertight shared edges, and self-intersection
 * avoidance at several scene scales. */
#include <math.h>
#include <stdint.h>

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
    fr_ray r = {v3(0, 0, 0), v3(0, 0, 1)};
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
    fr_ray r = {v3(0, 5, 0), v3(0, -1, 0)};
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
    fr_ray r = {v3(0.25f, 0.25f, 0), v3(0, 0, 1)};
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
        fr_ray r = {o, v3_sub(target, o)};
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

/* A ray leaving a surface from geo_offset must not hit that surface again,
 * at small and large coordinates. */
static void test_offset(void)
{
    uint32_t st = 7;
    int acne = 0, total = 0;
    float scales[] = {1e-2f, 1.0f, 500.0f, 1e5f};
    for (int si = 0; si < 4; si++) {
        float sc = scales[si];
        fr_sphere s = {v3(sc * 3, sc * -2, sc * 5), sc};
        vec3 a = v3(sc * 10, 0, sc), b = v3(sc * 11, sc * 0.3f, sc * 1.2f), c = v3(sc * 10.2f, sc * 1.1f, sc * 0.8f);
        for (int k = 0; k < 20000; k++, total += 2) {
            /* Sphere: hit from a random outside point, leave outward. */
            vec3 o = v3_add(s.center, v3_scale(v3(rnd(&st) - 0.5f, rnd(&st) - 0.5f, rnd(&st) - 0.5f), sc * 8));
            fr_ray r = {o, v3_norm(v3_sub(s.center, o))};
            float t = geo_sphere(&s, &r, INFINITY);
            if (t > 0.0f) {
                vec3 p = v3_madd(r.o, r.d, t), n = v3_norm(v3_sub(p, s.center));
                vec3 out = v3_norm(v3_add(n, v3(rnd(&st) * 0.5f, rnd(&st) * 0.5f, rnd(&st) * 0.5f)));
                if (v3_dot(out, n) > 0.05f) {
                    fr_ray r2 = {geo_offset(p, n, out), out};
                    acne += geo_sphere(&s, &r2, INFINITY) > 0.0f;
                }
            }
            /* Triangle: hit, then leave to the side the ray came from. */
            vec3 tgt = v3_add(a, v3_add(v3_scale(v3_sub(b, a), rnd(&st) * 0.5f), v3_scale(v3_sub(c, a), rnd(&st) * 0.5f)));
            vec3 o2 = v3_add(tgt, v3_scale(v3(rnd(&st) - 0.5f, rnd(&st) - 0.5f, 1.0f), sc * 4));
            fr_ray rt = {o2, v3_sub(tgt, o2)};
            float b1, b2;
            float tt = geo_triangle(a, b, c, &rt, INFINITY, &b1, &b2);
            if (tt > 0.0f) {
                vec3 p = v3_madd(rt.o, rt.d, tt), ng = v3_norm(v3_cross(v3_sub(b, a), v3_sub(c, a)));
                vec3 back = v3_norm(v3_neg(rt.d));
                fr_ray r2 = {geo_offset(p, ng, back), back};
                acne += geo_triangle(a, b, c, &r2, INFINITY, &b1, &b2) > 0.0f;
            }
        }
    }
    CHECK(acne == 0, "%d of %d offset rays hit their own surface again", acne, total);
}

int main(void)
{
    test_sphere();
    test_plane_rect();
    test_triangle();
    test_watertight();
    test_offset();
    return check_done();
}
