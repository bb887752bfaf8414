/* mesh.c -- the JSON scene's `mesh` shape: files read, placed, levels of
 * detail (see mesh.h). */

#include "compile/mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "fmath.h"
#include "compile/builder_instance.h"
#include "compile/jsonval.h"
#include "compile/mesh_import.h"
#include "compile/standin.h"

#define XXH_INLINE_ALL
#include <xxhash.h>

enum { LOD_MAX = 16 };
#define LOD_DENSITY 0.25f      /* default triangles per pixel of projected area */

/* ---- reading files ---- */

/* Reads a mesh file by its extension, through `scope` (NULL: its own
 * folder): OBJ by obj_read, others by mesh_import into the same structure
 * (free with mesh_data_free).  The file's size, and each MTL file an OBJ
 * names, count against budget's read limit first (NULL: no limit). */
static int mesh_read(const fr_builder *b, const char *path, const confine *scope, mesh_data *m, fr_error *err)
{
    const char *dot = strrchr(path, '.');
    if (budget_take_file(b->budget, path, path, err) < 0)
        return -1;
    obj_warn w = {b->warn, b->warn_user};
    if (dot && !strcasecmp(dot, ".obj"))
        return obj_read(path, scope, b->budget, &w, m, err);
    return mesh_import(path, scope, m, err);
}

/* ---- placement ---- */

/* An affine transform: p' = M p + t (row-major 3x3 M). */
typedef struct { float m[3][3]; vec3 t; } xform;

static vec3 xf_point(const xform *x, vec3 p)
{
    return v3(x->m[0][0] * p.x + x->m[0][1] * p.y + x->m[0][2] * p.z + x->t.x,
              x->m[1][0] * p.x + x->m[1][1] * p.y + x->m[1][2] * p.z + x->t.y,
              x->m[2][0] * p.x + x->m[2][1] * p.y + x->m[2][2] * p.z + x->t.z);
}

static void mat_mul(float r[3][3], const float a[3][3], const float b[3][3])
{
    float t[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            t[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
    memcpy(r, t, sizeof t);
}

static int has(const cJSON *o, const char *k) { return cJSON_GetObjectItemCaseSensitive(o, k) != NULL; }

static int read_xform(const cJSON *o, const char *where, xform *x, float *det, fr_error *err)
{
    memset(x, 0, sizeof *x);
    x->m[0][0] = x->m[1][1] = x->m[2][2] = 1.0f;
    const cJSON *mx = cJSON_GetObjectItemCaseSensitive(o, "matrix");
    if (mx) {
        if (has(o, "scale") || has(o, "rotate") || has(o, "translate"))
            return fr_fail(err, "%s.matrix: give either matrix or scale/rotate/translate, not both", where);
        if (!cJSON_IsArray(mx) || cJSON_GetArraySize(mx) != 16)
            return fr_fail(err, "%s.matrix: expected 16 numbers (4x4, row-major)", where);
        float v[16];
        for (int i = 0; i < 16; i++) {
            const cJSON *e = cJSON_GetArrayItem(mx, i);
            if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > JV_MAX)
                return fr_fail(err, "%s.matrix[%d]: expected a finite number", where, i);
            v[i] = (float)e->valuedouble;
        }
        if (v[12] != 0.0f || v[13] != 0.0f || v[14] != 0.0f || v[15] != 1.0f)
            return fr_fail(err, "%s.matrix: the last row must be 0 0 0 1 (no projective transforms)", where);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                x->m[i][j] = v[4 * i + j];
        x->t = v3(v[3], v[7], v[11]);
    } else {
        vec3 s = v3s(1.0f), r, t;
        const cJSON *sc = cJSON_GetObjectItemCaseSensitive(o, "scale");
        if (cJSON_IsNumber(sc)) {
            float k;
            if (jv_number(o, "scale", where, 1, 1.0f, &k, err) < 0)
                return -1;
            s = v3s(k);
        } else if (jv_vec3(o, "scale", where, 0, v3s(1.0f), &s, err) < 0) {
            return -1;
        }
        if (jv_vec3(o, "rotate", where, 0, v3s(0.0f), &r, err) < 0 ||
            jv_vec3(o, "translate", where, 0, v3s(0.0f), &t, err) < 0)
            return -1;
        float S[3][3] = {{s.x, 0, 0}, {0, s.y, 0}, {0, 0, s.z}};
        memcpy(x->m, S, sizeof S);
        /* Rotations about x, then y, then z (degrees, right-handed). */
        float ang[3] = {r.x, r.y, r.z};
        for (int a = 0; a < 3; a++) {
            if (ang[a] == 0.0f)
                continue;
            float sn, cs;
            fm_sincosf(ang[a] * (FM_PI / 180.0f), &sn, &cs);
            float R[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
            int i = (a + 1) % 3, j = (a + 2) % 3;
            R[i][i] = cs; R[i][j] = -sn;
            R[j][i] = sn; R[j][j] = cs;
            mat_mul(x->m, R, x->m);
        }
        x->t = t;
    }
    const float (*m)[3] = x->m;
    *det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if (!(fabsf(*det) > 1.0e-30f) || !isfinite(*det))
        return fr_fail(err, "%s: the transform is singular (a zero scale?)", where);
    return 0;
}

/* The inverse transpose of x's linear part, for normals. */
static void normal_matrix(const xform *x, float det, float n[3][3])
{
    const float (*m)[3] = x->m;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            n[i][j] = (m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]) / det;
        }
}

