/* gltf_scene.c -- a glTF 2.0 scene into a builder (gltf_scene.h): nodes and
 * their transforms, meshes, the camera, punctual lights. */
#include "compile/gltf_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define XXH_INLINE_ALL
#include <xxhash.h>

#include "fmath.h"
#include "motion.h"
#include "compile/builder_instance.h"
#include "compile/builder_motion.h"
#include "compile/builder_object.h"
#include "compile/builder_light.h"
#include "compile/freeze.h"
#include "compile/gltf_anim.h"
#include "compile/gltf_doc.h"
#include "compile/gltf_mat.h"
#include "compile/standin.h"

/* Extensions read here or in gltf_mat.c; any other one used is reported. */
static const char *const known_extensions[] = {
    "KHR_texture_transform", "KHR_materials_emissive_strength", "KHR_lights_punctual", "KHR_mesh_quantization",
    "KHR_materials_transmission", "KHR_materials_ior", NULL};

enum { MODE_POINTS = 0, MODE_TRIANGLES = 4, MODE_STRIP = 5, MODE_FAN = 6 };

/* p' = M p + t, row-major; in double so that deep hierarchies keep their
 * precision until the vertices are rounded to float. */
typedef struct { double m[3][4]; } affine;

static void af_identity(affine *a)
{
    memset(a, 0, sizeof *a);
    a->m[0][0] = a->m[1][1] = a->m[2][2] = 1.0;
}

static void af_mul(affine *r, const affine *a, const affine *b)
{
    affine t;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 4; j++) {
            double s = a->m[i][0] * b->m[0][j] + a->m[i][1] * b->m[1][j] + a->m[i][2] * b->m[2][j];
            t.m[i][j] = j == 3 ? s + a->m[i][3] : s;
        }
    }
    *r = t;
}

static void af_apply(const affine *a, const double p[3], double w, double out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = a->m[i][0] * p[0] + a->m[i][1] * p[1] + a->m[i][2] * p[2] + w * a->m[i][3];
}

static double af_det(const affine *a)
{
    const double (*m)[4] = a->m;
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

/* Cofactor matrix of the linear part: the inverse transpose up to the
 * determinant's factor (normals are normalized afterwards; a negative
 * determinant is handled by the caller's sign). */
static void af_cofactor(const affine *a, double n[3][3])
{
    const double (*m)[4] = a->m;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            n[i][j] = m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1];
        }
}

typedef struct {
    gltf_doc *d;
    const scene_hooks *hooks;
    const gltf_options *o;
    fr_builder *b;
    gltf_result *r;
    gmat_ctx mat;
    uint32_t max_tri, vertices;
    int cam_node;              /* node whose camera was taken, or -1 */
    int counting;              /* the first pass over the nodes: only count the uses of each mesh */
    uint32_t *uses;            /* per glTF mesh: nodes that draw it */
    uint32_t *mesh_of;         /* per glTF mesh drawn more than once: its builder mesh, or FR_NONE */
    ganim_pose pose;           /* the animated nodes (o->animate), else empty */
    affine *world;             /* with skins: every node's world transform (from the counting pass) */
    unsigned char *placed;     /* with skins: which nodes of world are set (in the scene) */
    affine *shut[2];           /* with a shutter: every node's world transform at its opening and closing
                                  (gltf_motion), else NULL */
    int stand;                 /* reading a mesh for its materials only (placed_mesh): primitive() stops
                                  once it has made its material */
    uint32_t stand_mat;        /* then the first primitive's material, or FR_NONE */
} imp;

/* A skin as one node uses it: its joints' matrices (joint's world
 * transform times its inverse bind matrix). */
typedef struct {
    affine *joint;
    uint32_t n;
    uint32_t skin;             /* its index (messages) */
} skinning;

/* ---- nodes ------------------------------------------------------------ */

