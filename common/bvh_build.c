#include "bvh_build.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "simd4.h"

/* Costs are in units of one leaf block test (four triangles); a node test
 * (eight boxes) costs about the same, TRAV_COST.  Every slot of a node a
 * ray enters (a leaf or a child node) is also charged SLOT_COST: it adds a
 * box tested together with the others and one more leaf or subtree to
 * visit.  (Charged nothing, the collapse cuts sheets of long overlapping
 * slivers into many small leaves that cost more.)  A subtree becomes a
 * leaf of at most LEAF_MAX references (four blocks); binary leaves hold at
 * most LEAF_MIN (one block). */
enum { BINS = 32, LEAF_MIN = 4, LEAF_MAX = 16, SWEEP_MAX = 64 };
#define TRAV_COST 1.0f
#define SLOT_COST 0.5f
/* Spatial splits: tried where an object split's two sides overlap by more
 * than OVERLAP times the root's area, with room for as many extra
 * references as there are primitives. */
#define OVERLAP 1e-5f

typedef struct { f4 lo, hi; } box4;   /* lane 3 unused (kept 0) */

/* A contiguous range of references with its bounds and the bounds of its
 * centroids. */
typedef struct {
    uint32_t begin, end;       /* its references */
    uint32_t cap;              /* [end, cap): room for references a spatial split adds */
    box4 box, cent;
    int leaf;                  /* decided: becomes a leaf */
} span;

