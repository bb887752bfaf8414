/* bvh.c -- the check that a loaded 8-wide BVH is sound before any ray walks it
 * (see bvh.h). */

#include "bvh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "simd4.h"

#define AT(p) ((size_t)((const char *)(p) - (const char *)base))

/* One tree: `nodes` and `leaves` (named in messages as `sn` and `sl`) over
 * prims [lo, hi), each of which it must hold; leaves may mix primitive
 * kinds only where `mixed_ok`. */
static int validate_tree(const fr_scene *s, const void *base, const char *sn, const char *sl,
                         const fr_bvh_node *nodes, uint32_t n_nodes, const fr_bvh_leaf *leaves, uint32_t n_leaves,
                         uint32_t lo, uint32_t hi, int mixed_ok, fr_error *err)
{
    if (n_nodes == 0 || n_leaves == 0)
        return fr_fail(err, "section %s: the scene has primitives but no BVH", sn);
    unsigned char *depth = calloc(n_nodes, 1);
    unsigned char *owner = calloc(n_leaves, 1);      /* 1: in a leaf, 2: in a mixed leaf */
    unsigned char *seen = calloc(hi - lo + 1, 1);    /* 1: in some lane */
    int rc = 0;
    if (!depth || !owner || !seen) {
        rc = fr_fail(err, "out of memory validating the BVH");
        goto done;
    }
    depth[0] = 1;
    for (uint32_t i = 0; i < n_nodes && rc == 0; i++) {
        const fr_bvh_node *n = &nodes[i];
        if (depth[i] == 0) {
            rc = fr_fail(err, "section %s, byte %zu: node %u is not reachable from the root", sn, AT(n), i);
            break;
        }
        for (int k = 0; k < FR_BVH_WIDTH && rc == 0; k++) {
            uint32_t c = n->child[k], meta = n->leaf[k];
            if (c == FR_NONE) {
                int empty = meta == 0;
                for (int a = 0; a < 3; a++)
                    empty &= n->box[a][k] == INFINITY && n->box[3 + a][k] == -INFINITY;
                if (!empty)
                    rc = fr_fail(err, "section %s, byte %zu: node %u slot %d: an empty slot needs leaf 0 "
                                 "and the empty box (+inf, -inf)", sn, AT(n->child + k), i, k);
                continue;
            }
            for (int a = 0; a < 3 && rc == 0; a++)
                if (!(n->box[a][k] <= n->box[3 + a][k]) || !isfinite(n->box[a][k]) || !isfinite(n->box[3 + a][k]))
                    rc = fr_fail(err, "section %s, byte %zu: node %u slot %d: box not finite or inverted on axis %d",
                                 sn, AT(n->box[a] + k), i, k, a);
            if (rc)
                break;
            if (meta == 0) {
                if (c <= i || c >= n_nodes)
                    rc = fr_fail(err, "section %s, byte %zu: node %u slot %d: child %u not in (%u, %u)",
                                 sn, AT(n->child + k), i, k, c, i, n_nodes);
                else if (depth[c])
                    rc = fr_fail(err, "section %s, byte %zu: node %u slot %d: node %u has two parents",
                                 sn, AT(n->child + k), i, k, c);
                else if (depth[i] >= FR_BVH_MAX_DEPTH)
                    rc = fr_fail(err, "section %s, byte %zu: node %u slot %d: deeper than %d levels",
                                 sn, AT(n->child + k), i, k, FR_BVH_MAX_DEPTH);
                else
                    depth[c] = (unsigned char)(depth[i] + 1);
                continue;
            }
            uint32_t nblk = meta & FR_BVH_LEAF_MAX;
            if ((meta & ~(FR_BVH_LEAF_MAX | FR_BVH_MIXED)) || nblk == 0) {
                rc = fr_fail(err, "section %s, byte %zu: node %u slot %d: bad leaf word 0x%x",
                             sn, AT(n->leaf + k), i, k, meta);
                break;
            }
            if (c >= n_leaves || nblk > n_leaves - c) {
                rc = fr_fail(err, "section %s, byte %zu: node %u slot %d: leaf blocks %u..%u past the %u blocks",
                             sn, AT(n->child + k), i, k, c, c + nblk - 1, n_leaves);
                break;
            }
            for (uint32_t j = c; j < c + nblk && rc == 0; j++) {
                if (owner[j])
                    rc = fr_fail(err, "section %s, byte %zu: node %u slot %d: leaf block %u is in two leaves",
                                 sn, AT(n->child + k), i, k, j);
                owner[j] = (meta & FR_BVH_MIXED) ? 2 : 1;
            }
            if (rc == 0 && (meta & FR_BVH_MIXED) && !mixed_ok) {
                rc = fr_fail(err, "section %s, byte %zu: node %u slot %d: a mesh's leaves hold triangles only", sn,
                             AT(n->leaf + k), i, k);
                break;
            }
        }
    }
    /* Every lane names a primitive or none (unused lanes only end a block),
     * a triangle's lane holds copies of its vertices, and every primitive
     * is in at least one lane. */
    for (uint32_t j = 0; j < n_leaves && rc == 0; j++) {
        const fr_bvh_leaf *L = &leaves[j];
        if (!owner[j]) {
            rc = fr_fail(err, "section %s, byte %zu: block %u belongs to no leaf", sl, AT(L), j);
            break;
        }
        for (int lane = 0; lane < 4 && rc == 0; lane++) {
            uint32_t p = L->prim[lane];
            if (p == FR_NONE) {
                if (lane == 0 || (lane < 3 && L->prim[lane + 1] != FR_NONE))
                    rc = fr_fail(err, "section %s, byte %zu: block %u lane %d: unused, but %s", sl, AT(L->prim + lane),
                                 j, lane, lane == 0 ? "the first lane of a block must be used" : "a later lane is used");
                continue;
            }
            if (p < lo || p >= hi) {
                rc = fr_fail(err, "section %s, byte %zu: block %u lane %d: primitive %u not in [%u, %u)", sl,
                             AT(L->prim + lane), j, lane, p, lo, hi);
                break;
            }
            seen[p - lo] = 1;
            if (s->prims[p].kind != FR_PRIM_TRIANGLE) {
                if (owner[j] != 2)
                    rc = fr_fail(err, "section %s, byte %zu: block %u lane %d: primitive %u is not a triangle but "
                                 "its leaf is not marked mixed", sl, AT(L->prim + lane), j, lane, p);
                continue;
            }
            const fr_triangle *t = &s->triangles[s->prims[p].index];
            for (int v = 0; v < 3 && rc == 0; v++) {
                vec3 q = s->positions[t->v[v]];
                const float c[3] = {q.x, q.y, q.z};
                for (int a = 0; a < 3 && rc == 0; a++)
                    if (memcmp(&L->v[3 * v + a][lane], &c[a], sizeof c[a]))
                        rc = fr_fail(err, "section %s, byte %zu: block %u lane %d: vertex %d of primitive %u "
                                     "differs from its triangle's", sl, AT(&L->v[3 * v + a][lane]), j, lane, v, p);
            }
        }
        /* Every coordinate finite: x * 0 is 0 for finite x, NaN otherwise. */
        f4 acc = f4_set1(0.0f);
        for (int v = 0; v < 9; v++)
            acc = acc + f4_load(L->v[v]) * f4_set1(0.0f);
        if (rc == 0 && i4_bits(acc != acc))
            for (int v = 0; v < 36 && rc == 0; v++)
                if (!isfinite(L->v[v / 4][v % 4]))
                    rc = fr_fail(err, "section %s, byte %zu: block %u lane %d: non-finite vertex coordinate",
                                 sl, AT(&L->v[v / 4][v % 4]), j, v % 4);
    }
    for (uint32_t p = lo; p < hi && rc == 0; p++)
        if (!seen[p - lo])
            rc = fr_fail(err, "section prims, byte %zu: primitive %u is in no BVH leaf", AT(s->prims + p), p);
done:
    free(depth);
    free(owner);
    free(seen);
    return rc;
}