static int local_transform(imp *c, uint32_t n, affine *out, fr_error *err)
{
    gltf_doc *d = c->d;
    char ptr[48];
    snprintf(ptr, sizeof ptr, "/nodes/%u", n);
    const cJSON *o = d->nodes.v[n];
    double mx[16], t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    int has_m, has_t, has_r, has_s;
    if (gdoc_numbers(d, o, ptr, "matrix", 16, mx, &has_m, err) < 0 ||
        gdoc_numbers(d, o, ptr, "translation", 3, t, &has_t, err) < 0 ||
        gdoc_numbers(d, o, ptr, "rotation", 4, q, &has_r, err) < 0 ||
        gdoc_numbers(d, o, ptr, "scale", 3, s, &has_s, err) < 0)
        return -1;
    af_identity(out);
    const ganim_node *an = n < c->pose.n ? &c->pose.node[n] : NULL;
    if (an && an->set) {
        if (has_m)
            return gdoc_fail(d, err, ptr, "matrix: a node animated by /animations/%u/channels/%u must give "
                             "translation/rotation/scale instead", an->anim, an->channel);
        if (an->set & GANIM_T)
            memcpy(t, an->t, sizeof t);
        if (an->set & GANIM_R)
            memcpy(q, an->r, sizeof q), has_r = 1;
        if (an->set & GANIM_S)
            memcpy(s, an->s, sizeof s);
    }
    if (has_m) {
        if (has_t || has_r || has_s)
            return gdoc_fail(d, err, ptr, "both matrix and translation/rotation/scale");
        /* Column-major: element (row i, column j) is mx[4 j + i]. */
        if (mx[3] != 0.0 || mx[7] != 0.0 || mx[11] != 0.0 || mx[15] != 1.0)
            return gdoc_fail(d, err, ptr, "matrix: the last row must be 0 0 0 1 (no projective transforms)");
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 4; j++)
                out->m[i][j] = mx[4 * j + i];
        return 0;
    }
    double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(l > 1e-12))
        return gdoc_fail(d, err, ptr, "rotation: a zero quaternion");
    double x = q[0] / l, y = q[1] / l, z = q[2] / l, w = q[3] / l;
    const double r[3][3] = {
        {1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
        {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
        {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            out->m[i][j] = has_r ? r[i][j] * s[j] : (i == j ? s[j] : 0.0);
        out->m[i][3] = t[i];
    }
    return 0;
}

/* ---- meshes ----------------------------------------------------------- */

/* Vertex k of triangle t of a primitive with `n` indices in `mode`. */
static uint32_t corner(uint32_t mode, uint32_t t, int k)
{
    if (mode == MODE_TRIANGLES)
        return 3 * t + (uint32_t)k;
    if (mode == MODE_STRIP) {
        static const uint32_t even[3] = {0, 1, 2}, odd[3] = {0, 2, 1};
        return t + (t % 2 ? odd[k] : even[k]);
    }
    return k == 0 ? t + 1 : k == 1 ? t + 2 : 0; /* fan */
}

/* The morph weights a node gives its mesh. */
typedef struct {
    double w[GANIM_MAX_WEIGHTS];
    uint32_t n;                /* 0: none (the base mesh) */
    char from[64];             /* where they come from (messages) */
} morph;

/* The morph targets of primitive `ptr` (object p) with nv vertices, as
 * weights `mw` blend them: the accessors of the targets of non-zero
 * weight into t[] (*nt of them, their weights in wt[]), NORMAL ones into
 * tn[] where present. */
static int morph_targets(imp *c, const cJSON *p, const char *ptr, uint32_t nv, const morph *mw, gdoc_acc *t,
                         gdoc_acc *tn, int *has_n, double *wt, uint32_t *nt, fr_error *err)
{
    gltf_doc *d = c->d;
    const cJSON *targets = cJSON_GetObjectItemCaseSensitive(p, "targets");
    *nt = 0;
    if (!targets)
        return 0;
    char tp[112];
    snprintf(tp, sizeof tp, "%s/targets", ptr);
    int n = cJSON_GetArraySize(targets);
    if (!cJSON_IsArray(targets) || n > GANIM_MAX_WEIGHTS)
        return gdoc_fail(d, err, tp, "expected an array of at most %d targets", GANIM_MAX_WEIGHTS);
    if (mw->n && mw->n != (uint32_t)n)
        return gdoc_fail(d, err, tp, "%d targets, but %s gives %u weights", n, mw->from, mw->n);
    int k = 0;
    for (const cJSON *o = targets->child; o; o = o->next, k++) {
        if (!mw->n || mw->w[k] == 0.0)
            continue;
        char op[128];
        snprintf(op, sizeof op, "%s/%d", tp, k);
        uint32_t ip, in;
        if (!cJSON_IsObject(o))
            return gdoc_fail(d, err, op, "expected an object");
        if (gdoc_index(d, o, op, "POSITION", 0, d->accessors.n, "accessors", &ip, err) < 0 ||
            gdoc_index(d, o, op, "NORMAL", 0, d->accessors.n, "accessors", &in, err) < 0)
            return -1;
        if (ip == UINT32_MAX && in == UINT32_MAX)
            continue;
        gdoc_acc *a = &t[*nt], *an = &tn[*nt];
        memset(a, 0, sizeof *a);
        memset(an, 0, sizeof *an);
        if ((ip != UINT32_MAX && gdoc_accessor(d, ip, op, 3, NULL, a, err) < 0) ||
            (in != UINT32_MAX && gdoc_accessor(d, in, op, 3, NULL, an, err) < 0))
            return -1;
        if ((ip != UINT32_MAX && a->count != nv) || (in != UINT32_MAX && an->count != nv))
            return gdoc_fail(d, err, op, "a target of a different count than POSITION's %u", nv);
        has_n[*nt] = in != UINT32_MAX;
        if (ip == UINT32_MAX)
            a->count = 0;              /* no position offsets: all zeros */
        wt[(*nt)++] = mw->w[k];
    }
    return 0;
}

/* Vertex i's matrix under skin sk: the joints' matrices weighted by
 * JOINTS_0 and WEIGHTS_0, in the order of the four components. */
static void skin_matrix(const skinning *sk, const gdoc_acc *joints, const gdoc_acc *weights, uint32_t i, affine *m)
{
    memset(m, 0, sizeof *m);
    for (uint32_t k = 0; k < 4; k++) {
        double wk = gdoc_get(weights, i, k);
        if (wk == 0.0)
            continue;
        const affine *j = &sk->joint[(uint32_t)gdoc_get(joints, i, k)];
        for (int r = 0; r < 3; r++)
            for (int q = 0; q < 4; q++)
                m->m[r][q] += wk * j->m[r][q];
    }
}

/* JOINTS_0 and WEIGHTS_0 of a skinned primitive (attributes `attrs` at
 * `ap`, nv vertices), every joint index checked against the skin. */
static int skin_attributes(imp *c, const cJSON *attrs, const char *ap, uint32_t nv, const skinning *sk,
                           gdoc_acc *joints, gdoc_acc *weights, fr_error *err)
{
    gltf_doc *d = c->d;
    static const uint32_t jtypes[] = {GDOC_U8, GDOC_U16, 0}, wtypes[] = {GDOC_F32, GDOC_U8, GDOC_U16, 0};
    uint32_t ij, iw;
    if (gdoc_index(d, attrs, ap, "JOINTS_0", 1, d->accessors.n, "accessors", &ij, err) < 0 ||
        gdoc_index(d, attrs, ap, "WEIGHTS_0", 1, d->accessors.n, "accessors", &iw, err) < 0 ||
        gdoc_accessor(d, ij, ap, 4, jtypes, joints, err) < 0 || gdoc_accessor(d, iw, ap, 4, wtypes, weights, err) < 0)
        return -1;
    if (joints->count != nv || weights->count != nv)
        return gdoc_fail(d, err, ap, "JOINTS_0 and WEIGHTS_0 need %u elements (POSITION's count)", nv);
    if (cJSON_GetObjectItemCaseSensitive(attrs, "JOINTS_1"))
        gdoc_warn(d, "joints1", "%s/JOINTS_1: more than four joints a vertex: the first four are used", ap);
    for (uint32_t i = 0; i < nv; i++)
        for (uint32_t k = 0; k < 4; k++) {
            double wk = gdoc_get(weights, i, k);
            if (!isfinite(wk))
                return gdoc_fail(d, err, ap, "WEIGHTS_0: element %u is not finite", i);
            if (wk != 0.0 && gdoc_get(joints, i, k) >= sk->n)
                return gdoc_fail(d, err, ap, "JOINTS_0: element %u names joint %g; /skins/%u has %u", i,
                                 gdoc_get(joints, i, k), sk->skin, sk->n);
        }
    return 0;
}

static int primitive(imp *c, uint32_t mesh, uint32_t pi, const cJSON *p, const affine *w, const morph *mw,
                     const skinning *sk, fr_error *err)
{
    gltf_doc *d = c->d;
    fr_builder *b = c->b;
    char ptr[80], ap[96];
    snprintf(ptr, sizeof ptr, "/meshes/%u/primitives/%u", mesh, pi);
    snprintf(ap, sizeof ap, "%s/attributes", ptr);
    if (!cJSON_IsObject(p))
        return gdoc_fail(d, err, ptr, "expected an object");
    const cJSON *attrs;
    uint64_t mode;
    uint32_t ipos, inrm, iuv, iidx, imat;
    if (gdoc_object(d, p, ptr, "attributes", &attrs, err) < 0 ||
        gdoc_uint(d, p, ptr, "mode", MODE_TRIANGLES, 6, &mode, err) < 0 ||
        gdoc_index(d, p, ptr, "indices", 0, d->accessors.n, "accessors", &iidx, err) < 0 ||
        gdoc_index(d, p, ptr, "material", 0, d->materials.n, "materials", &imat, err) < 0)
        return -1;
    if (!attrs)
        return gdoc_fail(d, err, ptr, "attributes is missing");
    if (gdoc_index(d, attrs, ap, "POSITION", 0, d->accessors.n, "accessors", &ipos, err) < 0 ||
        gdoc_index(d, attrs, ap, "NORMAL", 0, d->accessors.n, "accessors", &inrm, err) < 0 ||
        gdoc_index(d, attrs, ap, "TEXCOORD_0", 0, d->accessors.n, "accessors", &iuv, err) < 0)
        return -1;
    if (cJSON_GetObjectItemCaseSensitive(attrs, "TANGENT"))
        gdoc_warn(d, "tangent", "%s/TANGENT: vertex tangents are not used (normal maps use tangents derived from "
                  "the UVs of each triangle)", ap);
    if (cJSON_GetObjectItemCaseSensitive(attrs, "COLOR_0"))
        gdoc_warn(d, "color", "%s/COLOR_0: vertex colours are not supported: ignored", ap);
    if (mode < MODE_TRIANGLES) {
        gdoc_warn(d, "points", "%s/mode: points and lines are not rendered", ptr);
        return 0;
    }
    if (ipos == UINT32_MAX) {
        gdoc_warn(d, "noposition", "%s: a primitive without POSITION is skipped", ptr);
        return 0;
    }
    gdoc_acc pos, nrm, uv, idx;
    static const uint32_t index_types[] = {GDOC_U8, GDOC_U16, GDOC_U32, 0};
    /* The counts first: the budget is checked before any buffer is read or
     * anything allocated. */
    uint32_t nv, n;
    if (gdoc_count(d, ipos, ap, &nv, err) < 0 || (iidx != UINT32_MAX && gdoc_count(d, iidx, ptr, &n, err) < 0))
        return -1;
    if (iidx == UINT32_MAX)
        n = nv;
    uint32_t ntri = mode == MODE_TRIANGLES ? n / 3 : n >= 3 ? n - 2 : 0;
    char where[4200];
    snprintf(where, sizeof where, "%s: %s", d->path, ptr);
    if (budget_take(b->budget, BUDGET_VERTICES, nv, where, err) < 0 ||
        budget_take(b->budget, BUDGET_TRIANGLES, ntri, where, err) < 0)
        return -1;
    if (gdoc_accessor(d, ipos, ap, 3, NULL, &pos, err) < 0 ||
        (inrm != UINT32_MAX && gdoc_accessor(d, inrm, ap, 3, NULL, &nrm, err) < 0) ||
        (iuv != UINT32_MAX && gdoc_accessor(d, iuv, ap, 2, NULL, &uv, err) < 0) ||
        (iidx != UINT32_MAX && gdoc_accessor(d, iidx, ptr, 1, index_types, &idx, err) < 0))
        return -1;
    if ((inrm != UINT32_MAX && nrm.count != nv) || (iuv != UINT32_MAX && uv.count != nv))
        return gdoc_fail(d, err, ap, "attributes of different counts (POSITION has %u)", nv);
    if (mode == MODE_TRIANGLES && n % 3)
        gdoc_warn(d, "partial", "%s: %u indices is not a whole number of triangles: the last %u ignored", ptr, n,
                  n % 3);
    if (ntri == 0)
        return 0;
    /* Accessors without a bufferView or sparse values are all zeros: every
     * position at the origin, or every index 0, makes every triangle
     * zero-area (dropped below), whatever the count. */
    if ((!pos.base && !pos.n_sparse) || (iidx != UINT32_MAX && !idx.base && !idx.n_sparse)) {
        gdoc_warn(d, "zeros", "%s: every triangle has zero area (an accessor of zeros): skipped", ptr);
        return 0;
    }
    if (!b->budget && (ntri > c->max_tri - c->r->triangles || nv > 3 * (uint64_t)c->max_tri - c->vertices))
        return gdoc_fail(d, err, ptr, "the scene would have more than %u triangles", c->max_tri);
    /* Indices checked before anything is added. */
    for (uint32_t i = 0; iidx != UINT32_MAX && i < idx.count; i++) {
        uint32_t v = gdoc_get_uint(&idx, i);
        if (v >= nv)
            return gdoc_fail(d, err, ptr, "indices: accessor %u element %u is %u, not below the vertex count %u",
                             iidx, i, v, nv);
    }
    gdoc_acc joints, weights;
    if (sk && skin_attributes(c, attrs, ap, nv, sk, &joints, &weights, err) < 0)
        return -1;
    gdoc_acc tpos[GANIM_MAX_WEIGHTS], tnrm[GANIM_MAX_WEIGHTS];
    int tn_has[GANIM_MAX_WEIGHTS];
    double tw[GANIM_MAX_WEIGHTS];
    uint32_t nt;
    if (morph_targets(c, p, ptr, nv, mw, tpos, tnrm, tn_has, tw, &nt, err) < 0)
        return -1;
    uint32_t mat = c->o->material;
    const double *uvxf = NULL;
    if (mat == FR_NONE && gmat_material(&c->mat, imat, &mat, &uvxf, err) < 0)
        return -1;
    if (c->stand) {
        if (c->stand_mat == FR_NONE)
            c->stand_mat = mat;
        return 0;
    }

    /* (a skinned mesh: its first joint's orientation decides the winding) */
    double det = af_det(sk ? &sk->joint[0] : w), cof[3][3];
    af_cofactor(w, cof);
    uint32_t base = b->positions.count;
    int use_n = inrm != UINT32_MAX, use_uv = iuv != UINT32_MAX;
    if ((use_n && bld_pad(&b->normals, base) < 0) || (use_uv && bld_pad(&b->uvs, base) < 0))
        return gdoc_fail(d, err, ptr, "out of memory");
    for (uint32_t i = 0; i < nv; i++) {
        double in[3] = {gdoc_get(&pos, i, 0), gdoc_get(&pos, i, 1), gdoc_get(&pos, i, 2)}, o[3];
        for (uint32_t k = 0; k < nt; k++)          /* morph targets, in the file's order */
            for (int j = 0; j < 3 && tpos[k].count; j++)
                in[j] += tw[k] * gdoc_get(&tpos[k], i, (uint32_t)j);
        affine vm;
        const affine *pw = w;
        double vdet = det, vcof[3][3];
        const double (*cf)[3] = cof;
        if (sk) {                                  /* skinned: the vertex's own matrix */
            skin_matrix(sk, &joints, &weights, i, &vm);
            pw = &vm;
            vdet = af_det(&vm);
            af_cofactor(&vm, vcof);
            cf = vcof;
        }
        af_apply(pw, in, 1.0, o);
        vec3 p = v3((float)o[0], (float)o[1], (float)o[2]);
        if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z))
            return gdoc_fail(d, err, ap, "POSITION: accessor %u element %u is not finite once placed", ipos, i);
        if (bld_push(&b->positions, &p) == FR_NONE)
            return gdoc_fail(d, err, ptr, "out of memory");
        if (use_n) {
            double nn[3] = {gdoc_get(&nrm, i, 0), gdoc_get(&nrm, i, 1), gdoc_get(&nrm, i, 2)}, m[3];
            for (uint32_t k = 0; k < nt; k++)
                for (int j = 0; j < 3 && tn_has[k]; j++)
                    nn[j] += tw[k] * gdoc_get(&tnrm[k], i, (uint32_t)j);
            for (int k = 0; k < 3; k++)
                m[k] = (vdet < 0 ? -1.0 : 1.0) * (cf[k][0] * nn[0] + cf[k][1] * nn[1] + cf[k][2] * nn[2]);
            double l = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
            vec3 q = l > 0 && isfinite(l) ? v3((float)(m[0] / l), (float)(m[1] / l), (float)(m[2] / l)) : v3s(0);
            if (bld_push(&b->normals, &q) == FR_NONE)
                return gdoc_fail(d, err, ptr, "out of memory");
        }
        if (use_uv) {
            double u = gdoc_get(&uv, i, 0), v = gdoc_get(&uv, i, 1);
            if (uvxf) {
                double tu = uvxf[0] * u + uvxf[1] * v + uvxf[2];
                v = uvxf[3] * u + uvxf[4] * v + uvxf[5];
                u = tu;
            }
            vec2 t = {(float)u, (float)(1.0 - v)};
            if (!isfinite(t.u) || !isfinite(t.v))
                t = (vec2){0, 0};
            if (bld_push(&b->uvs, &t) == FR_NONE)
                return gdoc_fail(d, err, ptr, "out of memory");
        }
    }
    c->vertices += nv;
    /* Triangles: a mirroring transform swaps two corners so that the front
     * stays the counter-clockwise side; zero-area ones are dropped. */
    const vec3 *ps = b->positions.data;
    uint32_t flags = (use_n ? FR_TRI_NORMALS : 0) | (use_uv ? FR_TRI_UVS : 0);
    for (uint32_t t = 0; t < ntri; t++) {
        uint32_t v[3];
        for (int k = 0; k < 3; k++) {
            uint32_t e = corner((uint32_t)mode, t, k);
            v[k] = base + (iidx != UINT32_MAX ? gdoc_get_uint(&idx, e) : e);
        }
        if (det < 0) {
            uint32_t tmp = v[1];
            v[1] = v[2];
            v[2] = tmp;
        }
        if (!(v3_len2(v3_cross(v3_sub(ps[v[1]], ps[v[0]]), v3_sub(ps[v[2]], ps[v[0]]))) > 0.0f))
            continue;
        fr_triangle tri = {{v[0], v[1], v[2]}, flags};
        uint32_t ti = bld_push(&b->triangles, &tri);
        fr_prim pr = {FR_PRIM_TRIANGLE, ti, mat, FR_NONE};
        if (ti == FR_NONE || bld_push(&b->prims, &pr) == FR_NONE)
            return gdoc_fail(d, err, ptr, "out of memory");
        c->r->triangles++;
    }
    return 0;
}

