/* test_lighttree.c -- the light tree (scene.h, fr_light_node; light.c): its pick probabilities
 * sum to one at every point and are the frequencies its walk picks with (a
 * chi-square test over the lights), lgt_pick_pdf gives the walk's pick bit
 * for bit; a scene of one light renders the same bits with the tree and
 * with the power table, and so does one flat lamp (which gets no tree); a
 * lamp-lit ground converges to the same mean with
 * and without the tree, and with much less noise with it; a furnace of
 * emissive triangles gives its closed form; the triangles of a mostly
 * black textured screen are picked by the light on them. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bsdf.h"
#include "check.h"
#include "compile/freeze.h"
#include "compile/texstore.h"
#include "estimate.h"
#include "light.h"
#include "pathtrace.h"
#include "scenes.h"
#include "stats.h"

/* A growing JSON text. */
typedef struct { char *p; size_t n, cap; } text;
static void put(text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(text *t, const char *fmt, ...)
{
    va_list ap;
    for (;;) {
        va_start(ap, fmt);
        int k = vsnprintf(t->p ? t->p + t->n : NULL, t->p ? t->cap - t->n : 0, fmt, ap);
        va_end(ap);
        if (t->p && t->n + (size_t)k < t->cap) {
            t->n += (size_t)k;
            return;
        }
        t->cap = (t->cap + (size_t)k + 1) * 2;
        t->p = realloc(t->p, t->cap);
        if (!t->p)
            abort();
    }
}

/* A scene of every kind of light at random places and orientations: a
 * sun, point and spot lights, one- and two-sided rectangles, triangles and
 * spheres. */
static void mixed_scene(int n, fr_scene *s)
{
    uint32_t st = 12345;
    text t = {0};
    put(&t, "{\"image\": {\"width\": 4, \"height\": 4, \"spp\": 1},"
            " \"camera\": {\"position\": [0, 0, -30], \"target\": [0, 0, 0], \"fov\": 40},"
            " \"materials\": {\"one\": {\"type\": \"emitter\", \"emission\": [3, 2, 1]},"
            "   \"two\": {\"type\": \"emitter\", \"emission\": [1, 1, 4], \"two_sided\": true}},"
            " \"lights\": [{\"type\": \"sun\", \"direction\": [0.2, 1, 0.1], \"irradiance\": [0.5, 0.5, 0.5]}");
    for (int i = 0; i < 6; i++)
        put(&t, ", {\"type\": \"point\", \"position\": [%.3f, %.3f, %.3f], \"intensity\": [%.3f, 1, 1]}",
            20 * st_rnd(&st) - 10, 20 * st_rnd(&st) - 10, 20 * st_rnd(&st) - 10, 5 * st_rnd(&st));
    for (int i = 0; i < 6; i++)
        put(&t, ", {\"type\": \"spot\", \"position\": [%.3f, %.3f, %.3f], \"direction\": [%.3f, %.3f, %.3f],"
                " \"intensity\": [3, 3, 3], \"inner_angle\": %.1f, \"outer_angle\": %.1f}",
            20 * st_rnd(&st) - 10, 20 * st_rnd(&st) - 10, 20 * st_rnd(&st) - 10, st_rnd(&st) - 0.5,
            st_rnd(&st) - 0.5, st_rnd(&st) - 0.5, 10 * st_rnd(&st), 20 + 100 * st_rnd(&st));
    put(&t, "], \"shapes\": [");
    for (int i = 0; i < n; i++) {
        double x = 20 * st_rnd(&st) - 10, y = 20 * st_rnd(&st) - 10, z = 20 * st_rnd(&st) - 10;
        const char *m = st_rnd(&st) < 0.3 ? "two" : "one";
        double k = st_rnd(&st);
        if (i)
            put(&t, ",");
        if (k < 0.4)
            put(&t, "{\"type\": \"rect\", \"origin\": [%.3f, %.3f, %.3f], \"edge_u\": [%.3f, %.3f, %.3f],"
                    " \"edge_v\": [%.3f, %.3f, %.3f], \"material\": \"%s\"}",
                x, y, z, st_rnd(&st) - 0.5, st_rnd(&st) - 0.5, st_rnd(&st) - 0.5, st_rnd(&st) - 0.5,
                st_rnd(&st) - 0.5, st_rnd(&st) - 0.5, m);
        else if (k < 0.9)
            put(&t, "{\"type\": \"triangle\", \"vertices\": [[%.3f, %.3f, %.3f], [%.3f, %.3f, %.3f], [%.3f, %.3f, %.3f]],"
                    " \"material\": \"%s\"}",
                x, y, z, x + st_rnd(&st) - 0.5, y + st_rnd(&st) - 0.5, z + st_rnd(&st) - 0.5, x + st_rnd(&st) - 0.5,
                y + st_rnd(&st) - 0.5, z + st_rnd(&st) - 0.5, m);
        else
            put(&t, "{\"type\": \"sphere\", \"center\": [%.3f, %.3f, %.3f], \"radius\": %.3f, \"material\": \"%s\"}", x,
                y, z, 0.05 + 0.3 * st_rnd(&st), m);
    }
    put(&t, "]}");
    test_scene(t.p, s);
    free(t.p);
}

/* At random points (with random normals, and none): the walk's
 * frequencies, with "no light" as one more outcome, match lgt_pick_pdf
 * (chi-square), and every pick lgt_choose reports is lgt_pick_pdf's float
 * exactly.  The picks sum to at most one: a walk may end at a node whose
 * children both reach nothing from the point (spots turned away, the back
 * of one-sided emitters) though the node's looser bounds do; where every
 * light reaches the point they sum to one (lamp_sums). */
static void pick_probabilities(void)
{
    fr_scene s;
    mixed_scene(300, &s);
    CHECK(s.n_light_nodes == 2 * (s.n_lights - lgt_n_distant(&s)) - 1, "%u tree nodes for %u lights",
          s.n_light_nodes, s.n_lights);
    uint32_t st = 777, n = s.n_lights;
    double *pdf = malloc(n * sizeof *pdf), *seen = malloc((n + 1) * sizeof *seen), *want = malloc((n + 1) * sizeof *want);
    int bad_sum = 0, bad_bits = 0, bad_chi = 0;
    const int points = 12, draws = 200000;
    for (int k = 0; k < points; k++) {
        vec3 p = v3(24 * st_rnd(&st) - 12, 24 * st_rnd(&st) - 12, 24 * st_rnd(&st) - 12), nrm = v3s(0.0f);
        if (k % 3)
            nrm = v3_norm(v3(st_rnd(&st) - 0.5, st_rnd(&st) - 0.5, st_rnd(&st) - 0.5));
        double sum = 0;
        for (uint32_t i = 0; i < n; i++) {
            pdf[i] = lgt_pick_pdf(&s, i, p, nrm);
            sum += pdf[i];
            seen[i] = 0;
        }
        seen[n] = 0;
        if (!(sum <= 1.0 + 1e-4 && sum > 0.5) && bad_sum++ < 3)
            CHECK(0, "point %d: the picks sum to %.7f", k, sum);
        for (int d = 0; d < draws; d++) {
            float u = (float)(((double)d + st_rnd(&st)) / draws), pick = 0.0f;
            uint32_t li = lgt_choose(&s, p, nrm, &u, &pick);
            if (li == FR_NONE) {
                seen[n] += 1;
                continue;
            }
            seen[li] += 1;
            float again = lgt_pick_pdf(&s, li, p, nrm);
            if (memcmp(&again, &pick, sizeof pick) != 0 && bad_bits++ < 3)
                CHECK(0, "point %d, light %u: lgt_choose's pick %a, lgt_pick_pdf %a", k, li, (double)pick,
                      (double)again);
            if (!(u >= 0.0f && u < 1.0f) && bad_bits++ < 3)
                CHECK(0, "point %d: the rescaled number %g is not in [0, 1)", k, (double)u);
        }
        for (uint32_t i = 0; i < n; i++)
            want[i] = pdf[i] * draws;
        want[n] = sum < 1.0 ? (1.0 - sum) * draws : 0.0;
        double pv = st_chi2_test(seen, want, (int)n + 1, 3);
        if (pv < 1e-4 && bad_chi++ < 3)
            CHECK(0, "point %d: pick frequencies against lgt_pick_pdf: chi-square p = %g", k, pv);
    }
    CHECK(bad_sum == 0, "%d points whose picks sum above one (or below a half)", bad_sum);
    CHECK(bad_bits == 0, "%d picks differ from lgt_pick_pdf", bad_bits);
    CHECK(bad_chi == 0, "%d points fail the chi-square test", bad_chi);
    free(pdf);
    free(seen);
    free(want);
    scn_free(&s);
}

/* lgt_sample's pdf against lgt_pdf for the points it samples on area
 * lights (the same pick; the geometric factor within rounding). */
static void sample_pdf(void)
{
    fr_scene s;
    mixed_scene(200, &s);
    uint32_t st = 99;
    int bad = 0, tried = 0;
    for (int k = 0; k < 20000; k++) {
        vec3 p = v3(24 * st_rnd(&st) - 12, 24 * st_rnd(&st) - 12, 24 * st_rnd(&st) - 12);
        vec3 nrm = v3_norm(v3(st_rnd(&st) - 0.5, st_rnd(&st) - 0.5, st_rnd(&st) - 0.5));
        fr_light_sample ls;
        if (!lgt_sample(&s, p, nrm, (float)st_rnd(&st), (float)st_rnd(&st), (float)st_rnd(&st), &ls) ||
            ls.prim == FR_NONE)
            continue;
        tried++;
        float pdf = lgt_pdf(&s, ls.light, p, nrm, ls.p, ls.n);
        if (!(fabsf(pdf - ls.pdf) <= 1e-3f * ls.pdf) && bad++ < 3)
            CHECK(0, "light %u: lgt_sample's pdf %g, lgt_pdf %g", ls.light, (double)ls.pdf, (double)pdf);
    }
    CHECK(tried > 5000 && bad == 0, "%d of %d area-light samples with another pdf", bad, tried);
    scn_free(&s);
}

/* A ground lit by an n x n grid of small downward lamps 4 units up and 10
 * apart, the camera near the ground (tests/bench/lamps.awk's scene). */
static void lamps(int n, const char *sampling, fr_scene *s)
{
    text t = {0};
    put(&t, "{\"image\": {\"width\": 16, \"height\": 16, \"spp\": 1, \"max_depth\": 1, \"light_sampling\": \"%s\"},"
            " \"camera\": {\"position\": [1.3, 1.7, -2.1], \"target\": [1.3, 0.2, 9.9], \"fov\": 60},"
            " \"materials\": {\"ground\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]},"
            "   \"lamp\": {\"type\": \"emitter\", \"emission\": [400, 380, 300]}},"
            " \"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"ground\"}",
        sampling);
    double half = (n - 1) / 2.0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            put(&t, ", {\"type\": \"rect\", \"origin\": [%g, 4, %g], \"edge_u\": [0.5, 0, 0], \"edge_v\": [0, 0, 0.5],"
                    " \"material\": \"lamp\"}",
                (i - half) * 10 - 0.25, (j - half) * 10 - 0.25);
    put(&t, "]}");
    test_scene(t.p, s);
    free(t.p);
}

/* Under lamps that all face the ground, every lamp reaches every point of
 * it: the picks sum to one. */
static void lamp_sums(void)
{
    fr_scene s;
    lamps(30, "tree", &s);
    uint32_t st = 5;
    double worst = 0;
    for (int k = 0; k < 50; k++) {
        vec3 p = v3(300 * st_rnd(&st) - 150, 0, 300 * st_rnd(&st) - 150);
        double sum = 0;
        for (uint32_t i = 0; i < s.n_lights; i++)
            sum += lgt_pick_pdf(&s, i, p, v3(0, 1, 0));
        worst = fmax(worst, fabs(sum - 1.0));
    }
    CHECK(worst < 1e-4, "lamps over a ground: the picks at a point of it sum to one within %g", worst);
    scn_free(&s);
}

/* The foreground (the lower half of the image) of the lamp-lit ground:
 * with 64 lamps, where the power table converges too, the same mean with
 * the tree as with it; with 900, at least 10 times less noise (100 times
 * less variance) with the tree at equal samples (measured: 37 times). */
static void lamp_ground(void)
{
    fr_scene tree, power;
    lamps(8, "tree", &tree);
    lamps(8, "power", &power);
    estimate et = est_region(&tree, PT_MIS, 4096, 0, 16, 8, 16);
    estimate ep = est_region(&power, PT_MIS, 4096, 0, 16, 8, 16);
    printf("64 lamps, foreground mean: tree %.5f +- %.5f, power table %.5f +- %.5f\n", et.mean, et.se, ep.mean, ep.se);
    double d = fabs(et.mean - ep.mean), sd = sqrt(et.se * et.se + ep.se * ep.se);
    CHECK(d < 4 * sd && sd < 0.01 * et.mean, "64 lamps: tree and power table differ by %.5f (%.1f sigma of %.5f)", d,
          d / sd, sd);
    scn_free(&tree);
    scn_free(&power);
    lamps(30, "tree", &tree);
    lamps(30, "power", &power);
    et = est_region(&tree, PT_MIS, 256, 0, 16, 8, 16);
    ep = est_region(&power, PT_MIS, 256, 0, 16, 8, 16);
    printf("900 lamps, foreground mean: tree %.5f +- %.5f, power table %.5f +- %.5f\n", et.mean, et.se, ep.mean,
           ep.se);
    d = fabs(et.mean - ep.mean), sd = sqrt(et.se * et.se + ep.se * ep.se);
    CHECK(d < 4 * sd, "900 lamps: tree and power table differ by %.5f (%.1f sigma)", d, d / sd);
    CHECK(et.se * 10 < ep.se, "900 lamps: standard error with the tree %.5f, with the power table %.5f: not 10 "
          "times less", et.se, ep.se);
    scn_free(&tree);
    scn_free(&power);
}

/* A scene of one light: the tree is one leaf picked with probability 1, so
 * the image has the power table's bits. */
static void one_light(void)
{
    fr_scene a, b;
    lamps(1, "tree", &a);
    lamps(1, "power", &b);
    int same = 1;
    for (uint32_t y = 0; y < 16; y++)
        for (uint32_t x = 0; x < 16; x++)
            for (uint32_t i = 0; i < 4; i++) {
                vec3 ca = pt_sample(&a, PT_MIS, x, y, i), cb = pt_sample(&b, PT_MIS, x, y, i);
                same &= memcmp(&ca, &cb, sizeof ca) == 0;
            }
    CHECK(a.n_light_nodes == 1 && b.n_light_nodes == 0, "one light: %u and %u tree nodes", a.n_light_nodes,
          b.n_light_nodes);
    CHECK(same, "one light: the tree's image differs from the power table's");
    scn_free(&a);
    scn_free(&b);
}

/* A ground lit by the quads (each four corners, JSON) of quads_json. */
static void quad_lamps(const char *quads_json, const char *sampling, fr_scene *s)
{
    text t = {0};
    put(&t, "{\"image\": {\"width\": 16, \"height\": 16, \"spp\": 1, \"max_depth\": 2, \"light_sampling\": \"%s\"},"
            " \"camera\": {\"position\": [0, 1.5, -3], \"target\": [0, 0, 0], \"fov\": 60},"
            " \"materials\": {\"ground\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]},"
            "   \"lamp\": {\"type\": \"emitter\", \"emission\": [40, 38, 30]}},"
            " \"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"ground\"}",
        sampling);
    for (const char *q = quads_json; *q;) {
        const char *e = strchr(q, ';');
        int len = e ? (int)(e - q) : (int)strlen(q);
        put(&t, ", {\"type\": \"quad\", \"material\": \"lamp\", \"vertices\": %.*s}", len, q);
        q += len + (e != NULL);
    }
    put(&t, "]}");
    test_scene(t.p, s);
    free(t.p);
}

/* One flat lamp -- a quad (two triangles), level or tilted, or two quads
 * side by side in one plane -- gets no tree: the tree could only pick its
 * triangles as the power table does, so the image has the power table's
 * bits.  Quads at two heights, or facing two ways, keep it. */
static void flat_lamp(void)
{
    static const struct { const char *quads; int tree; } cases[] = {
        {"[[-0.5, 2, -0.5], [0.5, 2, -0.5], [0.5, 2, 0.5], [-0.5, 2, 0.5]]", 0},
        {"[[-0.5, 2, -0.5], [0.5, 2.3, -0.5], [0.5, 2.3, 0.5], [-0.5, 2, 0.5]]", 0},
        {"[[-1.5, 2, -0.5], [-0.5, 2, -0.5], [-0.5, 2, 0.5], [-1.5, 2, 0.5]];"
         "[[0.5, 2, -0.5], [1.5, 2, -0.5], [1.5, 2, 0.5], [0.5, 2, 0.5]]", 0},
        {"[[-1.5, 2, -0.5], [-0.5, 2, -0.5], [-0.5, 2, 0.5], [-1.5, 2, 0.5]];"
         "[[0.5, 3, -0.5], [1.5, 3, -0.5], [1.5, 3, 0.5], [0.5, 3, 0.5]]", 1},
        {"[[-1.5, 2, -0.5], [-0.5, 2, -0.5], [-0.5, 2, 0.5], [-1.5, 2, 0.5]];"
         "[[0.5, 2, 0.5], [1.5, 2, 0.5], [1.5, 2, -0.5], [0.5, 2, -0.5]]", 1},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        fr_scene a, b;
        quad_lamps(cases[c].quads, "tree", &a);
        quad_lamps(cases[c].quads, "power", &b);
        uint32_t nl = a.n_lights - lgt_n_distant(&a);
        CHECK(cases[c].tree ? a.n_light_nodes == 2 * nl - 1 : a.n_light_nodes == 0,
              "lamp case %zu: %u tree nodes for %u lights", c, a.n_light_nodes, nl);
        int same = 1;
        for (uint32_t y = 0; y < 16; y++)
            for (uint32_t x = 0; x < 16; x++)
                for (uint32_t i = 0; i < 4; i++) {
                    vec3 ca = pt_sample(&a, PT_MIS, x, y, i), cb = pt_sample(&b, PT_MIS, x, y, i);
                    same &= memcmp(&ca, &cb, sizeof ca) == 0;
                }
        CHECK(cases[c].tree || same, "lamp case %zu: the image differs from the power table's", c);
        scn_free(&a);
        scn_free(&b);
    }
}

/* A furnace: a small Lambert square (albedo 0.5) inside a closed icosphere
 * of 320 inward-facing emissive triangles of radiance 2, seen with direct
 * light only.  The square's upper side sees emitters over its whole
 * hemisphere, so its radiance is albedo x 2 = 1, whichever triangle each
 * sample picks; light sampling alone (the tree's picks and pdfs) must give
 * it. */
static void furnace(void)
{
    /* The icosahedron, subdivided twice and pushed onto the sphere of
     * radius 5. */
    static const double t0 = 1.6180339887498949;
    double v[12][3] = {{-1, t0, 0}, {1, t0, 0}, {-1, -t0, 0}, {1, -t0, 0}, {0, -1, t0}, {0, 1, t0},
                       {0, -1, -t0}, {0, 1, -t0}, {t0, 0, -1}, {t0, 0, 1}, {-t0, 0, -1}, {-t0, 0, 1}};
    static const int f[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                                 {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    double (*tri)[3][3] = malloc(320 * sizeof *tri);
    int nt = 0;
    for (int k = 0; k < 20; k++)
        for (int a = 0; a < 4; a++)
            for (int b = 0; a + b < 4; b++)
                for (int up = 0; up < 2; up++) {
                    if (up && a + b == 3)
                        continue;
                    /* Barycentric lattice points of the small triangle. */
                    int c[3][2] = {{a, b}, {a + 1, b}, {a, b + 1}};
                    if (up) {
                        c[0][0] = a + 1, c[0][1] = b + 1;
                        c[1][0] = a, c[1][1] = b + 1;
                        c[2][0] = a + 1, c[2][1] = b;
                    }
                    for (int q = 0; q < 3; q++) {
                        double wa = c[q][0] / 4.0, wb = c[q][1] / 4.0, w0 = 1 - wa - wb, p[3], len = 0;
                        for (int x = 0; x < 3; x++) {
                            p[x] = w0 * v[f[k][0]][x] + wa * v[f[k][1]][x] + wb * v[f[k][2]][x];
                            len += p[x] * p[x];
                        }
                        for (int x = 0; x < 3; x++)
                            tri[nt][q][x] = 5 * p[x] / sqrt(len);
                    }
                    nt++;
                }
    text t = {0};
    put(&t, "{\"image\": {\"width\": 8, \"height\": 8, \"spp\": 1, \"max_depth\": 1},"
            " \"camera\": {\"position\": [0, 2, 0.01], \"target\": [0, 0, 0], \"up\": [0, 0, 1], \"fov\": 10},"
            " \"materials\": {\"floor\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]},"
            "   \"glow\": {\"type\": \"emitter\", \"emission\": [2, 2, 2]}},"
            " \"shapes\": [{\"type\": \"rect\", \"origin\": [-1, 0, 1], \"edge_u\": [2, 0, 0], \"edge_v\": [0, 0, -2],"
            " \"material\": \"floor\"}");
    /* Outward winding from the icosahedron's faces; reversed, the
     * triangles face the centre. */
    for (int k = 0; k < nt; k++)
        put(&t, ", {\"type\": \"triangle\", \"vertices\": [[%.6f, %.6f, %.6f], [%.6f, %.6f, %.6f], [%.6f, %.6f, %.6f]],"
                " \"material\": \"glow\"}",
            tri[k][0][0], tri[k][0][1], tri[k][0][2], tri[k][2][0], tri[k][2][1], tri[k][2][2], tri[k][1][0],
            tri[k][1][1], tri[k][1][2]);
    put(&t, "]}");
    fr_scene s;
    test_scene(t.p, &s);
    free(t.p);
    free(tri);
    estimate e = est_image(&s, PT_LIGHT_ONLY, 256), m = est_image(&s, PT_MIS, 256);
    printf("furnace of %d emissive triangles: light sampling %.5f +- %.5f, MIS %.5f +- %.5f (expected 1)\n", nt, e.mean, e.se, m.mean, m.se);
    CHECK(s.n_light_nodes == 2 * 320 - 1, "%u tree nodes for 320 triangles", s.n_light_nodes);
    CHECK(fabs(e.mean - 1.0) < 4 * e.se + 1e-3, "furnace: light sampling gives %.5f, expected 1", e.mean);
    CHECK(fabs(m.mean - 1.0) < 4 * m.se + 1e-3, "furnace: MIS gives %.5f, expected 1", m.mean);
    scn_free(&s);
}

/* A screen split into 16 x 16 squares of two triangles, facing down 1 above
 * a Lambert floor, its emission texture (64 x 64, clamped) black but for
 * the 4 x 4 texels of its corner u < 1/16, v > 15/16: the triangles of the
 * screen's corner square (with those beside it, where the bilinear lookup
 * spills half a texel) take nearly all the pick probability, black ones
 * next to none but never 0; the floor's mean is the same with the tree, the
 * power table, and the power table with picks in proportion to area (as
 * if the screen were lit all over), with far less noise than the last.
 * `sampling`: 0 tree, 1 power table, 2 picks by area. */
static int textured_screen_scene(int sampling, fr_scene *s)
{
    fr_builder b;
    bld_init(&b);
    b.settings = (fr_settings){.width = 16, .height = 16, .spp = 1, .max_depth = 1};
    b.no_light_tree = sampling != 0;
    b.camera.position = v3(0, 0.6f, -4.5f);
    b.camera.target = v3(0, 0, 0.5f);
    b.camera.up = v3(0, 1, 0);
    b.camera.vfov = 0.9f;
    b.camera.focus = 5;
    float *px = calloc(64 * 64, sizeof *px);
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 4; x++)
            px[y * 64 + x] = 1.0f;     /* rows from the top: v > 15/16 */
    scene_image img;
    memset(&img, 0, sizeof img);
    img.pixels = px;
    img.width = img.height = 64;
    img.channels = 1;
    img.type = SCENE_PIX_F32;
    fr_texture t;
    memset(&t, 0, sizeof t);
    t.kind = FR_TEX_IMAGE;
    t.wrap = FR_WRAP_CLAMP;
    t.scale = (vec2){1, 1};
    fr_error err;
    int rc = texstore_image(&b, &img, 0, &t, "screen", &err);
    free(px);
    if (rc == 0) {
        bld_push(&b.textures, &t);
        fr_material floor, screen;
        bld_material_init(&floor);
        floor.diffuse = v3s(0.5f);
        bsdf_material_finish(&floor);
        bld_material_init(&screen);
        screen.emission = v3s(40.0f);
        screen.tex_emission = 0;
        bld_push(&b.materials, &floor);
        bld_push(&b.materials, &screen);
        bld_rect(&b, v3(-4, 0, -4), v3(0, 0, 8), v3(8, 0, 0), 0);
        for (int j = 0; j < 16; j++)
            for (int i = 0; i < 16; i++) {
                float x0 = -2 + i * 0.25f, z0 = -2 + j * 0.25f, u0 = i / 16.0f, v0 = j / 16.0f, d = 1 / 16.0f;
                /* Wound to face down: (x, z) -> (x + d, z) -> (x, z + d). */
                const vec3 p1[3] = {{x0, 1, z0}, {x0 + 0.25f, 1, z0}, {x0, 1, z0 + 0.25f}};
                const vec2 t1[3] = {{u0, v0}, {u0 + d, v0}, {u0, v0 + d}};
                const vec3 p2[3] = {{x0 + 0.25f, 1, z0}, {x0 + 0.25f, 1, z0 + 0.25f}, {x0, 1, z0 + 0.25f}};
                const vec2 t2[3] = {{u0 + d, v0}, {u0 + d, v0 + d}, {u0, v0 + d}};
                bld_triangle_uv(&b, p1, t1, 1);
                bld_triangle_uv(&b, p2, t2, 1);
            }
        rc = frz_scene(&b, s, &err);
    }
    bld_free(&b);
    CHECK(rc == 0, "textured screen: %s", rc ? err.msg : "");
    if (rc < 0)
        return -1;
    if (sampling == 2) {
        /* The power table by area alone: the blob is the test's own memory. */
        fr_light *l = (fr_light *)s->lights;
        double total = 0, acc = 0;
        for (uint32_t i = 0; i < s->n_lights; i++)
            total += l[i].area;
        for (uint32_t i = 0; i < s->n_lights; i++) {
            acc += l[i].area / total;
            l[i].pick = (float)(l[i].area / total);
            l[i].cdf = i + 1 == s->n_lights ? 1.0f : (float)acc;
        }
    }
    return 0;
}

static void textured_screen(void)
{
    fr_scene tree, power, area;
    if (textured_screen_scene(0, &tree) < 0)
        return;
    if (textured_screen_scene(1, &power) < 0 || textured_screen_scene(2, &area) < 0) {
        scn_free(&tree);
        return;
    }
    /* Picks of the triangles of the corner square, of the three squares
     * beside it, and the least and most of the rest. */
    double corner = 0, beside = 0, least = 1, most = 0;
    for (uint32_t i = 0; i < power.n_lights; i++) {
        const fr_triangle *tr = &power.triangles[power.prims[power.lights[i].prim].index];
        float u = 0, v = 0;
        for (int q = 0; q < 3; q++)
            u += power.uvs[tr->v[q]].u / 3, v += power.uvs[tr->v[q]].v / 3;
        double pk = power.lights[i].pick;
        if (u < 1 / 16.0f && v > 15 / 16.0f)
            corner += pk;
        else if (u < 2 / 16.0f && v > 14 / 16.0f)
            beside += pk;
        else
            least = fmin(least, pk), most = fmax(most, pk);
    }
    printf("textured screen of %u triangles: picks of the lit corner's 2 %.5f, of the 6 beside it %.5f, of each "
           "other %.3g to %.3g\n", power.n_lights, corner, beside, least, most);
    CHECK(power.n_lights == 512 && corner > 0.9 && corner + beside > 0.99,
          "textured screen: the lit corner's triangles have %.4f of the picks (with those beside it %.4f)", corner,
          corner + beside);
    CHECK(least > 0 && most < 1e-4, "textured screen: a black triangle's pick %g to %g, expected in (0, 1e-4)", least,
          most);
    /* The lower half of the image: the floor alone (the camera looks down). */
    estimate et = est_region(&tree, PT_MIS, 256, 0, 16, 8, 16), ep = est_region(&power, PT_MIS, 256, 0, 16, 8, 16),
             ea = est_region(&area, PT_MIS, 256, 0, 16, 8, 16);
    printf("textured screen, floor's mean: tree %.5f +- %.5f, power table %.5f +- %.5f, picks by area %.5f +- %.5f\n",
           et.mean, et.se, ep.mean, ep.se, ea.mean, ea.se);
    double d1 = fabs(et.mean - ep.mean), s1 = hypot(et.se, ep.se), d2 = fabs(ep.mean - ea.mean), s2 = hypot(ep.se, ea.se);
    CHECK(et.mean > 0 && d1 < 4 * s1 && d2 < 4 * s2,
          "textured screen: tree %.5f, power table %.5f, by area %.5f (+- %.5f %.5f %.5f)", et.mean, ep.mean, ea.mean,
          et.se, ep.se, ea.se);
    CHECK(ep.se * 4 < ea.se && et.se * 4 < ea.se,
          "textured screen: standard error %.5f (tree), %.5f (power table), %.5f by area: not 4 times less", et.se,
          ep.se, ea.se);
    scn_free(&tree);
    scn_free(&power);
    scn_free(&area);
}

int main(void)
{
    pick_probabilities();
    sample_pdf();
    one_light();
    flat_lamp();
    lamp_sums();
    lamp_ground();
    furnace();
    textured_screen();
    return check_done();
}
