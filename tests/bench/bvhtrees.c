/* bvhtrees.c -- trees of the same triangles walked by the same walk: is a
 * gap to Embree the tree's or the walk's?
 *
 *   bvhtrees SCENE.fbin [--size WxH] [--passes N] [--chunk N] [--leaf N]
 *                       [--order dfs|bfs] [--pages 2m|4k|map] [--trees LIST]
 *
 * Loads a compiled scene (only triangles) and makes trees over its
 * triangles, each in Franja's 8-wide layout (nodes and leaf blocks, checked
 * by bvh_validate) and walked by trace_closest and trace_occluded, the
 * renderer's own walk.  LIST (comma-separated; default
 * build,emb-med,emb-high) picks them besides the first, always there:
 *   file      the tree stored in the scene (the builder that compiled it);
 *   build     bvh_build run now (this build's builder);
 *   emb-med   Embree's own builder (rtcBuildBVH, RTC_BUILD_QUALITY_MEDIUM:
 *             binned SAH), eight children a node, leaves of at most --leaf
 *             triangles (default 16) and at least 4, costs in blocks of four
 *             triangles with a node test costing one block, as Embree's BVH8
 *             of four-triangle blocks is built; laid out as bvh_build lays
 *             out its trees (nodes depth first, a node's leaf blocks where
 *             its slot is reached), or with --order bfs a node's child nodes
 *             side by side;
 *   emb-high  the same at RTC_BUILD_QUALITY_HIGH with spatial splits (room
 *             for one extra reference per triangle);
 *   grouped   the stored tree with each node's leaf blocks side by side and
 *             then its child nodes side by side;
 *   sorted    grouped, with a node's slots by decreasing box area;
 *   copy-4k, copy-2m   the stored tree copied into 4 KiB or 2 MiB pages
 *             whatever --pages says;
 *   file2     a second copy of the stored tree (the noise between equals).
 * The trees' arrays lie in anonymous memory of 2 MiB pages (--pages 2m,
 * the default: as Embree places its own) or of 4 KiB pages (4k); with
 * --pages map the stored tree is walked where the scene's file is mapped,
 * as a worker walks it, and the others lie in 2 MiB pages.  The walk's
 * speed depends on the pages (bench_pages.h).  Embree's own traversal of its
 * own scenes (rtcIntersect1 and rtcOccluded1) is timed beside them, the
 * reference the goal is measured against: embree-rt at the default build
 * quality, embree-rt-high at RTC_BUILD_QUALITY_HIGH.
 *
 * For each tree: nodes, leaf blocks, filled lanes, the SAH cost in the
 * builder's model (bvh_sah_cost), its build time, and, over the diffuse
 * bounce rays of bench_rays.h, nodes and leaf blocks tested per ray, counted
 * by a scalar copy of the walk's order (nearest entered child first,
 * subtrees beyond the best hit skipped).  Then rays per second of process
 * CPU time, every tree and both Embree scenes taking turns on chunks of --chunk rays
 * (default 4096; the first to run rotates; a chunk larger than the rays
 * makes whole passes), summed over --passes passes (default 5), so that a
 * busy machine's drift falls on all alike.  Every tree must give every
 * closest-hit ray the same t and triangle and every any-hit ray the same
 * answer as the stored one; the program fails otherwise. */
#include <embree3/rtcore.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_pages.h"
#include "bench_rays.h"
#include "compile/builder.h"
#include "bvh.h"
#include "compile/bvh_build.h"
#include "fbin.h"
#include "trace.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- Embree's tree, as its builder hands it over ---- */

typedef struct enode {
    int leaf;                  /* 0 */
    unsigned n;
    const void *kid[FR_BVH_WIDTH];
    struct RTCBounds box[FR_BVH_WIDTH];
} enode;

typedef struct {
    int leaf;                  /* 1 */
    unsigned n;
    unsigned prim[];           /* Franja prim indices */
} eleaf;

static void *cb_node(RTCThreadLocalAllocator a, unsigned n, void *user)
{
    (void)user;
    enode *x = rtcThreadLocalAlloc(a, sizeof *x, 16);
    x->leaf = 0;
    x->n = n;
    return x;
}

static void cb_children(void *node, void **kid, unsigned n, void *user)
{
    (void)user;
    enode *x = node;
    for (unsigned i = 0; i < n; i++)
        x->kid[i] = kid[i];
}

static void cb_bounds(void *node, const struct RTCBounds **b, unsigned n, void *user)
{
    (void)user;
    enode *x = node;
    for (unsigned i = 0; i < n; i++)
        x->box[i] = *b[i];
}