/* ---- level of detail ---- */

/* Projected area, in pixels, of the bounding sphere of the mesh's placed
 * vertices as the camera sees it (capped at the image); infinite when the
 * camera is inside the sphere. */
static float projected_pixels(const fr_builder *b, const mesh_data *m, const xform *x)
{
    vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY);
    for (uint32_t i = 0; i < m->n_vert; i++) {
        vec3 p = xf_point(x, m->pos[i]);
        lo = v3_vmin(lo, p);
        hi = v3_vmax(hi, p);
    }
    vec3 c = v3_scale(v3_add(lo, hi), 0.5f);
    float r = 0.5f * v3_len(v3_sub(hi, lo));
    float d = v3_len(v3_sub(c, b->camera.position));
    if (d <= r)
        return INFINITY;
    const fr_camera *cam = &b->camera;
    float h = (float)b->settings.height, w = (float)b->settings.width;
    float r_px = r / (d * cam->tan_half) * 0.5f * h;
    float area = FM_PI * r_px * r_px;
    return area < w * h ? area : w * h;
}

/* ---- the hook ---- */

static int only_fields(const cJSON *o, const char *where, fr_error *err)
{
    static const char *const ok[] = {"type", "material", "file", "lod", "lod_density", "scale", "rotate",
                                     "translate", "matrix", "normals", "instances", NULL};
    for (const cJSON *c = o->child; c; c = c->next) {
        int found = 0;
        for (int i = 0; ok[i] && !found; i++)
            found = !strcmp(c->string, ok[i]);
        if (!found)
            return fr_fail(err, "%s.%s: unknown field (mesh fields: file, lod, lod_density, material, scale, "
                           "rotate, translate, matrix, normals, instances)", where, c->string);
    }
    return 0;
}

/* The `instances` of a mesh shape: each a transform (scale, rotate,
 * translate or matrix) placing mesh `mesh` once more. */
static int place_instances(fr_builder *b, const cJSON *list, const char *where, uint32_t mesh, fr_error *err)
{
    int i = 0;
    for (const cJSON *e = list->child; e; e = e->next, i++) {
        char at[512];
        snprintf(at, sizeof at, "%s.instances[%d]", where, i);
        if (!cJSON_IsObject(e))
            return fr_fail(err, "%s: expected an object with scale, rotate, translate or matrix", at);
        for (const cJSON *c = e->child; c; c = c->next)
            if (strcmp(c->string, "scale") && strcmp(c->string, "rotate") && strcmp(c->string, "translate") &&
                strcmp(c->string, "matrix"))
                return fr_fail(err, "%s.%s: unknown field (an instance has scale, rotate, translate or matrix)", at,
                               c->string);
        xform x;
        float det;
        if (read_xform(e, at, &x, &det, err) < 0)
            return -1;
        float xf[3][4];
        for (int r = 0; r < 3; r++) {
            for (int c = 0; c < 3; c++)
                xf[r][c] = x.m[r][c];
        }
        xf[0][3] = x.t.x;
        xf[1][3] = x.t.y;
        xf[2][3] = x.t.z;
        fr_error e2;
        if (bld_instance(b, mesh, (const float(*)[4])xf, &e2) < 0)
            return fr_fail(err, "%s: %s", at, e2.msg);
    }
    return 0;
}

