/* freeze_lighttree.c -- the light tree built over a scene's local lights (see
 * freeze_lighttree.h). */
#include "compile/freeze_lighttree.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fmath.h"

/* Bounds of a set of lights while the tree is built. */
typedef struct {
    vec3 lo, hi;
    vec3 at; /* a point of the light (a single light's bound) */
    vec3 axis;
    float cos_o, cos_e;
    double power;
    int two_sided, empty;
} lbound;

static const lbound empty_bound = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY},
                                   {0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f}, 1.0f, 1.0f, 0.0, 0, 1};

/* Angles of cones are widened by this much (radians) where they are
 * merged, so that rounding never leaves a direction outside. */
#define CONE_SLACK 1e-5f

/* Unit-vector angle, accurate for near and opposite vectors. */
static float angle_between(vec3 a, vec3 b)
{
    if (v3_dot(a, b) < 0.0f)
        return FM_PI - 2.0f * fm_asinf(0.5f * v3_len(v3_add(a, b)));
    return 2.0f * fm_asinf(0.5f * v3_len(v3_sub(a, b)));
}

/* The smallest cone (of the kind pbrt-v4's DirectionCone::Union gives)
 * holding cones (wa, cos_a) and (wb, cos_b); *cos_r receives its cosine. */
static vec3 cone_union(vec3 wa, float cos_a, vec3 wb, float cos_b, float *cos_r)
{
    float ta = fm_acosf(cos_a), tb = fm_acosf(cos_b), td = angle_between(wa, wb);
    if (fminf(td + tb, FM_PI) <= ta) {
        *cos_r = cos_a;
        return wa;
    }
    if (fminf(td + ta, FM_PI) <= tb) {
        *cos_r = cos_b;
        return wb;
    }
    float to = 0.5f * (ta + td + tb) + CONE_SLACK;
    vec3 k = v3_cross(wa, wb);
    if (to >= FM_PI || !(v3_len2(k) > 0.0f)) {
        *cos_r = -1.0f;
        return wa;
    }
    /* wa turned toward wb by to - ta about k (Rodrigues; k is normal to wa). */
    k = v3_norm(k);
    float s, c;
    fm_sincosf(to - ta, &s, &c);
    vec3 w = v3_norm(v3_add(v3_scale(wa, c), v3_scale(v3_cross(k, wa), s)));
    *cos_r = fm_cosf(to);
    return w;
}

static lbound bound_union(lbound a, const lbound *b)
{
    if (b->empty)
        return a;
    if (a.empty)
        return *b;
    a.lo = v3_vmin(a.lo, b->lo);
    a.hi = v3_vmax(a.hi, b->hi);
    a.axis = cone_union(a.axis, a.cos_o, b->axis, b->cos_o, &a.cos_o);
    a.cos_e = fminf(a.cos_e, b->cos_e);
    a.power += b->power;
    a.two_sided |= b->two_sided;
    return a;
}

/* The solid angle (times pi, as in the paper) that a cone of normals
 * with spread cos_o and emission spread cos_e sends light into: M_omega of
 * Conty Estevez and Kulla (2018). */
static double cone_measure(float cos_o, float cos_e)
{
    double to = fm_acosf(cos_o), te = fm_acosf(cos_e), tw = to + te < FM_PI ? to + te : FM_PI;
    double so = sqrt(fmax(0.0, 1.0 - (double)cos_o * cos_o));
    return 2.0 * FM_PI * (1.0 - cos_o) +
           FM_PI / 2.0 * (2.0 * tw * so - fm_cosf((float)(to - 2.0 * tw)) - 2.0 * to * so + cos_o);
}

static double box_area(vec3 lo, vec3 hi)
{
    vec3 d = v3_sub(hi, lo);
    return 2.0 * ((double)d.x * d.y + (double)d.y * d.z + (double)d.z * d.x);
}

/* The split cost of a side with bounds b in a node whose box has extent
 * `ext` (its largest coordinate max_ext) along the split axis. */