static void *cb_leaf(RTCThreadLocalAllocator a, const struct RTCBuildPrimitive *p, size_t n, void *user)
{
    (void)user;
    eleaf *x = rtcThreadLocalAlloc(a, sizeof *x + n * sizeof(unsigned), 16);
    x->leaf = 1;
    x->n = (unsigned)n;
    for (size_t i = 0; i < n; i++)
        x->prim[i] = p[i].primID;
    return x;
}

static void vert(const fr_scene *s, uint32_t prim, vec3 v[3])
{
    const fr_triangle *t = &s->triangles[s->prims[prim].index];
    for (int k = 0; k < 3; k++)
        v[k] = s->positions[t->v[k]];
}

static float coord(vec3 p, unsigned a) { return a == 0 ? p.x : a == 1 ? p.y : p.z; }

static void box_add(struct RTCBounds *b, vec3 p, float e)
{
    b->lower_x = fminf(b->lower_x, p.x - e); b->upper_x = fmaxf(b->upper_x, p.x + e);
    b->lower_y = fminf(b->lower_y, p.y - e); b->upper_y = fmaxf(b->upper_y, p.y + e);
    b->lower_z = fminf(b->lower_z, p.z - e); b->upper_z = fmaxf(b->upper_z, p.z + e);
}

/* Spatial splits: the parts of a reference's triangle on either side of
 * the plane x[dim] = pos, within the reference's bounds (edge crossings
 * widened far beyond their rounding error, so a part is never too small). */
static void cb_split(const struct RTCBuildPrimitive *p, unsigned dim, float pos, struct RTCBounds *l,
                     struct RTCBounds *r, void *user)
{
    const fr_scene *s = user;
    vec3 v[3];
    vert(s, p->primID, v);
    struct RTCBounds e = {INFINITY, INFINITY, INFINITY, 0, -INFINITY, -INFINITY, -INFINITY, 0};
    *l = *r = e;
    for (int k = 0; k < 3; k++) {
        vec3 a = v[k], b = v[k == 2 ? 0 : k + 1];
        float pa = coord(a, dim), pb = coord(b, dim);
        if (pa <= pos)
            box_add(l, a, 0.0f);
        if (pa >= pos)
            box_add(r, a, 0.0f);
        if ((pa < pos && pb > pos) || (pa > pos && pb < pos)) {
            float t = (pos - pa) / (pb - pa);
            vec3 x = v3_add(a, v3_scale(v3_sub(b, a), t));
            float err = (fabsf(a.x) + fabsf(a.y) + fabsf(a.z) + fabsf(b.x) + fabsf(b.y) + fabsf(b.z)) * 0x1p-18f;
            box_add(l, x, err);
            box_add(r, x, err);
        }
    }
    float lo[3] = {p->lower_x, p->lower_y, p->lower_z}, hi[3] = {p->upper_x, p->upper_y, p->upper_z};
    float *L[2][6] = {{&l->lower_x, &l->lower_y, &l->lower_z, &l->upper_x, &l->upper_y, &l->upper_z},
                      {&r->lower_x, &r->lower_y, &r->lower_z, &r->upper_x, &r->upper_y, &r->upper_z}};
    for (int side = 0; side < 2; side++)
        for (int a = 0; a < 3; a++) {
            *L[side][a] = fmaxf(*L[side][a], lo[a]);
            *L[side][3 + a] = fminf(*L[side][3 + a], hi[a]);
        }
    if (l->upper_x < l->lower_x) *l = e;   /* nothing of it left there */
    if (r->upper_x < r->lower_x) *r = e;
    *L[0][3 + dim] = fminf(*L[0][3 + dim], pos);
    *L[1][dim] = fmaxf(*L[1][dim], pos);
}

/* ---- conversion into Franja's layout ---- */

typedef struct {
    const fr_scene *s;
    fr_array nodes, leaves;
    int bfs;
} conv;

static int emit_leaf(conv *C, const eleaf *x, uint32_t *first, uint32_t *meta)
{
    uint32_t ids[256], n = 0;
    for (unsigned i = 0; i < x->n; i++) {
        uint32_t k = 0;
        while (k < n && ids[k] != x->prim[i])
            k++;
        if (k == n && n < 256)
            ids[n++] = x->prim[i];
    }
    uint32_t nblk = (n + 3) / 4;
    if (nblk > FR_BVH_LEAF_MAX)
        return -1;
    *first = C->leaves.count;
    for (uint32_t b = 0; b < nblk; b++) {
        fr_bvh_leaf L;
        memset(&L, 0, sizeof L);
        for (uint32_t lane = 0; lane < 4; lane++) {
            uint32_t i = 4 * b + lane;
            L.prim[lane] = i < n ? ids[i] : FR_NONE;
            if (i >= n)
                continue;
            vec3 v[3];
            vert(C->s, ids[i], v);
            for (int c = 0; c < 3; c++) {
                L.v[3 * c + 0][lane] = v[c].x;
                L.v[3 * c + 1][lane] = v[c].y;
                L.v[3 * c + 2][lane] = v[c].z;
            }
        }
        if (bld_push(&C->leaves, &L) == FR_NONE)
            return -1;
    }
    *meta = nblk;
    return 0;
}

