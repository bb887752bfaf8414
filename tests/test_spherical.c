/* test_spherical.c -- solid-angle sampling of rectangle and triangle lights.
 *
 * Next-event estimation samples a rectangle or triangle light uniformly in
 * the solid angle it subtends (spherical.h) where that is safe, else by
 * area.  For each configuration (near, grazing, outside the rectangle's
 * extent, far enough to fall back to area sampling, from behind a two-sided
 * light): a chi-square test of the sampled points against lgt_pdf
 * integrated over cells of the emitter, the same integral over the whole
 * emitter against the pick, lgt_pdf and the sample's pdf bit for bit, the
 * points on the emitter, the same bits for the same numbers; irradiance
 * against Lambert's formula for polygons; the power table's samples
 * (bidirectional connections, equiangular sampling) still by area. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "light.h"
#include "scenes.h"
#include "spherical.h"
#include "stats.h"

/* A scene with one emitter 1 unit up facing down (rectangle or triangle),
 * and a floor. */
static void light_scene(int tri, int two_sided, fr_scene *s)
{
    char json[2048];
    const char *shape =
        tri ? "{\"type\": \"triangle\", \"material\": \"lamp\","
              " \"vertices\": [[-0.5, 1, -0.3], [0.6, 1, -0.2], [0, 1, 0.4]]}"
            : "{\"type\": \"rect\", \"material\": \"lamp\", \"origin\": [-0.5, 1, -0.25],"
              " \"edge_u\": [1, 0, 0], \"edge_v\": [0, 0, 0.5]}";
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 1, \"height\": 1, \"spp\": 1, \"max_depth\": 1},"
             " \"camera\": {\"position\": [0, 0.5, -3], \"target\": [0, 0.5, 0], \"fov\": 40},"
             " \"materials\": {\"floor\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]},"
             " \"lamp\": {\"type\": \"emitter\", \"emission\": [2, 2, 2]%s}},"
             " \"shapes\": [{\"type\": \"plane\", \"point\": [0, -200, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"},"
             " %s]}",
             two_sided ? ", \"two_sided\": true" : "", shape);
    test_scene(json, s);
}

/* The emitter's corners: three for a triangle, four for the rectangle (in
 * order around it); returns how many. */
static int corners(const fr_scene *s, vec3 c[4])
{
    const fr_prim *pr = &s->prims[s->lights[0].prim];
    if (pr->kind == FR_PRIM_RECT) {
        const fr_rect *q = &s->rects[pr->index];
        c[0] = q->origin;
        c[1] = v3_add(q->origin, q->edge_u);
        c[2] = v3_add(c[1], q->edge_v);
        c[3] = v3_add(q->origin, q->edge_v);
        return 4;
    }
    const fr_triangle *t = &s->triangles[pr->index];
    for (int i = 0; i < 3; i++)
        c[i] = s->positions[t->v[i]];
    return 3;
}

/* The emitter's cells: a rectangle's N x N grid of (s, t), a triangle's
 * N^2 sub-triangles of (b1, b2), numbered by cell_of. */
#define N 6
#define CELLS (2 * N * N)

/* The cell of point p of the emitter, or -1 when p is off it (by more than
 * rounding). */
static int cell_of(const fr_scene *s, vec3 p)
{
    vec3 c[4];
    int n = corners(s, c);
    double a, b;
    if (n == 4) {
        const fr_rect *q = &s->rects[s->prims[s->lights[0].prim].index];
        vec3 d = v3_sub(p, q->origin);
        a = v3_dot(d, q->dual_u);
        b = v3_dot(d, q->dual_v);
        if (fabs(v3_dot(d, v3_norm(q->normal))) > 1e-5 || a < -1e-6 || a > 1 + 1e-6 || b < -1e-6 || b > 1 + 1e-6)
            return -1;
        int i = (int)fmin(N - 1, fmax(0, floor(a * N))), j = (int)fmin(N - 1, fmax(0, floor(b * N)));
        return 2 * (i * N + j);
    }
    /* Barycentrics of p1 and p2 by least squares in the plane. */
    vec3 e1 = v3_sub(c[1], c[0]), e2 = v3_sub(c[2], c[0]), d = v3_sub(p, c[0]);
    double d11 = v3_dot(e1, e1), d12 = v3_dot(e1, e2), d22 = v3_dot(e2, e2), dd1 = v3_dot(d, e1), dd2 = v3_dot(d, e2);
    double det = d11 * d22 - d12 * d12;
    a = (d22 * dd1 - d12 * dd2) / det;
    b = (d11 * dd2 - d12 * dd1) / det;
    vec3 nrm = v3_norm(v3_cross(e1, e2));
    if (fabs(v3_dot(d, nrm)) > 1e-5 || a < -1e-6 || b < -1e-6 || a + b > 1 + 1e-6)
        return -1;
    int i = (int)fmin(N - 1, fmax(0, floor(a * N))), j = (int)fmin(N - 1, fmax(0, floor(b * N)));
    double fa = a * N - i, fb = b * N - j;
    return 2 * (i * N + j) + (fa + fb > 1.0);
}

