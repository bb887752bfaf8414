/* bvh_build.c -- the BVH build: binned SAH binary tree collapsed to the 8-wide
 * layout (see bvh_build.h). */

#include "compile/bvh_build.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "compile/builder_instance.h"
#include "compile/bvh2.h"
#include "compile/bvh_reinsert.h"
#include "simd4.h"

enum { BINS = 32, SWEEP_MAX = 64 };
/* Spatial splits: tried where an object split's two sides overlap by more
 * than OVERLAP times the root's area, with room for as many extra
 * references as there are primitives. */
#define OVERLAP 1e-5f

/* Box midpoints (halves added: no overflow for coordinates near FLT_MAX). */
static f4 centroid(bvh2_box b) { return b.lo * f4_set1(0.5f) + b.hi * f4_set1(0.5f); }

/* A contiguous range of references with its bounds and the bounds of its
 * centroids. */
typedef struct {
    uint32_t begin, end;       /* its references */
    uint32_t cap;              /* [end, cap): room for references a spatial split adds */
    bvh2_box box, cent;
    int leaf;                  /* decided: becomes a leaf */
} span;

typedef struct {
    bvh2_box *box;             /* per reference: bounds of its part of its primitive */
    uint32_t *id;              /* per reference: index into the builder's prims */
    bvh2_box *tbox;            /* scratch for a spatial split's references */
    uint32_t *tid;
    const fr_builder *b;
    fr_prim *out;              /* prims in the order leaves first name them */
    uint32_t *out_of;          /* per builder prim: its index in out, FR_NONE before */
    uint32_t n_out;
    float min_overlap;         /* half area of the root times OVERLAP */
    fr_array *nodes, *leaves;
    fr_error *err;
    bvh2_node *bn;             /* the binary tree */
    uint32_t n_bn, cap_bn;
} build;

