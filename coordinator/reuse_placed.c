/* reuse_placed.c -- a frame made of the frame before's mesh sections and a
 * skeleton's placements (see reuse_placed.h). */
#include "reuse_placed.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "file.h"
#include "fpatch.h"

/* Section ids (common/FORMAT.md). */
enum {
    S_PRIMS = 4, S_TRIANGLES = 7, S_POSITIONS = 8, S_NORMALS = 9, S_UVS = 10, S_MESHES = 22, S_MESH_NODES = 24,
    S_MESH_LEAVES = 25, S_OBJECTS = 29
};

int reuse_placed_bounds(const fr_scene *s, float **bounds, uint32_t *n, fr_error *err)
{
    *bounds = NULL;
    *n = 0;
    if (!s->n_meshes)
        return 0;
    float *b = malloc(sizeof(float) * 6 * s->n_meshes);
    if (!b)
        return fr_fail(err, "out of memory for the meshes' bounds");
    for (uint32_t k = 0; k < s->n_meshes; k++) {
        const fr_mesh *m = &s->meshes[k];
        vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY);
        if (m->prim_first > s->n_prims || m->n_prims > s->n_prims - m->prim_first) {
            free(b);
            return fr_fail(err, "mesh %u: prims out of range", k);
        }
        for (uint32_t i = m->prim_first; i < m->prim_first + m->n_prims; i++) {
            const fr_prim *p = &s->prims[i];
            if (p->kind != FR_PRIM_TRIANGLE || p->index >= s->n_triangles) {
                free(b);
                return fr_fail(err, "mesh %u: prim %u is not a triangle", k, i);
            }
            for (int c = 0; c < 3; c++) {
                uint32_t v = s->triangles[p->index].v[c];
                if (v >= s->n_positions) {
                    free(b);
                    return fr_fail(err, "mesh %u: vertex %u out of range", k, v);
                }
                lo = v3_vmin(lo, s->positions[v]);
                hi = v3_vmax(hi, s->positions[v]);
            }
        }
        float *o = b + 6 * (size_t)k;
        o[0] = lo.x, o[1] = lo.y, o[2] = lo.z, o[3] = hi.x, o[4] = hi.y, o[5] = hi.z;
    }
    *bounds = b;
    *n = s->n_meshes;
    return 0;
}

/* The number of prims of a scene's tree (before the meshes' prims), or
 * -1 when the meshes' table does not say so plainly. */
static int64_t tree_prims(const fpatch_sect *s)
{
    const fr_mesh *m = s[S_MESHES].data;
    uint64_t in_meshes = 0;
    for (uint64_t k = 0; k < s[S_MESHES].count; k++)
        in_meshes += m[k].n_prims;
    if (in_meshes > s[S_PRIMS].count)
        return -1;
    uint64_t top = s[S_PRIMS].count - in_meshes;
    for (uint64_t k = 0; k < s[S_MESHES].count; k++) {
        if (m[k].prim_first != top)
            return -1;
        top += m[k].n_prims;
    }
    return (int64_t)(s[S_PRIMS].count - in_meshes);
}

/* 1 when elements [a, a + n) of section x and [b, b + n) of y are the same bytes. */
static int same_range(const fpatch_sect *x, uint64_t a, const fpatch_sect *y, uint64_t b, uint64_t n)
{
    if (x->elem != y->elem || a + n > x->count || b + n > y->count)
        return 0;
    return n == 0 || !memcmp((const char *)x->data + a * x->elem, (const char *)y->data + b * y->elem, n * x->elem);
}

/* Appends elements [a, a + n) of s at *at (a buffer of the right size). */
static void put(char **at, const fpatch_sect *s, uint64_t a, uint64_t n)
{
    if (n) {
        memcpy(*at, (const char *)s->data + a * s->elem, n * s->elem);
        *at += n * s->elem;
    }
}

static int is_mesh_section(int id)
{
    return id == S_TRIANGLES || id == S_POSITIONS || id == S_NORMALS || id == S_UVS || id == S_MESHES ||
           id == S_MESH_NODES || id == S_MESH_LEAVES;
}

int reuse_placed_splice(const fr_scene *full, const fr_scene *was, const fr_scene *now, const char *out,
                        fr_error *err)
{
    fpatch_sect f[FPATCH_SECTIONS + 1], w[FPATCH_SECTIONS + 1], n[FPATCH_SECTIONS + 1];
    fr_error e;
    if (fpatch_sections(full->blob, full->blob_size, f, &e) < 0 ||
        fpatch_sections(was->blob, was->blob_size, w, &e) < 0 ||
        fpatch_sections(now->blob, now->blob_size, n, &e) < 0 || !f[S_MESHES].count)
        return 0;
    for (int id = 1; id <= FPATCH_SECTIONS; id++) {
        if (is_mesh_section(id) ? !fpatch_same(&w[id], &n[id])
                                : id != S_PRIMS && id != S_OBJECTS && !fpatch_same(&w[id], &f[id]))
            return 0;
    }
    /* prims: the tree's (was's as full's, now's), then the meshes' (full's). */
    int64_t ft = tree_prims(f), wt = tree_prims(w), nt = tree_prims(n);
    if (ft < 0 || wt != ft || nt != ft || !same_range(&w[S_PRIMS], 0, &f[S_PRIMS], 0, (uint64_t)ft))
        return 0;
    uint64_t top = (uint64_t)ft, fp = f[S_PRIMS].count, wp = w[S_PRIMS].count, np = n[S_PRIMS].count;
    /* objects: one per prim, then per plane and instance; or none. */
    uint64_t fo = f[S_OBJECTS].count, wo = w[S_OBJECTS].count, no = n[S_OBJECTS].count;
    if (!fo != !wo || !fo != !no || (fo && (fo < fp || wo < wp || no < np || fo - fp != wo - wp ||
                                            !same_range(&w[S_OBJECTS], 0, &f[S_OBJECTS], 0, top) ||
                                            !same_range(&w[S_OBJECTS], wp, &f[S_OBJECTS], fp, fo - fp))))
        return 0;
    fpatch_sect s[FPATCH_SECTIONS + 1];
    for (int id = 1; id <= FPATCH_SECTIONS; id++)
        s[id] = is_mesh_section(id) ? f[id] : n[id];
    char *prims = malloc(fp * sizeof(fr_prim) + 1), *objects = malloc((fo ? top + (fp - top) + (no - np) : 0) * 4 + 1);
    int rc = 0;
    if (!prims || !objects)
        rc = fr_fail(err, "out of memory for the frame's scene");
    if (rc == 0) {
        char *at = prims;
        put(&at, &n[S_PRIMS], 0, top);
        put(&at, &f[S_PRIMS], top, fp - top);
        s[S_PRIMS].data = prims;
        s[S_PRIMS].count = fp;
        at = objects;
        if (fo) {
            put(&at, &n[S_OBJECTS], 0, top);
            put(&at, &f[S_OBJECTS], top, fp - top);
            put(&at, &n[S_OBJECTS], np, no - np);
            s[S_OBJECTS].data = objects;
            s[S_OBJECTS].count = fp + (no - np);
        }
    }
    void *blob = NULL;
    size_t size;
    uint64_t hash;
    int made = 0;
    if (rc == 0 && fpatch_assemble(s, &blob, &size, &hash, &e) == 0) {
        made = 1;
        rc = file_write_atomic(out, blob, size, err);
    }
    free(blob);
    free(prims);
    free(objects);
    return rc < 0 ? -1 : made;
}