static double side_cost(const lbound *b, float ext, float max_ext)
{
    if (b->empty)
        return 0.0;
    double kr = ext > 0.0f ? (double)max_ext / ext : 1.0;
    return b->power * cone_measure(b->cos_o, b->cos_e) * kr * box_area(b->lo, b->hi);
}

typedef struct {
    const lbound *lb;          /* per local light */
    uint32_t *idx;             /* local light indices, reordered by the build */
    fr_light_node *nodes;
    uint32_t nl, next;         /* local lights; next inner node */
    int axis;                  /* the axis qsort compares along */
} build;

static vec3 centre(const lbound *b) { return v3_scale(v3_add(b->lo, b->hi), 0.5f); }

static const build *sort_ctx;
static int by_centre(const void *pa, const void *pb)
{
    uint32_t a = *(const uint32_t *)pa, b = *(const uint32_t *)pb;
    float ca = v3_get(centre(&sort_ctx->lb[a]), sort_ctx->axis), cb = v3_get(centre(&sort_ctx->lb[b]), sort_ctx->axis);
    return ca < cb ? -1 : ca > cb ? 1 : a < b ? -1 : a > b;
}

enum { BUCKETS = 12, SAH_DEPTH = 32 };

static void store(fr_light_node *n, const lbound *b)
{
    n->lo = b->lo;
    n->hi = b->hi;
    n->axis = b->axis;
    n->cos_o = b->cos_o;
    n->cos_e = b->cos_e;
    n->power = b->power < FLT_MAX ? (float)b->power : FLT_MAX; /* finite, as the loader asks */
    n->flags = b->two_sided ? FR_LNODE_TWO_SIDED : 0;
}

/* The subtree over idx[begin, end) at depth `depth`; returns its node. */
static uint32_t build_range(build *bd, uint32_t begin, uint32_t end, int depth)
{
    if (end - begin == 1) {
        uint32_t j = bd->idx[begin];
        store(&bd->nodes[j], &bd->lb[j]);
        bd->nodes[j].child[0] = bd->nodes[j].child[1] = FR_NONE;
        return j;
    }
    lbound all = empty_bound, cen = empty_bound;
    for (uint32_t i = begin; i < end; i++) {
        const lbound *b = &bd->lb[bd->idx[i]];
        all = bound_union(all, b);
        vec3 c = centre(b);
        cen.lo = v3_vmin(cen.lo, c);
        cen.hi = v3_vmax(cen.hi, c);
    }
    vec3 ext = v3_sub(all.hi, all.lo), cext = v3_sub(cen.hi, cen.lo);
    float max_ext = v3_max(ext);
    uint32_t mid = begin;
    if (depth < SAH_DEPTH) {
        double best = INFINITY;
        int best_axis = -1, best_k = 0;
        for (int a = 0; a < 3; a++) {
            float lo = v3_get(cen.lo, a), w = v3_get(cext, a);
            if (!(w > 0.0f))
                continue;
            lbound bk[BUCKETS];
            for (int k = 0; k < BUCKETS; k++)
                bk[k] = empty_bound;
            for (uint32_t i = begin; i < end; i++) {
                const lbound *b = &bd->lb[bd->idx[i]];
                int k = (int)((v3_get(centre(b), a) - lo) / w * BUCKETS);
                k = k < 0 ? 0 : k >= BUCKETS ? BUCKETS - 1 : k;
                bk[k] = bound_union(bk[k], b);
            }
            lbound right[BUCKETS];
            right[BUCKETS - 1] = bk[BUCKETS - 1];
            for (int k = BUCKETS - 2; k >= 0; k--)
                right[k] = bound_union(right[k + 1], &bk[k]);
            lbound left = empty_bound;
            for (int k = 0; k < BUCKETS - 1; k++) {
                left = bound_union(left, &bk[k]);
                if (left.empty || right[k + 1].empty)
                    continue;
                double c = side_cost(&left, v3_get(ext, a), max_ext) + side_cost(&right[k + 1], v3_get(ext, a), max_ext);
                if (c < best) {
                    best = c;
                    best_axis = a;
                    best_k = k;
                }
            }
        }
        if (best_axis >= 0 && best > 0.0f) {
            float lo = v3_get(cen.lo, best_axis), w = v3_get(cext, best_axis);
            uint32_t i = begin, j = end;
            while (i < j) {
                int k = (int)((v3_get(centre(&bd->lb[bd->idx[i]]), best_axis) - lo) / w * BUCKETS);
                if (k <= best_k) {
                    i++;
                } else {
                    uint32_t t = bd->idx[i];
                    bd->idx[i] = bd->idx[--j];
                    bd->idx[j] = t;
                }
            }
            mid = i;
        }
    }
    if (mid == begin || mid == end) {
        /* The median along the widest spread of centres (of boxes when the
         * centres coincide); ties by index, so every host builds one tree. */
        int a = 0;
        vec3 e = v3_max(cext) > 0.0f ? cext : ext;
        if (e.y > v3_get(e, a))
            a = 1;
        if (e.z > v3_get(e, a))
            a = 2;
        bd->axis = a;
        sort_ctx = bd;
        qsort(bd->idx + begin, end - begin, sizeof *bd->idx, by_centre);
        mid = begin + (end - begin) / 2;
    }
    uint32_t c0 = build_range(bd, begin, mid, depth + 1), c1 = build_range(bd, mid, end, depth + 1);
    uint32_t me = bd->next++;
    fr_light_node *n = &bd->nodes[me];
    store(n, &all);
    n->child[0] = c0;
    n->child[1] = c1;
    bd->nodes[c0].parent = bd->nodes[c1].parent = me;
    return me;
}

