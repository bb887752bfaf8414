/* test_motion.c -- moving instances: their transform across the shutter,
 * their bounds, and rays at random times.
 *
 * Transforms made of random rotations, scales (a mirror among them) and
 * translations are split at compile time (bld_instance_motion) and
 * blended back (motion_at): the ends come back to 1e-5, a turn about z
 * blends at constant angular speed, and the inverse is the inverse at
 * every time.  The bound over the shutter (bld_motion_bounds) holds the
 * mesh's vertices at 2000 random times.  In a frozen scene of a still,
 * a sliding, a half-turning and a turning-and-growing instance, rays at
 * random times find exactly what testing every triangle of every
 * instance placed at that time finds, in every walk: so the top-level
 * BVH bounds each instance at every time.  The loader refuses damaged
 * motions; a flat blend is refused when compiled.  The per-thread cache
 * of blended poses gives motion_at's bits. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define XXH_INLINE_ALL
#include <xxhash.h>

#include "check.h"
#include "compile/builder_instance.h"
#include "compile/builder_motion.h"
#include "compile/freeze.h"
#include "fbin.h"
#include "geom.h"
#include "motion.h"
#include "trace.h"

static uint32_t rng = 12345u;
static float rnd(void)
{
    rng = rng * 1664525u + 1013904223u;
    return (float)(rng >> 8) / 16777216.0f;
}

/* xf = T R(axis, deg) diag(s), in double then rounded. */
static void make_xf(float xf[3][4], vec3 axis, double deg, vec3 s, vec3 t)
{
    double a = deg * M_PI / 180.0, c = cos(a), sn = sin(a), n = sqrt(v3_dot(axis, axis));
    double x = axis.x / n, y = axis.y / n, z = axis.z / n, k = 1.0 - c;
    double r[3][3] = {{c + x * x * k, x * y * k - z * sn, x * z * k + y * sn},
                      {y * x * k + z * sn, c + y * y * k, y * z * k - x * sn},
                      {z * x * k - y * sn, z * y * k + x * sn, c + z * z * k}};
    double sc[3] = {s.x, s.y, s.z}, tt[3] = {t.x, t.y, t.z};
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            xf[i][j] = (float)(r[i][j] * sc[j]);
        xf[i][3] = (float)tt[i];
    }
}

static vec3 rnd_axis(void) { return v3(rnd() - 0.5f, rnd() - 0.5f, rnd() - 0.5f + 1e-3f); }

static void rnd_xf(float xf[3][4], int mirror)
{
    vec3 s = v3(0.3f + 2.0f * rnd(), 0.3f + 2.0f * rnd(), 0.3f + 2.0f * rnd());
    if (mirror)
        s.y = -s.y;
    make_xf(xf, rnd_axis(), 340.0 * rnd() - 170.0, s, v3(8 * rnd() - 4, 8 * rnd() - 4, 8 * rnd() - 4));
}

/* A mesh of n random triangles in [-1, 1]^3. */
static uint32_t mesh(fr_builder *b, int n)
{
    uint32_t m = bld_mesh_begin(b);
    for (int i = 0; i < n; i++) {
        uint32_t base = b->positions.count;
        vec3 c = v3(2 * rnd() - 1, 2 * rnd() - 1, 2 * rnd() - 1);
        for (int k = 0; k < 3; k++) {
            vec3 p = v3_add(c, v3(0.6f * rnd() - 0.3f, 0.6f * rnd() - 0.3f, 0.6f * rnd() - 0.3f));
            p = v3_vmin(v3s(1.0f), v3_vmax(v3s(-1.0f), p));
            bld_push(&b->positions, &p);
        }
        fr_triangle t = {{base, base + 1, base + 2}, 0};
        fr_prim p = {FR_PRIM_TRIANGLE, bld_push(&b->triangles, &t), 0, FR_NONE};
        bld_push(&b->prims, &p);
    }
    /* And three triangles through the cube's eight corners, which its
     * box's corners are: the farthest points from its centre. */
    for (int i = 0; i < 3; i++) {
        uint32_t base = b->positions.count;
        for (int k = 0; k < 3; k++) {
            int c = (3 * i + k) % 8;
            vec3 p = v3(c & 1 ? 1.0f : -1.0f, c & 2 ? 1.0f : -1.0f, c & 4 ? 1.0f : -1.0f);
            bld_push(&b->positions, &p);
        }
        fr_triangle t = {{base, base + 1, base + 2}, 0};
        fr_prim p = {FR_PRIM_TRIANGLE, bld_push(&b->triangles, &t), 0, FR_NONE};
        bld_push(&b->prims, &p);
    }
    fr_error e;
    CHECK(bld_mesh_end(b, m, &e) == 0, "mesh: %s", e.msg);
    return m;
}