typedef struct {
    box4 *box;                 /* per reference: bounds of its part of its primitive */
    uint32_t *id;              /* per reference: index into the builder's prims */
    box4 *tbox;                /* scratch for a spatial split's references */
    uint32_t *tid;
    const fr_builder *b;
    fr_prim *out;              /* prims in the order leaves first name them */
    uint32_t *out_of;          /* per builder prim: its index in out, FR_NONE before */
    uint32_t n_out;
    float min_overlap;         /* half area of the root times OVERLAP */
    fr_array *nodes, *leaves;
    fr_error *err;
    struct bnode *bn;          /* the binary tree */
    uint32_t n_bn, cap_bn;
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

static int box_is_empty(box4 b) { return !(b.lo[0] <= b.hi[0] && b.lo[1] <= b.hi[1] && b.lo[2] <= b.hi[2]); }

static box4 box_clip(box4 a, box4 b) { return (box4){f4_max_num(b.lo, a.lo), f4_min_num(b.hi, a.hi)}; }

static f4 vload(vec3 p) { return (f4){p.x, p.y, p.z, 0.0f}; }

/* The point where edge p-q crosses the plane x[a] = c (p[a] and q[a] on
 * opposite sides, strictly), added to *r as a small box that surely holds
 * the exact point: the rounded coordinates are widened by far more than
 * their rounding error (a few units in the last place of |p| + |q|) and
 * kept within the edge's own bounds; on axis a the point is c exactly. */
static void add_crossing(box4 *r, f4 p, f4 q, i4 on_a, float pa, float qa, float c)
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
static box4 ref_slab(const build *B, uint32_t i, int a, float lo, float hi)
{
    box4 rb = B->box[i];
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
    box4 r = box_empty();
    for (int k = 0; k < 3; k++) {
        f4 P = v[k], Q = v[k == 2 ? 0 : k + 1];
        float pa = P[a], qa = Q[a];
        if (pa >= lo && pa <= hi)
            box_add(&r, P);
        if ((pa < lo && qa > lo) || (pa > lo && qa < lo))
            add_crossing(&r, P, Q, on_a, pa, qa, lo);
        if ((pa < hi && qa > hi) || (pa > hi && qa < hi))
            add_crossing(&r, P, Q, on_a, pa, qa, hi);
    }
    return box_clip(r, rb);
}

/* The cheapest spatial split of s across its longest axis (trying the
 * other two costs twice the build time for about 1 % fewer leaf blocks per
 * ray on the meshes of tests/bench): *axis and *plane, its cost (INFINITY
 * if none).  Bins are slabs of equal width of the span's box; a reference
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
    box4 bins[BINS];
    uint32_t enter[BINS], leave[BINS];
    for (int k = 0; k < nb; k++) {
        bins[k] = box_empty();
        enter[k] = leave[k] = 0;
    }
    for (uint32_t i = s->begin; i < s->end; i++) {
        box4 bx = B->box[i];
        int k0 = bin_at(bx.lo[a], lo, scale, nb), k1 = bin_at(bx.hi[a], lo, scale, nb);
        enter[k0]++;
        leave[k1]++;
        if (k0 == k1) {
            box_grow(&bins[k0], bx);
            continue;
        }
        for (int k = k0; k <= k1; k++) {
            box4 part = ref_slab(B, i, a, k == k0 ? -INFINITY : lo + w * (float)k,
                                 k == k1 ? INFINITY : lo + w * (float)(k + 1));
            if (!box_is_empty(part))
                box_grow(&bins[k], part);
        }
    }
    float right_area[BINS];
    uint32_t right_count[BINS];
    box4 acc = box_empty();
    uint32_t c = 0;
    for (int k = nb - 1; k > 0; k--) {
        box_grow(&acc, bins[k]);
        c += leave[k];
        right_count[k] = c;
        right_area[k] = c ? half_area(acc) : 0.0f;
    }
    acc = box_empty();
    c = 0;
    for (int k = 1; k < nb; k++) {
        box_grow(&acc, bins[k - 1]);
        c += enter[k - 1];
        if (c == 0 || right_count[k] == 0)
            continue;
        float cost = half_area(acc) * blocks(c) + right_area[k] * blocks(right_count[k]);
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
        box4 bx = B->box[i], lb = bx, rb = bx;
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
    box4 rbox[SWEEP_MAX];
    float best = INFINITY;
    for (int a = 0; a < 3; a++) {
        if (!(s->cent.hi[a] > s->cent.lo[a]))
            continue;
        sweep_keys(B, s, a, k);
        box4 acc = box_empty();
        for (uint32_t i = n - 1; i > 0; i--) {
            box_grow(&acc, B->box[k[i].pos]);
            rbox[i] = acc;
        }
        acc = box_empty();
        for (uint32_t i = 1; i < n; i++) {
            box_grow(&acc, B->box[k[i - 1].pos]);
            float cost = half_area(acc) * blocks(i) + half_area(rbox[i]) * blocks(n - i);
            if (cost < best) {
                best = cost;
                *axis = a;
                *nleft = i;
                box4 o = box_clip(acc, rbox[i]);
                *overlap = box_is_empty(o) ? 0.0f : half_area(o);
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
        box4 bins[3][BINS];
        uint32_t count[3][BINS];
        for (int a = 0; a < 3; a++)
            for (int k = 0; k < nb; k++) {
                bins[a][k] = box_empty();
                count[a][k] = 0;
            }
        for (uint32_t i = s->begin; i < s->end && !sweep; i++) {
            box4 bx = B->box[i];
            i4 k = bin_of(centroid(bx), s->cent.lo, scale, nb);
            for (int a = 0; a < 3; a++) {
                box_grow(&bins[a][k[a]], bx);
                count[a][k[a]]++;
            }
        }
        for (int a = 0; a < 3; a++) {
            if (sweep || scale[a] == 0.0f)
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
        /* A spatial split where the object split's sides overlap much. */
        int sp_axis = -1;
        float sp_plane = 0.0f, sp_cost = INFINITY;
        if (s->cap > s->end && n > 1) {
            float overlap = INFINITY;
            if (sweep) {
                overlap = sweep_overlap;
            } else if (best_axis >= 0) {
                box4 lb = box_empty(), rb = box_empty();
                for (int k = 0; k < nb; k++)
                    box_grow(k < best_bin ? &lb : &rb, bins[best_axis][k]);
                box4 o = box_clip(lb, rb);
                overlap = box_is_empty(o) ? 0.0f : half_area(o);
            }
            if (overlap > B->min_overlap)
                sp_cost = spatial_best(B, s, nb, &sp_axis, &sp_plane);
        }
        if (sp_cost < best_cost && spatial_split(B, s, sp_axis, sp_plane, l, r))
            return;
    }
    *l = (span){s->begin, s->begin, s->begin, box_empty(), box_empty(), 0};
    *r = (span){s->end, s->end, s->cap, box_empty(), box_empty(), 0};
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
            box_grow(&side->box, B->box[q]);
            box_add(&side->cent, centroid(B->box[q]));
        }
    }
    /* Partition by bin, collecting both sides' bounds on the way. */
    float lo = s->cent.lo[best_axis], sc = scale[best_axis];
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
 * LEAF_MIN (always taking the split, SAH or spatial, that split_span finds
 * best), then chooses which binary nodes become 8-wide nodes and which
 * subtrees become leaves by dynamic programming over the binary tree
 * (bottom-up): cost[v][j-1] is the least SAH cost of v's subtree given as
 * at most j slots of a wide node, each slot a leaf (area times its blocks)
 * or a wide node (area times TRAV_COST plus the cost of its own up to eight
 * slots), each slot also charged its area times SLOT_COST.  A subtree
 * becomes a leaf only with at most LEAF_MAX references; its references are
 * packed into blocks together, so small binary leaves fill blocks. */