/* Fill node `me` (already pushed) from x; children pushed depth first, or
 * (bfs) all of a node's child nodes pushed before any is filled. */
static int fill_node(conv *C, uint32_t me, const enode *x)
{
    uint32_t kids[FR_BVH_WIDTH];
    int nk = 0;
    for (int i = 0; i < FR_BVH_WIDTH; i++) {
        fr_bvh_node *nd = (fr_bvh_node *)C->nodes.data + me;
        int used = i < (int)x->n;
        const struct RTCBounds *b = &x->box[i];
        float lo[3] = {b->lower_x, b->lower_y, b->lower_z}, hi[3] = {b->upper_x, b->upper_y, b->upper_z};
        for (int a = 0; a < 3; a++) {
            nd->box[a][i] = used ? lo[a] + 0.0f : INFINITY;
            nd->box[3 + a][i] = used ? hi[a] + 0.0f : -INFINITY;
        }
        nd->child[i] = FR_NONE;
        nd->leaf[i] = 0;
        if (!used)
            continue;
        const int *tag = x->kid[i];
        uint32_t child, meta = 0;
        if (*tag) {
            if (emit_leaf(C, x->kid[i], &child, &meta) < 0)
                return -1;
        } else {
            fr_bvh_node blank;
            memset(&blank, 0, sizeof blank);
            child = bld_push(&C->nodes, &blank);
            if (child == FR_NONE)
                return -1;
            if (!C->bfs && fill_node(C, child, x->kid[i]) < 0)
                return -1;
            kids[nk++] = (uint32_t)i;
        }
        nd = (fr_bvh_node *)C->nodes.data + me;
        nd->child[i] = child;
        nd->leaf[i] = meta;
    }
    if (C->bfs)
        for (int k = 0; k < nk; k++) {
            const fr_bvh_node *nd = (const fr_bvh_node *)C->nodes.data + me;
            if (fill_node(C, nd->child[kids[k]], x->kid[kids[k]]) < 0)
                return -1;
        }
    return 0;
}

/* Where the trees' arrays go: anonymous memory in 2 MiB pages (1, the
 * default), in 4 KiB pages (0); the walk's speed depends on it. */
static int g_huge = 1;

/* A copy of n elements of `size` bytes, on a 2 MiB boundary in pages of
 * the size --pages asks for. */
static void *tree_copy(const void *p, size_t n, size_t size)
{
    size_t bytes = n * size;
    return page_copy(p, bytes ? bytes : 1, g_huge);
}

/* *out becomes s with the tree of nodes and leaves, copied as tree_copy
 * does; the arrays are freed.  -1 if a copy failed. */
static int adopt_tree(const fr_scene *s, fr_array *nodes, fr_array *leaves, fr_scene *out)
{
    *out = *s;
    out->nodes = tree_copy(nodes->data, nodes->count, sizeof(fr_bvh_node));
    out->n_nodes = nodes->count;
    out->leaves = tree_copy(leaves->data, leaves->count, sizeof(fr_bvh_leaf));
    out->n_leaves = leaves->count;
    free(nodes->data);
    free(leaves->data);
    return out->nodes && out->leaves ? 0 : -1;
}

/* A tree made by Embree's builder at quality q over the triangles of s, in
 * Franja's layout: *out is s with that tree (its arrays malloc'd). */
