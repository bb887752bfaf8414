/* obj.c -- the Wavefront OBJ and MTL reader, with file:line errors (see
 * obj.h). */

#include "compile/obj.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "bsdf.h"
#include "compile/builder.h"
#include "file.h"
#include "scene.h"

/* Polygons with more corners than this are triangulated as a fan (ear
 * clipping is quadratic in the corner count; such faces come from caps of
 * convex shapes in practice). */
enum { EAR_MAX = 64, MAT_MAX = 4096 };

/* A read cursor over one line of NUL-terminated text. */
typedef struct {
    const char *p;             /* current position */
    const char *name;          /* file name, for messages */
    int line;
    fr_error *err;
} cursor;

static int is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }
static int at_end(const char *p) { return *p == '\n' || *p == 0 || *p == '#'; }
static void skip_space(cursor *c) { while (is_space(*c->p)) c->p++; }

/* Next whitespace-separated word of the line into buf; 0 at end of line. */
static int word(cursor *c, char *buf, size_t cap)
{
    skip_space(c);
    if (at_end(c->p))
        return 0;
    size_t n = 0;
    while (!is_space(*c->p) && !at_end(c->p)) {
        if (n + 1 < cap)
            buf[n++] = *c->p;
        c->p++;
    }
    buf[n] = 0;
    return 1;
}

/* Next number of the line; 0 at end of line, -1 (error set) if malformed. */
static int number(cursor *c, float *out, const char *what)
{
    skip_space(c);
    if (at_end(c->p))
        return 0;
    char *end;
    errno = 0;
    float v = strtof(c->p, &end);
    if (end == c->p || !(is_space(*end) || at_end(end)) || !isfinite(v))
        return fr_fail(c->err, "%s:%d: expected a finite number for %s", c->name, c->line, what);
    c->p = end;
    *out = v;
    return 1;
}

/* A material name (newmtl, usemtl): the rest of the line without the
 * blanks around it; blanks and '#' inside belong to it ("Material #25").
 * May be empty; -1 (error set) when longer than cap - 1 bytes. */
static int name_rest(cursor *c, char *buf, size_t cap, const char *what)
{
    skip_space(c);
    const char *s = c->p, *e = s;
    while (*e && *e != '\n')
        e++;
    c->p = e;
    while (e > s && is_space(e[-1]))
        e--;
    size_t n = (size_t)(e - s);
    if (n >= cap)
        return fr_fail(c->err, "%s:%d: %s: a material name longer than %zu bytes", c->name, c->line, what, cap - 1);
    memcpy(buf, s, n);
    buf[n] = 0;
    return 0;
}

/* Text that is not 8-bit: a UTF-16 byte-order mark or a NUL byte gets an
 * error naming the file (and the line of the NUL); -1 then, else 0. */
static int not_text(const char *text, size_t len, const char *name, fr_error *err)
{
    const unsigned char *u = (const unsigned char *)text;
    if (len >= 2 && ((u[0] == 0xfe && u[1] == 0xff) || (u[0] == 0xff && u[1] == 0xfe)))
        return fr_fail(err, "%s: UTF-16 text (it starts with a byte-order mark): save it as UTF-8 or ASCII", name);
    const char *nul = memchr(text, 0, len);
    if (!nul)
        return 0;
    int line = 1;
    for (const char *q = text; q < nul; q++)
        line += *q == '\n';
    return fr_fail(err, "%s:%d: NUL byte in a text file", name, line);
}

/* Where the text starts: after a UTF-8 byte-order mark, if any. */
static const char *skip_bom(const char *text)
{
    return !strncmp(text, "\xef\xbb\xbf", 3) ? text + 3 : text;
}

static int end_of_line(cursor *c, const char *what)
{
    skip_space(c);
    if (!at_end(c->p))
        return fr_fail(c->err, "%s:%d: unexpected text after %s", c->name, c->line, what);
    return 0;
}