/* lgt_pdf (per steradian) integrated over the world triangle q0 q1 q2 seen
 * from `from`: m x m sub-triangles, each by its centroid. */
static double integrate_tri(const fr_scene *s, vec3 from, vec3 q0, vec3 q1, vec3 q2, int m)
{
    vec3 e1 = v3_sub(q1, q0), e2 = v3_sub(q2, q0), ng = v3_cross(e1, e2);
    double area = 0.5 * v3_len(ng) / ((double)m * m), sum = 0;
    vec3 n = v3_norm(ng);
    for (int i = 0; i < m; i++)
        for (int j = 0; i + j < m; j++)
            for (int up = 0; up < 2 && (up == 0 || i + j + 1 < m); up++) {
                double a = (i + (up ? 2.0 : 1.0) / 3.0) / m, b = (j + (up ? 2.0 : 1.0) / 3.0) / m;
                vec3 p = v3_add(q0, v3_add(v3_scale(e1, (float)a), v3_scale(e2, (float)b)));
                vec3 d = v3_sub(p, from);
                double d2 = v3_len2(d), cosl = fabs(v3_dot(n, d)) / sqrt(d2);
                sum += lgt_pdf(s, 0, from, v3s(0.0f), p, n) * cosl / d2 * area;
            }
    return sum;
}

/* lgt_pdf integrated over each cell, into expect[CELLS]; returns the sum. */
static double integrate_cells(const fr_scene *s, vec3 from, double *expect)
{
    vec3 c[4];
    int n = corners(s, c);
    double total = 0;
    memset(expect, 0, CELLS * sizeof *expect);
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++) {
            if (n == 4) {
                vec3 eu = v3_sub(c[1], c[0]), ev = v3_sub(c[3], c[0]);
                vec3 q[4];
                for (int k = 0; k < 4; k++) {
                    float a = (float)(i + (k == 1 || k == 2)) / N, b = (float)(j + (k >= 2)) / N;
                    q[k] = v3_add(c[0], v3_add(v3_scale(eu, a), v3_scale(ev, b)));
                }
                expect[2 * (i * N + j)] = integrate_tri(s, from, q[0], q[1], q[2], 12) +
                                          integrate_tri(s, from, q[0], q[2], q[3], 12);
            } else {
                if (i + j >= N)
                    continue;
                vec3 e1 = v3_sub(c[1], c[0]), e2 = v3_sub(c[2], c[0]);
#define BARY(a, b) v3_add(c[0], v3_add(v3_scale(e1, (float)(a) / N), v3_scale(e2, (float)(b) / N)))
                expect[2 * (i * N + j)] = integrate_tri(s, from, BARY(i, j), BARY(i + 1, j), BARY(i, j + 1), 12);
                if (i + j + 1 < N)
                    expect[2 * (i * N + j) + 1] =
                        integrate_tri(s, from, BARY(i + 1, j), BARY(i + 1, j + 1), BARY(i, j + 1), 12);
#undef BARY
            }
            total += expect[2 * (i * N + j)] + expect[2 * (i * N + j) + 1];
        }
    return total;
}

