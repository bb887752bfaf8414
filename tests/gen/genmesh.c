/* genmesh.c -- procedural triangle meshes as Wavefront OBJ files, for tests,
 * benchmarks and example scenes (nothing can be downloaded, so the project
 * makes its own detailed meshes).
 *
 *   genmesh knot    [--tris N] [--p P] [--q Q] -o FILE.obj   torus knot tube
 *   genmesh sphere  [--tris N] [--seed S]       -o FILE.obj   displaced sphere
 *   genmesh terrain [--tris N] [--seed S]       -o FILE.obj   heightfield
 *   genmesh thin    [--tris N] [--seed S]       -o FILE.obj   long thin slivers
 *
 * --tris is the approximate triangle count (default 100000, up to ~20 M).
 * --flat leaves out vertex normals, --no-uv texture coordinates;
 * --material NAME adds `mtllib NAME.mtl` and `usemtl NAME` (the MTL file
 * is the caller's).  Every
 * mesh has unit-ish size around the origin, +y up.  The numbers come from
 * fmath and integer hashing only, so a file is the same on every machine. */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmath.h"
#include "vec.h"

typedef struct {
    const char *kind, *out, *material;
    long tris;
    int p, q, normals, uvs;
    uint32_t seed;
} options;

/* A u x v grid of vertices (u wraps when wrap_u, v when wrap_v). */
typedef struct {
    int nu, nv, wrap_u, wrap_v;
    vec3 *pos, *nrm;
} grid;

/* ---- noise: value noise on an integer lattice, hashed ---- */

static uint32_t hash3i(int x, int y, int z, uint32_t seed)
{
    uint32_t h = seed * 0x9E3779B9u ^ (uint32_t)x * 0x85EBCA6Bu ^ (uint32_t)y * 0xC2B2AE35u ^ (uint32_t)z * 0x27D4EB2Fu;
    h ^= h >> 15; h *= 0x2C1B3C6Du; h ^= h >> 12; h *= 0x297A2D39u; h ^= h >> 15;
    return h;
}

static float lattice(int x, int y, int z, uint32_t seed) { return (float)(hash3i(x, y, z, seed) >> 8) / 8388608.0f - 1.0f; }

static float smooth(float t) { return t * t * (3.0f - 2.0f * t); }

static float value_noise(vec3 p, uint32_t seed)
{
    float fx = floorf(p.x), fy = floorf(p.y), fz = floorf(p.z);
    int x = (int)fx, y = (int)fy, z = (int)fz;
    float tx = smooth(p.x - fx), ty = smooth(p.y - fy), tz = smooth(p.z - fz);
    float c[2][2];
    for (int j = 0; j < 2; j++)
        for (int k = 0; k < 2; k++) {
            float a = lattice(x, y + j, z + k, seed), b = lattice(x + 1, y + j, z + k, seed);
            c[j][k] = a + (b - a) * tx;
        }
    float e0 = c[0][0] + (c[1][0] - c[0][0]) * ty, e1 = c[0][1] + (c[1][1] - c[0][1]) * ty;
    return e0 + (e1 - e0) * tz;
}

/* Fractal sum of octaves, roughly in [-1, 1]. */
static float fbm(vec3 p, int octaves, uint32_t seed)
{
    float sum = 0.0f, amp = 0.5f;
    for (int i = 0; i < octaves; i++) {
        sum += amp * value_noise(p, seed + (uint32_t)i);
        p = v3_scale(p, 2.03f);
        amp *= 0.5f;
    }
    return sum;
}

/* ---- shapes ---- */

static vec3 knot_curve(float t, int p, int q)
{
    float sp, cp, sq, cq;
    fm_sincosf((float)p * t, &sp, &cp);
    fm_sincosf((float)q * t, &sq, &cq);
    float r = 2.0f + cq;
    return v3_scale(v3(r * cp, -sq, r * sp), 0.3f);
}

static void make_knot(grid *g, const options *o)
{
    /* Tube around a (p, q) torus knot: nu along the curve, nv around. */
    for (int i = 0; i < g->nu; i++) {
        float t = 2.0f * FM_PI * (float)i / (float)g->nu, dt = 1.0e-3f;
        vec3 c = knot_curve(t, o->p, o->q);
        vec3 tan = v3_norm(v3_sub(knot_curve(t + dt, o->p, o->q), knot_curve(t - dt, o->p, o->q)));
        vec3 n = v3_norm(v3_cross(tan, v3(0.0f, 1.0f, 0.0f)));
        vec3 b = v3_cross(tan, n);
        for (int j = 0; j < g->nv; j++) {
            float s, cs;
            fm_sincosf(2.0f * FM_PI * (float)j / (float)g->nv, &s, &cs);
            vec3 dir = v3_add(v3_scale(n, cs), v3_scale(b, s));
            g->pos[i * g->nv + j] = v3_madd(c, dir, 0.12f);
        }
    }
}