/* Grow *p (elements of `elem` bytes, capacity *cap) to hold `need`. */
static int grow(void *pp, uint32_t *cap, uint64_t need, size_t elem)
{
    void **p = pp;
    if (need <= *cap)
        return 0;
    uint64_t c = *cap ? *cap : 64;
    while (c < need)
        c *= 2;
    if (c > 0x7fffffffu)
        return -1;
    void *q = realloc(*p, (size_t)c * elem);
    if (!q)
        return -1;
    *p = q;
    *cap = (uint32_t)c;
    return 0;
}

/* ---- materials ---- */

typedef struct {
    mesh_data *m;
    uint32_t cap_mats;
} mat_table;

/* What a material is before its statements: black, not transmissive
 * beyond Tf's default, Ni 1.5 (the default material for faces before any
 * usemtl is then given Kd 0.8). */
static void mat_defaults(mesh_material *mt, const char *name)
{
    memset(mt, 0, sizeof *mt);
    snprintf(mt->name, sizeof mt->name, "%s", name);
    mt->tf = v3s(1.0f);
    mt->ns = 0.0f;
    mt->ni = 1.5f;
    mt->d = 1.0f;
    mt->illum = -1;
}

/* Index of material `name`, appended (undefined, used at `line`) if new. */
static int mat_find(mesh_data *m, uint32_t *cap, const char *name, int line, uint32_t *out, cursor *c)
{
    for (uint32_t i = 1; i < m->n_mats; i++)
        if (!strcmp(m->mats[i].name, name)) {
            *out = i;
            return 0;
        }
    if (m->n_mats >= MAT_MAX)
        return fr_fail(c->err, "%s:%d: more than %d materials", c->name, c->line, MAT_MAX);
    if (grow(&m->mats, cap, m->n_mats + 1ull, sizeof *m->mats) < 0)
        return fr_fail(c->err, "%s:%d: out of memory", c->name, c->line);
    mat_defaults(&m->mats[m->n_mats], name);
    m->mats[m->n_mats].line = line;
    *out = m->n_mats++;
    return 0;
}

static int read_color(cursor *c, vec3 *out, const char *what)
{
    float v[3];
    int n = 0, r;
    while (n < 3 && (r = number(c, &v[n], what)) > 0)
        n++;
    if (r < 0)
        return -1;
    if (n == 0)
        return fr_fail(c->err, "%s:%d: %s: expected r [g b]", c->name, c->line, what);
    if (n == 1)
        v[1] = v[2] = v[0];
    else if (n == 2)
        return fr_fail(c->err, "%s:%d: %s: expected r [g b], got two numbers", c->name, c->line, what);
    if (v[0] < 0.0f || v[1] < 0.0f || v[2] < 0.0f)
        return fr_fail(c->err, "%s:%d: %s: colours must be >= 0", c->name, c->line, what);
    *out = v3(v[0], v[1], v[2]);
    return end_of_line(c, what);
}

static int read_scalar(cursor *c, float *out, const char *what, float lo, float hi)
{
    int r = number(c, out, what);
    if (r < 0)
        return -1;
    if (r == 0 || !(*out >= lo && *out <= hi))
        return fr_fail(c->err, "%s:%d: %s: expected a number in [%g, %g]", c->name, c->line, what, (double)lo,
                       (double)hi);
    return end_of_line(c, what);
}

/* MTL statements with no meaning here (ambient colour, texture maps until
 * textures arrive, PBR extensions): accepted and ignored. */
static int mtl_ignored(const char *kw)
{
    static const char *const names[] = {"Ka", "sharpness", "bump", "disp", "decal", "refl", "norm", "Pr", "Pm",
                                        "Ps", "Pc", "Pcr", "aniso", "anisor", "Km", NULL};
    if (!strncmp(kw, "map_", 4))
        return 1;
    for (int i = 0; names[i]; i++)
        if (!strcmp(kw, names[i]))
            return 1;
    return 0;
}