/* Names of the levels of detail, finest first, as paths next to the scene. */
static int level_paths(const cJSON *o, const char *where, const char *dir, char paths[][4096], int *n,
                       fr_error *err)
{
    const cJSON *file = cJSON_GetObjectItemCaseSensitive(o, "file");
    const cJSON *lod = cJSON_GetObjectItemCaseSensitive(o, "lod");
    const cJSON *names[LOD_MAX];
    *n = 0;
    if (!file == !lod)
        return fr_fail(err, "%s: give exactly one of file (a mesh file) or lod (files, finest first)", where);
    if (file) {
        if (!cJSON_IsString(file) || !file->valuestring[0])
            return fr_fail(err, "%s.file: expected a file name", where);
        names[(*n)++] = file;
    } else {
        if (!cJSON_IsArray(lod) || cJSON_GetArraySize(lod) < 1 || cJSON_GetArraySize(lod) > LOD_MAX)
            return fr_fail(err, "%s.lod: expected an array of 1 to %d file names, finest first", where, LOD_MAX);
        for (const cJSON *e = lod->child; e; e = e->next) {
            if (!cJSON_IsString(e) || !e->valuestring[0])
                return fr_fail(err, "%s.lod[%d]: expected a file name", where, *n);
            names[(*n)++] = e;
        }
    }
    for (int i = 0; i < *n; i++) {
        const char *s = names[i]->valuestring;
        if (snprintf(paths[i], 4096, "%s%s%s", s[0] == '/' ? "" : dir, s[0] == '/' ? "" : "/", s) >= 4096)
            return fr_fail(err, "%s: file name too long", where);
    }
    return 0;
}

/* Folds n bytes at p into *key. */
static void fold(uint64_t *key, const void *p, size_t n) { *key = XXH3_64bits_withSeed(p, n, *key); }

int mesh_key(const fr_builder *b, const cJSON *o, const char *where, const char *dir, uint32_t material,
             uint64_t *key, fr_error *err)
{
    char paths[LOD_MAX][4096];
    int levels;
    if (level_paths(o, where, dir, paths, &levels, err) < 0)
        return -1;
    char *text = cJSON_PrintUnformatted(o);
    if (!text)
        return fr_fail(err, "%s: out of memory", where);
    fold(key, where, strlen(where) + 1);
    fold(key, text, strlen(text) + 1);
    free(text);
    fold(key, &material, sizeof material);
    for (int i = 0; i < levels; i++) {
        struct stat st;
        uint64_t id[6] = {0};
        if (stat(paths[i], &st) == 0)
            id[0] = 1, id[1] = (uint64_t)st.st_dev, id[2] = (uint64_t)st.st_ino, id[3] = (uint64_t)st.st_size,
            id[4] = (uint64_t)st.st_mtim.tv_sec, id[5] = (uint64_t)st.st_mtim.tv_nsec;
        fold(key, paths[i], strlen(paths[i]) + 1);
        fold(key, id, sizeof id);
    }
    /* The level is chosen by the mesh's size on screen; a mesh with an
     * interior medium may hold the camera (fr_volume.camera_medium). */
    const fr_material *mats = b->materials.data;
    if (levels > 1 || (material != FR_NONE && material < b->materials.count && mats[material].medium)) {
        const fr_camera *c = &b->camera;
        float cam[12] = {c->position.x, c->position.y, c->position.z, c->target.x, c->target.y, c->target.z,
                         c->up.x, c->up.y, c->up.z, c->tan_half, (float)b->settings.width, (float)b->settings.height};
        fold(key, cam, sizeof cam);
    }
    return 0;
}

int mesh_stand_in(fr_builder *b, fr_error *err)
{
    mesh_material dm;
    memset(&dm, 0, sizeof dm);
    dm.kd = v3s(0.8f);
    dm.tf = v3s(1.0f);
    dm.ni = 1.5f;
    dm.d = 1.0f;
    dm.illum = -1;
    fr_material fm;
    mesh_data_material(&dm, &fm);
    uint32_t m = bld_push(&b->materials, &fm);
    if (m == FR_NONE || bld_sphere(b, v3s(0.0f), 1.0f, m) == FR_NONE)
        return fr_fail(err, "out of memory");
    return 0;
}