/* A builder with one grey material, small image settings and a camera,
 * and a mesh of n random triangles (and the cube's corners): its index. */
static uint32_t builder(fr_builder *b, int n)
{
    bld_init(b);
    fr_material mat;
    bld_material_init(&mat);
    mat.diffuse = v3s(0.5f);
    bld_push(&b->materials, &mat);
    b->settings = (fr_settings){16, 16, 1, 1, 0, 0, 0.0f, 0};
    b->camera.position = v3(0, 0, 10);
    b->camera.target = v3s(0.0f);
    b->camera.up = v3(0, 1, 0);
    b->camera.vfov = 0.8f;
    b->camera.focus = 10.0f;
    return mesh(b, n);
}

static float err_xf(const float (*a)[4], const float (*b)[4])
{
    float e = 0.0f;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            e = fmaxf(e, fabsf(a[i][j] - b[i][j]) / (1.0f + fabsf(b[i][j])));
    return e;
}

/* The ends, the inverse, and a constant angular speed. */
/* motion_at_cached gives motion_at's bits: motions sharing cache slots,
 * few times (so entries are met again), and a motion changed in place
 * at the same time (a new scene at the old address) is blended anew. */
static void test_cached(const fr_inst_motion *mo, uint32_t n)
{
    const float times[3] = {0.25f, 0.7f, 0.7000001f};
    for (int i = 0; i < 4000 && n; i++) {
        uint32_t k = (uint32_t)(rnd() * (float)n) % n;
        float u = times[i % 3 == 0 ? 0 : (int)(rnd() * 3.0f) % 3];
        float xf[3][4], inv[3][4];
        motion_at(&mo[k], u, xf, inv);
        const motion_pose *p = motion_at_cached(&mo[k], k, u);
        CHECK(memcmp(p->xf, xf, sizeof xf) == 0 && memcmp(p->inv, inv, sizeof inv) == 0,
              "cached pose %d of motion %u at %g is not motion_at's", i, k, u);
    }
    if (n < 2)
        return;
    fr_inst_motion m = mo[0];
    const motion_pose *p = motion_at_cached(&m, 0, 0.5f);
    float xf0 = p->xf[0][0];
    m = mo[1];
    float xf[3][4];
    motion_at(&m, 0.5f, xf, NULL);
    p = motion_at_cached(&m, 0, 0.5f);
    CHECK(memcmp(p->xf, xf, sizeof xf) == 0 && (xf0 != xf[0][0] || memcmp(&mo[0], &mo[1], sizeof m) == 0),
          "a motion changed in place kept its old cached pose");
}