static int embree_tree(RTCDevice dev, const fr_scene *s, enum RTCBuildQuality q, unsigned max_leaf, int bfs,
                       fr_scene *out, double *ms)
{
    size_t n = s->n_prims, cap = q == RTC_BUILD_QUALITY_HIGH ? 2 * n : n;
    struct RTCBuildPrimitive *p = aligned_alloc(32, cap * sizeof *p);
    if (!p)
        return -1;
    for (uint32_t i = 0; i < n; i++) {
        vec3 v[3];
        vert(s, i, v);
        vec3 lo = v3_vmin(v3_vmin(v[0], v[1]), v[2]), hi = v3_vmax(v3_vmax(v[0], v[1]), v[2]);
        p[i] = (struct RTCBuildPrimitive){lo.x, lo.y, lo.z, 0, hi.x, hi.y, hi.z, i};
    }
    RTCBVH bvh = rtcNewBVH(dev);
    struct RTCBuildArguments a = rtcDefaultBuildArguments();
    a.buildQuality = q;
    a.maxBranchingFactor = FR_BVH_WIDTH;
    a.maxDepth = 40;
    a.sahBlockSize = 4;
    a.minLeafSize = 4;
    a.maxLeafSize = max_leaf;
    a.traversalCost = 1.0f;
    a.intersectionCost = 1.0f;
    a.bvh = bvh;
    a.primitives = p;
    a.primitiveCount = n;
    a.primitiveArrayCapacity = cap;
    a.createNode = cb_node;
    a.setNodeChildren = cb_children;
    a.setNodeBounds = cb_bounds;
    a.createLeaf = cb_leaf;
    a.splitPrimitive = q == RTC_BUILD_QUALITY_HIGH ? cb_split : NULL;
    a.userPtr = (void *)s;
    double t0 = now();
    const int *root = rtcBuildBVH(&a);
    *ms = (now() - t0) * 1e3;
    if (!root)
        return -1;
    conv C = {s, {NULL, 0, 0, sizeof(fr_bvh_node)}, {NULL, 0, 0, sizeof(fr_bvh_leaf)}, bfs};
    enode wrap;
    const enode *top = (const enode *)root;
    if (*root) {   /* a leaf at the top: the root node holds it */
        memset(&wrap, 0, sizeof wrap);
        wrap.n = 1;
        wrap.kid[0] = root;
        wrap.box[0] = (struct RTCBounds){INFINITY, INFINITY, INFINITY, 0, -INFINITY, -INFINITY, -INFINITY, 0};
        for (size_t i = 0; i < n; i++) {
            box_add(&wrap.box[0], (vec3){p[i].lower_x, p[i].lower_y, p[i].lower_z}, 0.0f);
            box_add(&wrap.box[0], (vec3){p[i].upper_x, p[i].upper_y, p[i].upper_z}, 0.0f);
        }
        top = &wrap;
    }
    fr_bvh_node blank;
    memset(&blank, 0, sizeof blank);
    int rc = bld_push(&C.nodes, &blank) == FR_NONE || fill_node(&C, 0, top) < 0 ? -1 : 0;
    rtcReleaseBVH(bvh);
    free(p);
    return adopt_tree(s, &C.nodes, &C.leaves, out) < 0 || rc < 0 ? -1 : 0;
}

/* The tree bvh_build makes now over the triangles of s: *out is s with it
 * (and the builder's primitive order). */
static int franja_tree(const fr_scene *s, fr_scene *out, double *ms)
{
    fr_builder b;
    bld_init(&b);
    fr_material mat;
    bld_material_init(&mat);
    bld_push(&b.materials, &mat);
    for (uint32_t i = 0; i < s->n_positions; i++)
        bld_push(&b.positions, &s->positions[i]);
    for (uint32_t i = 0; i < s->n_triangles; i++)
        bld_push(&b.triangles, &s->triangles[i]);
    for (uint32_t i = 0; i < s->n_prims; i++)
        bld_push(&b.prims, &s->prims[i]);
    fr_array nodes = {NULL, 0, 0, sizeof(fr_bvh_node)}, leaves = {NULL, 0, 0, sizeof(fr_bvh_leaf)};
    fr_error err;
    double t0 = now();
    int rc = bvh_build(&b, &nodes, &leaves, NULL, &err);
    *ms = (now() - t0) * 1e3;
    if (rc < 0) {
        fprintf(stderr, "bvhtrees: %s\n", err.msg);
        return -1;
    }
    rc = adopt_tree(s, &nodes, &leaves, out);
    out->prims = tree_copy(b.prims.data, b.prims.count, sizeof(fr_prim));
    bld_free(&b);
    return rc < 0 || !out->prims ? -1 : 0;
}

/* ---- another layout of the same tree ---- */

typedef struct {
    const fr_scene *s;
    fr_array nodes, leaves;
    int sort;
} relay;

static float slot_area(const fr_bvh_node *n, int i)
{
    float dx = n->box[3][i] - n->box[0][i], dy = n->box[4][i] - n->box[1][i], dz = n->box[5][i] - n->box[2][i];
    return dx * dy + dy * dz + dz * dx;
}

/* Node v of R->s into node `me` of the copy: its leaves' blocks side by
 * side, then its child nodes side by side, then their subtrees in turn;
 * with `sort`, slots by decreasing box area. */