static void make_sphere(grid *g, const options *o)
{
    /* Latitude-longitude sphere pushed in and out by fractal noise; the
     * poles are single points (rows 0 and nu-1 collapse). */
    for (int i = 0; i < g->nu; i++) {
        float th = FM_PI * (float)i / (float)(g->nu - 1), st, ct;
        fm_sincosf(th, &st, &ct);
        for (int j = 0; j < g->nv; j++) {
            float ph = 2.0f * FM_PI * (float)j / (float)g->nv, sp, cp;
            fm_sincosf(ph, &sp, &cp);
            vec3 d = v3(st * cp, ct, st * sp);
            float r = 1.0f + 0.18f * fbm(v3_scale(d, 3.0f), 7, o->seed);
            g->pos[i * g->nv + j] = v3_scale(d, r);
        }
    }
}

static void make_terrain(grid *g, const options *o)
{
    for (int i = 0; i < g->nu; i++)
        for (int j = 0; j < g->nv; j++) {
            float x = 2.0f * (float)j / (float)(g->nv - 1) - 1.0f, z = 2.0f * (float)i / (float)(g->nu - 1) - 1.0f;
            float h = fbm(v3(x * 3.0f, 0.5f, z * 3.0f), 9, o->seed);
            float ridge = 1.0f - fabsf(fbm(v3(x * 1.5f, 7.5f, z * 1.5f), 5, o->seed + 99u));
            g->pos[i * g->nv + j] = v3(x, 0.35f * h + 0.25f * ridge * ridge, z);
        }
}

/* A wavy sheet of slivers (cells about 300 times longer than wide: 0.17
 * by 5e-4 at 100 k triangles), turned 45 degrees about y and tilted so
 * they lie diagonal to every axis: boxes far larger than their triangles,
 * the case spatial splits are for. */
static void make_thin(grid *g, const options *o)
{
    for (int i = 0; i < g->nu; i++)
        for (int j = 0; j < g->nv; j++) {
            float s = 2.0f * (float)i / (float)(g->nu - 1) - 1.0f, t = 2.0f * (float)j / (float)(g->nv - 1) - 1.0f;
            float h = 0.3f * fbm(v3(s * 4.0f, 0.5f, t * 2.0f), 6, o->seed);
            g->pos[i * g->nv + j] = v3((s - t) * 0.70710678f, h + 0.3f * t, (s + t) * 0.70710678f);
        }
}

/* Index of grid vertex (i, j), wrapping where the grid wraps. */
static int at(const grid *g, int i, int j)
{
    if (g->wrap_u) i = (i + g->nu) % g->nu;
    if (g->wrap_v) j = (j + g->nv) % g->nv;
    return i * g->nv + j;
}

/* Vertex normals: area-weighted sums of the incident cells' normals,
 * turned to the side the triangles face (`flip` reverses the winding). */
static void grid_normals(grid *g, int flip)
{
    memset(g->nrm, 0, (size_t)g->nu * g->nv * sizeof *g->nrm);
    int cu = g->wrap_u ? g->nu : g->nu - 1, cv = g->wrap_v ? g->nv : g->nv - 1;
    for (int i = 0; i < cu; i++)
        for (int j = 0; j < cv; j++) {
            int a = at(g, i, j), b = at(g, i + 1, j), c = at(g, i + 1, j + 1), d = at(g, i, j + 1);
            vec3 n = v3_cross(v3_sub(g->pos[c], g->pos[a]), v3_sub(g->pos[d], g->pos[b]));
            g->nrm[a] = v3_add(g->nrm[a], n); g->nrm[b] = v3_add(g->nrm[b], n);
            g->nrm[c] = v3_add(g->nrm[c], n); g->nrm[d] = v3_add(g->nrm[d], n);
        }
    for (int i = 0; i < g->nu * g->nv; i++) {
        float l = v3_len(g->nrm[i]);
        g->nrm[i] = l > 0.0f ? v3_scale(g->nrm[i], (flip ? -1.0f : 1.0f) / l) : v3(0.0f, 1.0f, 0.0f);
    }
}

