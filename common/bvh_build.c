#include "bvh_build.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "simd4.h"

/* Leaves hold up to LEAF_MAX primitives (four blocks) when the SAH finds
 * that cheaper than splitting; LEAF_MIN or fewer always make a leaf (one
 * block is tested as fast as one triangle).  Costs are in units of one
 * block test; a node test (eight boxes) costs about the same.  Splitting a
 * child into two slots of a node that still has a free slot adds no node
 * test, only a box tested together with the others and one more leaf or
 * subtree to visit: that split is charged half a node test.  (Charged
 * nothing, such splits cut the leaf blocks a ray tests on the knot and the
 * terrain of tests/bench by a quarter, but also cut sheets of long
 * overlapping slivers into many small leaves that cost more; half a node
 * keeps the first and not the second.) */
enum { BINS = 32, LEAF_MIN = 4, LEAF_MAX = 16 };
#define TRAV_COST 1.0f
#define SLOT_COST 0.5f

typedef struct { f4 lo, hi; } box4;   /* lane 3 unused (kept 0) */

/* A contiguous range of references with its bounds and the bounds of its
 * centroids. */
typedef struct {
    uint32_t begin, end;
    box4 box, cent;
    int leaf;                  /* decided: becomes a leaf */
} span;

typedef struct {
    box4 *box;                 /* per reference: bounds of its primitive */
    uint32_t *id;              /* per reference: index into the builder's prims */
    const fr_builder *b;
    fr_prim *out;              /* prims in leaf order */
    uint32_t n_out;
    fr_array *nodes, *leaves;
    fr_error *err;
} build;

static box4 box_empty(void) { return (box4){f4_set1(INFINITY), f4_set1(-INFINITY)}; }
static void box_grow(box4 *a, box4 b) { a->lo = f4_min_num(b.lo, a->lo); a->hi = f4_max_num(b.hi, a->hi); }
static void box_add(box4 *a, f4 p) { a->lo = f4_min_num(p, a->lo); a->hi = f4_max_num(p, a->hi); }
/* Box midpoints (halves added: no overflow for coordinates near FLT_MAX). */
static f4 centroid(box4 b) { return b.lo * f4_set1(0.5f) + b.hi * f4_set1(0.5f); }

/* Half the surface area: the SAH only compares areas. */
static float half_area(box4 b)
{
    f4 d = b.hi - b.lo;
    return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
}

static float blocks(uint32_t n) { return (float)((n + 3) / 4); }

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

/* Bounds of references [begin, end). */
static void span_bounds(const build *B, span *s)
{
    s->box = box_empty();
    s->cent = box_empty();
    for (uint32_t i = s->begin; i < s->end; i++) {
        box_grow(&s->box, B->box[i]);
        box_add(&s->cent, centroid(B->box[i]));
    }
}

static void swap_refs(build *B, uint32_t i, uint32_t j)
{
    box4 tb = B->box[i]; B->box[i] = B->box[j]; B->box[j] = tb;
    uint32_t ti = B->id[i]; B->id[i] = B->id[j]; B->id[j] = ti;
}

/* Bins for a span of n references: fewer for small spans, whose SAH sweep
 * would otherwise cost more than their binning. */
static int bin_count(uint32_t n) { return n >= 4 * (BINS - 4) ? BINS : 4 + (int)(n / 4); }

/* Bin scale per axis: nb bins slightly shrunk so the largest centroid
 * lands in the last bin; 0 on an axis where every centroid is equal. */
static f4 bin_scale(const span *s, int nb)
{
    f4 ext = s->cent.hi - s->cent.lo, k = f4_set1(0.0f);
    for (int a = 0; a < 3; a++)
        if (ext[a] > 0.0f)
            k[a] = ((float)nb * 0.9999f) / ext[a];
    return k;
}

/* Bin of centroid coordinate(s) c: clamped to [0, nb-1] while still a
 * float (an extent that overflowed gives inf or NaN here, which must not
 * reach the integer conversion); bin_of and bin_at agree lane for lane. */
static i4 bin_of(f4 c, f4 lo, f4 scale, int nb)
{
    f4 f = f4_max_num(f4_min_num((c - lo) * scale, f4_set1((float)(nb - 1))), f4_set1(0.0f));
    return __builtin_convertvector(f, i4);
}

static int bin_at(float c, float lo, float scale, int nb)
{
    float f = (c - lo) * scale;
    f = f < (float)(nb - 1) ? f : (float)(nb - 1);
    return (int)(f > 0.0f ? f : 0.0f);
}

/* Split span s into *l and *r.  Returns 0 when s should rather be a leaf
 * (allowed only if !force), 1 after partitioning.  `trav` is what the
 * split adds to the traversal (TRAV_COST for a new node, SLOT_COST for a
 * free slot).  `median` skips the SAH and halves the range (the depth
 * guard: halving always terminates). */