static int relay_node(relay *R, uint32_t v, uint32_t me)
{
    fr_bvh_node x = R->s->nodes[v], y;
    int perm[FR_BVH_WIDTH], n = 0;
    for (int i = 0; i < FR_BVH_WIDTH; i++)
        if (x.child[i] != FR_NONE) {
            int j = n++;
            for (; R->sort && j > 0 && slot_area(&x, perm[j - 1]) < slot_area(&x, i); j--)
                perm[j] = perm[j - 1];
            perm[j] = i;
        }
    y = x;
    for (int k = 0; k < FR_BVH_WIDTH; k++) {
        int i = k < n ? perm[k] : -1;
        for (int a = 0; a < 6; a++)
            y.box[a][k] = i >= 0 ? x.box[a][i] : (a < 3 ? INFINITY : -INFINITY);
        y.child[k] = i >= 0 ? x.child[i] : FR_NONE;
        y.leaf[k] = i >= 0 ? x.leaf[i] : 0;
        if (i < 0 || !y.leaf[k])
            continue;
        y.child[k] = R->leaves.count;
        for (uint32_t b = 0; b < (y.leaf[k] & FR_BVH_LEAF_MAX); b++)
            if (bld_push(&R->leaves, &R->s->leaves[x.child[i] + b]) == FR_NONE)
                return -1;
    }
    uint32_t src[FR_BVH_WIDTH];
    for (int k = 0; k < n; k++) {
        if (y.leaf[k])
            continue;
        src[k] = y.child[k];
        y.child[k] = bld_push(&R->nodes, &x);   /* filled below */
        if (y.child[k] == FR_NONE)
            return -1;
    }
    ((fr_bvh_node *)R->nodes.data)[me] = y;
    for (int k = 0; k < n; k++)
        if (!y.leaf[k] && relay_node(R, src[k], y.child[k]) < 0)
            return -1;
    return 0;
}

static int relayout(const fr_scene *s, int sort, fr_scene *out)
{
    relay R = {s, {NULL, 0, 0, sizeof(fr_bvh_node)}, {NULL, 0, 0, sizeof(fr_bvh_leaf)}, sort};
    int rc = bld_push(&R.nodes, &s->nodes[0]) == FR_NONE || relay_node(&R, 0, 0) < 0 ? -1 : 0;
    return adopt_tree(s, &R.nodes, &R.leaves, out) < 0 || rc < 0 ? -1 : 0;
}

/* ---- what a tree costs a ray, counted ---- */

/* The walk's order, scalar: nodes and leaf blocks tested by ray r. */
static void count_walk(const fr_scene *s, const fr_ray *r, int any, double *nodes, double *blocks)
{
    const float FAR = 1.0000153f;
    float o[3] = {r->o.x, r->o.y, r->o.z}, inv[3] = {1.0f / r->d.x, 1.0f / r->d.y, 1.0f / r->d.z};
    float best = INFINITY;
    typedef struct { uint32_t child, leaf; float t; } entry;
    entry stack[(FR_BVH_WIDTH - 1) * FR_BVH_MAX_DEPTH + 1];
    int sp = 0;
    uint32_t child = 0, leaf = 0;
    for (;;) {
        if (!leaf) {
            const fr_bvh_node *n = &s->nodes[child];
            ++*nodes;
            float tn[FR_BVH_WIDTH];
            int e[FR_BVH_WIDTH], k = 0;
            for (int i = 0; i < FR_BVH_WIDTH; i++) {
                if (n->child[i] == FR_NONE)
                    continue;
                float t0 = 0.0f, t1 = best * FAR;
                for (int a = 0; a < 3; a++) {
                    float u = (n->box[a][i] - o[a]) * inv[a], v = (n->box[3 + a][i] - o[a]) * inv[a];
                    t0 = fmaxf(t0, fminf(u, v));
                    t1 = fminf(t1, fmaxf(u, v) * FAR);
                }
                if (!(t0 <= t1))
                    continue;
                tn[i] = t0;
                int j = k++;
                for (; !any && j > 0 && tn[e[j - 1]] > t0; j--)
                    e[j] = e[j - 1];
                e[j] = i;
            }
            if (k) {
                for (int j = k - 1; j > 0; j--)
                    stack[sp++] = (entry){n->child[e[j]], n->leaf[e[j]], tn[e[j]]};
                child = n->child[e[0]];
                leaf = n->leaf[e[0]];
                continue;
            }
        } else {
            uint32_t end = child + (leaf & FR_BVH_LEAF_MAX);
            for (uint32_t b = child; b < end; b++) {
                ++*blocks;
                for (int lane = 0; lane < 4; lane++) {
                    uint32_t p = s->leaves[b].prim[lane];
                    if (p == FR_NONE)
                        continue;
                    float ba, bb, t = trace_prim(s, p, r, best, &ba, &bb);
                    if (t > 0.0f && t < best) {
                        if (any)
                            return;
                        best = t;
                    }
                }
            }
        }
        for (;;) {
            if (sp == 0)
                return;
            sp--;
            if (!any && !(stack[sp].t <= best * FAR))
                continue;
            child = stack[sp].child;
            leaf = stack[sp].leaf;
            break;
        }
    }
}