static int parse_mtl(const char *text, const char *name, mesh_data *m, uint32_t *cap, fr_error *err)
{
    cursor c = {skip_bom(text), name, 0, err};
    mesh_material *cur = NULL;
    char kw[64], arg[sizeof cur->name];
    while (*c.p) {
        c.line++;
        const char *next = strchr(c.p, '\n');
        if (word(&c, kw, sizeof kw)) {
            if (!strcmp(kw, "newmtl")) {
                if (name_rest(&c, arg, sizeof arg, "newmtl") < 0)
                    return -1;
                uint32_t i;
                if (mat_find(m, cap, arg, c.line, &i, &c) < 0)
                    return -1;
                cur = &m->mats[i];
                if (cur->defined)
                    return fr_fail(err, "%s:%d: newmtl: the material is defined twice", name, c.line);
                int line = cur->line;
                mat_defaults(cur, arg);
                cur->line = line;
                cur->defined = 1;
            } else if (mtl_ignored(kw)) {
                /* skipped */
            } else if (!cur) {
                return fr_fail(err, "%s:%d: a material statement before any newmtl", name, c.line);
            } else if (!strcmp(kw, "Kd")) {
                if (read_color(&c, &cur->kd, "Kd") < 0) return -1;
            } else if (!strcmp(kw, "Ks")) {
                if (read_color(&c, &cur->ks, "Ks") < 0) return -1;
            } else if (!strcmp(kw, "Ke")) {
                if (read_color(&c, &cur->ke, "Ke") < 0) return -1;
            } else if (!strcmp(kw, "Tf")) {
                if (read_color(&c, &cur->tf, "Tf") < 0) return -1;
            } else if (!strcmp(kw, "Ns")) {
                if (read_scalar(&c, &cur->ns, "Ns", 0.0f, 1.0e6f) < 0) return -1;
            } else if (!strcmp(kw, "Ni")) {
                if (read_scalar(&c, &cur->ni, "Ni", 0.0f, 16.0f) < 0) return -1;
            } else if (!strcmp(kw, "d")) {
                if (read_scalar(&c, &cur->d, "d", 0.0f, 1.0f) < 0) return -1;
            } else if (!strcmp(kw, "Tr")) {
                float tr;
                if (read_scalar(&c, &tr, "Tr", 0.0f, 1.0f) < 0) return -1;
                cur->d = 1.0f - tr;
            } else if (!strcmp(kw, "illum")) {
                float v;
                if (read_scalar(&c, &v, "illum", 0.0f, 10.0f) < 0) return -1;
                if (v != floorf(v))
                    return fr_fail(err, "%s:%d: illum: expected an integer 0..10", name, c.line);
                cur->illum = (int)v;
            } else {
                return fr_fail(err, "%s:%d: unknown MTL statement (expected newmtl, Kd, Ks, Ke, Tf, Ns, Ni, d, Tr, "
                               "illum or map_*)", name, c.line);
            }
        }
        if (!next)
            break;
        c.p = next + 1;
    }
    return 0;
}

/* ---- geometry ---- */

typedef struct {
    mesh_data *m;
    cursor c;
    const char *dir;
    const confine *scope;       /* where mtllib files may be read */
    const obj_warn *warn;       /* where warnings go (NULL: nowhere) */
    fr_budget *budget;         /* counts the MTL files read (NULL: no limit) */
    /* raw attribute lists of the file */
    vec3 *v; uint32_t n_v, cap_v;
    vec2 *vt; uint32_t n_vt, cap_vt;
    vec3 *vn; uint32_t n_vn, cap_vn;
    /* unified vertices: (v, vt, vn) -> index, open addressing */
    uint32_t (*keys)[3]; uint32_t *vals; uint32_t hcap;
    uint32_t cap_vert, cap_tri, cap_mats;
    int any_vt, any_vn;
    uint32_t material;          /* current usemtl */
} parser;

static uint32_t hash3(const uint32_t k[3])
{
    uint64_t h = k[0] * 0x9E3779B97F4A7C15ull ^ (k[1] + 0x632BE59BD9B4E019ull) * 0xC2B2AE3D27D4EB4Full ^
                 (k[2] + 0x165667B19E3779F9ull) * 0x27D4EB2F165667C5ull;
    return (uint32_t)(h ^ (h >> 29));
}