int mesh_stand_in_placed(fr_builder *b, const cJSON *node, const char *where, const float box[6],
                         uint32_t material, fr_error *err)
{
    const cJSON *insts = cJSON_GetObjectItemCaseSensitive(node, "instances");
    if (!cJSON_IsArray(insts) || cJSON_GetArraySize(insts) == 0)
        return fr_fail(err, "%s.instances: expected a non-empty array of transforms", where);
    uint32_t mesh;
    fr_error e;
    if (standin_mesh(b, box, material, &mesh, &e) < 0)
        return fr_fail(err, "%s: %s", where, e.msg);
    return place_instances(b, insts, where, mesh, err);
}

int mesh_add(fr_builder *b, const cJSON *o, const char *where, const char *dir, const confine *scope, uint32_t material,
             fr_error *err)
{
    char paths[LOD_MAX][4096];
    int levels;
    xform x;
    float det = 1.0f, density;
    if (only_fields(o, where, err) < 0 || level_paths(o, where, dir, paths, &levels, err) < 0 ||
        read_xform(o, where, &x, &det, err) < 0 ||
        jv_number(o, "lod_density", where, 0, LOD_DENSITY, &density, err) < 0)
        return -1;
    if (!(density > 0.0f))
        return fr_fail(err, "%s.lod_density: expected triangles per pixel > 0", where);
    int flat = 0;
    const cJSON *nm = cJSON_GetObjectItemCaseSensitive(o, "normals");
    if (nm) {
        if (!cJSON_IsString(nm) || (strcmp(nm->valuestring, "file") && strcmp(nm->valuestring, "flat")))
            return fr_fail(err, "%s.normals: expected \"file\" (smooth, from the file's vertex normals) or \"flat\"",
                           where);
        flat = !strcmp(nm->valuestring, "flat");
    }

    const cJSON *insts = cJSON_GetObjectItemCaseSensitive(o, "instances");
    if (insts && (!cJSON_IsArray(insts) || cJSON_GetArraySize(insts) == 0))
        return fr_fail(err, "%s.instances: expected a non-empty array of transforms", where);

    /* Level of detail: from the coarsest level up, the first with enough
     * triangles for the mesh's size on screen; the finest if none is (and
     * for a mesh placed by instances, which share one level). */
    mesh_data m;
    int level = insts ? 0 : levels - 1;
    if (mesh_read(b, paths[level], scope, &m, err) < 0)
        return -1;
    float need = insts ? 0.0f : density * projected_pixels(b, &m, &x);
    while (level > 0 && (float)m.n_tri < need) {
        mesh_data_free(&m);
        --level;
        if (mesh_read(b, paths[level], scope, &m, err) < 0)
            return -1;
    }
    if (budget_take(b->budget, BUDGET_VERTICES, m.n_vert, paths[level], err) < 0 ||
        budget_take(b->budget, BUDGET_TRIANGLES, m.n_tri, paths[level], err) < 0) {
        mesh_data_free(&m);
        return -1;
    }

    int rc = 0;
    /* Materials: the override, or one Franja material per MTL material the
     * mesh uses. */
    uint32_t *mat_of = calloc(m.n_mats, sizeof *mat_of);
    if (!mat_of) {
        mesh_data_free(&m);
        return fr_fail(err, "%s: out of memory", where);
    }
    for (uint32_t i = 0; i < m.n_mats; i++)
        mat_of[i] = material;
    if (material == FR_NONE) {
        /* A name no MTL file defines gets the default material (0), as in
         * Blender; one warning names the first use and the count. */
        uint32_t undefined = 0, first = 0;
        for (uint32_t t = 0; t < m.n_tri && rc == 0; t++) {
            uint32_t k = m.tri_mat[t];
            if (mat_of[k] != FR_NONE)
                continue;
            if (!m.mats[k].defined) {
                if (undefined++ == 0 || m.mats[k].line < m.mats[first].line)
                    first = k;
                if (mat_of[0] == FR_NONE) {
                    fr_material fm;
                    mesh_data_material(&m.mats[0], &fm);
                    if ((mat_of[0] = bld_push(&b->materials, &fm)) == FR_NONE)
                        rc = fr_fail(err, "%s: out of memory", where);
                }
                mat_of[k] = mat_of[0];
                continue;
            }
            fr_material fm;
            mesh_data_material(&m.mats[k], &fm);
            if ((mat_of[k] = bld_push(&b->materials, &fm)) == FR_NONE ||
                bld_material_name(b, mat_of[k], m.mats[k].name) < 0)
                rc = fr_fail(err, "%s: out of memory", where);
        }
        if (rc == 0 && undefined > 0 && b->warn) {
            char msg[sizeof err->msg];
            snprintf(msg, sizeof msg, "%s:%d: usemtl: %u material name%s defined in no mtllib file (the first used "
                     "here): %s the default material", paths[level], m.mats[first].line, undefined,
                     undefined == 1 ? "" : "s", undefined == 1 ? "it gets" : "they get");
            fr_escape_controls(msg, sizeof msg);
            b->warn(b->warn_user, msg);
        }
    }

    /* With instances, what follows is the mesh in its own space. */
    uint32_t mesh_id = FR_NONE;
    if (rc == 0 && insts && (mesh_id = bld_mesh_begin(b)) == FR_NONE)
        rc = fr_fail(err, "%s: out of memory", where);

    /* Vertices, placed; normals by the inverse transpose. */
    uint32_t base = b->positions.count;
    int use_n = m.nrm && !flat, use_uv = m.uv != NULL;
    float nmat[3][3];
    normal_matrix(&x, det, nmat);
    if (rc == 0 && ((use_n && bld_pad(&b->normals, base) < 0) || (use_uv && bld_pad(&b->uvs, base) < 0)))
        rc = fr_fail(err, "%s: out of memory", where);
    for (uint32_t i = 0; i < m.n_vert && rc == 0; i++) {
        vec3 p = xf_point(&x, m.pos[i]);
        if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z))
            rc = fr_fail(err, "%s: vertex %u of %s is not finite once transformed", where, i, paths[level]);
        else if (bld_push(&b->positions, &p) == FR_NONE)
            rc = fr_fail(err, "%s: out of memory", where);
        if (rc == 0 && use_n) {
            vec3 n = m.nrm[i];
            n = v3(nmat[0][0] * n.x + nmat[0][1] * n.y + nmat[0][2] * n.z,
                   nmat[1][0] * n.x + nmat[1][1] * n.y + nmat[1][2] * n.z,
                   nmat[2][0] * n.x + nmat[2][1] * n.y + nmat[2][2] * n.z);
            float l2 = v3_len2(n);
            n = l2 > 0.0f && isfinite(l2) ? v3_scale(n, 1.0f / sqrtf(l2)) : v3s(0.0f);
            if (bld_push(&b->normals, &n) == FR_NONE)
                rc = fr_fail(err, "%s: out of memory", where);
        }
        if (rc == 0 && use_uv && bld_push(&b->uvs, &m.uv[i]) == FR_NONE)
            rc = fr_fail(err, "%s: out of memory", where);
    }

    /* Triangles; a mirroring transform swaps two corners so the front side
     * stays the outside.  Zero-area triangles can never be hit and would
     * be zero-area lights: they are dropped. */
    const vec3 *pos = b->positions.data;
    for (uint32_t t = 0; t < m.n_tri && rc == 0; t++) {
        uint32_t a = base + m.tri[t][0], c1 = base + m.tri[t][1], c2 = base + m.tri[t][2];
        if (det < 0.0f) {
            uint32_t tmp = c1; c1 = c2; c2 = tmp;
        }
        if (!(v3_len2(v3_cross(v3_sub(pos[c1], pos[a]), v3_sub(pos[c2], pos[a]))) > 0.0f))
            continue;
        uint32_t flags = m.tri_flags[t] & ((use_n ? FR_TRI_NORMALS : 0) | (use_uv ? FR_TRI_UVS : 0));
        fr_triangle tri = {{a, c1, c2}, flags};
        uint32_t ti = bld_push(&b->triangles, &tri);
        fr_prim p = {FR_PRIM_TRIANGLE, ti, mat_of[m.tri_mat[t]], FR_NONE};
        if (ti == FR_NONE || bld_push(&b->prims, &p) == FR_NONE)
            rc = fr_fail(err, "%s: out of memory", where);
    }
    if (rc == 0 && insts)
        rc = bld_mesh_end(b, mesh_id, err) < 0 ? -1 : place_instances(b, insts, where, mesh_id, err);
    free(mat_of);
    mesh_data_free(&m);
    return rc;
}