/* Bounds of local light l (power p). */
static lbound light_bound(const fr_builder *b, const fr_light *l, double p)
{
    lbound r = empty_bound;
    r.empty = 0;
    r.power = p;
    r.cos_o = -1.0f;
    r.cos_e = 0.0f;
    if (l->kind == FR_LIGHT_POINT || l->kind == FR_LIGHT_SPOT) {
        r.lo = r.hi = r.at = l->position;
        if (l->kind == FR_LIGHT_SPOT) {
            /* Full intensity inside the inner cone, none beyond the outer one:
             * cos_e = cos(outer - inner). */
            float ci = l->cone_aux, co = l->cone_cos;
            float si = sqrtf(fmaxf(0.0f, 1.0f - ci * ci)), so = sqrtf(fmaxf(0.0f, 1.0f - co * co));
            r.axis = l->axis;
            r.cos_o = ci;
            /* Its intensity as a point light's power, as pbrt-v4 does: the
             * cone bounds where it shines, and inside the cone it is as
             * bright as a point light of that intensity. */
            r.power = 4.0 * FM_PI * v3_luma(l->intensity);
            r.cos_e = fmaxf(-1.0f, fminf(1.0f, co * ci + so * si));
        }
        return r;
    }
    const fr_prim *pr = (const fr_prim *)b->prims.data + l->prim;
    const fr_material *m = (const fr_material *)b->materials.data + pr->material;
    vec3 nrm = v3s(0.0f);
    if (pr->kind == FR_PRIM_SPHERE) {
        const fr_sphere *s = (const fr_sphere *)b->spheres.data + pr->index;
        r.at = s->center;
        r.lo = v3_sub(s->center, v3s(s->radius));
        r.hi = v3_add(s->center, v3s(s->radius));
    } else if (pr->kind == FR_PRIM_RECT) {
        const fr_rect *q = (const fr_rect *)b->rects.data + pr->index;
        vec3 c[4] = {q->origin, v3_add(q->origin, q->edge_u), v3_add(q->origin, q->edge_v),
                     v3_add(v3_add(q->origin, q->edge_u), q->edge_v)};
        r.lo = r.hi = r.at = c[0];
        for (int k = 1; k < 4; k++) {
            r.lo = v3_vmin(r.lo, c[k]);
            r.hi = v3_vmax(r.hi, c[k]);
        }
        nrm = v3_cross(q->edge_u, q->edge_v);
    } else {
        const fr_triangle *t = (const fr_triangle *)b->triangles.data + pr->index;
        const vec3 *pos = b->positions.data;
        vec3 p0 = pos[t->v[0]], p1 = pos[t->v[1]], p2 = pos[t->v[2]];
        r.at = p0;
        r.lo = v3_vmin(p0, v3_vmin(p1, p2));
        r.hi = v3_vmax(p0, v3_vmax(p1, p2));
        nrm = v3_cross(v3_sub(p1, p0), v3_sub(p2, p0));
    }
    /* A flat emitter's normals: one direction, both with two sides.  In
     * double: the cross product of large edges overflows a float. */
    double nx = nrm.x, ny = nrm.y, nz = nrm.z, len = sqrt(nx * nx + ny * ny + nz * nz);
    if (len > 0.0 && isfinite(len)) {
        r.axis = v3((float)(nx / len), (float)(ny / len), (float)(nz / len));
        r.cos_o = 1.0f;
        r.two_sided = m->two_sided != 0;
    }
    return r;
}