static void test_blend(void)
{
    fr_builder b;
    uint32_t m = builder(&b, 4);
    fr_error e;
    for (int n = 0; n < 300; n++) {
        float open[3][4], close[3][4];
        int mirror = n % 5 == 0;
        rnd_xf(open, mirror);
        rnd_xf(close, mirror);
        uint32_t k = b.instances.count;
        CHECK(bld_instance(&b, m, (const float(*)[4])open, &e) == 0, "instance: %s", e.msg);
        CHECK(bld_instance_motion(&b, k, (const float(*)[4])close, &e) == 0, "motion %d: %s", n, e.msg);
        const fr_instance *in = (const fr_instance *)b.instances.data + k;
        if (!in->motion)
            continue;
        const fr_inst_motion *mo = (const fr_inst_motion *)b.inst_motions.data + in->motion - 1;
        float xf[3][4], inv[3][4];
        motion_at(mo, 0.0f, xf, NULL);
        CHECK(err_xf((const float(*)[4])xf, (const float(*)[4])open) < 1e-5f, "motion %d: open off by %g", n,
              err_xf((const float(*)[4])xf, (const float(*)[4])open));
        motion_at(mo, 1.0f, xf, NULL);
        CHECK(err_xf((const float(*)[4])xf, (const float(*)[4])close) < 1e-5f, "motion %d: close off by %g", n,
              err_xf((const float(*)[4])xf, (const float(*)[4])close));
        float u = rnd();
        motion_at(mo, u, xf, inv);
        float worst = 0.0f;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 4; j++) {
                float v = xf[i][0] * inv[0][j] + xf[i][1] * inv[1][j] + xf[i][2] * inv[2][j] + (j == 3 ? xf[i][3] : 0);
                worst = fmaxf(worst, fabsf(v - (i == j ? 1.0f : 0.0f)) / (1.0f + fabsf(xf[i][3])));
            }
        CHECK(worst < 1e-5f, "motion %d: xf * inv off identity by %g at u %g", n, worst, u);
    }
    /* A turn of 120 degrees about z and a doubling of scale: 30 degrees and
     * 1.25 at a quarter of the shutter. */
    float open[3][4], close[3][4], xf[3][4];
    make_xf(open, v3(0, 0, 1), 0.0, v3s(1.0f), v3s(0.0f));
    make_xf(close, v3(0, 0, 1), 120.0, v3s(2.0f), v3(4, 0, 0));
    uint32_t k = b.instances.count;
    bld_instance(&b, m, (const float(*)[4])open, &e);
    CHECK(bld_instance_motion(&b, k, (const float(*)[4])close, &e) == 0, "turn: %s", e.msg);
    const fr_instance *in = (const fr_instance *)b.instances.data + k;
    for (int q = 1; q < 4; q++) {
        motion_at((const fr_inst_motion *)b.inst_motions.data + in->motion - 1, q / 4.0f, xf, NULL);
        double a = 30.0 * q * M_PI / 180.0, sc = 1.0 + q / 4.0;
        CHECK(fabs(xf[0][0] - sc * cos(a)) < 1e-5 && fabs(xf[1][0] - sc * sin(a)) < 1e-5 &&
                  fabs(xf[0][3] - q) < 1e-5, "turn at %d/4: %g %g %g", q, xf[0][0], xf[1][0], xf[0][3]);
    }
    /* The same transform at both ends adds no motion. */
    k = b.instances.count;
    bld_instance(&b, m, (const float(*)[4])open, &e);
    CHECK(bld_instance_motion(&b, k, (const float(*)[4])open, &e) == 0 &&
          ((const fr_instance *)b.instances.data)[k].motion == 0, "a still instance was given a motion");
    /* A scale through 0 is refused. */
    make_xf(close, v3(0, 0, 1), 0.0, v3(1, -1, 1), v3s(0.0f));
    CHECK(bld_instance_motion(&b, k, (const float(*)[4])close, &e) < 0 && strstr(e.msg, "flat"),
          "a blend through a flat transform was accepted");
    test_cached((const fr_inst_motion *)b.inst_motions.data, b.inst_motions.count);
    bld_free(&b);
}