/* Bounding box of prim `i` of the builder, into *lo and *hi. */
static void bvh_prim_bounds(const fr_builder *b, uint32_t i, vec3 *lo, vec3 *hi)
{
    const fr_prim *p = (const fr_prim *)b->prims.data + i;
    if (p->kind == FR_PRIM_INSTANCE) {
        bld_instance_bounds(b, p->index, lo, hi);
    } else if (p->kind == FR_PRIM_SPHERE) {
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
    s->box = bvh2_box_empty();
    s->cent = bvh2_box_empty();
    for (uint32_t i = s->begin; i < s->end; i++) {
        bvh2_box_grow(&s->box, B->box[i]);
        bvh2_box_add(&s->cent, centroid(B->box[i]));
    }
}

static void swap_refs(build *B, uint32_t i, uint32_t j)
{
    bvh2_box tb = B->box[i]; B->box[i] = B->box[j]; B->box[j] = tb;
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

/* ---- spatial splits ----
 *
 * A reference is a primitive, or the part of one between planes earlier
 * splits cut it at, with the bounds of that part.  A spatial split cuts a
 * span's box at a plane and gives each side the references reaching into
 * it, with the bounds of their part on that side: a long triangle crossing
 * the plane goes to both sides, each with a smaller box than the whole
 * triangle's.  Such splits are tried only where an object split (every
 * reference to one side, by centroid) leaves its two sides overlapping by
 * more than a fraction of the root's area, and only while the span has room
 * for the extra references (the reference budget is shared out with the
 * references as spans are split). */

static int box_is_empty(bvh2_box b) { return !(b.lo[0] <= b.hi[0] && b.lo[1] <= b.hi[1] && b.lo[2] <= b.hi[2]); }

static bvh2_box box_clip(bvh2_box a, bvh2_box b)
{
    return (bvh2_box){f4_max_num(b.lo, a.lo), f4_min_num(b.hi, a.hi)};
}

static f4 vload(vec3 p) { return (f4){p.x, p.y, p.z, 0.0f}; }

/* The point where edge p-q crosses the plane x[a] = c (p[a] and q[a] on
 * opposite sides, strictly), added to *r as a small box that surely holds
 * the exact point: the rounded coordinates are widened by far more than
 * their rounding error (a few units in the last place of |p| + |q|) and
 * kept within the edge's own bounds; on axis a the point is c exactly. */
static void add_crossing(bvh2_box *r, f4 p, f4 q, i4 on_a, float pa, float qa, float c)
{
    f4 t = f4_set1((c - pa) / (qa - pa));
    f4 x = p + (q - p) * t;
    f4 e = (f4_abs(p) + f4_abs(q)) * f4_set1(0x1p-20f);
    f4 lo = f4_max_num(x - e, f4_min_num(p, q)), hi = f4_min_num(x + e, f4_max_num(p, q));
    f4 cv = f4_set1(c);
    lo = (f4)(((i4)cv & on_a) | ((i4)lo & ~on_a));
    hi = (f4)(((i4)cv & on_a) | ((i4)hi & ~on_a));
    r->lo = f4_min_num(lo, r->lo);
    r->hi = f4_max_num(hi, r->hi);
}

/* Bounds of the part of reference i between the planes x[a] = lo and
 * x[a] = hi (either may be infinite): for a triangle, its vertices in the
 * slab and the points where its edges cross the planes, within the
 * reference's box; for other primitives the reference's box cut to the
 * slab.  May be empty. */
static bvh2_box ref_slab(const build *B, uint32_t i, int a, float lo, float hi)
{
    bvh2_box rb = B->box[i];
    const fr_prim *p = (const fr_prim *)B->b->prims.data + B->id[i];
    if (p->kind != FR_PRIM_TRIANGLE) {
        rb.lo[a] = rb.lo[a] > lo ? rb.lo[a] : lo;
        rb.hi[a] = rb.hi[a] < hi ? rb.hi[a] : hi;
        return rb;
    }
    const fr_triangle *t = (const fr_triangle *)B->b->triangles.data + p->index;
    const vec3 *pos = B->b->positions.data;
    f4 v[3] = {vload(pos[t->v[0]]), vload(pos[t->v[1]]), vload(pos[t->v[2]])};
    i4 on_a = i4_set1(0);
    on_a[a] = -1;
    bvh2_box r = bvh2_box_empty();
    for (int k = 0; k < 3; k++) {
        f4 P = v[k], Q = v[k == 2 ? 0 : k + 1];
        float pa = P[a], qa = Q[a];
        if (pa >= lo && pa <= hi)
            bvh2_box_add(&r, P);
        if ((pa < lo && qa > lo) || (pa > lo && qa < lo))
            add_crossing(&r, P, Q, on_a, pa, qa, lo);
        if ((pa < hi && qa > hi) || (pa > hi && qa < hi))
            add_crossing(&r, P, Q, on_a, pa, qa, hi);
    }
    return box_clip(r, rb);
}

/* The cheapest spatial split of s across its longest axis (trying the
 * other two costs much build time for hardly fewer leaf blocks per ray on
 * the meshes of tests/bench; tests/bench/README.md, "Spatial splits on one axis"):
 * *axis and *plane, its cost (INFINITY if none).  Bins are slabs of equal width of the span's box; a reference
 * enters the bin of its lower bound, leaves from that of its upper bound,
 * and adds the bounds of its part in each bin it crosses. */
static float spatial_best(const build *B, const span *s, int nb, int *axis, float *plane)
{
    f4 ext4 = s->box.hi - s->box.lo;
    int a = ext4[0] >= ext4[1] ? (ext4[0] >= ext4[2] ? 0 : 2) : (ext4[1] >= ext4[2] ? 1 : 2);
    float best = INFINITY, lo = s->box.lo[a], ext = s->box.hi[a] - lo;
    if (!(ext > 0.0f))
        return best;
    float scale = (float)nb / ext, w = ext / (float)nb;
    bvh2_box bins[BINS];
    uint32_t enter[BINS], leave[BINS];
    for (int k = 0; k < nb; k++) {
        bins[k] = bvh2_box_empty();
        enter[k] = leave[k] = 0;
    }
    for (uint32_t i = s->begin; i < s->end; i++) {
        bvh2_box bx = B->box[i];
        int k0 = bin_at(bx.lo[a], lo, scale, nb), k1 = bin_at(bx.hi[a], lo, scale, nb);
        enter[k0]++;
        leave[k1]++;
        if (k0 == k1) {
            bvh2_box_grow(&bins[k0], bx);
            continue;
        }
        for (int k = k0; k <= k1; k++) {
            bvh2_box part = ref_slab(B, i, a, k == k0 ? -INFINITY : lo + w * (float)k,
                                 k == k1 ? INFINITY : lo + w * (float)(k + 1));
            if (!box_is_empty(part))
                bvh2_box_grow(&bins[k], part);
        }
    }
    float right_area[BINS];
    uint32_t right_count[BINS];
    bvh2_box acc = bvh2_box_empty();
    uint32_t c = 0;
    for (int k = nb - 1; k > 0; k--) {
        bvh2_box_grow(&acc, bins[k]);
        c += leave[k];
        right_count[k] = c;
        right_area[k] = c ? bvh2_area(acc) : 0.0f;
    }
    acc = bvh2_box_empty();
    c = 0;
    for (int k = 1; k < nb; k++) {
        bvh2_box_grow(&acc, bins[k - 1]);
        c += enter[k - 1];
        if (c == 0 || right_count[k] == 0)
            continue;
        float cost = bvh2_area(acc) * bvh2_blocks(c) + right_area[k] * bvh2_blocks(right_count[k]);
        if (cost < best) {
            best = cost;
            *axis = a;
            *plane = lo + w * (float)k;
        }
    }
    return best;
}

/* The room left in s shared between its two sides in proportion to their
 * references: *l gets its references at s->begin, *r after l's room. */
static void share_room(const span *s, uint32_t nl, uint32_t nr, span *l, span *r)
{
    uint32_t room = s->cap - s->begin - nl - nr;
    uint32_t rl = (uint32_t)((uint64_t)room * nl / (nl + nr));
    l->begin = s->begin;
    l->end = s->begin + nl;
    l->cap = l->end + rl;
    r->begin = l->cap;
    r->end = r->begin + nr;
    r->cap = s->cap;
}

/* Cut s at x[a] = plane into *l and *r.  Returns 0 when the result does not
 * fit s's room or leaves a side empty (nothing is changed then), 1 after
 * the split. */
static int spatial_split(build *B, const span *s, int a, float plane, span *l, span *r)
{
    uint32_t room = s->cap - s->begin, nl = 0, nr = 0;
    /* Left references from the front of the scratch, right ones from its back. */
    for (uint32_t i = s->begin; i < s->end; i++) {
        bvh2_box bx = B->box[i], lb = bx, rb = bx;
        int left = bx.lo[a] < plane || (bx.lo[a] == plane && bx.hi[a] == plane);
        int right = bx.hi[a] > plane;
        if (left && right) {
            lb = ref_slab(B, i, a, -INFINITY, plane);
            rb = ref_slab(B, i, a, plane, INFINITY);
            left = !box_is_empty(lb);
            right = !box_is_empty(rb);
            if (!left && !right) {   /* rounding left nothing: keep the whole */
                lb = bx;
                left = 1;
            }
        }
        if (nl + nr + (uint32_t)left + (uint32_t)right > room)
            return 0;
        if (left) {
            B->tbox[nl] = lb;
            B->tid[nl++] = B->id[i];
        }
        if (right) {
            nr++;
            B->tbox[room - nr] = rb;
            B->tid[room - nr] = B->id[i];
        }
    }
    /* A side may keep every reference (long slivers all cross the plane):
     * their boxes shrink, and such a split uses up room, so splitting ends. */
    if (nl == 0 || nr == 0)
        return 0;
    share_room(s, nl, nr, l, r);
    memcpy(B->box + l->begin, B->tbox, nl * sizeof *B->box);
    memcpy(B->id + l->begin, B->tid, nl * sizeof *B->id);
    memcpy(B->box + r->begin, B->tbox + room - nr, nr * sizeof *B->box);
    memcpy(B->id + r->begin, B->tid + room - nr, nr * sizeof *B->id);
    l->leaf = r->leaf = 0;
    span_bounds(B, l);
    span_bounds(B, r);
    return 1;
}

/* ---- exact sweeps for small spans ----
 * Spans of at most SWEEP_MAX references are split by sorting their
 * centroids along each axis and trying every cut between neighbours (ties
 * broken by primitive index, which appears at most once in a span, so the
 * order is one whatever the sort's algorithm). */
typedef struct { float key; uint32_t id, pos; } skey;

static int skey_cmp(const void *pa, const void *pb)
{
    const skey *a = pa, *b = pb;
    if (a->key != b->key)
        return a->key < b->key ? -1 : 1;
    return (a->id > b->id) - (a->id < b->id);
}

/* The references of s in centroid order along axis a, into k. */
static void sweep_keys(const build *B, const span *s, int a, skey *k)
{
    for (uint32_t i = s->begin; i < s->end; i++)
        k[i - s->begin] = (skey){centroid(B->box[i])[a], B->id[i], i};
    qsort(k, s->end - s->begin, sizeof *k, skey_cmp);
}

/* The cheapest cut of s in centroid order: its cost (INFINITY if every
 * centroid is the same point), *axis, *nleft references on the left, and
 * *overlap, the half area where the two sides' boxes overlap. */
static float sweep_best(const build *B, const span *s, int *axis, uint32_t *nleft, float *overlap)
{
    uint32_t n = s->end - s->begin;
    skey k[SWEEP_MAX];
    bvh2_box rbox[SWEEP_MAX];
    float best = INFINITY;
    for (int a = 0; a < 3; a++) {
        if (!(s->cent.hi[a] > s->cent.lo[a]))
            continue;
        sweep_keys(B, s, a, k);
        bvh2_box acc = bvh2_box_empty();
        for (uint32_t i = n - 1; i > 0; i--) {
            bvh2_box_grow(&acc, B->box[k[i].pos]);
            rbox[i] = acc;
        }
        acc = bvh2_box_empty();
        for (uint32_t i = 1; i < n; i++) {
            bvh2_box_grow(&acc, B->box[k[i - 1].pos]);
            float cost = bvh2_area(acc) * bvh2_blocks(i) + bvh2_area(rbox[i]) * bvh2_blocks(n - i);
            if (cost < best) {
                best = cost;
                *axis = a;
                *nleft = i;
                bvh2_box o = box_clip(acc, rbox[i]);
                *overlap = box_is_empty(o) ? 0.0f : bvh2_area(o);
            }
        }
    }
    return best;
}

/* Split span s (of at least two references) into *l and *r: the cheapest
 * object split (SAH on blocks), or a spatial split where that is cheaper.
 * `median` skips the SAH and halves the range (the depth guard: halving
 * always terminates). */
static void split_span(build *B, const span *s, span *l, span *r, int median)
{
    uint32_t n = s->end - s->begin;
    int best_axis = -1, best_bin = 0, nb = bin_count(n);
    float best_cost = INFINITY;
    f4 scale = bin_scale(s, nb);
    uint32_t sweep_left = 0;
    float sweep_overlap = INFINITY;
    int sweep = !median && n <= SWEEP_MAX;
    if (sweep)
        best_cost = sweep_best(B, s, &best_axis, &sweep_left, &sweep_overlap);
    if (!median) {
        bvh2_box bins[3][BINS];
        uint32_t count[3][BINS];
        for (int a = 0; a < 3; a++)
            for (int k = 0; k < nb; k++) {
                bins[a][k] = bvh2_box_empty();
                count[a][k] = 0;
            }
        for (uint32_t i = s->begin; i < s->end && !sweep; i++) {
            bvh2_box bx = B->box[i];
            i4 k = bin_of(centroid(bx), s->cent.lo, scale, nb);
            for (int a = 0; a < 3; a++) {
                bvh2_box_grow(&bins[a][k[a]], bx);
                count[a][k[a]]++;
            }
        }
        for (int a = 0; a < 3; a++) {
            if (sweep || scale[a] == 0.0f)
                continue;
            float right_area[BINS];
            uint32_t right_count[BINS];
            bvh2_box acc = bvh2_box_empty();
            uint32_t c = 0;
            for (int k = nb - 1; k > 0; k--) {
                bvh2_box_grow(&acc, bins[a][k]);
                c += count[a][k];
                right_count[k] = c;
                right_area[k] = c ? bvh2_area(acc) : 0.0f;
            }
            acc = bvh2_box_empty();
            c = 0;
            for (int k = 1; k < nb; k++) {
                bvh2_box_grow(&acc, bins[a][k - 1]);
                c += count[a][k - 1];
                if (c == 0 || right_count[k] == 0)
                    continue;
                float cost = bvh2_area(acc) * bvh2_blocks(c) + right_area[k] * bvh2_blocks(right_count[k]);
                if (cost < best_cost) {
                    best_cost = cost;
                    best_axis = a;
                    best_bin = k;
                }
            }
        }
        /* A spatial split where the object split's sides overlap much. */
        int sp_axis = -1;
        float sp_plane = 0.0f, sp_cost = INFINITY;
        if (s->cap > s->end && n > 1) {
            float overlap = INFINITY;
            if (sweep) {
                overlap = sweep_overlap;
            } else if (best_axis >= 0) {
                bvh2_box lb = bvh2_box_empty(), rb = bvh2_box_empty();
                for (int k = 0; k < nb; k++)
                    bvh2_box_grow(k < best_bin ? &lb : &rb, bins[best_axis][k]);
                bvh2_box o = box_clip(lb, rb);
                overlap = box_is_empty(o) ? 0.0f : bvh2_area(o);
            }
            if (overlap > B->min_overlap)
                sp_cost = spatial_best(B, s, nb, &sp_axis, &sp_plane);
        }
        if (sp_cost < best_cost && spatial_split(B, s, sp_axis, sp_plane, l, r))
            return;
    }
    *l = (span){s->begin, s->begin, s->begin, bvh2_box_empty(), bvh2_box_empty(), 0};
    *r = (span){s->end, s->end, s->cap, bvh2_box_empty(), bvh2_box_empty(), 0};
    if (best_axis < 0) {
        /* Every centroid in one bin (or the depth guard): halve the range. */
        l->end = l->cap = r->begin = s->begin + n / 2;
        span_bounds(B, l);
        span_bounds(B, r);
        return;
    }
    uint32_t i = s->begin, j = s->end;
    if (sweep) {
        /* Sort the references along the axis and cut after sweep_left. */
        skey k[SWEEP_MAX];
        sweep_keys(B, s, best_axis, k);
        for (uint32_t q = 0; q < n; q++) {
            B->tbox[q] = B->box[k[q].pos];
            B->tid[q] = B->id[k[q].pos];
        }
        memcpy(B->box + s->begin, B->tbox, n * sizeof *B->box);
        memcpy(B->id + s->begin, B->tid, n * sizeof *B->id);
        i = j = s->begin + sweep_left;
        for (uint32_t q = s->begin; q < s->end; q++) {
            span *side = q < i ? l : r;
            bvh2_box_grow(&side->box, B->box[q]);
            bvh2_box_add(&side->cent, centroid(B->box[q]));
        }
    }
    /* Partition by bin, collecting both sides' bounds on the way. */
    float lo = s->cent.lo[best_axis], sc = scale[best_axis];
    while (i < j) {
        bvh2_box bx = B->box[i];
        f4 c = centroid(bx);
        if (bin_at(c[best_axis], lo, sc, nb) < best_bin) {
            bvh2_box_grow(&l->box, bx);
            bvh2_box_add(&l->cent, c);
            i++;
        } else {
            bvh2_box_grow(&r->box, bx);
            bvh2_box_add(&r->cent, c);
            j--;
            swap_refs(B, i, j);
        }
    }
    /* Share the room: move the right side up past the left side's part. */
    uint32_t nl = i - s->begin, nr = s->end - i;
    span L = *l, R = *r;
    share_room(s, nl, nr, l, r);
    if (r->begin != i) {
        memmove(B->box + r->begin, B->box + i, nr * sizeof *B->box);
        memmove(B->id + r->begin, B->id + i, nr * sizeof *B->id);
    }
    l->box = L.box; l->cent = L.cent;
    r->box = R.box; r->cent = R.cent;
}

/* ---- the binary tree and its collapse ----
 *
 * The builder first splits references down to binary leaves of at most
 * BVH2_LEAF_MIN (always taking the split, SAH or spatial, that split_span finds
 * best), then chooses which binary nodes become 8-wide nodes and which
 * subtrees become leaves by dynamic programming over the binary tree
 * (bottom-up): cost[v][j-1] is the least SAH cost of v's subtree given as
 * at most j slots of a wide node, each slot a leaf (area times its blocks)
 * or a wide node (area times BVH2_TRAV_COST plus the cost of its own up to eight
 * slots), each slot also charged its area times BVH2_SLOT_COST.  A subtree
 * becomes a leaf only with at most BVH2_LEAF_MAX references; its references are
 * packed into blocks together, so small binary leaves fill blocks.
 *
 * A leaf holds triangles only or other primitives only (spheres, rects,
 * instances): a binary leaf of both kinds is split by kind, and a subtree
 * of both never becomes a leaf.  The walk then tests a triangle leaf's
 * blocks in its wide vectors without looking up any lane's kind, and a
 * leaf of shapes without a triangle test (on the rough metals: 10736 ->
 * 8696 instructions a sample, tests/bench/README.md). */


/* Levels of halving below a binary node of n references. */
static int halving_levels(uint32_t n)
{
    int l = 0;
    while (n > BVH2_LEAF_MIN) {
        n = n - n / 2;
        l++;
    }
    return l;
}

static uint32_t bnode_push(build *B)
{
    if (B->n_bn == B->cap_bn) {
        size_t cap = B->cap_bn ? 2 * (size_t)B->cap_bn : 1024;
        if (cap > 0xffffffffu)
            return FR_NONE;
        bvh2_node *m = realloc(B->bn, cap * sizeof *m);
        if (!m)
            return FR_NONE;
        B->bn = m;
        B->cap_bn = (uint32_t)cap;
    }
    memset(&B->bn[B->n_bn], 0, sizeof *B->bn);
    return B->n_bn++;
}

/* What references [begin, end) of s are: BVH2_TRIS, BVH2_SHAPES. */
static uint32_t span_kinds(const build *B, const span *s)
{
    const fr_prim *prims = B->b->prims.data;
    uint32_t k = 0;
    for (uint32_t i = s->begin; i < s->end; i++)
        k |= prims[B->id[i]].kind == FR_PRIM_TRIANGLE ? BVH2_TRIS : BVH2_SHAPES;
    return k;
}

/* s's triangles into *l, its other references into *r (in their order). */
static void split_kinds(build *B, const span *s, span *l, span *r)
{
    const fr_prim *prims = B->b->prims.data;
    uint32_t nl = 0, nr = 0, n = s->end - s->begin;
    for (uint32_t i = s->begin; i < s->end; i++) {
        if (prims[B->id[i]].kind == FR_PRIM_TRIANGLE) {
            B->tbox[nl] = B->box[i];
            B->tid[nl++] = B->id[i];
        }
    }
    for (uint32_t i = s->begin; i < s->end; i++) {
        if (prims[B->id[i]].kind != FR_PRIM_TRIANGLE) {
            B->tbox[nl + nr] = B->box[i];
            B->tid[nl + nr++] = B->id[i];
        }
    }
    memcpy(B->box + s->begin, B->tbox, n * sizeof *B->box);
    memcpy(B->id + s->begin, B->tid, n * sizeof *B->id);
    share_room(s, nl, nr, l, r);
    if (r->begin != s->begin + nl) {
        memmove(B->box + r->begin, B->box + s->begin + nl, nr * sizeof *B->box);
        memmove(B->id + r->begin, B->id + s->begin + nl, nr * sizeof *B->id);
    }
    l->leaf = r->leaf = 0;
    span_bounds(B, l);
    span_bounds(B, r);
}

/* Split s into the binary subtree rooted at a new node, *index. */
static int bin_build(build *B, const span *s, int depth, int median, uint32_t *index)
{
    uint32_t me = bnode_push(B);
    if (me == FR_NONE)
        return fr_fail(B->err, "out of memory for the BVH build");
    uint32_t n = s->end - s->begin;
    if (!median)
        median = depth + 2 + halving_levels(n) >= FR_BVH_MAX_DEPTH;
    span pair[2];
    uint32_t kinds = n <= BVH2_LEAF_MIN ? span_kinds(B, s) : 0;
    if (kinds == (BVH2_TRIS | BVH2_SHAPES)) {
        /* Triangles and other primitives in separate leaves. */
        split_kinds(B, s, &pair[0], &pair[1]);
    } else if (n <= BVH2_LEAF_MIN) {
        bvh2_node *v = &B->bn[me];
        v->kinds = (uint8_t)kinds;
        v->box = s->box;
        v->kid[0] = s->begin;
        v->kid[1] = s->end;
        v->refs = n;
        v->is_leaf = 1;
        bvh2_costs(B->bn, me);
        *index = me;
        return 0;
    } else {
        split_span(B, s, &pair[0], &pair[1], median);
    }
    uint32_t kid[2];
    for (int c = 0; c < 2; c++)
        if (bin_build(B, &pair[c], depth + 1, median, &kid[c]) < 0)
            return -1;
    bvh2_node *v = &B->bn[me];   /* the array may have moved */
    v->box = s->box;
    v->kid[0] = kid[0];
    v->kid[1] = kid[1];
    v->refs = B->bn[kid[0]].refs + B->bn[kid[1]].refs;
    bvh2_costs(B->bn, me);
    *index = me;
    return 0;
}

/* The slots of binary node v given as at most j slots, appended to
 * slot[*ns]. */
static void gather_slots(const bvh2_node *bn, uint32_t v, int j, uint32_t *slot, int *ns)
{
    while (j > 1 && !bn[v].is_leaf && bn[v].pick[j - 1] == 0)
        j--;
    if (j == 1 || bn[v].is_leaf) {
        slot[(*ns)++] = v;
        return;
    }
    int k = bn[v].pick[j - 1];
    gather_slots(bn, bn[v].kid[0], k, slot, ns);
    gather_slots(bn, bn[v].kid[1], j - k, slot, ns);
}

/* The references of v's subtree, each primitive once, appended to
 * B->tid[*n]. */
static void gather_refs(build *B, uint32_t v, uint32_t *n)
{
    const bvh2_node *x = &B->bn[v];
    if (!x->is_leaf) {
        gather_refs(B, x->kid[0], n);
        gather_refs(B, x->kid[1], n);
        return;
    }
    for (uint32_t i = x->kid[0]; i < x->kid[1]; i++) {
        uint32_t id = B->id[i], k = 0;
        while (k < *n && B->tid[k] != id)
            k++;
        if (k == *n)
            B->tid[(*n)++] = id;
    }
}

/* Fill the blocks of a leaf holding v's subtree; *first and *meta become
 * the parent's slot. */
static int emit_leaf(build *B, uint32_t v, uint32_t *first, uint32_t *meta)
{
    const fr_prim *prims = B->b->prims.data;
    const fr_triangle *tris = B->b->triangles.data;
    const vec3 *pos = B->b->positions.data;
    uint32_t n = 0;
    gather_refs(B, v, &n);
    uint32_t nblk = (n + 3) / 4, mixed = 0;
    *first = B->leaves->count;
    for (uint32_t k = 0; k < nblk; k++) {
        fr_bvh_leaf L;
        memset(&L, 0, sizeof L);
        for (uint32_t lane = 0; lane < 4; lane++) {
            uint32_t i = 4 * k + lane;
            if (i >= n) {
                L.prim[lane] = FR_NONE;
                continue;
            }
            uint32_t id = B->tid[i];
            const fr_prim *p = &prims[id];
            if (B->out_of[id] == FR_NONE) {
                B->out_of[id] = B->n_out;
                B->out[B->n_out++] = *p;
            }
            L.prim[lane] = B->out_of[id];
            if (p->kind != FR_PRIM_TRIANGLE) {
                mixed = FR_BVH_MIXED;
                continue;
            }
            const fr_triangle *t = &tris[p->index];
            for (int c = 0; c < 3; c++) {
                vec3 q = pos[t->v[c]];
                L.v[3 * c + 0][lane] = q.x;
                L.v[3 * c + 1][lane] = q.y;
                L.v[3 * c + 2][lane] = q.z;
            }
        }
        if (bld_push(B->leaves, &L) == FR_NONE)
            return fr_fail(B->err, "out of memory for the BVH leaves");
    }
    *meta = nblk | mixed;
    return 0;
}

/* Emit binary node v as a wide node (children after it, depth first);
 * *index receives the node's index. */
static int emit_node(build *B, uint32_t v, uint32_t *index)
{
    fr_bvh_node node;
    memset(&node, 0, sizeof node);
    uint32_t me = bld_push(B->nodes, &node);
    if (me == FR_NONE)
        return fr_fail(B->err, "out of memory for the BVH nodes");
    uint32_t slot[FR_BVH_WIDTH];
    int ns = 0;
    const bvh2_node *x = &B->bn[v];
    if (x->is_leaf) {
        slot[ns++] = v;
    } else {
        gather_slots(B->bn, x->kid[0], x->wide, slot, &ns);
        gather_slots(B->bn, x->kid[1], FR_BVH_WIDTH - x->wide, slot, &ns);
    }
    for (int i = 0; i < FR_BVH_WIDTH; i++) {
        fr_bvh_node *nd = (fr_bvh_node *)B->nodes->data + me;
        bvh2_box bx = i < ns ? B->bn[slot[i]].box : bvh2_box_empty();
        /* + 0 makes a zero bound +0: where -0 meets +0, SSE's and NEON's
         * min and max return different zeros, and the bytes must not
         * depend on the machine. */
        for (int a = 0; a < 3; a++) {
            nd->box[a][i] = bx.lo[a] + 0.0f;
            nd->box[3 + a][i] = bx.hi[a] + 0.0f;
        }
        nd->child[i] = FR_NONE;
        nd->leaf[i] = 0;
        if (i >= ns)
            continue;
        uint32_t child, meta = 0;
        if (B->bn[slot[i]].as_leaf) {
            if (emit_leaf(B, slot[i], &child, &meta) < 0)
                return -1;
        } else if (emit_node(B, slot[i], &child) < 0) {
            return -1;
        }
        nd = (fr_bvh_node *)B->nodes->data + me;   /* the array may have moved */
        nd->child[i] = child;
        nd->leaf[i] = meta;
    }
    *index = me;
    return 0;
}

int bvh_build(fr_builder *b, fr_array *nodes, fr_array *leaves, uint32_t **placed, fr_error *err)
{
    return bvh_build_with(b, NULL, nodes, leaves, placed, err);
}

/* Cost of the node whose slot box has half area `area`, and its slots. */
static double sah_node(const fr_bvh_node *nodes, uint32_t n_nodes, uint32_t v, double area, int depth)
{
    const fr_bvh_node *x = &nodes[v];
    double c = area * BVH2_TRAV_COST;
    for (int i = 0; i < FR_BVH_WIDTH && depth < FR_BVH_MAX_DEPTH; i++) {
        if (x->child[i] == FR_NONE)
            continue;
        f4 d = {x->box[3][i] - x->box[0][i], x->box[4][i] - x->box[1][i], x->box[5][i] - x->box[2][i], 0.0f};
        double a = (double)d[0] * d[1] + (double)d[1] * d[2] + (double)d[2] * d[0];
        c += a * BVH2_SLOT_COST;
        if (x->leaf[i])
            c += a * (double)(x->leaf[i] & FR_BVH_LEAF_MAX);
        else if (x->child[i] > v && x->child[i] < n_nodes)
            c += sah_node(nodes, n_nodes, x->child[i], a, depth + 1);
    }
    return c;
}

double bvh_sah_cost(const fr_bvh_node *nodes, uint32_t n_nodes)
{
    if (n_nodes == 0)
        return 0.0;
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < FR_BVH_WIDTH; i++)
        for (int a = 0; a < 3 && nodes[0].child[i] != FR_NONE; a++) {
            lo[a] = nodes[0].box[a][i] < lo[a] ? nodes[0].box[a][i] : lo[a];
            hi[a] = nodes[0].box[3 + a][i] > hi[a] ? nodes[0].box[3 + a][i] : hi[a];
        }
    double d0 = (double)hi[0] - lo[0], d1 = (double)hi[1] - lo[1], d2 = (double)hi[2] - lo[2];
    double area = d0 * d1 + d1 * d2 + d2 * d0;
    if (!(area > 0.0))
        return 0.0;
    return sah_node(nodes, n_nodes, 0, area, 1) / area;
}

int bvh_build_with(fr_builder *b, const bvh_options *opt, fr_array *nodes, fr_array *leaves, uint32_t **placed,
                   fr_error *err)
{
    int reinsert = opt ? opt->reinsert : 1;
    uint32_t n = b->prims.count;
    if (placed && n == 0)
        *placed = NULL;
    if (n == 0)
        return 0;
    if (n >= 0x80000000u)
        return fr_fail(err, "%u primitives: the BVH holds at most 2^31 - 1", n);
    /* Room for as many references as spatial splits may add: n more. */
    uint32_t cap = n + n;
    build B = {0};
    B.box = malloc((size_t)cap * sizeof *B.box);
    B.id = malloc((size_t)cap * sizeof *B.id);
    B.tbox = malloc((size_t)cap * sizeof *B.tbox);
    B.tid = malloc((size_t)cap * sizeof *B.tid);
    B.out = malloc((size_t)n * sizeof *B.out);
    B.out_of = malloc((size_t)n * sizeof *B.out_of);
    B.b = b;
    B.nodes = nodes;
    B.leaves = leaves;
    B.err = err;
    int rc = 0;
    if (!B.box || !B.id || !B.tbox || !B.tid || !B.out || !B.out_of)
        rc = fr_fail(err, "out of memory for the BVH (%u primitives)", n);
    for (uint32_t i = 0; i < n && rc == 0; i++) {
        vec3 lo, hi;
        bvh_prim_bounds(b, i, &lo, &hi);
        if (!isfinite(lo.x) || !isfinite(lo.y) || !isfinite(lo.z) || !isfinite(hi.x) || !isfinite(hi.y) ||
            !isfinite(hi.z))
            rc = fr_fail(err, "primitive %u has non-finite bounds", i);
        B.box[i] = (bvh2_box){{lo.x, lo.y, lo.z, 0.0f}, {hi.x, hi.y, hi.z, 0.0f}};
        B.id[i] = i;
        B.out_of[i] = FR_NONE;
    }
    if (rc == 0) {
        span all = {0, n, cap, bvh2_box_empty(), bvh2_box_empty(), 0};
        span_bounds(&B, &all);
        B.min_overlap = bvh2_area(all.box) * OVERLAP;
        uint32_t broot, root;
        rc = bin_build(&B, &all, 1, 0, &broot);
        /* The references' boxes are in the tree now: gone before the
         * wide tree and its leaves are made (a peak of the compile). */
        free(B.box);
        free(B.tbox);
        B.box = B.tbox = NULL;
        if (rc == 0 && reinsert)
            rc = bvh_reinsert(B.bn, B.n_bn, &broot, err);
        if (rc == 0)
            rc = emit_node(&B, broot, &root);
    }
    if (rc == 0 && B.n_out != n)
        rc = fr_fail(err, "BVH build lost primitives (%u of %u in leaves)", B.n_out, n);
    free(B.box);
    free(B.id);
    free(B.tbox);
    free(B.tid);
    free(B.bn);
    if (rc < 0) {
        free(B.out);
        free(B.out_of);
        return -1;
    }
    if (placed)
        *placed = B.out_of;
    else
        free(B.out_of);
    free(b->prims.data);
    b->prims.data = B.out;
    b->prims.cap = n;
    return 0;
}