typedef struct bnode {
    box4 box;
    uint32_t kid[2];           /* children, or a leaf's references [kid[0], kid[1]) */
    uint32_t refs;             /* references in the subtree */
    uint8_t is_leaf;
    uint8_t as_leaf;           /* as one slot: 1 a leaf, 0 a wide node */
    uint8_t wide;              /* as a wide node: slots from kid[0] (the rest from kid[1]) */
    uint8_t pick[FR_BVH_WIDTH]; /* pick[j-1], j >= 2: 0 = as j-1 slots, else slots from kid[0] */
    float cost[FR_BVH_WIDTH];  /* cost[j-1]: as at most j slots */
} bnode;

/* Levels of halving below a binary node of n references. */
static int halving_levels(uint32_t n)
{
    int l = 0;
    while (n > LEAF_MIN) {
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
        bnode *m = realloc(B->bn, cap * sizeof *m);
        if (!m)
            return FR_NONE;
        B->bn = m;
        B->cap_bn = (uint32_t)cap;
    }
    memset(&B->bn[B->n_bn], 0, sizeof *B->bn);
    return B->n_bn++;
}

/* The costs of binary node v from those of its children. */
static void bnode_costs(bnode *bn, uint32_t v)
{
    bnode *n = &bn[v];
    float area = half_area(n->box), slot = area * SLOT_COST;
    if (n->is_leaf) {
        for (int j = 0; j < FR_BVH_WIDTH; j++) {
            n->cost[j] = slot + area * blocks(n->refs);
            n->pick[j] = 0;
        }
        n->as_leaf = 1;
        return;
    }
    const float *ca = bn[n->kid[0]].cost, *cb = bn[n->kid[1]].cost;
    float split[FR_BVH_WIDTH + 1];
    uint8_t at[FR_BVH_WIDTH + 1];
    for (int j = 2; j <= FR_BVH_WIDTH; j++) {
        split[j] = INFINITY;
        at[j] = 1;
        for (int k = 1; k < j; k++) {
            float c = ca[k - 1] + cb[j - k - 1];
            if (c < split[j]) {
                split[j] = c;
                at[j] = (uint8_t)k;
            }
        }
    }
    float as_node = area * TRAV_COST + split[FR_BVH_WIDTH];
    float as_leaf = n->refs <= LEAF_MAX ? area * blocks(n->refs) : INFINITY;
    n->wide = at[FR_BVH_WIDTH];
    n->as_leaf = as_leaf <= as_node;
    n->cost[0] = slot + (n->as_leaf ? as_leaf : as_node);
    n->pick[0] = 0;
    for (int j = 2; j <= FR_BVH_WIDTH; j++) {
        if (split[j] < n->cost[j - 2]) {
            n->cost[j - 1] = split[j];
            n->pick[j - 1] = at[j];
        } else {
            n->cost[j - 1] = n->cost[j - 2];
            n->pick[j - 1] = 0;
        }
    }
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
    if (n <= LEAF_MIN) {
        bnode *v = &B->bn[me];
        v->box = s->box;
        v->kid[0] = s->begin;
        v->kid[1] = s->end;
        v->refs = n;
        v->is_leaf = 1;
        bnode_costs(B->bn, me);
        *index = me;
        return 0;
    }
    split_span(B, s, &pair[0], &pair[1], median);
    uint32_t kid[2];
    for (int c = 0; c < 2; c++)
        if (bin_build(B, &pair[c], depth + 1, median, &kid[c]) < 0)
            return -1;
    bnode *v = &B->bn[me];   /* the array may have moved */
    v->box = s->box;
    v->kid[0] = kid[0];
    v->kid[1] = kid[1];
    v->refs = B->bn[kid[0]].refs + B->bn[kid[1]].refs;
    bnode_costs(B->bn, me);
    *index = me;
    return 0;
}

