/* bvh.c -- the check that a loaded 8-wide BVH is sound before any ray walks it
 * (see bvh.h). */

#include "bvh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "simd4.h"

#define AT(p) ((size_t)((const char *)(p) - (const char *)base))

int bvh_validate(const fr_scene *s, const void *base, fr_error *err)
{
    if (s->n_prims == 0) {
        if (s->n_nodes || s->n_leaves)
            return fr_fail(err, "section nodes: a scene without primitives has no BVH");
        return 0;
    }
    if (s->n_prims >= 0x80000000u)
        return fr_fail(err, "section prims: %u primitives, at most 2^31 - 1", s->n_prims);
    if (s->n_nodes == 0 || s->n_leaves == 0)
        return fr_fail(err, "section nodes: the scene has primitives but no BVH");
    unsigned char *depth = calloc(s->n_nodes, 1);
    unsigned char *owner = calloc(s->n_leaves, 1);   /* 1: in a leaf, 2: in a mixed leaf */
    unsigned char *seen = calloc(s->n_prims, 1);     /* 1: in some lane */
    int rc = 0;
    if (!depth || !owner || !seen) {
        rc = fr_fail(err, "out of memory validating the BVH");
        goto done;
    }
    depth[0] = 1;
    for (uint32_t i = 0; i < s->n_nodes && rc == 0; i++) {
        const fr_bvh_node *n = &s->nodes[i];
        if (depth[i] == 0) {
            rc = fr_fail(err, "section nodes, byte %zu: node %u is not reachable from the root", AT(n), i);
            break;
        }
        for (int k = 0; k < FR_BVH_WIDTH && rc == 0; k++) {
            uint32_t c = n->child[k], meta = n->leaf[k];
            if (c == FR_NONE) {
                int empty = meta == 0;
                for (int a = 0; a < 3; a++)
                    empty &= n->box[a][k] == INFINITY && n->box[3 + a][k] == -INFINITY;
                if (!empty)
                    rc = fr_fail(err, "section nodes, byte %zu: node %u slot %d: an empty slot needs leaf 0 "
                                 "and the empty box (+inf, -inf)", AT(n->child + k), i, k);
                continue;
            }
            for (int a = 0; a < 3 && rc == 0; a++)
                if (!(n->box[a][k] <= n->box[3 + a][k]) || !isfinite(n->box[a][k]) || !isfinite(n->box[3 + a][k]))
                    rc = fr_fail(err, "section nodes, byte %zu: node %u slot %d: box not finite or inverted on axis %d",
                                 AT(n->box[a] + k), i, k, a);
            if (rc)
                break;
            if (meta == 0) {
                if (c <= i || c >= s->n_nodes)
                    rc = fr_fail(err, "section nodes, byte %zu: node %u slot %d: child %u not in (%u, %u)",
                                 AT(n->child + k), i, k, c, i, s->n_nodes);
                else if (depth[c])
                    rc = fr_fail(err, "section nodes, byte %zu: node %u slot %d: node %u has two parents",
                                 AT(n->child + k), i, k, c);
                else if (depth[i] >= FR_BVH_MAX_DEPTH)
                    rc = fr_fail(err, "section nodes, byte %zu: node %u slot %d: deeper than %d levels",
                                 AT(n->child + k), i, k, FR_BVH_MAX_DEPTH);
                else
                    depth[c] = (unsigned char)(depth[i] + 1);
                continue;
            }
            uint32_t nblk = meta & FR_BVH_LEAF_MAX;
            if ((meta & ~(FR_BVH_LEAF_MAX | FR_BVH_MIXED)) || nblk == 0) {
                rc = fr_fail(err, "section nodes, byte %zu: node %u slot %d: bad leaf word 0x%x",
                             AT(n->leaf + k), i, k, meta);
                break;
            }
            if (c >= s->n_leaves || nblk > s->n_leaves - c) {
                rc = fr_fail(err, "section nodes, byte %zu: node %u slot %d: leaf blocks %u..%u past the %u blocks",
                             AT(n->child + k), i, k, c, c + nblk - 1, s->n_leaves);
                break;
            }
            for (uint32_t j = c; j < c + nblk && rc == 0; j++) {
                if (owner[j])
                    rc = fr_fail(err, "section nodes, byte %zu: node %u slot %d: leaf block %u is in two leaves",
                                 AT(n->child + k), i, k, j);
                owner[j] = (meta & FR_BVH_MIXED) ? 2 : 1;
            }
        }
    }
    /* Every lane names a primitive or none (unused lanes only end a block),
     * a triangle's lane holds copies of its vertices, and every primitive
     * is in at least one lane. */
    for (uint32_t j = 0; j < s->n_leaves && rc == 0; j++) {
        const fr_bvh_leaf *L = &s->leaves[j];
        if (!owner[j]) {
            rc = fr_fail(err, "section leaves, byte %zu: block %u belongs to no leaf", AT(L), j);
            break;
        }
        for (int lane = 0; lane < 4 && rc == 0; lane++) {
            uint32_t p = L->prim[lane];
            if (p == FR_NONE) {
                if (lane == 0 || (lane < 3 && L->prim[lane + 1] != FR_NONE))
                    rc = fr_fail(err, "section leaves, byte %zu: block %u lane %d: unused, but %s", AT(L->prim + lane),
                                 j, lane, lane == 0 ? "the first lane of a block must be used" : "a later lane is used");
                continue;
            }
            if (p >= s->n_prims) {
                rc = fr_fail(err, "section leaves, byte %zu: block %u lane %d: primitive %u of %u", AT(L->prim + lane),
                             j, lane, p, s->n_prims);
                break;
            }
            seen[p] = 1;
            if (s->prims[p].kind != FR_PRIM_TRIANGLE) {
                if (owner[j] != 2)
                    rc = fr_fail(err, "section leaves, byte %zu: block %u lane %d: primitive %u is not a triangle but "
                                 "its leaf is not marked mixed", AT(L->prim + lane), j, lane, p);
                continue;
            }
            const fr_triangle *t = &s->triangles[s->prims[p].index];
            for (int v = 0; v < 3 && rc == 0; v++) {
                vec3 q = s->positions[t->v[v]];
                const float c[3] = {q.x, q.y, q.z};
                for (int a = 0; a < 3 && rc == 0; a++)
                    if (memcmp(&L->v[3 * v + a][lane], &c[a], sizeof c[a]))
                        rc = fr_fail(err, "section leaves, byte %zu: block %u lane %d: vertex %d of primitive %u "
                                     "differs from its triangle's", AT(&L->v[3 * v + a][lane]), j, lane, v, p);
            }
        }
        /* Every coordinate finite: x * 0 is 0 for finite x, NaN otherwise. */
        f4 acc = f4_set1(0.0f);
        for (int v = 0; v < 9; v++)
            acc = acc + f4_load(L->v[v]) * f4_set1(0.0f);
        if (rc == 0 && i4_bits(acc != acc))
            for (int v = 0; v < 36 && rc == 0; v++)
                if (!isfinite(L->v[v / 4][v % 4]))
                    rc = fr_fail(err, "section leaves, byte %zu: block %u lane %d: non-finite vertex coordinate",
                                 AT(&L->v[v / 4][v % 4]), j, v % 4);
    }
    for (uint32_t p = 0; p < s->n_prims && rc == 0; p++)
        if (!seen[p])
            rc = fr_fail(err, "section prims, byte %zu: primitive %u is in no BVH leaf", AT(s->prims + p), p);
done:
    free(depth);
    free(owner);
    free(seen);
    return rc;
}