static void describe(const char *name, const fr_scene *t, const fr_ray *rays, uint32_t n, double build_ms)
{
    uint32_t lanes = 0, slots = 0, leaf_slots = 0;
    for (uint32_t b = 0; b < t->n_leaves; b++)
        for (int k = 0; k < 4; k++)
            lanes += t->leaves[b].prim[k] != FR_NONE;
    for (uint32_t v = 0; v < t->n_nodes; v++)
        for (int k = 0; k < FR_BVH_WIDTH; k++) {
            slots += t->nodes[v].child[k] != FR_NONE;
            leaf_slots += t->nodes[v].leaf[k] != 0;
        }
    double cn = 0, cb = 0, an = 0, ab = 0;
    for (uint32_t i = 0; i < n; i++) {
        count_walk(t, &rays[i], 0, &cn, &cb);
        count_walk(t, &rays[i], 1, &an, &ab);
    }
    printf("%-9s %6u nodes (%.2f slots each), %6u leaves of %.2f blocks, %7u blocks %.1f %% full, SAH %.3f, "
           "build %.0f ms; per bounce ray: closest %.2f nodes %.2f blocks, any-hit %.2f nodes %.2f blocks\n",
           name, t->n_nodes, (double)slots / t->n_nodes, leaf_slots, (double)t->n_leaves / leaf_slots,
           t->n_leaves, 100.0 * lanes / (4.0 * t->n_leaves), bvh_sah_cost(t->nodes, t->n_nodes), build_ms, cn / n,
           cb / n, an / n, ab / n);
}

/* ---- timing ---- */

static double franja_chunk(const fr_scene *t, const fr_ray *r, uint32_t n, int any, uint32_t *acc)
{
    double t0 = now();
    uint32_t a = 0;
    if (any) {
        for (uint32_t i = 0; i < n; i++)
            a += (uint32_t)trace_occluded(t, &r[i], INFINITY, FR_NONE);
    } else {
        for (uint32_t i = 0; i < n; i++) {
            fr_hit h;
            if (trace_closest(t, &r[i], INFINITY, &h))
                a += h.prim;
        }
    }
    *acc += a;
    return now() - t0;
}

static double embree_chunk(RTCScene es, const fr_ray *r, uint32_t n, int any, uint32_t *acc)
{
    struct RTCIntersectContext ctx;
    uint32_t a = 0;
    double t0 = now();
    for (uint32_t i = 0; i < n; i++) {
        struct RTCRayHit rh;
        memset(&rh, 0, sizeof rh);
        rh.ray.org_x = r[i].o.x; rh.ray.org_y = r[i].o.y; rh.ray.org_z = r[i].o.z;
        rh.ray.dir_x = r[i].d.x; rh.ray.dir_y = r[i].d.y; rh.ray.dir_z = r[i].d.z;
        rh.ray.tfar = INFINITY;
        rh.ray.mask = 0xffffffffu;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcInitIntersectContext(&ctx);
        if (any) {
            rtcOccluded1(es, &ctx, &rh.ray);
            a += rh.ray.tfar < 0.0f;
        } else {
            rtcIntersect1(es, &ctx, &rh);
            a += rh.hit.primID;
        }
    }
    *acc += a;
    return now() - t0;
}

/* Same answers as the stored tree on every ray: closest t bits and
 * triangle, any-hit yes or no.  Returns the rays that differ. */
static uint32_t differences(const fr_scene *ref, const fr_scene *t, const fr_ray *r, uint32_t n)
{
    uint32_t bad = 0;
    for (uint32_t i = 0; i < n; i++) {
        fr_hit a, b;
        int ha = trace_closest(ref, &r[i], INFINITY, &a), hb = trace_closest(t, &r[i], INFINITY, &b);
        if (ha != hb || (ha && (memcmp(&a.t, &b.t, sizeof a.t) ||
                                ref->prims[a.prim].index != t->prims[b.prim].index)))
            bad++;
        else if (trace_occluded(ref, &r[i], INFINITY, FR_NONE) != trace_occluded(t, &r[i], INFINITY, FR_NONE))
            bad++;
    }
    return bad;
}

static int paged(const fr_scene *s, int huge, fr_scene *out)
{
    *out = *s;
    out->nodes = page_copy(s->nodes, (size_t)s->n_nodes * sizeof(fr_bvh_node), huge);
    out->leaves = page_copy(s->leaves, (size_t)s->n_leaves * sizeof(fr_bvh_leaf), huge);
    return out->nodes && out->leaves ? 0 : -1;
}