/* ---- reinsertion ----
 *
 * Before the collapse the binary tree is improved by moving subtrees (the
 * insertion-based optimisation of Bittner, Hapala and Havran, 2013), each
 * move kept only where it lowers the collapse's cost of the whole tree.
 * Leaves keep their references, so a primitive cut by spatial splits stays
 * in the same leaves.
 *   - A leaf N is taken out (its parent goes, its sibling takes the
 *     parent's place, the nodes above are refitted) and put as the sibling
 *     of another node under a new parent.
 *   - An inner node N is taken out with its parent, and its two children
 *     are put back one after the other (the larger first).
 * Where a subtree goes is chosen by the summed area of the inner nodes,
 * the usual stand-in for the SAH: beside the node where it grows least,
 * found by branch and bound from the root (nodes in the order of how much
 * their ancestors would grow, a heap with ties to the lower index, a
 * subtree skipped where that growth plus the moved subtree's own area
 * reaches the best place found; no place where the tree would get deeper
 * than FR_BVH_MAX_DEPTH).  A move that does not lower the inner area is
 * not tried; one that does is kept only if the collapse's cost of the
 * root (bnode_costs, recomputed up both paths) falls, else undone exactly.
 * A pass tries, worst first, the twentieth of the nodes whose parent is
 * largest against its two children (area(P) / (area(N) + area(S)) *
 * area(P)); passes stop when one gains less than REINS_STOP of the cost,
 * or after REINS_PASSES. */

enum { REINS_PASSES = 3, REINS_SHARE = 20 };
#define REINS_STOP 0.01f

typedef struct {
    float c;                   /* growth of the ancestors' areas */
    uint32_t node, depth;      /* depth: the root is 1 */
} reins_item;

typedef struct {
    bnode *bn;                 /* the tree, changed in place */
    float *area;               /* per node: half_area(box) */
    uint32_t *up;              /* parent, FR_NONE at the root and out of the tree */
    uint8_t *height;           /* levels of the subtree: 1 for a leaf */
    uint32_t root, n;
    reins_item *heap;          /* the search's (a node enters it once) */
    uint32_t nh;
} reins;

static int reins_before(reins_item a, reins_item b) { return a.c < b.c || (a.c == b.c && a.node < b.node); }

static void reins_push(reins *R, reins_item it)
{
    uint32_t i = R->nh++;
    while (i > 0) {
        uint32_t p = (i - 1) / 2;
        if (!reins_before(it, R->heap[p]))
            break;
        R->heap[i] = R->heap[p];
        i = p;
    }
    R->heap[i] = it;
}

static reins_item reins_pop(reins *R)
{
    reins_item top = R->heap[0], last = R->heap[--R->nh];
    uint32_t i = 0, n = R->nh;
    for (;;) {
        uint32_t c = 2 * i + 1;
        if (c >= n)
            break;
        if (c + 1 < n && reins_before(R->heap[c + 1], R->heap[c]))
            c++;
        if (!reins_before(R->heap[c], last))
            break;
        R->heap[i] = R->heap[c];
        i = c;
    }
    if (n > 0)
        R->heap[i] = last;
    return top;
}

static uint8_t max_u8(uint8_t a, uint8_t b) { return a > b ? a : b; }

/* Box, area, height, references and costs of inner node x and its
 * ancestors from their children. */