static int write_obj(const grid *g, const options *o, int flip)
{
    FILE *f = fopen(o->out, "w");
    if (!f) {
        fprintf(stderr, "genmesh: %s: %s\n", o->out, strerror(errno));
        return 1;
    }
    static char buf[1 << 20];
    setvbuf(f, buf, _IOFBF, sizeof buf);
    int cu = g->wrap_u ? g->nu : g->nu - 1, cv = g->wrap_v ? g->nv : g->nv - 1;
    fprintf(f, "# genmesh %s: %d x %d grid, %ld triangles\n", o->kind, g->nu, g->nv, 2L * cu * cv);
    if (o->material)
        fprintf(f, "mtllib %s.mtl\n", o->material);
    fprintf(f, "o %s\n", o->kind);
    for (int i = 0; i < g->nu * g->nv; i++)
        fprintf(f, "v %.6f %.6f %.6f\n", (double)g->pos[i].x, (double)g->pos[i].y, (double)g->pos[i].z);
    if (o->normals)
        for (int i = 0; i < g->nu * g->nv; i++)
            fprintf(f, "vn %.5f %.5f %.5f\n", (double)g->nrm[i].x, (double)g->nrm[i].y, (double)g->nrm[i].z);
    if (o->material)
        fprintf(f, "usemtl %s\n", o->material);
    if (o->uvs)
        for (int i = 0; i < g->nu; i++)
            for (int j = 0; j < g->nv; j++)
                fprintf(f, "vt %.5f %.5f\n", (double)j / (g->nv - 1 + g->wrap_v), (double)i / (g->nu - 1 + g->wrap_u));
    for (int i = 0; i < cu; i++)
        for (int j = 0; j < cv; j++) {
            int q[4] = {at(g, i, j) + 1, at(g, i + 1, j) + 1, at(g, i + 1, j + 1) + 1, at(g, i, j + 1) + 1};
            if (flip) { int t = q[1]; q[1] = q[3]; q[3] = t; }
            int tri[2][3] = {{q[0], q[1], q[2]}, {q[0], q[2], q[3]}};
            for (int k = 0; k < 2; k++) {
                fputc('f', f);
                for (int c = 0; c < 3; c++) {
                    int v = tri[k][c];
                    if (o->normals && o->uvs) fprintf(f, " %d/%d/%d", v, v, v);
                    else if (o->normals) fprintf(f, " %d//%d", v, v);
                    else if (o->uvs) fprintf(f, " %d/%d", v, v);
                    else fprintf(f, " %d", v);
                }
                fputc('\n', f);
            }
        }
    if (fclose(f) != 0) {
        fprintf(stderr, "genmesh: %s: %s\n", o->out, strerror(errno));
        return 1;
    }
    return 0;
}

static const char usage[] =
    "usage: genmesh knot|sphere|terrain|thin [--tris N] [--p P] [--q Q] [--seed S]\n"
    "               [--flat] [--no-uv] [--material NAME] -o FILE.obj\n";

int main(int argc, char **argv)
{
    options o = {NULL, NULL, NULL, 100000, 2, 3, 1, 1, 1};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int more = i + 1 < argc;
        if (!strcmp(a, "--help")) { fputs(usage, stdout); return 0; }
        else if (!strcmp(a, "--flat")) o.normals = 0;
        else if (!strcmp(a, "--no-uv")) o.uvs = 0;
        else if (!strcmp(a, "--tris") && more) o.tris = atol(argv[++i]);
        else if (!strcmp(a, "--p") && more) o.p = atoi(argv[++i]);
        else if (!strcmp(a, "--q") && more) o.q = atoi(argv[++i]);
        else if (!strcmp(a, "--seed") && more) o.seed = (uint32_t)strtoul(argv[++i], NULL, 10);
        else if (!strcmp(a, "-o") && more) o.out = argv[++i];
        else if (!strcmp(a, "--material") && more) o.material = argv[++i];
        else if (a[0] != '-' && !o.kind) o.kind = a;
        else { fprintf(stderr, "genmesh: bad argument '%s'\n%s", a, usage); return 2; }
    }
    if (!o.kind || !o.out || o.tris < 8 || o.tris > 20000000 || o.p < 1 || o.q < 1) {
        fputs(usage, stderr);
        return 2;
    }
    grid g = {0};
    int flip = 0;
    /* Pick grid sides with the shape's aspect so cells are roughly square. */
    double cells = (double)o.tris / 2.0;
    if (!strcmp(o.kind, "knot")) {
        g.nv = (int)sqrt(cells / 12.0) + 3;
        g.nu = (int)(cells / g.nv) + 1;
        g.wrap_u = g.wrap_v = 1;
        flip = 1;
    } else if (!strcmp(o.kind, "sphere")) {
        g.nu = (int)sqrt(cells / 2.0) + 3;
        g.nv = (int)(cells / (g.nu - 1)) + 1;
        g.wrap_v = 1;
        flip = 1;
    } else if (!strcmp(o.kind, "terrain")) {
        g.nu = g.nv = (int)sqrt(cells) + 2;
    } else if (!strcmp(o.kind, "thin")) {
        g.nv = (int)sqrt(cells / 400.0) + 2;
        g.nu = (int)(cells / (g.nv - 1)) + 2;
    } else {
        fprintf(stderr, "genmesh: unknown kind '%s'\n%s", o.kind, usage);
        return 2;
    }
    g.pos = malloc((size_t)g.nu * g.nv * sizeof *g.pos);
    g.nrm = malloc((size_t)g.nu * g.nv * sizeof *g.nrm);
    if (!g.pos || !g.nrm) {
        fprintf(stderr, "genmesh: out of memory\n");
        return 1;
    }
    if (!strcmp(o.kind, "knot")) make_knot(&g, &o);
    else if (!strcmp(o.kind, "sphere")) make_sphere(&g, &o);
    else if (!strcmp(o.kind, "terrain")) make_terrain(&g, &o);
    else make_thin(&g, &o);
    grid_normals(&g, flip);
    int rc = write_obj(&g, &o, flip);
    free(g.pos);
    free(g.nrm);
    return rc;
}