static int split_span(build *B, const span *s, span *l, span *r, int force, int median, float trav)
{
    uint32_t n = s->end - s->begin;
    int best_axis = -1, best_bin = 0, nb = bin_count(n);
    float best_cost = INFINITY;
    f4 scale = bin_scale(s, nb);
    if (!median) {
        box4 bins[3][BINS];
        uint32_t count[3][BINS];
        for (int a = 0; a < 3; a++)
            for (int k = 0; k < nb; k++) {
                bins[a][k] = box_empty();
                count[a][k] = 0;
            }
        for (uint32_t i = s->begin; i < s->end; i++) {
            box4 bx = B->box[i];
            i4 k = bin_of(centroid(bx), s->cent.lo, scale, nb);
            for (int a = 0; a < 3; a++) {
                box_grow(&bins[a][k[a]], bx);
                count[a][k[a]]++;
            }
        }
        for (int a = 0; a < 3; a++) {
            if (scale[a] == 0.0f)
                continue;
            float right_area[BINS];
            uint32_t right_count[BINS];
            box4 acc = box_empty();
            uint32_t c = 0;
            for (int k = nb - 1; k > 0; k--) {
                box_grow(&acc, bins[a][k]);
                c += count[a][k];
                right_count[k] = c;
                right_area[k] = c ? half_area(acc) : 0.0f;
            }
            acc = box_empty();
            c = 0;
            for (int k = 1; k < nb; k++) {
                box_grow(&acc, bins[a][k - 1]);
                c += count[a][k - 1];
                if (c == 0 || right_count[k] == 0)
                    continue;
                float cost = half_area(acc) * blocks(c) + right_area[k] * blocks(right_count[k]);
                if (cost < best_cost) {
                    best_cost = cost;
                    best_axis = a;
                    best_bin = k;
                }
            }
        }
        if (!force) {
            float area = half_area(s->box);
            if (area * blocks(n) <= trav * area + best_cost)
                return 0;
        }
    }
    *l = (span){s->begin, s->begin, box_empty(), box_empty(), 0};
    *r = (span){s->end, s->end, box_empty(), box_empty(), 0};
    if (best_axis < 0) {
        /* Every centroid in one bin (or the depth guard): halve the range. */
        l->end = r->begin = s->begin + n / 2;
        span_bounds(B, l);
        span_bounds(B, r);
        return 1;
    }
    /* Partition by bin, collecting both sides' bounds on the way. */
    float lo = s->cent.lo[best_axis], sc = scale[best_axis];
    uint32_t i = s->begin, j = s->end;
    while (i < j) {
        box4 bx = B->box[i];
        f4 c = centroid(bx);
        if (bin_at(c[best_axis], lo, sc, nb) < best_bin) {
            box_grow(&l->box, bx);
            box_add(&l->cent, c);
            i++;
        } else {
            box_grow(&r->box, bx);
            box_add(&r->cent, c);
            j--;
            swap_refs(B, i, j);
        }
    }
    l->end = r->begin = i;
    return 1;
}

/* Fill the blocks of a leaf; *first and *meta become the parent's slot. */
static int emit_leaf(build *B, const span *s, uint32_t *first, uint32_t *meta)
{
    const fr_prim *prims = B->b->prims.data;
    const fr_triangle *tris = B->b->triangles.data;
    const vec3 *pos = B->b->positions.data;
    uint32_t n = s->end - s->begin, nblk = (n + 3) / 4, mixed = 0;
    *first = B->leaves->count;
    for (uint32_t k = 0; k < nblk; k++) {
        fr_bvh_leaf L;
        memset(&L, 0, sizeof L);
        for (uint32_t lane = 0; lane < 4; lane++) {
            uint32_t i = s->begin + 4 * k + lane;
            if (i >= s->end) {
                L.prim[lane] = FR_NONE;
                continue;
            }
            const fr_prim *p = &prims[B->id[i]];
            L.prim[lane] = B->n_out;
            B->out[B->n_out++] = *p;
            if (p->kind != FR_PRIM_TRIANGLE) {
                mixed = FR_BVH_MIXED;
                continue;
            }
            const fr_triangle *t = &tris[p->index];
            for (int v = 0; v < 3; v++) {
                vec3 q = pos[t->v[v]];
                L.v[3 * v + 0][lane] = q.x;
                L.v[3 * v + 1][lane] = q.y;
                L.v[3 * v + 2][lane] = q.z;
            }
        }
        if (bld_push(B->leaves, &L) == FR_NONE)
            return fr_fail(B->err, "out of memory for the BVH leaves");
    }
    *meta = nblk | mixed;
    return 0;
}