static void reins_update(reins *R, uint32_t x)
{
    bnode *bn = R->bn;
    for (; x != FR_NONE; x = R->up[x]) {
        uint32_t a = bn[x].kid[0], b = bn[x].kid[1];
        bn[x].box = bn[a].box;
        box_grow(&bn[x].box, bn[b].box);
        bn[x].refs = bn[a].refs + bn[b].refs;
        R->area[x] = half_area(bn[x].box);
        R->height[x] = (uint8_t)(1 + max_u8(R->height[a], R->height[b]));
        bnode_costs(bn, x);
    }
}

/* Put x where child `from` of p was (p FR_NONE: as the root). */
static void reins_replace(reins *R, uint32_t p, uint32_t from, uint32_t x)
{
    R->up[x] = p;
    if (p == FR_NONE)
        R->root = x;
    else
        R->bn[p].kid[R->bn[p].kid[0] == from ? 0 : 1] = x;
}

/* Take subtree x (not the root's child) out of the tree: its parent goes,
 * the sibling takes the parent's place. */
static void reins_detach(reins *R, uint32_t x)
{
    uint32_t p = R->up[x], g = R->up[p];
    reins_replace(R, g, p, R->bn[p].kid[R->bn[p].kid[0] == x ? 1 : 0]);
    reins_update(R, g);
    R->up[x] = R->up[p] = FR_NONE;
}

/* Put subtree n beside x under the free node p (n its first child if
 * n_first). */
static void reins_attach(reins *R, uint32_t n, uint32_t x, uint32_t p, int n_first)
{
    reins_replace(R, R->up[x], x, p);
    R->bn[p].kid[0] = n_first ? n : x;
    R->bn[p].kid[1] = n_first ? x : n;
    R->up[x] = R->up[n] = p;
    reins_update(R, p);
}

/* The cheapest place for subtree n (out of the tree) as above: the node to
 * put it beside, FR_NONE if there is none within the depth; *cost gets the
 * growth of the inner area there. */
static uint32_t reins_search(reins *R, uint32_t n, float *cost)
{
    const bnode *bn = R->bn;
    box4 nb = bn[n].box;
    float an = R->area[n], best = INFINITY;
    uint32_t best_x = FR_NONE, hn = R->height[n];
    R->nh = 0;
    reins_push(R, (reins_item){0.0f, R->root, 1});
    while (R->nh > 0) {
        reins_item it = reins_pop(R);
        if (!(it.c + an < best))
            break;
        uint32_t x = it.node, h = R->height[x] > hn ? R->height[x] : hn;
        box4 u = bn[x].box;
        box_grow(&u, nb);
        float au = half_area(u), total = it.c + au;
        if (total < best && it.depth + h <= FR_BVH_MAX_DEPTH) {
            best = total;
            best_x = x;
        }
        if (bn[x].is_leaf)
            continue;
        float c = it.c + (au - R->area[x]);
        if (c + an < best)
            for (int k = 0; k < 2; k++)
                reins_push(R, (reins_item){c, bn[x].kid[k], it.depth + 1});
    }
    *cost = best;
    return best_x;
}

/* The growth of the inner area from putting subtree n beside x, added up
 * as reins_search adds it. */
static float reins_cost_at(const reins *R, uint32_t n, uint32_t x)
{
    uint32_t path[256];
    int np = 0;
    for (uint32_t y = R->up[x]; y != FR_NONE && np < 256; y = R->up[y])
        path[np++] = y;
    box4 nb = R->bn[n].box;
    float c = 0.0f;
    while (np > 0) {
        uint32_t y = path[--np];
        box4 u = R->bn[y].box;
        box_grow(&u, nb);
        c = c + (half_area(u) - R->area[y]);
    }
    box4 u = R->bn[x].box;
    box_grow(&u, nb);
    return c + half_area(u);
}

/* The cost of binary node v emitted as the root (a wide node, as
 * emit_node makes it). */
static float bnode_root_cost(const bnode *bn, uint32_t v)
{
    const bnode *n = &bn[v];
    if (n->is_leaf)
        return n->cost[0];
    float best = INFINITY;
    for (int k = 1; k < FR_BVH_WIDTH; k++) {
        float c = bn[n->kid[0]].cost[k - 1] + bn[n->kid[1]].cost[FR_BVH_WIDTH - k - 1];
        best = c < best ? c : best;
    }
    return half_area(n->box) * TRAV_COST + best;
}

