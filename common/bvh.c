#include "bvh.h"

#include <stdlib.h>
#include <string.h>

void bvh_prim_bounds(const fr_builder *b, uint32_t i, vec3 *lo, vec3 *hi)
{
    const fr_prim *p = (const fr_prim *)b->prims.data + i;
    if (p->kind == FR_PRIM_SPHERE) {
        const fr_sphere *s = (const fr_sphere *)b->spheres.data + p->index;
        *lo = v3_sub(s->center, v3s(s->radius));
        *hi = v3_add(s->center, v3s(s->radius));
    } else if (p->kind == FR_PRIM_RECT) {
        const fr_rect *q = (const fr_rect *)b->rects.data + p->index;
        vec3 a = q->origin, c = v3_add(q->origin, q->edge_u), d = v3_add(q->origin, q->edge_v);
        vec3 e = v3_add(c, q->edge_v);
        *lo = v3_vmin(v3_vmin(a, c), v3_vmin(d, e));
        *hi = v3_vmax(v3_vmax(a, c), v3_vmax(d, e));
    } else {
        const fr_triangle *t = (const fr_triangle *)b->triangles.data + p->index;
        const vec3 *pos = b->positions.data;
        *lo = v3_vmin(v3_vmin(pos[t->v[0]], pos[t->v[1]]), pos[t->v[2]]);
        *hi = v3_vmax(v3_vmax(pos[t->v[0]], pos[t->v[1]]), pos[t->v[2]]);
    }
}

typedef struct { vec3 lo, hi, c; } item;

static int build_rec(fr_builder *b, item *items, fr_prim *prims, uint32_t first, uint32_t count,
                     fr_array *nodes, int depth, fr_error *err)
{
    fr_bvh_node node;
    vec3 lo = items[first].lo, hi = items[first].hi, clo = items[first].c, chi = items[first].c;
    for (uint32_t i = first + 1; i < first + count; i++) {
        lo = v3_vmin(lo, items[i].lo); hi = v3_vmax(hi, items[i].hi);
        clo = v3_vmin(clo, items[i].c); chi = v3_vmax(chi, items[i].c);
    }
    node.lo = lo; node.hi = hi;
    vec3 ext = v3_sub(chi, clo);
    int axis = ext.x > ext.y ? (ext.x > ext.z ? 0 : 2) : (ext.y > ext.z ? 1 : 2);
    if (count <= 4 || depth >= BVH_MAX_DEPTH - 2 || v3_get(ext, axis) <= 0.0f) {
        node.offset = first; node.count = count;
        return bld_push(nodes, &node) == FR_NONE ? fr_fail(err, "out of memory for the BVH") : 0;
    }
    /* Split at the centroid midpoint, partition in place. */
    float mid = 0.5f * (v3_get(clo, axis) + v3_get(chi, axis));
    uint32_t i = first, j = first + count;
    while (i < j) {
        if (v3_get(items[i].c, axis) < mid) { i++; continue; }
        j--;
        item ti = items[i]; items[i] = items[j]; items[j] = ti;
        fr_prim tp = prims[i]; prims[i] = prims[j]; prims[j] = tp;
    }
    uint32_t left = i - first;
    if (left == 0 || left == count) left = count / 2;
    node.offset = 0; node.count = (uint32_t)axis << 24;
    uint32_t me = bld_push(nodes, &node);
    if (me == FR_NONE) return fr_fail(err, "out of memory for the BVH");
    if (build_rec(b, items, prims, first, left, nodes, depth + 1, err) < 0) return -1;
    ((fr_bvh_node *)nodes->data)[me].offset = nodes->count;
    return build_rec(b, items, prims, first + left, count - left, nodes, depth + 1, err);
}

int bvh_build(fr_builder *b, fr_array *nodes, fr_error *err)
{
    uint32_t n = b->prims.count;
    if (n == 0) return 0;
    item *items = malloc((size_t)n * sizeof *items);
    if (!items) return fr_fail(err, "out of memory for the BVH");
    for (uint32_t i = 0; i < n; i++) {
        bvh_prim_bounds(b, i, &items[i].lo, &items[i].hi);
        items[i].c = v3_scale(v3_add(items[i].lo, items[i].hi), 0.5f);
    }
    int rc = build_rec(b, items, b->prims.data, 0, n, nodes, 0, err);
    free(items);
    return rc;
}