/* Whether spherical.h's setup accepts the emitter seen from `from`. */
static int solid_accepted(const fr_scene *s, vec3 from)
{
    vec3 c[4];
    if (corners(s, c) == 4) {
        const fr_rect *q = &s->rects[s->prims[s->lights[0].prim].index];
        spherical_rect r;
        return spherical_rect_setup(from, q->origin, q->edge_u, q->edge_v, &r);
    }
    spherical_tri t;
    return spherical_tri_setup(from, c[0], c[1], c[2], &t);
}

/* One configuration: `want_solid` whether the point should be sampled by
 * solid angle (1) or fall back to area (0). */
static void configuration(const char *name, int tri, int two_sided, vec3 from, int want_solid)
{
    fr_scene s;
    light_scene(tri, two_sided, &s);
    const char *kind = tri ? "triangle" : "rectangle";
    CHECK(!want_solid || solid_accepted(&s, from), "%s %s: spherical.h refuses the light", kind, name);
    float pick = lgt_pick_pdf(&s, 0, from, v3s(0.0f));
    double expect[CELLS], count[CELLS] = {0};
    double total = integrate_cells(&s, from, expect);
    CHECK(fabs(total - pick) < 2e-3 * pick, "%s %s: lgt_pdf integrates to %.6f over the emitter, pick %.6f", kind,
          name, total, (double)pick);
    const int n = 200000;
    uint32_t st = 7;
    int off = 0, same = 1, pdfs = 1, fails = 0, constant = 1;
    float first = 0.0f;
    for (int k = 0; k < n; k++) {
        float u1 = (float)st_rnd(&st), u2 = (float)st_rnd(&st);
        fr_light_sample ls, again;
        if (!lgt_sample_chosen(&s, 0, pick, from, u1, u2, &ls)) {
            fails++;
            continue;
        }
        int c = cell_of(&s, ls.p);
        if (c < 0) {
            off++;
            continue;
        }
        count[c]++;
        if (first == 0.0f)
            first = ls.pdf;
        constant &= ls.pdf == first;
        lgt_sample_chosen(&s, 0, pick, from, u1, u2, &again);
        same &= !memcmp(&ls.p, &again.p, sizeof ls.p) && !memcmp(&ls.wi, &again.wi, sizeof ls.wi) &&
                !memcmp(&ls.pdf, &again.pdf, sizeof ls.pdf) && !memcmp(&ls.radiance, &again.radiance, sizeof ls.radiance);
        float pl = lgt_pdf(&s, 0, from, v3s(0.0f), ls.p, ls.n);
        if (want_solid ? memcmp(&pl, &ls.pdf, sizeof pl) != 0 : !(fabsf(pl - ls.pdf) <= 1e-4f * ls.pdf)) {
            if (pdfs)
                printf("  %s %s: sample pdf %.9g, lgt_pdf %.9g\n", kind, name, (double)ls.pdf, (double)pl);
            pdfs = 0;
        }
    }
    /* Uniform in solid angle: one density for every point; by area: not. */
    CHECK(constant == want_solid, "%s %s: sampled %s", kind, name, want_solid ? "by area" : "in solid angle");
    CHECK(fails == 0, "%s %s: %d samples carried no light", kind, name, fails);
    CHECK(off == 0, "%s %s: %d sampled points off the emitter", kind, name, off);
    CHECK(same, "%s %s: the same numbers gave other bits", kind, name);
    CHECK(pdfs, "%s %s: lgt_pdf differs from the sample's pdf", kind, name);
    for (int i = 0; i < CELLS; i++)
        expect[i] *= (n - fails) / total;
    double pv = st_chi2_test(count, expect, CELLS, 3.0);
    if (getenv("SPH_DEBUG"))
        for (int i = 0; i < CELLS; i++)
            printf("  cell %d: %g expected %g\n", i, count[i], expect[i]);
    CHECK(pv > 1e-3, "%s %s: chi-square p-value %g of the points against lgt_pdf", kind, name, pv);
    scn_free(&s);
}

/* Irradiance (per unit radiance) at `from` with normal n from the polygon
 * c[0..k): Lambert's formula, half the sum over the edges of the angle
 * each subtends times the cosine between n and the normal of the plane
 * through the point and the edge. */