/* The bound over the shutter holds every vertex at any time. */
static void test_bounds(void)
{
    fr_builder b;
    uint32_t m = builder(&b, 40);
    fr_error e;
    const bld_mesh *bm = (const bld_mesh *)b.meshes.data + m;
    int outside = 0, checked = 0;
    for (int n = 0; n < 60; n++) {
        float open[3][4], close[3][4];
        rnd_xf(open, 0);
        rnd_xf(close, 0);
        uint32_t k = b.instances.count;
        bld_instance(&b, m, (const float(*)[4])open, &e);
        if (bld_instance_motion(&b, k, (const float(*)[4])close, &e) < 0)
            continue;
        vec3 lo, hi;
        bld_instance_bounds(&b, k, &lo, &hi);
        const fr_instance *in = (const fr_instance *)b.instances.data + k;
        for (int t = 0; t < 2000; t++) {
            float xf[3][4];
            motion_at((const fr_inst_motion *)b.inst_motions.data + in->motion - 1, rnd(), xf, NULL);
            for (uint32_t v = 0; v < b.positions.count; v++) {
                vec3 p = ((const vec3 *)b.positions.data)[v];
                vec3 w = v3(xf[0][0] * p.x + xf[0][1] * p.y + xf[0][2] * p.z + xf[0][3],
                            xf[1][0] * p.x + xf[1][1] * p.y + xf[1][2] * p.z + xf[1][3],
                            xf[2][0] * p.x + xf[2][1] * p.y + xf[2][2] * p.z + xf[2][3]);
                checked++;
                outside += w.x < lo.x || w.y < lo.y || w.z < lo.z || w.x > hi.x || w.y > hi.y || w.z > hi.z;
            }
        }
    }
    CHECK(outside == 0 && checked > 1000000, "%d of %d placed vertices outside the bound over the shutter",
          outside, checked);
    (void)bm;
    bld_free(&b);
}

/* The nearest hit of ray r at its time by testing every triangle of every
 * instance, each ray taken into object space as trace.c does. */
static float brute(const fr_scene *s, const fr_ray *r)
{
    float best = INFINITY;
    for (uint32_t i = 0; i < s->n_instances; i++) {
        const fr_instance *in = &s->instances[i];
        float inv[3][4];
        if (in->motion)
            motion_at(&s->inst_motions[in->motion - 1], r->time, NULL, inv);
        else
            memcpy(inv, in->inv, sizeof inv);
        vec3 p = r->o, d = r->d;
        fr_ray o = {v3(inv[0][0] * p.x + inv[0][1] * p.y + inv[0][2] * p.z + inv[0][3],
                       inv[1][0] * p.x + inv[1][1] * p.y + inv[1][2] * p.z + inv[1][3],
                       inv[2][0] * p.x + inv[2][1] * p.y + inv[2][2] * p.z + inv[2][3]),
                    v3(inv[0][0] * d.x + inv[0][1] * d.y + inv[0][2] * d.z, inv[1][0] * d.x + inv[1][1] * d.y + inv[1][2] * d.z,
                       inv[2][0] * d.x + inv[2][1] * d.y + inv[2][2] * d.z),
                    r->time};
        const fr_mesh *m = &s->meshes[in->mesh];
        for (uint32_t k = m->prim_first; k < m->prim_first + m->n_prims; k++) {
            const fr_triangle *t = &s->triangles[s->prims[k].index];
            float a, bb, h = geo_triangle(s->positions[t->v[0]], s->positions[t->v[1]], s->positions[t->v[2]], &o,
                                          best, &a, &bb);
            if (h > 0.0f && h < best)
                best = h;
        }
    }
    return best;
}

static fr_scene scene_moving(void)
{
    fr_builder b;
    uint32_t m = builder(&b, 60);
    fr_error e;
    float xf[4][2][3][4];
    make_xf(xf[0][0], v3(0, 1, 0), 10.0, v3s(1.0f), v3(-5, 0, 0));          /* still */
    make_xf(xf[0][1], v3(0, 1, 0), 10.0, v3s(1.0f), v3(-5, 0, 0));
    make_xf(xf[1][0], v3(0, 0, 1), 0.0, v3s(0.7f), v3(-6, 3, 0));           /* slides */
    make_xf(xf[1][1], v3(0, 0, 1), 0.0, v3s(0.7f), v3(6, 3, 0));
    make_xf(xf[2][0], v3(1, 1, 0), 0.0, v3(3, 0.4f, 0.4f), v3(0, -3, 0));   /* a long bar, half a turn less a bit */
    make_xf(xf[2][1], v3(1, 1, 0), 175.0, v3(3, 0.4f, 0.4f), v3(0, -3, 0));
    make_xf(xf[3][0], v3(0, 0, 1), -40.0, v3s(0.5f), v3(4, 0, 1));          /* turns and grows */
    make_xf(xf[3][1], v3(0.2f, 0, 1), 60.0, v3(1.5f, 1.0f, 2.0f), v3(4, 0, -1));
    for (int i = 0; i < 4; i++) {
        uint32_t k = b.instances.count;
        CHECK(bld_instance(&b, m, (const float(*)[4])xf[i][0], &e) == 0, "instance %d: %s", i, e.msg);
        CHECK(bld_instance_motion(&b, k, (const float(*)[4])xf[i][1], &e) == 0, "motion %d: %s", i, e.msg);
    }
    fr_scene s;
    memset(&s, 0, sizeof s);
    CHECK(frz_scene(&b, &s, &e) == 0, "freeze: %s", e.msg);
    bld_free(&b);
    return s;
}