static int mesh_prims(imp *c, uint32_t m, const affine *w, const morph *mw, const skinning *sk, fr_error *err)
{
    gltf_doc *d = c->d;
    char ptr[48];
    snprintf(ptr, sizeof ptr, "/meshes/%u", m);
    const cJSON *prims = cJSON_GetObjectItemCaseSensitive(d->meshes.v[m], "primitives");
    if (!cJSON_IsArray(prims))
        return gdoc_fail(d, err, ptr, "primitives: expected an array");
    uint32_t i = 0;
    for (const cJSON *p = prims->child; p; p = p->next, i++)
        if (primitive(c, m, i, p, w, mw, sk, err) < 0)
            return -1;
    return 0;
}

/* The morph weights node n gives mesh m: the animations', else the
 * node's `weights`, else the mesh's; none (n 0) when all are zero. */
static int morph_weights(imp *c, uint32_t n, uint32_t m, morph *mw, fr_error *err)
{
    gltf_doc *d = c->d;
    const ganim_node *an = n < c->pose.n ? &c->pose.node[n] : NULL;
    mw->n = 0;
    if (an && (an->set & GANIM_W)) {
        mw->n = an->n_weights;
        memcpy(mw->w, an->w, mw->n * sizeof *mw->w);
        snprintf(mw->from, sizeof mw->from, "/animations/%u (a weights channel)", an->anim);
    } else {
        char ptr[48];
        const cJSON *o = d->nodes.v[n];
        snprintf(ptr, sizeof ptr, "/nodes/%u", n);
        if (!cJSON_GetObjectItemCaseSensitive(o, "weights")) {
            o = d->meshes.v[m];
            snprintf(ptr, sizeof ptr, "/meshes/%u", m);
        }
        const cJSON *a = cJSON_GetObjectItemCaseSensitive(o, "weights");
        if (!a)
            return 0;
        snprintf(mw->from, sizeof mw->from, "%s/weights", ptr);
        if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) > GANIM_MAX_WEIGHTS)
            return gdoc_fail(d, err, mw->from, "expected an array of at most %d numbers", GANIM_MAX_WEIGHTS);
        for (const cJSON *e = a->child; e; e = e->next) {
            if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > 1e30)
                return gdoc_fail(d, err, mw->from, "element %u: expected a finite number", mw->n);
            mw->w[mw->n++] = e->valuedouble;
        }
    }
    uint32_t nonzero = 0;
    for (uint32_t i = 0; i < mw->n; i++)
        nonzero += mw->w[i] != 0.0;
    if (!nonzero)
        mw->n = 0;
    return 0;
}