static double lambert(const vec3 *c, int k, vec3 from, vec3 n)
{
    double sum = 0;
    for (int i = 0; i < k; i++) {
        vec3 p = c[i], q = c[(i + 1) % k];
        double a[3] = {(double)p.x - from.x, (double)p.y - from.y, (double)p.z - from.z};
        double b[3] = {(double)q.x - from.x, (double)q.y - from.y, (double)q.z - from.z};
        double x[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
        double lx = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        double ang = atan2(lx, a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
        sum += ang * (n.x * x[0] + n.y * x[1] + n.z * x[2]) / lx;
    }
    return 0.5 * fabs(sum);
}

static void irradiance(const char *name, int tri, vec3 from, vec3 n)
{
    fr_scene s;
    light_scene(tri, 0, &s);
    vec3 c[4];
    int k = corners(&s, c);
    double want = lambert(c, k, from, n), sum = 0, sum2 = 0;
    const int count = 100000;
    uint32_t st = 11;
    for (int i = 0; i < count; i++) {
        fr_light_sample ls;
        double v = 0;
        if (lgt_sample_chosen(&s, 0, 1.0f, from, (float)st_rnd(&st), (float)st_rnd(&st), &ls))
            v = ls.radiance.y / 2.0 * fmax(0.0, v3_dot(n, ls.wi)) / ls.pdf;
        sum += v;
        sum2 += v * v;
    }
    double mean = sum / count, se = sqrt(fmax(0, sum2 / count - mean * mean) / count);
    CHECK(fabs(mean - want) < 4 * se + 1e-4 * want, "%s %s: irradiance %.9f +- %.9f, Lambert's formula %.9f",
          tri ? "triangle" : "rectangle", name, mean, se, want);
    scn_free(&s);
}

/* The power table's samples (lgt_sample_table: the bidirectional
 * connections and equiangular sampling, whose MIS counts points by area)
 * keep the area density: lgt_pdf_table's, not lgt_pdf's. */
static void table_by_area(int tri)
{
    fr_scene s;
    light_scene(tri, 0, &s);
    vec3 from = v3(0.1f, 0.7f, 0.05f);
    uint32_t st = 3;
    int bad = 0, differ = 0;
    for (int i = 0; i < 1000; i++) {
        fr_light_sample ls;
        if (!lgt_sample_table(&s, from, (float)st_rnd(&st), (float)st_rnd(&st), (float)st_rnd(&st), &ls))
            continue;
        vec3 d = v3_sub(ls.p, from);
        float area = (float)(ls.pick * v3_len2(d) / (fabs(v3_dot(ls.n, d)) / v3_len(d) * s.lights[0].area));
        float pt = lgt_pdf_table(&s, 0, from, ls.p, ls.n), ps = lgt_pdf(&s, 0, from, v3s(0.0f), ls.p, ls.n);
        bad += !(fabsf(ls.pdf - area) <= 1e-4f * area) || !(fabsf(ls.pdf - pt) <= 1e-4f * area);
        differ += ps != pt;
    }
    CHECK(bad == 0, "%s: %d table samples not by area", tri ? "triangle" : "rectangle", bad);
    CHECK(differ > 900, "%s: lgt_pdf equals the area density for %d of 1000 points near the light",
          tri ? "triangle" : "rectangle", 1000 - differ);
    scn_free(&s);
}

int main(void)
{
    for (int tri = 0; tri < 2; tri++) {
        configuration("near", tri, 0, v3(0.1f, 0.8f, 0.05f), 1);
        configuration("grazing", tri, 0, v3(1.5f, 0.98f, 0.1f), 1);
        configuration("outside", tri, 0, v3(-1.2f, 0.3f, 0.9f), 1);
        configuration("far", tri, 0, v3(0.3f, -40.0f, 0.2f), 0);
        configuration("in the plane", tri, 1, v3(2.0f, 0.99999f, 0.1f), 0);
        configuration("behind, two-sided", tri, 1, v3(0.2f, 1.6f, -0.1f), 1);
        irradiance("overhead", tri, v3(0.05f, 0.3f, 0.0f), v3(0, 1, 0));
        irradiance("tilted", tri, v3(0.9f, 0.5f, 0.4f), v3_norm(v3(-0.5f, 1.0f, -0.2f)));
        irradiance("far", tri, v3(0.3f, -40.0f, 0.2f), v3(0, 1, 0));
        table_by_area(tri);
    }
    return check_done();
}