/* Whether a move from cost `before` is kept: the root's cost falls by more
 * than rounding. */
static int reins_better(const reins *R, float before)
{
    return bnode_root_cost(R->bn, R->root) < before * 0.999999f;
}

/* Move leaf n; returns whether it moved. */
static int reins_move(reins *R, uint32_t n)
{
    uint32_t p = R->up[n];
    int n_first = R->bn[p].kid[0] == n;
    uint32_t s = R->bn[p].kid[n_first ? 1 : 0];
    float before = bnode_root_cost(R->bn, R->root), cost;
    reins_detach(R, n);
    float stay = reins_cost_at(R, n, s);
    uint32_t x = reins_search(R, n, &cost);
    if (x != FR_NONE && x != s && cost < stay) {
        reins_attach(R, n, x, p, 0);
        if (reins_better(R, before))
            return 1;
        reins_detach(R, n);
    }
    reins_attach(R, n, s, p, n_first);
    return 0;
}

/* Summed area of y and its ancestors. */
static float reins_path_area(const reins *R, uint32_t y)
{
    float sum = 0.0f;
    for (; y != FR_NONE; y = R->up[y])
        sum += R->area[y];
    return sum;
}

/* Take inner node n out with its parent and put its children back;
 * returns whether that was kept. */
static int reins_split(reins *R, uint32_t n)
{
    bnode *bn = R->bn;
    uint32_t p = R->up[n], g = R->up[p], a = bn[n].kid[0], b = bn[n].kid[1];
    int n_first = bn[p].kid[0] == n;
    uint32_t s = bn[p].kid[n_first ? 1 : 0];
    float before = bnode_root_cost(bn, R->root), area_before = reins_path_area(R, n);
    reins_detach(R, n);
    float area_after = reins_path_area(R, g);
    R->up[a] = R->up[b] = FR_NONE;
    uint32_t first = R->area[a] >= R->area[b] ? a : b, second = first == a ? b : a;
    /* Beside s is where first was, within the depth; where second finds
     * no place within it, all is undone. */
    float c1, c2;
    uint32_t x1 = reins_search(R, first, &c1);
    if (x1 == FR_NONE)
        c1 = reins_cost_at(R, first, x1 = s);
    reins_attach(R, first, x1, n, 0);
    uint32_t x2 = reins_search(R, second, &c2);
    int undo = x2 == FR_NONE;
    reins_attach(R, second, undo ? first : x2, p, 0);
    if (!undo && area_before - area_after > c1 + c2 && reins_better(R, before))
        return 1;
    reins_detach(R, second);
    reins_detach(R, first);
    bn[n].kid[0] = a;
    bn[n].kid[1] = b;
    R->up[a] = R->up[b] = n;
    R->up[n] = FR_NONE;
    reins_update(R, n);
    reins_attach(R, n, s, p, n_first);
    return 0;
}

typedef struct {
    float score;
    uint32_t node;
} reins_cand;

/* Worst first, ties to the lower index (a total order: qsort's algorithm
 * does not matter). */
static int reins_cand_cmp(const void *a, const void *b)
{
    const reins_cand *x = a, *y = b;
    if (x->score != y->score)
        return x->score > y->score ? -1 : 1;
    return x->node < y->node ? -1 : x->node > y->node;
}

/* One pass (cand: scratch for every node). */
static void reins_pass(reins *R, reins_cand *cand)
{
    const bnode *bn = R->bn;
    uint32_t nc = 0;
    for (uint32_t i = 0; i < R->n; i++) {
        uint32_t p = R->up[i];
        if (p == FR_NONE || R->up[p] == FR_NONE)
            continue;
        uint32_t s = bn[p].kid[bn[p].kid[0] == i ? 1 : 0];
        float score = R->area[p] / (R->area[s] + R->area[i]) * R->area[p];
        cand[nc++] = (reins_cand){score == score ? score : 0.0f, i};   /* 0/0: flat boxes */
    }
    qsort(cand, nc, sizeof *cand, reins_cand_cmp);
    for (uint32_t k = 0; k < nc / REINS_SHARE; k++) {
        uint32_t n = cand[k].node, p = R->up[n];
        if (p == FR_NONE || R->up[p] == FR_NONE)   /* now a child of the root */
            continue;
        if (bn[n].is_leaf)
            reins_move(R, n);
        else
            reins_split(R, n);
    }
}