enum { KINDS = 9, EMBREE_RUNS = 2, MAX_RUNS = KINDS + EMBREE_RUNS };
static const char *kind_names[KINDS] = {"file", "build", "emb-med", "emb-high", "grouped", "sorted", "copy-4k", "copy-2m", "file2"};

int main(int argc, char **argv)
{
    const char *path = NULL, *pick = "build,emb-med,emb-high", *pages = "2m";
    uint32_t w = 1024, h = 1024, chunk = 4096;
    unsigned max_leaf = 16;
    int passes = 5, bfs = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--size") && i + 1 < argc) sscanf(argv[++i], "%ux%u", &w, &h);
        else if (!strcmp(argv[i], "--passes") && i + 1 < argc) passes = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--chunk") && i + 1 < argc) chunk = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--leaf") && i + 1 < argc) max_leaf = (unsigned)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--order") && i + 1 < argc) bfs = !strcmp(argv[++i], "bfs");
        else if (!strcmp(argv[i], "--trees") && i + 1 < argc) pick = argv[++i];
        else if (!strcmp(argv[i], "--pages") && i + 1 < argc) pages = argv[++i];
        else if (argv[i][0] != '-') path = argv[i];
        else { fprintf(stderr, "bvhtrees: unknown argument %s\n", argv[i]); return 2; }
    }
    int kinds[KINDS], n_trees = 1;
    kinds[0] = 0;   /* the stored tree, the reference, always */
    for (const char *q = pick; *q;) {
        size_t len = strcspn(q, ",");
        int k = 0;
        while (k < KINDS && !(strlen(kind_names[k]) == len && !strncmp(q, kind_names[k], len)))
            k++;
        if (k == KINDS) {
            fprintf(stderr, "bvhtrees: --trees: unknown tree '%.*s'\n", (int)len, q);
            return 2;
        }
        if (k > 0 && n_trees < KINDS)
            kinds[n_trees++] = k;
        q += len + (q[len] == ',');
    }
    g_huge = strcmp(pages, "4k") != 0;
    int as_mapped = !strcmp(pages, "map");
    if (!as_mapped && strcmp(pages, "2m") && strcmp(pages, "4k"))
        path = NULL;
    if (!path || passes < 1 || chunk == 0 || w == 0 || h == 0 || max_leaf < 4 ||
        max_leaf > RTC_BUILD_MAX_PRIMITIVES_PER_LEAF) {
        fprintf(stderr, "usage: bvhtrees SCENE.fbin [--size WxH] [--passes N] [--chunk N] [--leaf 4..32] "
                        "[--order dfs|bfs] [--pages 2m|4k|map] [--trees file,build,emb-med,emb-high,grouped,sorted,copy-4k,copy-2m]\n");
        return 2;
    }
    fr_scene s;
    fr_error err;
    if (fbin_load(path, &s, &err) < 0) {
        fprintf(stderr, "bvhtrees: %s\n", err.msg);
        return 1;
    }
    for (uint32_t i = 0; i < s.n_prims; i++)
        if (s.prims[i].kind != FR_PRIM_TRIANGLE) {
            fprintf(stderr, "bvhtrees: %s: primitive %u is not a triangle\n", path, i);
            return 1;
        }
    RTCDevice dev = rtcNewDevice("threads=1");
    if (!dev) {
        fprintf(stderr, "bvhtrees: rtcNewDevice failed\n");
        return 1;
    }
    const char *names[MAX_RUNS];
    fr_scene tree[KINDS];
    double ms[KINDS] = {0};
    for (int t = 0; t < n_trees; t++) {
        int k = kinds[t], rc = 0;
        names[t] = kind_names[k];
        switch (k) {
        case 0:
            tree[t] = s;
            if (!as_mapped)
                rc = paged(&s, g_huge, &tree[t]);
            break;
        case 1: rc = franja_tree(&s, &tree[t], &ms[t]); break;
        case 2: rc = embree_tree(dev, &s, RTC_BUILD_QUALITY_MEDIUM, max_leaf, bfs, &tree[t], &ms[t]); break;
        case 3: rc = embree_tree(dev, &s, RTC_BUILD_QUALITY_HIGH, max_leaf, bfs, &tree[t], &ms[t]); break;
        case 4: rc = relayout(&s, 0, &tree[t]); break;
        case 5: rc = relayout(&s, 1, &tree[t]); break;
        case 6: case 7: rc = paged(&s, k == 7, &tree[t]); break;
        default: rc = paged(&s, g_huge, &tree[t]); break;
        }
        if (rc < 0) {
            fprintf(stderr, "bvhtrees: tree %s could not be made\n", names[t]);
            return 1;
        }
        if (k > 0 && bvh_validate(&tree[t], tree[t].nodes, &err) < 0) {
            fprintf(stderr, "bvhtrees: tree %s: %s\n", names[t], err.msg);
            return 1;
        }
    }
    names[n_trees] = "embree-rt";
    names[n_trees + 1] = "embree-rt-high";
    /* Embree's own scenes (default and high build quality) for its own traversal. */
    float *vx = malloc(((size_t)s.n_positions * 3 + 1) * sizeof *vx);
    uint32_t *ix = malloc((size_t)s.n_triangles * 3 * sizeof *ix);
    if (!vx || !ix)
        return 1;
    for (uint32_t i = 0; i < s.n_positions; i++) {
        vx[3 * i] = s.positions[i].x; vx[3 * i + 1] = s.positions[i].y; vx[3 * i + 2] = s.positions[i].z;
    }
    vx[3 * s.n_positions] = 0.0f;
    for (uint32_t i = 0; i < s.n_triangles; i++)
        for (int k = 0; k < 3; k++)
            ix[3 * i + k] = s.triangles[i].v[k];
    RTCScene es[EMBREE_RUNS];
    for (int e = 0; e < EMBREE_RUNS; e++) {
        es[e] = rtcNewScene(dev);
        RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vx, 0, 12, s.n_positions);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, ix, 0, 12, s.n_triangles);
        if (e == 1) {
            rtcSetSceneBuildQuality(es[e], RTC_BUILD_QUALITY_HIGH);
            rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
        }
        rtcCommitGeometry(g);
        rtcAttachGeometry(es[e], g);
        rtcReleaseGeometry(g);
        rtcCommitScene(es[e]);
    }

    uint32_t np = 0, nb = 0;
    fr_ray *all = make_rays(&s, w, h, &np, &nb);
    if (!all || nb == 0) {
        fprintf(stderr, "bvhtrees: no bounce rays\n");
        return 1;
    }
    const fr_ray *rays = all + np;
    printf("stored sections at byte %zu (nodes), %zu (leaves), %zu (prims) of a 64-byte line\n",
           (size_t)(uintptr_t)s.nodes % 64, (size_t)(uintptr_t)s.leaves % 64, (size_t)(uintptr_t)s.prims % 64);
    printf("scene %s: %u triangles; %u bounce rays from a %ux%u grid; Embree leaves of 4..%u triangles, %s order\n",
           path, s.n_triangles, nb, w, h, max_leaf, bfs ? "breadth-first" : "depth-first");
    for (int k = 1; k < n_trees; k++) {
        uint32_t bad = differences(&s, &tree[k], all, np + nb);
        if (bad) {
            fprintf(stderr, "bvhtrees: tree %s answers %u of %u rays otherwise than the stored tree\n", names[k], bad,
                    np + nb);
            return 1;
        }
    }
    printf("every tree gives the stored tree's answers on all %u primary and bounce rays\n", np + nb);
    for (int k = 0; k < n_trees; k++)
        describe(names[k], &tree[k], rays, nb, ms[k]);
    fflush(stdout);

    uint32_t acc = 0;
    for (int any = 0; any < 2; any++) {
        double sum[MAX_RUNS] = {0};
        uint32_t turn = 0;
        for (int p = 0; p < passes; p++)
            for (uint32_t c = 0; c < nb; c += chunk, turn++) {
                uint32_t n = nb - c < chunk ? nb - c : chunk;
                for (int j = 0; j < n_trees + EMBREE_RUNS; j++) {
                    int k = (int)((turn + (uint32_t)j) % (uint32_t)(n_trees + EMBREE_RUNS));
                    sum[k] += k < n_trees ? franja_chunk(&tree[k], rays + c, n, any, &acc)
                                        : embree_chunk(es[k - n_trees], rays + c, n, any, &acc);
                }
            }
        printf("bounce %s, %d passes, Mrays/s (ratio to file):", any ? "any-hit" : "closest", passes);
        for (int k = 0; k < n_trees + EMBREE_RUNS; k++)
            printf("  %s %.3f (%.3f)", names[k], (double)nb * passes / sum[k] / 1e6, sum[0] / sum[k]);
        printf("\n");
        fflush(stdout);
    }
    if (acc == 1)
        printf(" \n");   /* keeps the answers live */
    for (int e = 0; e < EMBREE_RUNS; e++)
        rtcReleaseScene(es[e]);
    rtcReleaseDevice(dev);
    free(all);
    free(vx);
    free(ix);
    return 0;
}