static int rehash(parser *P)
{
    uint32_t ncap = P->hcap ? P->hcap * 2 : 1024;
    if (ncap < P->hcap)
        return -1;
    uint32_t (*keys)[3] = malloc((size_t)ncap * sizeof *keys);
    uint32_t *vals = malloc((size_t)ncap * sizeof *vals);
    if (!keys || !vals) {
        free(keys);
        free(vals);
        return -1;
    }
    for (uint32_t i = 0; i < ncap; i++)
        vals[i] = FR_NONE;
    for (uint32_t i = 0; i < P->hcap; i++) {
        if (P->vals[i] == FR_NONE)
            continue;
        uint32_t h = hash3(P->keys[i]) & (ncap - 1);
        while (vals[h] != FR_NONE)
            h = (h + 1) & (ncap - 1);
        memcpy(keys[h], P->keys[i], sizeof keys[h]);
        vals[h] = P->vals[i];
    }
    free(P->keys);
    free(P->vals);
    P->keys = keys;
    P->vals = vals;
    P->hcap = ncap;
    return 0;
}

/* The unified vertex of corner (v, vt, vn) (FR_NONE for absent parts). */
static int vertex(parser *P, const uint32_t k[3], uint32_t *out)
{
    mesh_data *m = P->m;
    if ((uint64_t)m->n_vert * 2 >= P->hcap && rehash(P) < 0)
        return fr_fail(P->c.err, "%s:%d: out of memory", P->c.name, P->c.line);
    uint32_t h = hash3(k) & (P->hcap - 1);
    while (P->vals[h] != FR_NONE) {
        if (!memcmp(P->keys[h], k, sizeof P->keys[h])) {
            *out = P->vals[h];
            return 0;
        }
        h = (h + 1) & (P->hcap - 1);
    }
    if (m->n_vert == P->cap_vert) {
        uint32_t c1 = P->cap_vert, c2 = c1, c3 = c1;
        if (grow(&m->pos, &c1, m->n_vert + 1ull, sizeof *m->pos) < 0 ||
            grow(&m->nrm, &c2, m->n_vert + 1ull, sizeof *m->nrm) < 0 ||
            grow(&m->uv, &c3, m->n_vert + 1ull, sizeof *m->uv) < 0)
            return fr_fail(P->c.err, "%s:%d: out of memory", P->c.name, P->c.line);
        P->cap_vert = c1;
    }
    uint32_t i = m->n_vert++;
    m->pos[i] = P->v[k[0]];
    m->nrm[i] = k[2] == FR_NONE ? v3s(0.0f) : P->vn[k[2]];
    m->uv[i] = k[1] == FR_NONE ? (vec2){0.0f, 0.0f} : P->vt[k[1]];
    memcpy(P->keys[h], k, sizeof P->keys[h]);
    P->vals[h] = i;
    *out = i;
    return 0;
}

/* An OBJ index (1-based, or negative: relative to the `count` so far). */
static int resolve(parser *P, long idx, uint32_t count, const char *what, uint32_t *out)
{
    if (idx > 0 && (uint64_t)idx <= count) {
        *out = (uint32_t)(idx - 1);
        return 0;
    }
    if (idx < 0 && (uint64_t)(-idx) <= count) {
        *out = (uint32_t)(count + idx);
        return 0;
    }
    return fr_fail(P->c.err, "%s:%d: %s index %ld out of range (%u defined so far)", P->c.name, P->c.line, what, idx,
                   count);
}

static int push_tri(parser *P, uint32_t a, uint32_t b, uint32_t c, uint8_t flags)
{
    mesh_data *m = P->m;
    if (m->n_tri == P->cap_tri) {
        uint32_t c1 = P->cap_tri, c2 = c1, c3 = c1;
        if (grow(&m->tri, &c1, m->n_tri + 1ull, sizeof *m->tri) < 0 ||
            grow(&m->tri_flags, &c2, m->n_tri + 1ull, 1) < 0 ||
            grow(&m->tri_mat, &c3, m->n_tri + 1ull, sizeof *m->tri_mat) < 0)
            return fr_fail(P->c.err, "%s:%d: out of memory", P->c.name, P->c.line);
        P->cap_tri = c1;
    }
    m->tri[m->n_tri][0] = a;
    m->tri[m->n_tri][1] = b;
    m->tri[m->n_tri][2] = c;
    m->tri_flags[m->n_tri] = flags;
    m->tri_mat[m->n_tri] = P->material;
    m->n_tri++;
    return 0;
}