/* Reinsertion over the binary tree at *root (its costs as bin_build left
 * them); *root may change.  Returns 0, or -1 with B->err set on memory
 * exhaustion. */
static int bvh_reinsert(build *B, uint32_t *root)
{
    uint32_t n = B->n_bn;
    if (n < 7)
        return 0;
    reins R = {0};
    R.bn = B->bn;
    R.n = n;
    R.root = *root;
    R.area = malloc((size_t)n * sizeof *R.area);
    R.up = malloc((size_t)n * sizeof *R.up);
    R.height = malloc(n);
    R.heap = malloc((size_t)n * sizeof *R.heap);
    reins_cand *cand = malloc((size_t)n * sizeof *cand);
    int rc = 0;
    if (!R.area || !R.up || !R.height || !R.heap || !cand) {
        rc = fr_fail(B->err, "out of memory for the BVH reinsertion (%u nodes)", n);
        goto done;
    }
    /* bin_build numbers a node before its children: from the back, children
     * come first. */
    for (uint32_t i = n; i-- > 0;) {
        const bnode *v = &R.bn[i];
        R.up[i] = FR_NONE;
        R.height[i] = 1;
        if (!v->is_leaf) {
            R.height[i] = (uint8_t)(1 + max_u8(R.height[v->kid[0]], R.height[v->kid[1]]));
            R.up[v->kid[0]] = R.up[v->kid[1]] = i;
        }
        R.area[i] = half_area(v->box);
    }
    for (int pass = 0; pass < REINS_PASSES; pass++) {
        float before = bnode_root_cost(R.bn, R.root);
        reins_pass(&R, cand);
        if (!(bnode_root_cost(R.bn, R.root) < before * (1.0f - REINS_STOP)))
            break;
    }
    *root = R.root;
done:
    free(R.area);
    free(R.up);
    free(R.height);
    free(R.heap);
    free(cand);
    return rc;
}

/* The slots of binary node v given as at most j slots, appended to
 * slot[*ns]. */
static void gather_slots(const bnode *bn, uint32_t v, int j, uint32_t *slot, int *ns)
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
    const bnode *x = &B->bn[v];
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
    const bnode *x = &B->bn[v];
    if (x->is_leaf) {
        slot[ns++] = v;
    } else {
        gather_slots(B->bn, x->kid[0], x->wide, slot, &ns);
        gather_slots(B->bn, x->kid[1], FR_BVH_WIDTH - x->wide, slot, &ns);
    }
    for (int i = 0; i < FR_BVH_WIDTH; i++) {
        fr_bvh_node *nd = (fr_bvh_node *)B->nodes->data + me;
        box4 bx = i < ns ? B->bn[slot[i]].box : box_empty();
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
    double c = area * TRAV_COST;
    for (int i = 0; i < FR_BVH_WIDTH && depth < FR_BVH_MAX_DEPTH; i++) {
        if (x->child[i] == FR_NONE)
            continue;
        f4 d = {x->box[3][i] - x->box[0][i], x->box[4][i] - x->box[1][i], x->box[5][i] - x->box[2][i], 0.0f};
        double a = (double)d[0] * d[1] + (double)d[1] * d[2] + (double)d[2] * d[0];
        c += a * SLOT_COST;
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
        B.box[i] = (box4){{lo.x, lo.y, lo.z, 0.0f}, {hi.x, hi.y, hi.z, 0.0f}};
        B.id[i] = i;
        B.out_of[i] = FR_NONE;
    }
    if (rc == 0) {
        span all = {0, n, cap, box_empty(), box_empty(), 0};
        span_bounds(&B, &all);
        B.min_overlap = half_area(all.box) * OVERLAP;
        uint32_t broot, root;
        rc = bin_build(&B, &all, 1, 0, &broot);
        if (rc == 0 && reinsert)
            rc = bvh_reinsert(&B, &broot);
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