/* Whether moving instance k at mid-shutter is at `frame` (the node's pose
 * at the frame's time), to 10^-3 of the transform's size: else the motion
 * across the shutter is not the blend of its ends that the renderer draws. */
static int blends(const fr_builder *b, uint32_t k, const affine *frame)
{
    const fr_instance *in = (const fr_instance *)b->instances.data + k;
    float mid[3][4];
    motion_at((const fr_inst_motion *)b->inst_motions.data + in->motion - 1, 0.5f, mid, NULL);
    /* Every element within 10^-3 of the largest (a sum of squares, not a
     * running maximum: GCC 12's AArch64 vectoriser fails on that loop). */
    double size = 0.0, off = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++) {
            double d = mid[i][j] - frame->m[i][j];
            size += frame->m[i][j] * frame->m[i][j];
            off += d * d;
        }
    return off <= 1e-6 * size;
}

/* A mesh drawn by one node is placed into the world's triangles; one drawn
 * by several is read once in its own space and placed by an instance per
 * node (builder_instance.h), unless morph weights bend it: then this node's
 * copy is placed into the world's triangles. */
/* What places and shapes node n's mesh m, folded into the hooks' key. */
static void mesh_key(uint64_t *k, uint32_t n, uint32_t m, const affine *w, const morph *mw, const skinning *sk)
{
    if (!k)
        return;
    uint32_t id[4] = {n, m, mw->n, sk ? sk->n : 0};
    *k = XXH3_64bits_withSeed(id, sizeof id, *k);
    *k = XXH3_64bits_withSeed(w->m, sizeof w->m, *k);
    *k = XXH3_64bits_withSeed(mw->w, mw->n * sizeof *mw->w, *k);
    if (sk)
        *k = XXH3_64bits_withSeed(sk->joint, sk->n * sizeof *sk->joint, *k);
}

/* What a placed skeleton's stand-in (scene_hooks.h's mesh_bounds) stands
 * for, folded into *k: node n's mesh m placed by an instance that moves
 * or not, wherever that is. */
static void placed_key(uint64_t *k, uint32_t n, uint32_t m, int moves)
{
    uint32_t id[4] = {n, m, (uint32_t)moves, 0x51a4du};
    if (k)
        *k = XXH3_64bits_withSeed(id, sizeof id, *k);
}

/* A placed skeleton's builder mesh for glTF mesh m into *k: its materials
 * made as reading it makes them (in the same order), then standin.h's
 * triangle spanning the bounds of the full compile's mesh of the same
 * index, of the first primitive's material. */
static int placed_mesh(imp *c, uint32_t m, const morph *mw, uint32_t *k, fr_error *err)
{
    const scene_hooks *h = c->hooks;
    uint32_t at = c->b->meshes.count;
    char ptr[48];
    snprintf(ptr, sizeof ptr, "/meshes/%u", m);
    if (at >= h->n_mesh_bounds)
        return gdoc_fail(c->d, err, ptr, "the skeleton has no bounds for its mesh %u", at);
    affine id;
    af_identity(&id);
    c->stand = 1;
    c->stand_mat = FR_NONE;
    int rc = mesh_prims(c, m, &id, mw, NULL, err);
    c->stand = 0;
    if (rc < 0)
        return -1;
    if (c->stand_mat == FR_NONE)
        return gdoc_fail(c->d, err, ptr, "no triangles for a stand-in");
    fr_error e;
    if (standin_mesh(c->b, h->mesh_bounds + 6 * (size_t)at, c->stand_mat, k, &e) < 0)
        return gdoc_fail(c->d, err, ptr, "%s", e.msg);
    c->r->triangles++;
    return 0;
}

/* A skeleton's mesh: one triangle of the default material in its place. */
static int stand_in(imp *c, fr_error *err)
{
    uint32_t mat;
    const double *uvxf;
    if (gmat_material(&c->mat, UINT32_MAX, &mat, &uvxf, err) < 0)
        return -1;
    if (bld_triangle(c->b, v3(0.0f, 0.0f, 0.0f), v3(1.0f, 0.0f, 0.0f), v3(0.0f, 1.0f, 0.0f), mat) == FR_NONE)
        return gdoc_fail(c->d, err, NULL, "out of memory");
    c->r->triangles++;
    return 0;
}

static int mesh(imp *c, uint32_t n, uint32_t m, const affine *w, const skinning *sk, fr_error *err)
{
    morph mw;
    if (morph_weights(c, n, m, &mw, err) < 0)
        return -1;
    /* A node that moves across the shutter places its mesh by a moving
     * instance (builder_motion.h), drawn once or not. */
    int moves = c->shut[0] && memcmp(&c->shut[0][n], &c->shut[1][n], sizeof(affine)) != 0;
    if (moves && (mw.n || sk)) {
        char ptr[48];
        snprintf(ptr, sizeof ptr, "/nodes/%u", n);
        gdoc_warn(c->d, "deforming", "%s: moves across the shutter, but a skinned or morphed mesh is not motion "
                  "blurred: it is posed at the frame's time, sharp", ptr);
        moves = 0;
    }
    /* A placed skeleton (scene_hooks.h's mesh_bounds) stands in for the
     * meshes placed by instances, keyed without their placement. */
    int instanced = (c->uses[m] >= 2 || moves) && !mw.n && !sk;
    int placed = c->hooks && c->hooks->skeleton && c->hooks->mesh_bounds && instanced;
    uint64_t *keys[2] = {c->hooks ? c->hooks->mesh_key : NULL, c->hooks ? c->hooks->placed_key : NULL};
    for (int i = 0; i < 2; i++) {
        if (i ? instanced : placed) {
            placed_key(keys[i], n, m, moves);
            continue;
        }
        mesh_key(keys[i], n, m, w, &mw, sk);
        /* The poses at the shutter's ends are part of what the mesh makes. */
        if (moves) {
            mesh_key(keys[i], n, m, &c->shut[0][n], &mw, sk);
            mesh_key(keys[i], n, m, &c->shut[1][n], &mw, sk);
        }
    }
    if (c->hooks && c->hooks->skeleton && !c->hooks->mesh_bounds)
        return stand_in(c, err);
    const affine *w_frame = w;
    if (moves)
        w = &c->shut[0][n];
    if ((c->uses[m] < 2 && !moves) || mw.n || sk)
        return mesh_prims(c, m, w, &mw, sk, err);
    if (c->mesh_of[m] == FR_NONE && placed && placed_mesh(c, m, &mw, &c->mesh_of[m], err) < 0)
        return -1;
    if (c->mesh_of[m] == FR_NONE) {
        affine id;
        af_identity(&id);
        uint32_t k = bld_mesh_begin(c->b);
        if (k == FR_NONE)
            return gdoc_fail(c->d, err, NULL, "out of memory");
        if (mesh_prims(c, m, &id, &mw, NULL, err) < 0)
            return -1;
        fr_error e;
        if (bld_mesh_end(c->b, k, &e) < 0)
            return gdoc_fail(c->d, err, NULL, "%s", e.msg);
        c->mesh_of[m] = k;
    }
    float xf[3][4];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            xf[i][j] = (float)w->m[i][j];
    fr_error e;
    uint32_t k = c->b->instances.count;
    if (bld_instance(c->b, c->mesh_of[m], (const float(*)[4])xf, &e) < 0) {
        char ptr[48];
        snprintf(ptr, sizeof ptr, "/meshes/%u", m);
        return gdoc_fail(c->d, err, ptr, "%s", e.msg);
    }
    if (!moves)
        return 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            xf[i][j] = (float)c->shut[1][n].m[i][j];
    char ptr[48];
    snprintf(ptr, sizeof ptr, "/nodes/%u", n);
    if (bld_instance_motion(c->b, k, (const float(*)[4])xf, &e) < 0)
        return gdoc_fail(c->d, err, ptr, "%s", e.msg);
    if (!blends(c->b, k, w_frame))
        gdoc_warn(c->d, "blend", "%s: at the frame's time the node is not where the blend of its poses at the "
                  "shutter's opening and closing puts it (more than half a turn across the shutter, or keys "
                  "inside it): it is blurred along that blend", ptr);
    return 0;
}