int bvh_validate(const fr_scene *s, const void *base, fr_error *err)
{
    if (s->n_prims >= 0x80000000u)
        return fr_fail(err, "section prims: %u primitives, at most 2^31 - 1", s->n_prims);
    /* The top-level tree holds the prims before the meshes' (fbin.c has
     * checked that the meshes' ranges tile the end of prims). */
    uint32_t top = s->n_meshes ? s->meshes[0].prim_first : s->n_prims;
    if (top == 0) {
        if (s->n_nodes || s->n_leaves)
            return fr_fail(err, "section nodes: a scene without primitives has no BVH");
    } else if (validate_tree(s, base, "nodes", "leaves", s->nodes, s->n_nodes, s->leaves, s->n_leaves, 0, top, 1,
                             err) < 0) {
        return -1;
    }
    for (uint32_t k = 0; k < s->n_meshes; k++) {
        const fr_mesh *m = &s->meshes[k];
        fr_error e;
        if (validate_tree(s, base, "mesh_nodes", "mesh_leaves", s->mesh_nodes + m->node_first, m->n_nodes,
                          s->mesh_leaves + m->leaf_first, m->n_leaves, m->prim_first, m->prim_first + m->n_prims, 0,
                          &e) < 0)
            return fr_fail(err, "mesh %u: %s", k, e.msg);
    }
    return 0;
}