static double cross2(const double *o, const double *a, const double *b)
{
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

/* Is p inside or on triangle (a, b, c) of orientation `sign`? */
static int in_tri(const double *a, const double *b, const double *c, const double *p, double sign)
{
    return sign * cross2(a, b, p) >= 0.0 && sign * cross2(b, c, p) >= 0.0 && sign * cross2(c, a, p) >= 0.0;
}

/* Triangulate polygon vert[0..n) (unified indices) by ear clipping in the
 * plane of its Newell normal, keeping the file's winding. */
static int triangulate(parser *P, uint32_t *vert, uint32_t n, uint8_t flags)
{
    const vec3 *pos = P->m->pos;
    if (n == 3)
        return push_tri(P, vert[0], vert[1], vert[2], flags);
    double nx = 0, ny = 0, nz = 0;
    for (uint32_t i = 0; i < n; i++) {
        vec3 a = pos[vert[i]], b = pos[vert[(i + 1) % n]];
        nx += ((double)a.y - b.y) * ((double)a.z + b.z);
        ny += ((double)a.z - b.z) * ((double)a.x + b.x);
        nz += ((double)a.x - b.x) * ((double)a.y + b.y);
    }
    double ax = fabs(nx), ay = fabs(ny), az = fabs(nz);
    if (n > EAR_MAX || (ax == 0.0 && ay == 0.0 && az == 0.0)) {
        for (uint32_t i = 1; i + 1 < n; i++)
            if (push_tri(P, vert[0], vert[i], vert[i + 1], flags) < 0)
                return -1;
        return 0;
    }
    /* Project by dropping the normal's largest axis; the sign of that
     * component is the polygon's orientation in the projection. */
    int drop = ax >= ay && ax >= az ? 0 : ay >= az ? 1 : 2;
    double sign = (drop == 0 ? nx : drop == 1 ? ny : nz) > 0.0 ? 1.0 : -1.0;
    double pt[EAR_MAX][2];
    uint32_t idx[EAR_MAX];
    for (uint32_t i = 0; i < n; i++) {
        vec3 p = pos[vert[i]];
        double c3[3] = {p.x, p.y, p.z};
        pt[i][0] = c3[(drop + 1) % 3];
        pt[i][1] = c3[(drop + 2) % 3];
        idx[i] = i;
    }
    uint32_t left = n;
    while (left > 3) {
        int found = 0;
        for (uint32_t k = 1; k <= left && !found; k++) {
            uint32_t ip = idx[(k - 1) % left], ic = idx[k % left], in = idx[(k + 1) % left];
            if (sign * cross2(pt[ip], pt[ic], pt[in]) <= 0.0)
                continue;   /* reflex or flat corner: not an ear */
            int empty = 1;
            for (uint32_t j = 0; j < left && empty; j++) {
                uint32_t q = idx[j];
                if (q != ip && q != ic && q != in && in_tri(pt[ip], pt[ic], pt[in], pt[q], sign))
                    empty = 0;
            }
            if (!empty)
                continue;
            if (push_tri(P, vert[ip], vert[ic], vert[in], flags) < 0)
                return -1;
            memmove(idx + k % left, idx + k % left + 1, (left - k % left - 1) * sizeof *idx);
            left--;
            found = 1;
        }
        if (!found)
            break;   /* self-intersecting or degenerate: fan the rest */
    }
    for (uint32_t i = 1; i + 1 < left; i++)
        if (push_tri(P, vert[idx[0]], vert[idx[i]], vert[idx[i + 1]], flags) < 0)
            return -1;
    return 0;
}

static int parse_face(parser *P)
{
    cursor *c = &P->c;
    uint32_t stack_buf[EAR_MAX], *vert = stack_buf, cap = EAR_MAX, n = 0;
    int all_vt = 1, all_vn = 1, rc = 0;
    for (;;) {
        skip_space(c);
        if (at_end(c->p))
            break;
        long part[3] = {0, 0, 0};
        int have[3] = {0, 0, 0};
        for (int k = 0; k < 3; k++) {
            if (k > 0) {
                if (*c->p != '/')
                    break;
                c->p++;
            }
            if (*c->p == '/' || is_space(*c->p) || at_end(c->p)) {
                if (k == 0)
                    break;
                continue;
            }
            char *end;
            errno = 0;
            part[k] = strtol(c->p, &end, 10);
            if (end == c->p || errno)
                break;
            c->p = end;
            have[k] = 1;
        }
        if (!have[0] || !(is_space(*c->p) || at_end(c->p))) {
            rc = fr_fail(c->err, "%s:%d: expected a face corner v, v/vt, v//vn or v/vt/vn", c->name, c->line);
            break;
        }
        uint32_t k[3] = {FR_NONE, FR_NONE, FR_NONE}, u = 0;
        if (resolve(P, part[0], P->n_v, "vertex", &k[0]) < 0 ||
            (have[1] && resolve(P, part[1], P->n_vt, "texture coordinate", &k[1]) < 0) ||
            (have[2] && resolve(P, part[2], P->n_vn, "normal", &k[2]) < 0) || vertex(P, k, &u) < 0) {
            rc = -1;
            break;
        }
        all_vt &= have[1];
        all_vn &= have[2];
        P->any_vt |= have[1];
        P->any_vn |= have[2];
        if (n == cap) {
            uint32_t *q = vert == stack_buf ? malloc(2 * (size_t)cap * sizeof *q) : realloc(vert, 2 * (size_t)cap * sizeof *q);
            if (!q) {
                rc = fr_fail(c->err, "%s:%d: out of memory", c->name, c->line);
                break;
            }
            if (vert == stack_buf)
                memcpy(q, stack_buf, sizeof stack_buf);
            vert = q;
            cap *= 2;
        }
        vert[n++] = u;
    }
    if (rc == 0 && n < 3)
        rc = fr_fail(c->err, "%s:%d: a face needs at least 3 corners, got %u", c->name, c->line, n);
    if (rc == 0)
        rc = triangulate(P, vert, n, (uint8_t)((all_vn ? FR_TRI_NORMALS : 0) | (all_vt ? FR_TRI_UVS : 0)));
    if (vert != stack_buf)
        free(vert);
    return rc;
}

/* OBJ statements with no meaning for a triangle mesh (smoothing groups,
 * lines, points, free-form geometry): accepted and ignored. */
static int obj_ignored(const char *kw)
{
    static const char *const names[] = {"s", "l", "p", "vp", "cstype", "deg", "bmat", "step", "curv", "curv2",
                                        "surf", "parm", "trim", "hole", "scrv", "sp", "end", "con", "mg",
                                        "lod", "bevel", "c_interp", "d_interp", "usemap", "maplib",
                                        "shadow_obj", "trace_obj", "ctech", "stech", NULL};
    for (int i = 0; names[i]; i++)
        if (!strcmp(kw, names[i]))
            return 1;
    return 0;
}

static void warn(parser *P, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void warn(parser *P, const char *fmt, ...)
{
    if (!P->warn || !P->warn->fn)
        return;
    char msg[sizeof ((fr_error *)0)->msg];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    fr_escape_controls(msg, sizeof msg);
    P->warn->fn(P->warn->user, msg);
}

static int load_mtllib(parser *P, const char *file)
{
    char path[4096];
    if (snprintf(path, sizeof path, "%s%s%s", file[0] == '/' ? "" : P->dir, file[0] == '/' ? "" : "/", file) >=
        (int)sizeof path)
        return fr_fail(P->c.err, "%s:%d: mtllib path too long", P->c.name, P->c.line);
    char *text, where[4200];
    size_t len;
    fr_error e;
    snprintf(where, sizeof where, "%s:%d: mtllib", P->c.name, P->c.line);
    /* A missing library is what Blender and Assimp shrug off (a file sent
     * without its .mtl): its names get the default material. */
    struct stat st;
    if (stat(path, &st) < 0 && (errno == ENOENT || errno == ENOTDIR)) {
        warn(P, "%s:%d: mtllib: %s does not exist: the materials it would define get the default material",
             P->c.name, P->c.line, path);
        return 0;
    }
    if (budget_take_file(P->budget, path, where, P->c.err) < 0)
        return -1;
    if (confine_read(P->scope, path, FILE_READ_MAX, &text, &len, &e) < 0)
        return fr_fail(P->c.err, "%s:%d: mtllib: %s", P->c.name, P->c.line, e.msg);
    int rc = not_text(text, len, path, P->c.err) < 0 ? -1 : parse_mtl(text, path, P->m, &P->cap_mats, P->c.err);
    free(text);
    return rc;
}

static int parse_line(parser *P, const char *kw)
{
    cursor *c = &P->c;
    mesh_data *m = P->m;
    if (!strcmp(kw, "v")) {
        float num[7];
        int n = 0, r = 0;
        while (n < 7 && (r = number(c, &num[n], "v")) > 0)
            n++;
        if (r < 0)
            return -1;
        /* x y z, then w or a vertex colour (not used) */
        if (n == 7)
            return fr_fail(c->err, "%s:%d: v: too many numbers (expected x y z [w] or x y z r g b)", c->name, c->line);
        if (n != 3 && n != 4 && n != 6)
            return fr_fail(c->err, "%s:%d: v: expected x y z [w] or x y z r g b, got %d numbers", c->name, c->line,
                           n);
        if (end_of_line(c, "v x y z") < 0)
            return -1;
        if (grow(&P->v, &P->cap_v, P->n_v + 1ull, sizeof *P->v) < 0)
            return fr_fail(c->err, "%s:%d: out of memory", c->name, c->line);
        P->v[P->n_v++] = v3(num[0], num[1], num[2]);
    } else if (!strcmp(kw, "vt")) {
        vec2 t = {0.0f, 0.0f};
        float w;
        int r = number(c, &t.u, "vt u");
        if (r <= 0)
            return r < 0 ? -1 : fr_fail(c->err, "%s:%d: vt: expected u [v [w]]", c->name, c->line);
        if ((r = number(c, &t.v, "vt v")) < 0 || (r > 0 && number(c, &w, "vt w") < 0) ||
            end_of_line(c, "vt u v w") < 0)
            return -1;
        if (grow(&P->vt, &P->cap_vt, P->n_vt + 1ull, sizeof *P->vt) < 0)
            return fr_fail(c->err, "%s:%d: out of memory", c->name, c->line);
        P->vt[P->n_vt++] = t;
    } else if (!strcmp(kw, "vn")) {
        vec3 n;
        int r;
        if ((r = number(c, &n.x, "vn x")) <= 0 || (r = number(c, &n.y, "vn y")) <= 0 ||
            (r = number(c, &n.z, "vn z")) <= 0)
            return r < 0 ? -1 : fr_fail(c->err, "%s:%d: vn: expected x y z", c->name, c->line);
        if (end_of_line(c, "vn x y z") < 0)
            return -1;
        if (grow(&P->vn, &P->cap_vn, P->n_vn + 1ull, sizeof *P->vn) < 0)
            return fr_fail(c->err, "%s:%d: out of memory", c->name, c->line);
        P->vn[P->n_vn++] = n;
    } else if (!strcmp(kw, "f")) {
        return parse_face(P);
    } else if (!strcmp(kw, "g") || !strcmp(kw, "o")) {
        /* Groups and objects only name faces; all of them are loaded. */
    } else if (!strcmp(kw, "usemtl")) {
        char name[sizeof m->mats->name];
        if (name_rest(c, name, sizeof name, "usemtl") < 0)
            return -1;
        return mat_find(m, &P->cap_mats, name, c->line, &P->material, c);
    } else if (!strcmp(kw, "mtllib")) {
        char file[1024];
        int n = 0;
        while (word(c, file, sizeof file)) {
            n++;
            if (P->dir && load_mtllib(P, file) < 0)
                return -1;
        }
        if (n == 0)
            return fr_fail(c->err, "%s:%d: mtllib: expected a file name", c->name, c->line);
    } else if (!obj_ignored(kw)) {
        return fr_fail(c->err, "%s:%d: unknown OBJ statement (expected v, vt, vn, f, g, o, s, usemtl or "
                       "mtllib)", c->name, c->line);
    }
    return 0;
}

static int parse_obj(const char *text, size_t len, const char *name, const char *dir, const confine *scope,
                     fr_budget *budget, const obj_warn *wn, mesh_data *m, fr_error *err)
{
    memset(m, 0, sizeof *m);
    confine own;
    if (dir && !scope) {
        char here[4200];
        snprintf(here, sizeof here, "%s/.", dir);
        if (confine_init(&own, here, NULL, 0, err) < 0)
            return -1;
        scope = &own;
    }
    /* A private NUL-terminated copy: the number parser needs the NUL, and
     * fuzzers hand over bare bytes. */
    char *buf = malloc(len + 1);
    if (!buf)
        return fr_fail(err, "%s: out of memory", name);
    memcpy(buf, text, len);
    buf[len] = 0;
    parser P;
    memset(&P, 0, sizeof P);
    P.m = m;
    P.c = (cursor){buf, name, 0, err};
    P.dir = dir;
    P.scope = scope;
    P.budget = budget;
    P.warn = wn;
    int rc = not_text(text, len, name, err);
    if (rc == 0 && grow(&m->mats, &P.cap_mats, 1, sizeof *m->mats) < 0)
        rc = fr_fail(err, "%s: out of memory", name);
    if (rc == 0) {
        mat_defaults(&m->mats[0], "(default)");
        m->mats[0].kd = v3s(0.8f);
        m->mats[0].defined = 1;
        m->n_mats = 1;
    }
    const char *p = skip_bom(buf);
    char kw[64];
    while (rc == 0 && *p) {
        P.c.line++;
        P.c.p = p;
        const char *next = strchr(p, '\n');
        if (word(&P.c, kw, sizeof kw))
            rc = parse_line(&P, kw);
        if (!next)
            break;
        p = next + 1;
    }
    if (rc == 0 && m->n_tri == 0)
        rc = fr_fail(err, "%s: no faces", name);
    free(P.v); free(P.vt); free(P.vn);
    free(P.keys); free(P.vals);
    free(buf);
    if (rc < 0) {
        mesh_data_free(m);
        return -1;
    }
    if (!P.any_vn) { free(m->nrm); m->nrm = NULL; }
    if (!P.any_vt) { free(m->uv); m->uv = NULL; }
    return 0;
}

int obj_parse(const char *text, size_t len, const char *name, const char *dir, const confine *scope,
              const obj_warn *warn, mesh_data *m, fr_error *err)
{
    return parse_obj(text, len, name, dir, scope, NULL, warn, m, err);
}

int obj_parse_mtl(const char *text, size_t len, const char *name, mesh_data *m, fr_error *err)
{
    char *buf = malloc(len + 1);
    if (!buf)
        return fr_fail(err, "%s: out of memory", name);
    memcpy(buf, text, len);
    buf[len] = 0;
    uint32_t cap = m->n_mats;
    int rc = 0;
    if (m->n_mats == 0) {
        /* mats[0] is always the default material, never found by name. */
        if (grow(&m->mats, &cap, 1, sizeof *m->mats) < 0) {
            free(buf);
            return fr_fail(err, "%s: out of memory", name);
        }
        mat_defaults(&m->mats[0], "(default)");
        m->mats[0].kd = v3s(0.8f);
        m->mats[0].defined = 1;
        m->n_mats = 1;
    }
    rc = not_text(text, len, name, err) < 0 ? -1 : parse_mtl(buf, name, m, &cap, err);
    free(buf);
    return rc;
}

int obj_read(const char *path, const confine *scope, fr_budget *budget, const obj_warn *warn, mesh_data *m,
             fr_error *err)
{
    char *text;
    size_t len;
    if ((scope ? confine_read(scope, path, FILE_READ_MAX, &text, &len, err) : file_read(path, &text, &len, err)) < 0)
        return -1;
    char dir[4096];
    file_dir(path, dir, sizeof dir);
    int rc = parse_obj(text, len, path, dir, scope, budget, warn, m, err);
    free(text);
    return rc;
}