/* ---- camera and lights ------------------------------------------------ */

static const char *name_of(const cJSON *o)
{
    const cJSON *n = cJSON_GetObjectItemCaseSensitive(o, "name");
    return cJSON_IsString(n) ? n->valuestring : NULL;
}

/* Node n refers to camera `cam`: take it if it is the one asked for. */
static int camera(imp *c, uint32_t n, uint32_t cam, const affine *w, fr_error *err)
{
    gltf_doc *d = c->d;
    if (!c->o->take_camera || c->cam_node >= 0)
        return 0;
    const cJSON *co = d->cameras.v[cam];
    const char *want = c->o->camera, *nn = name_of(d->nodes.v[n]), *cn = name_of(co);
    if (want && !(nn && !strcmp(nn, want)) && !(cn && !strcmp(cn, want)))
        return 0;
    char ptr[48], pp[80];
    snprintf(ptr, sizeof ptr, "/cameras/%u", cam);
    snprintf(pp, sizeof pp, "%s/perspective", ptr);
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(co, "type"), *persp;
    if (!cJSON_IsString(type))
        return gdoc_fail(d, err, ptr, "type: expected \"perspective\" or \"orthographic\"");
    if (strcmp(type->valuestring, "perspective") != 0) {
        if (want)
            return gdoc_fail(d, err, ptr, "camera '%s' is %s: only perspective cameras are supported", want,
                             type->valuestring);
        gdoc_warn(d, "ortho", "%s: %s cameras are not supported: skipped", ptr, type->valuestring);
        return 0;
    }
    double yfov, aspect;
    if (gdoc_object(d, co, ptr, "perspective", &persp, err) < 0)
        return -1;
    if (!persp)
        return gdoc_fail(d, err, ptr, "perspective is missing");
    if (gdoc_number(d, persp, pp, "yfov", -1, &yfov, err) < 0 || gdoc_number(d, persp, pp, "aspectRatio", 0, &aspect, err) < 0)
        return -1;
    if (!(yfov > 0.0 && yfov < FM_PI))
        return gdoc_fail(d, err, pp, "yfov: expected radians in (0, pi)%s",
                         cJSON_GetObjectItemCaseSensitive(persp, "yfov") ? "" : " (it is missing)");
    if (!(aspect >= 0.0))
        return gdoc_fail(d, err, pp, "aspectRatio: expected a positive number");
    const double o0[3] = {0, 0, 0}, fw[3] = {0, 0, -1}, up[3] = {0, 1, 0};
    double p[3], f[3], u[3];
    af_apply(w, o0, 1.0, p);
    af_apply(w, fw, 0.0, f);
    af_apply(w, up, 0.0, u);
    double lf = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]), lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    if (!(lf > 0) || !(lu > 0))
        return gdoc_fail(d, err, ptr, "the camera's node %u has a singular transform", n);
    fr_camera *cm = &c->b->camera;
    memset(cm, 0, sizeof *cm);
    cm->position = v3((float)p[0], (float)p[1], (float)p[2]);
    vec3 dir = v3((float)(f[0] / lf), (float)(f[1] / lf), (float)(f[2] / lf));
    cm->target = v3_add(cm->position, dir);
    cm->up = v3((float)(u[0] / lu), (float)(u[1] / lu), (float)(u[2] / lu));
    cm->vfov = (float)yfov;
    fr_error e;
    if (bld_camera_finish(cm, &e) < 0)
        return gdoc_fail(d, err, ptr, "%s", e.msg);
    cm->focus = v3_len(v3_sub(cm->target, cm->position));
    c->cam_node = (int)n;
    c->r->camera_found = 1;
    c->r->aspect = (float)aspect;
    return 0;
}

static int light(imp *c, uint32_t n, const cJSON *ext, const affine *w, fr_error *err)
{
    gltf_doc *d = c->d;
    char np[80];
    snprintf(np, sizeof np, "/nodes/%u/extensions/KHR_lights_punctual", n);
    uint32_t li;
    if (!cJSON_IsObject(ext))
        return gdoc_fail(d, err, np, "expected an object");
    if (gdoc_index(d, ext, np, "light", 1, d->lights.n, "the KHR_lights_punctual lights", &li, err) < 0)
        return -1;
    if (!c->o->take_lights)
        return 0;
    char ptr[64];
    snprintf(ptr, sizeof ptr, "/extensions/KHR_lights_punctual/lights/%u", li);
    const cJSON *o = d->lights.v[li];
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(o, "type");
    double col[3] = {1, 1, 1}, intensity;
    int has;
    if (!cJSON_IsString(type))
        return gdoc_fail(d, err, ptr, "type: expected \"point\", \"spot\" or \"directional\"");
    if (gdoc_numbers(d, o, ptr, "color", 3, col, &has, err) < 0 ||
        gdoc_number(d, o, ptr, "intensity", 1, &intensity, err) < 0)
        return -1;
    if (!(intensity >= 0) || !(col[0] >= 0 && col[1] >= 0 && col[2] >= 0))
        return gdoc_fail(d, err, ptr, "color and intensity must be >= 0");
    if (cJSON_GetObjectItemCaseSensitive(o, "range"))
        gdoc_warn(d, "range", "%s/range: light ranges are not used (lights fall off with the inverse square)", ptr);
    /* Candela and lux over 683 lm/W: the watts of Blender's exporter
     * (builder_light.h, scenes/README.md). */
    vec3 power = v3((float)(col[0] * intensity / 683.0), (float)(col[1] * intensity / 683.0),
                    (float)(col[2] * intensity / 683.0));
    if (v3_is_zero(power))
        return 0;
    const double o0[3] = {0, 0, 0}, fw[3] = {0, 0, -1};
    double p[3], f[3];
    af_apply(w, o0, 1.0, p);
    af_apply(w, fw, 0.0, f);
    vec3 pos = v3((float)p[0], (float)p[1], (float)p[2]), dir = v3((float)f[0], (float)f[1], (float)f[2]);
    fr_error e;
    int rc;
    if (!strcmp(type->valuestring, "point")) {
        rc = bld_point_light(c->b, pos, power, &e);
    } else if (!strcmp(type->valuestring, "spot")) {
        const cJSON *sp;
        char sptr[80];
        double inner = 0.0, outer = FM_PI / 4.0;
        snprintf(sptr, sizeof sptr, "%s/spot", ptr);
        if (gdoc_object(d, o, ptr, "spot", &sp, err) < 0 ||
            (sp && (gdoc_number(d, sp, sptr, "innerConeAngle", 0.0, &inner, err) < 0 ||
                    gdoc_number(d, sp, sptr, "outerConeAngle", FM_PI / 4.0, &outer, err) < 0)))
            return -1;
        rc = bld_spot_light(c->b, pos, dir, power, (float)inner, (float)outer, &e);
    } else if (!strcmp(type->valuestring, "directional")) {
        rc = bld_sun_light(c->b, dir, power, 0.0f, &e);
    } else {
        return gdoc_fail(d, err, ptr, "type: '%s' is not point, spot or directional", type->valuestring);
    }
    if (rc < 0)
        return gdoc_fail(d, err, ptr, "%s", e.msg);
    c->r->lights++;
    return 0;
}

/* The skin node n names, if any: its joints' matrices into *sk (malloc'd,
 * the caller frees sk->joint), from their world transforms at the pose
 * and the inverse bind matrices.  A skinned mesh's vertices are placed
 * by its joints alone (glTF ignores the node's own transform). */