/* Levels a tree of halving splits needs below a node of n references. */
static int median_levels(uint32_t n)
{
    int l = 0;
    while (n > LEAF_MIN) {
        n = (n + 3) / 4;
        l++;
    }
    return l;
}

/* Make a node at `depth` whose children start as init[0..nc); split the
 * widest child until there are FR_BVH_WIDTH.  *index receives the node's
 * index. */
static int build_node(build *B, const span *init, int nc, int depth, int median, uint32_t *index)
{
    fr_bvh_node node;
    memset(&node, 0, sizeof node);
    uint32_t me = bld_push(B->nodes, &node);
    if (me == FR_NONE)
        return fr_fail(B->err, "out of memory for the BVH nodes");
    span ch[FR_BVH_WIDTH];
    memcpy(ch, init, (size_t)nc * sizeof *ch);
    if (!median)
        median = depth + 2 + median_levels(init[nc - 1].end - init[0].begin) >= FR_BVH_MAX_DEPTH;
    while (nc < FR_BVH_WIDTH) {
        /* The child with the largest area (or most references, when only
         * halving) gains most from being split. */
        int pick = -1;
        float best = -1.0f;
        for (int i = 0; i < nc; i++) {
            float key = median ? (float)(ch[i].end - ch[i].begin) : half_area(ch[i].box);
            if (!ch[i].leaf && key > best) {
                best = key;
                pick = i;
            }
        }
        if (pick < 0)
            break;
        uint32_t n = ch[pick].end - ch[pick].begin;
        span l, r;
        if (n <= LEAF_MIN || !split_span(B, &ch[pick], &l, &r, n > LEAF_MAX, median, SLOT_COST)) {
            ch[pick].leaf = 1;
            continue;
        }
        ch[pick] = l;
        ch[nc++] = r;
    }
    for (int i = 0; i < FR_BVH_WIDTH; i++) {
        fr_bvh_node *nd = (fr_bvh_node *)B->nodes->data + me;
        box4 bx = i < nc ? ch[i].box : box_empty();
        for (int a = 0; a < 3; a++) {
            nd->box[a][i] = bx.lo[a];
            nd->box[3 + a][i] = bx.hi[a];
        }
        nd->child[i] = FR_NONE;
        nd->leaf[i] = 0;
        if (i >= nc)
            continue;
        uint32_t n = ch[i].end - ch[i].begin, child, meta = 0;
        span pair[2];
        if (!ch[i].leaf && n > LEAF_MIN && split_span(B, &ch[i], &pair[0], &pair[1], n > LEAF_MAX, median, TRAV_COST)) {
            if (build_node(B, pair, 2, depth + 1, median, &child) < 0)
                return -1;
        } else if (emit_leaf(B, &ch[i], &child, &meta) < 0) {
            return -1;
        }
        nd = (fr_bvh_node *)B->nodes->data + me;   /* the array may have moved */
        nd->child[i] = child;
        nd->leaf[i] = meta;
    }
    *index = me;
    return 0;
}

int bvh_build(fr_builder *b, fr_array *nodes, fr_array *leaves, fr_error *err)
{
    uint32_t n = b->prims.count;
    if (n == 0)
        return 0;
    if (n >= 0x80000000u)
        return fr_fail(err, "%u primitives: the BVH holds at most 2^31 - 1", n);
    build B = {0};
    B.box = malloc((size_t)n * sizeof *B.box);
    B.id = malloc((size_t)n * sizeof *B.id);
    B.out = malloc((size_t)n * sizeof *B.out);
    B.b = b;
    B.nodes = nodes;
    B.leaves = leaves;
    B.err = err;
    int rc = 0;
    if (!B.box || !B.id || !B.out)
        rc = fr_fail(err, "out of memory for the BVH (%u primitives)", n);
    for (uint32_t i = 0; i < n && rc == 0; i++) {
        vec3 lo, hi;
        bvh_prim_bounds(b, i, &lo, &hi);
        if (!isfinite(lo.x) || !isfinite(lo.y) || !isfinite(lo.z) || !isfinite(hi.x) || !isfinite(hi.y) ||
            !isfinite(hi.z))
            rc = fr_fail(err, "primitive %u has non-finite bounds", i);
        B.box[i] = (box4){{lo.x, lo.y, lo.z, 0.0f}, {hi.x, hi.y, hi.z, 0.0f}};
        B.id[i] = i;
    }
    if (rc == 0) {
        span all = {0, n, box_empty(), box_empty(), 0};
        span_bounds(&B, &all);
        uint32_t root;
        rc = build_node(&B, &all, 1, 1, 0, &root);
    }
    free(B.box);
    free(B.id);
    if (rc < 0) {
        free(B.out);
        return -1;
    }
    free(b->prims.data);
    b->prims.data = B.out;
    b->prims.cap = n;
    return 0;
}