static void test_rays(const fr_scene *s)
{
    CHECK(s->n_instances == 4 && s->n_inst_motions == 3 && (s->motion.flags & FR_MOTION_INSTANCES),
          "%u instances, %u motions, flags %u", s->n_instances, s->n_inst_motions, s->motion.flags);
    int missed = 0, extra = 0, differ = 0, hits = 0;
    unsigned walks = trace_walks();
    for (int n = 0; n < 20000; n++) {
        vec3 o = v3(20 * rnd() - 10, 20 * rnd() - 10, 10 + 5 * rnd());
        vec3 at = v3(14 * rnd() - 7, 10 * rnd() - 5, 2 * rnd() - 1);
        fr_ray r = {o, v3_norm(v3_sub(at, o)), rnd()};
        float want = brute(s, &r);
        for (int w = 0; w < TRACE_WALKS; w++) {
            if (!(walks >> w & 1))
                continue;
            trace_set_walk(w);
            fr_hit h;
            int found = trace_closest(s, &r, INFINITY, &h);
            missed += !found && want < INFINITY;
            extra += found && want == INFINITY;
            differ += found && want < INFINITY && h.t != want;
            hits += found;
            int occ = trace_occluded(s, &r, INFINITY, FR_NONE);
            missed += !occ && want < INFINITY;
            extra += occ && want == INFINITY;
        }
    }
    CHECK(missed == 0 && extra == 0 && differ == 0 && hits > 2000,
          "rays at random times: %d missed, %d extra, %d at another distance, %d hits", missed, extra, differ, hits);
}

/* The loader refuses damaged motions. */
static void test_refused(const fr_scene *good)
{
    enum { SEC_INSTANCES = 23, SEC_INST_MOTIONS = 33 };
    const char *what[] = {"quaternion", "angle", "index", "not finite"};
    for (int c = 0; c < 4; c++) {
        unsigned char *p = aligned_alloc(64, (good->blob_size + 63) / 64 * 64);
        memcpy(p, good->blob, good->blob_size);
        uint64_t off;
        memcpy(&off, p + 64 + 32 * (SEC_INST_MOTIONS - 1) + 8, 8);
        fr_inst_motion *m = (fr_inst_motion *)(p + off);
        if (c == 0)
            m->q0[0] += 0.5f;
        else if (c == 1)
            m->angle += 0.2f;
        else if (c == 3)
            m->s1[1][1] = NAN;
        else {
            memcpy(&off, p + 64 + 32 * (SEC_INSTANCES - 1) + 8, 8);
            ((fr_instance *)(p + off))[1].motion = 9;
        }
        uint64_t h = XXH3_64bits(p + 64, good->blob_size - 64);
        memcpy(p + 32, &h, 8);
        fr_scene s;
        fr_error e = {{0}};
        int rc = fbin_open_mem(p, good->blob_size, 0, &s, &e);
        CHECK(rc < 0 && strstr(e.msg, "byte") && strstr(e.msg, c == 2 ? "instances" : "inst_motions"),
              "damaged motion (%s) %s: %s", what[c], rc < 0 ? "refused unclearly" : "accepted", e.msg);
        if (rc == 0)
            scn_free(&s);
        else
            free(p);
    }
}

int main(void)
{
    test_blend();
    test_bounds();
    fr_scene s = scene_moving();
    test_rays(&s);
    test_refused(&s);
    scn_free(&s);
    return check_done();
}