static int skin_of(imp *c, uint32_t n, skinning *sk, fr_error *err)
{
    gltf_doc *d = c->d;
    char ptr[48], sp[48], jp[64];
    snprintf(ptr, sizeof ptr, "/nodes/%u", n);
    const cJSON *skins = cJSON_GetObjectItemCaseSensitive(d->root, "skins");
    uint32_t si, ibm;
    if (gdoc_index(d, d->nodes.v[n], ptr, "skin", 0, (uint32_t)cJSON_GetArraySize(skins), "skins", &si, err) < 0)
        return -1;
    if (si == UINT32_MAX)
        return 0;
    const cJSON *so = cJSON_GetArrayItem(skins, (int)si);
    snprintf(sp, sizeof sp, "/skins/%u", si);
    snprintf(jp, sizeof jp, "%s/joints", sp);
    const cJSON *joints = cJSON_GetObjectItemCaseSensitive(so, "joints");
    int nj = cJSON_GetArraySize(joints);
    if (!cJSON_IsObject(so) || !cJSON_IsArray(joints) || nj < 1)
        return gdoc_fail(d, err, sp, "expected an object with a non-empty array of joints");
    if (gdoc_index(d, so, sp, "inverseBindMatrices", 0, d->accessors.n, "accessors", &ibm, err) < 0)
        return -1;
    static const uint32_t floats[] = {GDOC_F32, 0};
    gdoc_acc ib;
    if (ibm != UINT32_MAX && (gdoc_accessor(d, ibm, sp, 16, floats, &ib, err) < 0))
        return -1;
    if (ibm != UINT32_MAX && ib.count != (uint32_t)nj)
        return gdoc_fail(d, err, sp, "inverseBindMatrices: %u matrices for %d joints", ib.count, nj);
    if (!c->world)
        return gdoc_fail(d, err, sp, "internal: no world transforms");
    if ((sk->joint = malloc((size_t)nj * sizeof *sk->joint)) == NULL)
        return gdoc_fail(d, err, sp, "out of memory");
    sk->n = (uint32_t)nj;
    sk->skin = si;
    int k = 0;
    for (const cJSON *e = joints->child; e; e = e->next, k++) {
        double x = e->valuedouble;
        if (!cJSON_IsNumber(e) || x != floor(x) || !(x >= 0 && x < d->nodes.n))
            return gdoc_fail(d, err, jp, "element %d is not a node index (the file has %u nodes)", k, d->nodes.n);
        uint32_t j = (uint32_t)x;
        if (!c->placed[j])
            return gdoc_fail(d, err, jp, "element %d: node %u is not in the scene", k, j);
        affine inv;
        af_identity(&inv);
        for (int r = 0; ibm != UINT32_MAX && r < 4; r++)
            for (int q = 0; q < 4; q++) {
                double v = gdoc_get(&ib, (uint32_t)k, (uint32_t)(4 * q + r)); /* column-major */
                if (!isfinite(v) || (r == 3 && v != (q == 3 ? 1.0 : 0.0)))
                    return gdoc_fail(d, err, sp, "inverseBindMatrices: matrix %d is not finite and affine", k);
                if (r < 3)
                    inv.m[r][q] = v;
            }
        af_mul(&sk->joint[k], &c->world[j], &inv);
    }
    return 0;
}

static int node(imp *c, uint32_t n, const affine *w, fr_error *err)
{
    gltf_doc *d = c->d;
    char ptr[48];
    snprintf(ptr, sizeof ptr, "/nodes/%u", n);
    const cJSON *o = d->nodes.v[n], *ext, *lp = NULL;
    uint32_t m, cam;
    if (gdoc_index(d, o, ptr, "mesh", 0, d->meshes.n, "meshes", &m, err) < 0 ||
        gdoc_index(d, o, ptr, "camera", 0, d->cameras.n, "cameras", &cam, err) < 0 ||
        gdoc_object(d, o, ptr, "extensions", &ext, err) < 0)
        return -1;
    if (c->counting == 2) {
        c->world[n] = *w;      /* gltf_motion's pass */
        return 0;
    }
    if (c->counting) {
        if (m != UINT32_MAX)
            c->uses[m]++;
        if (c->world) {
            c->world[n] = *w;
            c->placed[n] = 1;
        }
        return 0;
    }
    if (ext)
        lp = cJSON_GetObjectItemCaseSensitive(ext, "KHR_lights_punctual");
    if (m != UINT32_MAX && !c->o->camera_only) {
        /* The node is an object (builder_object.h), by its name. */
        char dflt[24];
        const char *name = name_of(o);
        snprintf(dflt, sizeof dflt, "node%u", n);
        fr_error e;
        if (bld_object(c->b, name ? name : dflt, &e) < 0)
            return gdoc_fail(d, err, ptr, "%s", e.msg);
    }
    skinning sk = {NULL, 0, 0};
    int rc = 0;
    if (m != UINT32_MAX && !c->o->camera_only && (rc = skin_of(c, n, &sk, err)) == 0)
        rc = mesh(c, n, m, w, sk.joint ? &sk : NULL, err);
    free(sk.joint);
    if (rc < 0 || (cam != UINT32_MAX && camera(c, n, cam, w, err) < 0) || (lp && light(c, n, lp, w, err) < 0))
        return -1;
    return 0;
}

/* Every node's parent, checking that the nodes form a forest. */
static int parents(imp *c, uint32_t *parent, fr_error *err)
{
    gltf_doc *d = c->d;
    for (uint32_t i = 0; i < d->nodes.n; i++)
        parent[i] = UINT32_MAX;
    for (uint32_t i = 0; i < d->nodes.n; i++) {
        const cJSON *ch = cJSON_GetObjectItemCaseSensitive(d->nodes.v[i], "children");
        if (!ch)
            continue;
        char ptr[48];
        snprintf(ptr, sizeof ptr, "/nodes/%u/children", i);
        if (!cJSON_IsArray(ch))
            return gdoc_fail(d, err, ptr, "expected an array of node indices");
        int k = 0;
        for (const cJSON *e = ch->child; e; e = e->next, k++) {
            double x = e->valuedouble;
            if (!cJSON_IsNumber(e) || x != floor(x) || !(x >= 0 && x < d->nodes.n))
                return gdoc_fail(d, err, ptr, "element %d is not a node index (the file has %u nodes)", k, d->nodes.n);
            uint32_t j = (uint32_t)x;
            if (j == i || parent[j] != UINT32_MAX)
                return gdoc_fail(d, err, ptr, "node %u %s: the nodes must form trees", j,
                                 j == i ? "is its own child" : "has two parents");
            parent[j] = i;
        }
    }
    return 0;
}

/* The scene's root nodes, in order, into roots[] (*n of them). */
static int scene_roots(imp *c, const uint32_t *parent, uint32_t *roots, uint32_t *n, fr_error *err)
{
    gltf_doc *d = c->d;
    *n = 0;
    if (d->scenes.n == 0) {
        gdoc_warn(d, "noscene", "the file has no scenes: every root node is drawn");
        for (uint32_t i = 0; i < d->nodes.n; i++)
            if (parent[i] == UINT32_MAX)
                roots[(*n)++] = i;
        return 0;
    }
    uint32_t s;
    if (gdoc_index(d, d->root, "", "scene", 0, d->scenes.n, "scenes", &s, err) < 0)
        return -1;
    if (s == UINT32_MAX)
        s = 0;
    char ptr[48];
    snprintf(ptr, sizeof ptr, "/scenes/%u/nodes", s);
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(d->scenes.v[s], "nodes");
    if (!a)
        return 0;
    if (!cJSON_IsArray(a))
        return gdoc_fail(d, err, ptr, "expected an array of node indices");
    /* Whether each node is listed already: one byte a node. */
    unsigned char *listed = calloc(d->nodes.n ? d->nodes.n : 1, 1);
    if (!listed)
        return gdoc_fail(d, err, ptr, "out of memory");
    int k = 0, rc = 0;
    for (const cJSON *e = a->child; e && rc == 0; e = e->next, k++) {
        double x = e->valuedouble;
        uint32_t j = 0;
        if (!cJSON_IsNumber(e) || x != floor(x) || !(x >= 0 && x < d->nodes.n))
            rc = gdoc_fail(d, err, ptr, "element %d is not a node index (the file has %u nodes)", k, d->nodes.n);
        else if (parent[j = (uint32_t)x] != UINT32_MAX)
            rc = gdoc_fail(d, err, ptr, "node %u is the child of node %u, not a root", j, parent[j]);
        else if (listed[j])
            rc = gdoc_fail(d, err, ptr, "node %u is listed twice", j);
        else
            listed[j] = 1, roots[(*n)++] = j;
    }
    free(listed);
    return rc;
}