/* Do bounds lb[0..n) make one flat lamp: at most FLAT_LAMP_MAX rectangles
 * or triangles (one quad lamp split into two, say) in one plane, facing
 * one way with the same sides?  From any point such lights subtend nearly
 * the same solid angle in proportion to their power, so the tree could
 * pick among them only as the power table does, at two importance
 * evaluations a light sample (on the Cornell box 9 % of its instructions,
 * for an RMSE equal to four digits; tests/bench/README.md, "A flat
 * lamp"). */
#define FLAT_LAMP_MAX 4
static int flat_lamp(const lbound *lb, uint32_t n)
{
    if (n < 2 || n > FLAT_LAMP_MAX)
        return 0;
    vec3 a = lb[0].axis;
    for (uint32_t j = 0; j < n; j++) {
        if (lb[j].cos_o < 1.0f || lb[j].two_sided != lb[0].two_sided || v3_dot(lb[j].axis, a) < 0.99999f)
            return 0;
        /* In the first light's plane, within a millionth of the distance. */
        vec3 d = v3_sub(lb[j].at, lb[0].at);
        if (fabsf(v3_dot(d, a)) > 1e-6f * v3_len(d))
            return 0;
    }
    return 1;
}

int frz_light_tree(fr_builder *b, const double *power, fr_error *err)
{
    const fr_light *lights = b->lights.data;
    uint32_t nd = 0;
    while (nd < b->lights.count && (lights[nd].kind == FR_LIGHT_SUN || lights[nd].kind == FR_LIGHT_ENV))
        nd++;
    uint32_t nl = b->lights.count - nd;
    b->light_nodes.count = 0;
    if (nl == 0)
        return 0;
    if (nl > 0x7fffffffu || bld_pad(&b->light_nodes, 2 * nl - 1) < 0)
        return fr_fail(err, "out of memory for the light tree (%u lights)", nl);
    build bd = {0};
    lbound *lb = malloc((size_t)nl * sizeof *lb);
    bd.idx = malloc((size_t)nl * sizeof *bd.idx);
    if (!lb || !bd.idx) {
        free(lb);
        free(bd.idx);
        return fr_fail(err, "out of memory for the light tree (%u lights)", nl);
    }
    for (uint32_t j = 0; j < nl; j++) {
        lb[j] = light_bound(b, &lights[nd + j], power[nd + j]);
        bd.idx[j] = j;
    }
    if (flat_lamp(lb, nl)) {
        b->light_nodes.count = 0;
        free(lb);
        free(bd.idx);
        return 0;
    }
    bd.lb = lb;
    bd.nodes = b->light_nodes.data;
    bd.nl = nl;
    bd.next = nl;
    uint32_t root = build_range(&bd, 0, nl, 1);
    bd.nodes[root].parent = FR_NONE;
    free(lb);
    free(bd.idx);
    return 0;
}