/* Depth first from the roots, in the file's order, with an explicit stack
 * (each node is on it at most once: the nodes form trees). */
static int walk_nodes(imp *c, fr_error *err);

/* With a shutter (the hooks' timed shutter, animations played): every
 * node's world transform at the shutter's opening and closing into
 * c->shut, each by a walk over the nodes posed at that time. */
static int gltf_motion(imp *c, fr_error *err)
{
    const scene_hooks *h = c->hooks;
    if (!c->o->animate || c->o->camera_only || !h || !h->timed || !(h->shutter > 0.0) || !ganim_present(c->d))
        return 0;
    uint32_t nn = c->d->nodes.n ? c->d->nodes.n : 1;
    ganim_pose frame = c->pose;
    affine *keep = c->world;
    int rc = 0;
    for (int k = 0; k < 2 && rc == 0; k++) {
        ganim_pose at = {0};
        if (!(c->shut[k] = calloc(nn, sizeof(affine)))) {
            rc = gdoc_fail(c->d, err, NULL, "out of memory");
            break;
        }
        rc = ganim_eval(c->d, ganim_hooks_time(h, h->frame + (k ? 0.5 : -0.5) * h->shutter), &at, err);
        c->pose = at;
        c->world = c->shut[k];
        c->counting = 2;
        if (rc == 0)
            rc = walk_nodes(c, err);
        c->counting = 0;
        ganim_free(&at);
    }
    c->pose = frame;
    c->world = keep;
    return rc;
}

/* Every node of the scene, twice: the uses of each mesh counted, then
 * each node read. */
static int traverse(imp *c, fr_error *err)
{
    uint32_t n = c->d->meshes.n ? c->d->meshes.n : 1;
    c->uses = calloc(n, sizeof *c->uses);
    c->mesh_of = malloc(n * sizeof *c->mesh_of);
    int rc = -1;
    if (!c->uses || !c->mesh_of) {
        gdoc_fail(c->d, err, NULL, "out of memory");
    } else {
        for (uint32_t i = 0; i < n; i++)
            c->mesh_of[i] = FR_NONE;
        /* With skins, the counting pass keeps every node's world transform
         * for the joints. */
        uint32_t nn = c->d->nodes.n ? c->d->nodes.n : 1;
        if (cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(c->d->root, "skins")) > 0 &&
            (!(c->world = malloc(nn * sizeof *c->world)) || !(c->placed = calloc(nn, 1)))) {
            free(c->uses);
            free(c->mesh_of);
            free(c->world);
            c->uses = c->mesh_of = NULL;
            c->world = NULL;
            return gdoc_fail(c->d, err, NULL, "out of memory");
        }
        c->counting = 1;
        rc = walk_nodes(c, err);
        c->counting = 0;
        if (rc == 0)
            rc = gltf_motion(c, err);
        if (rc == 0)
            rc = walk_nodes(c, err);
    }
    free(c->uses);
    free(c->mesh_of);
    free(c->world);
    free(c->placed);
    free(c->shut[0]);
    free(c->shut[1]);
    c->shut[0] = c->shut[1] = NULL;
    c->uses = c->mesh_of = NULL;
    c->world = NULL;
    c->placed = NULL;
    return rc;
}

static int walk_nodes(imp *c, fr_error *err)
{
    gltf_doc *d = c->d;
    uint32_t nn = d->nodes.n ? d->nodes.n : 1;
    uint32_t *parent = malloc(nn * sizeof *parent), *roots = malloc(nn * sizeof *roots);
    struct item { uint32_t node; affine w; } *stack = malloc(nn * sizeof *stack);
    int rc = -1;
    uint32_t nr, top = 0;
    if (!parent || !roots || !stack) {
        gdoc_fail(d, err, NULL, "out of memory");
        goto done;
    }
    if (parents(c, parent, err) < 0 || scene_roots(c, parent, roots, &nr, err) < 0)
        goto done;
    affine place;
    memcpy(place.m, c->o->place, sizeof place.m);
    for (uint32_t i = nr; i-- > 0;) {
        affine l;
        if (local_transform(c, roots[i], &l, err) < 0)
            goto done;
        stack[top].node = roots[i];
        af_mul(&stack[top++].w, &place, &l);
    }
    while (top > 0) {
        struct item it = stack[--top];
        if (node(c, it.node, &it.w, err) < 0)
            goto done;
        const cJSON *ch = cJSON_GetObjectItemCaseSensitive(d->nodes.v[it.node], "children");
        int k = cJSON_GetArraySize(ch);
        const cJSON **kids = k > 0 ? malloc((size_t)k * sizeof *kids) : NULL;
        if (k > 0 && !kids) {
            gdoc_fail(d, err, NULL, "out of memory");
            goto done;
        }
        int i = 0;
        for (const cJSON *e = ch ? ch->child : NULL; e; e = e->next)
            kids[i++] = e;
        for (int j = k - 1; j >= 0; j--) {
            uint32_t cn = (uint32_t)kids[j]->valuedouble;
            affine l;
            if (local_transform(c, cn, &l, err) < 0) {
                free(kids);
                goto done;
            }
            stack[top].node = cn;
            af_mul(&stack[top++].w, &it.w, &l);
        }
        free(kids);
    }
    rc = 0;
done:
    free(parent);
    free(roots);
    free(stack);
    return rc;
}

/* ---- entry points ------------------------------------------------------ */

void gltf_options_default(gltf_options *o)
{
    memset(o, 0, sizeof *o);
    o->take_camera = 1;
    o->take_lights = 1;
    o->material = FR_NONE;
    for (int i = 0; i < 3; i++)
        o->place[i][i] = 1.0;
}

static void pass_warnings(gltf_doc *d, const scene_hooks *hooks)
{
    if (!hooks || !hooks->warn)
        return;
    char line[700];
    for (uint32_t i = 0; i < d->n_warn; i++) {
        snprintf(line, sizeof line, "%s: %s", d->path, d->warn[i]);
        fr_escape_controls(line, sizeof line);
        hooks->warn(hooks->user, line);
    }
    if (d->n_warn_dropped) {
        snprintf(line, sizeof line, "%s: %u more warnings", d->path, d->n_warn_dropped);
        hooks->warn(hooks->user, line);
    }
}

/* The camera names of the file, for an error. */
static void camera_names(gltf_doc *d, char *out, size_t cap)
{
    size_t o = 0;
    out[0] = 0;
    for (uint32_t i = 0; i < d->nodes.n && o + 1 < cap; i++) {
        if (!cJSON_GetObjectItemCaseSensitive(d->nodes.v[i], "camera"))
            continue;
        const char *n = name_of(d->nodes.v[i]);
        o += (size_t)snprintf(out + o, cap - o, "%s'%s'", o ? ", " : "", n ? n : "(unnamed)");
    }
    if (!out[0])
        snprintf(out, cap, "none");
}

static int import_doc(gltf_doc *d, const scene_hooks *hooks, const gltf_options *o, fr_builder *b, gltf_result *r,
                      fr_error *err)
{
    memset(r, 0, sizeof *r);
    imp c = {d, hooks, o, b, r, {0}, o->max_triangles ? o->max_triangles : GLTF_MAX_TRIANGLES, 0, -1, 0,
             NULL, NULL, {0}, NULL, NULL, {NULL, NULL}, 0, FR_NONE};
    gdoc_warn_extensions(d, known_extensions);
    if (o->animate) {
        if (ganim_eval(d, o->time, &c.pose, err) < 0) {
            ganim_free(&c.pose);
            return -1;
        }
    } else if (ganim_present(d)) {
        gdoc_warn(d, "animations", "/animations: not played: the scene is drawn at rest (render with --frames to "
                  "pose it per frame)");
    }
    if (gmat_begin(&c.mat, d, hooks, b, err) < 0) {
        ganim_free(&c.pose);
        return -1;
    }
    int rc = traverse(&c, err);
    gmat_end(&c.mat);
    ganim_free(&c.pose);
    if (rc == 0 && o->take_camera && o->camera && c.cam_node < 0) {
        char names[256];
        camera_names(d, names, sizeof names);
        rc = gdoc_fail(d, err, NULL, "no perspective camera named '%s' in the scene (camera nodes: %s)", o->camera,
                       names);
    }
    pass_warnings(d, hooks);
    return rc;
}

/* The file's name and identity on disk (device, inode, size, time),
 * folded into the hooks' mesh key: another file, or this one rewritten,
 * may hold other meshes under the same nodes. */
static void file_key(const char *path, const scene_hooks *hooks)
{
    struct stat st;
    uint64_t id[5] = {0};
    if (!hooks)
        return;
    if (stat(path, &st) == 0)
        id[0] = (uint64_t)st.st_dev, id[1] = (uint64_t)st.st_ino, id[2] = (uint64_t)st.st_size,
        id[3] = (uint64_t)st.st_mtim.tv_sec, id[4] = (uint64_t)st.st_mtim.tv_nsec;
    uint64_t *keys[2] = {hooks->mesh_key, hooks->placed_key};
    for (int i = 0; i < 2; i++)
        if (keys[i]) {
            *keys[i] = XXH3_64bits_withSeed(path, strlen(path) + 1, *keys[i]);
            *keys[i] = XXH3_64bits_withSeed(id, sizeof id, *keys[i]);
        }
}

int gltf_import(const char *path, const scene_hooks *hooks, const gltf_options *o, fr_builder *b, gltf_result *r,
                fr_error *err)
{
    gltf_doc d;
    file_key(path, hooks);
    confine own;
    const confine *scope = o->scope;
    if (!scope) {
        if (confine_init(&own, path, hooks ? hooks->allow : NULL, hooks ? hooks->n_allow : 0, err) < 0)
            return -1;
        scope = &own;
    }
    if (gdoc_open(&d, path, scope, o->scope != NULL, err) < 0)
        return -1;
    d.budget = b->budget;
    if (budget_take(d.budget, BUDGET_READ, d.file_len, path, err) < 0) {
        gdoc_free(&d);
        return -1;
    }
    int rc = import_doc(&d, hooks, o, b, r, err);
    gdoc_free(&d);
    return rc;
}

int gltf_import_mem(const void *bytes, size_t len, const char *name, const scene_hooks *hooks, const gltf_options *o,
                    fr_builder *b, gltf_result *r, fr_error *err)
{
    gltf_doc d;
    if (gdoc_open_mem(&d, bytes, len, name, NULL, err) < 0)
        return -1;
    d.budget = b->budget;
    int rc = import_doc(&d, hooks, o, b, r, err);
    gdoc_free(&d);
    return rc;
}

static void warn(const scene_hooks *hooks, const char *path, const char *msg)
{
    if (hooks && hooks->warn) {
        char line[700];
        snprintf(line, sizeof line, "%s: %s", path, msg);
        fr_escape_controls(line, sizeof line);
        hooks->warn(hooks->user, line);
    }
}

/* A camera from +Z (glTF's front), a little above, framing the bounds. */
static int frame_bounds(fr_builder *b, vec3 lo, vec3 hi, fr_error *err)
{
    vec3 ctr = v3_scale(v3_add(lo, hi), 0.5f);
    float radius = 0.5f * v3_len(v3_sub(hi, lo)), s, co;
    if (!(radius > 0.0f))
        radius = 1.0f;
    fr_camera *cm = &b->camera;
    memset(cm, 0, sizeof *cm);
    cm->vfov = 40.0f * (FM_PI / 180.0f);
    fm_sincosf(0.5f * cm->vfov, &s, &co);
    float dist = 1.1f * radius / s;
    cm->position = v3_add(ctr, v3_scale(v3_norm(v3(0.0f, 0.3f, 1.0f)), dist));
    cm->target = ctr;
    cm->up = v3(0, 1, 0);
    cm->focus = dist;
    return bld_camera_finish(cm, err);
}

/* The camera of options o (take_camera) posed at time t into *cam. */
static int camera_at(const char *path, const void *bytes, size_t len, const gltf_options *o, double t,
                     fr_camera *cam, fr_error *err)
{
    gltf_options oc = *o;
    oc.camera_only = 1;
    oc.take_lights = 0;
    oc.time = t;
    fr_builder tmp;
    gltf_result r;
    bld_init(&tmp);
    int rc = bytes ? gltf_import_mem(bytes, len, path, NULL, &oc, &tmp, &r, err)
                   : gltf_import(path, NULL, &oc, &tmp, &r, err);
    *cam = tmp.camera;
    bld_free(&tmp);
    return rc;
}

/* With a shutter: the camera at shutter open (b->camera) and close
 * (b->motion), when they differ. */
static int camera_motion(const char *path, const void *bytes, size_t len, const scene_hooks *hooks,
                         const gltf_options *o, fr_builder *b, fr_error *err)
{
    fr_camera open, close;
    double f = hooks->frame, h = 0.5 * hooks->shutter;
    if (camera_at(path, bytes, len, o, ganim_hooks_time(hooks, f - h), &open, err) < 0 ||
        camera_at(path, bytes, len, o, ganim_hooks_time(hooks, f + h), &close, err) < 0)
        return -1;
    b->motion.shutter = (float)(hooks->shutter / hooks->fps);
    if (!memcmp(&open, &close, sizeof open))
        return 0;
    b->camera = open;
    b->motion.camera_close = close;
    b->motion.flags |= FR_MOTION_CAMERA;
    return 0;
}

int gltf_build_scene(const char *path, const void *bytes, size_t len, const scene_hooks *hooks, const char *camera,
                     uint32_t max_triangles, fr_builder *b, fr_error *err)
{
    gltf_options o;
    gltf_result r;
    gltf_options_default(&o);
    o.camera = camera;
    o.max_triangles = max_triangles;
    o.animate = hooks && hooks->timed;
    o.time = o.animate ? ganim_hooks_time(hooks, hooks->frame) : 0.0;
    int rc = bytes ? gltf_import_mem(bytes, len, path, hooks, &o, b, &r, err) : gltf_import(path, hooks, &o, b, &r, err);
    if (rc < 0)
        return -1;
    if (r.triangles == 0)
        return fr_fail(err, "%s: the scene has no triangles to render", path);
    fr_settings *st = &b->settings;
    st->width = 640;
    st->height = 480;
    if (r.aspect > 0.0f) {
        float h = 640.0f / r.aspect + 0.5f;
        st->height = h < 1.0f ? 1 : h > 65536.0f ? 65536 : (uint32_t)h;
    }
    st->spp = 64;
    st->max_depth = 8;
    vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY);
    const vec3 *p = b->positions.data;
    if (b->instances.count)
        bld_bounds(b, &lo, &hi);
    for (uint32_t i = 0; i < b->positions.count && !b->instances.count; i++) {
        lo = v3_vmin(lo, p[i]);
        hi = v3_vmax(hi, p[i]);
    }
    if (r.camera_found && o.animate && hooks->shutter > 0.0 && camera_motion(path, bytes, len, hooks, &o, b, err) < 0)
        return -1;
    if (!r.camera_found) {
        warn(hooks, path, "no perspective camera in the scene: one frames it from +Z");
        fr_error e;
        if (frame_bounds(b, lo, hi, &e) < 0)
            return fr_fail(err, "%s: %s", path, e.msg);
    }
    int emissive = 0;
    const fr_material *m = b->materials.data;
    for (uint32_t k = 0; k < b->prims.count && !emissive; k++)
        emissive = !v3_is_zero(m[((const fr_prim *)b->prims.data)[k].material].emission);
    if (b->lights.count == 0 && !emissive) {
        warn(hooks, path, "no lights in the scene: a white environment of radiance 1 lights it");
        fr_error e;
        if (bld_environment(b, v3s(1.0f), FR_NONE, 0.0f, &e) < 0)
            return fr_fail(err, "%s: %s", path, e.msg);
    }
    return 0;
}

int gltf_load_scene(const char *path, const scene_hooks *hooks, const char *camera, fr_scene *out, fr_error *err)
{
    fr_builder b;
    bld_init(&b);
    b.budget = hooks ? hooks->budget : NULL;
    int rc = gltf_build_scene(path, NULL, 0, hooks, camera, 0, &b, err);
    if (rc == 0) {
        fr_error e;
        if ((rc = hooks && hooks->fbin ? frz_scene_file(&b, hooks->fbin, out, &e) : frz_scene(&b, out, &e)) < 0)
            fr_fail(err, "%s: %s", path, e.msg);
    }
    bld_free(&b);
    return rc;
}
