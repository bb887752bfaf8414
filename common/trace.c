#include "trace.h"

#include <string.h>

#include "fmath.h"
#include "simd4.h"

/* Traversal's stack: at most FR_BVH_WIDTH - 1 entries wait per level of a
 * tree no deeper than FR_BVH_MAX_DEPTH (the loader refuses deeper ones). */
#define BVH_STACK ((FR_BVH_WIDTH - 1) * FR_BVH_MAX_DEPTH + 1)

float trace_prim(const fr_scene *s, uint32_t i, const fr_ray *r, float tmax, float *a, float *b)
{
    const fr_prim *p = &s->prims[i];
    if (p->kind == FR_PRIM_TRIANGLE) {
        const fr_triangle *t = &s->triangles[p->index];
        return geo_triangle(s->positions[t->v[0]], s->positions[t->v[1]], s->positions[t->v[2]], r, tmax, a, b);
    }
    if (p->kind == FR_PRIM_SPHERE) {
        *a = *b = 0.0f;
        return geo_sphere(&s->spheres[p->index], r, tmax);
    }
    return geo_rect(&s->rects[p->index], r, tmax, a, b);
}

/* ---- BVH traversal ----
 *
 * Hits are decided exactly as the per-primitive tests decide them (the
 * triangle lanes below repeat geo_triangle's operations in the same order,
 * four at a time), and among hits at the same t the lowest primitive index
 * wins (planes, tested first, win over primitives).  So the result does not
 * depend on the order nodes are visited in: it is the brute-force nearest
 * hit, on every machine. */

/* Box tests widen the far distance (and the best hit so far) by 2^-16.
 * 2*gamma(3) would cover the box test's own rounding (Ize 2013, "Robust
 * BVH ray traversal"); the rest covers the triangle test's rounded t, which
 * for a triangle lying in a face of its box can come out a few ulps before
 * the box's rounded entry distance.  Without it, of two coplanar triangles
 * the one in a box entered "after" the best hit would be skipped and the
 * result would depend on the visiting order. */
#define FAR_SCALE 1.0000153f

typedef struct {
    f4 ox, oy, oz, ix, iy, iz;   /* origin and 1/direction, in every lane */
    size_t near[3], far[3];      /* per axis, where the entry / exit plane's row starts in box[][] */
    /* the watertight triangle test's ray frame (see geo_triangle) */
    size_t kx, ky, kz;           /* where vertex 0's coordinate rows of the sheared axes start in a leaf's v[][] */
    f4 okx, oky, okz, sx, sy, sz;
} ray4;

/* Where the best hit so far is; `key` is the primitive that wins a tie at
 * t == best (lower indices win; 0 while nothing or only a plane was hit,
 * so nothing wins a tie with the ray's own tmax). */
typedef struct {
    float best;
    uint32_t key;
    fr_hit *hit;
    int found;
} hit_state;

/* The axes of the watertight triangle test's frame for a ray direction:
 * kz is the axis of the largest |d| (the first of x, y, z on ties), kx
 * and ky follow it cyclically, swapped when d along kz is negative to keep
 * the winding.  Indexed by kz and that sign. */
static const uint8_t frame_axes[3][2][2] = {{{1, 2}, {2, 1}}, {{2, 0}, {0, 2}}, {{0, 1}, {1, 0}}};

/* Written without branches on the direction (selects, a table): a ray's
 * direction is random, so a branch on it is mispredicted half the time. */
static void ray_setup(ray4 *R, const fr_ray *r)
{
    const float d[3] = {r->d.x, r->d.y, r->d.z}, o[3] = {r->o.x, r->o.y, r->o.z};
    const float inv[3] = {1.0f / d[0], 1.0f / d[1], 1.0f / d[2]};
    R->ox = f4_set1(o[0]); R->oy = f4_set1(o[1]); R->oz = f4_set1(o[2]);
    R->ix = f4_set1(inv[0]); R->iy = f4_set1(inv[1]); R->iz = f4_set1(inv[2]);
    /* 1/-0 is -inf: the sign bit picks the planes, as it must. */
    for (int a = 0; a < 3; a++) {
        size_t neg = signbit(d[a]) != 0;
        R->near[a] = ((size_t)a + 3 * neg) * FR_BVH_WIDTH;
        R->far[a] = ((size_t)a + 3 * (1 - neg)) * FR_BVH_WIDTH;
    }
    float x = fabsf(d[0]), y = fabsf(d[1]), z = fabsf(d[2]);
    int xy = x > y, gt = (xy ? x : y) > z;
    int kz = 2 - gt - (gt & xy);   /* x > y ? (x > z ? 0 : 2) : (y > z ? 1 : 2) */
    float dz = d[kz];
    const uint8_t *k = frame_axes[kz][dz < 0.0f];
    int kx = k[0], ky = k[1];
    R->kx = (size_t)kx * 4; R->ky = (size_t)ky * 4; R->kz = (size_t)kz * 4;
    R->okx = f4_set1(o[kx]); R->oky = f4_set1(o[ky]); R->okz = f4_set1(o[kz]);
    R->sx = f4_set1(d[kx] / dz);
    R->sy = f4_set1(d[ky] / dz);
    R->sz = f4_set1(inv[kz]);   /* 1 / dz, the very division above */
}

/* Entry distances tn[] of the ray into the boxes of node n, and which of
 * them it enters before tmax (bit mask), four lanes at a time. */
static inline unsigned node_hits(const fr_bvh_node *n, const ray4 *R, float tmax, float *tn)
{
    unsigned m = 0;
    for (int h = 0; h < FR_BVH_WIDTH; h += 4) {
        const float *b = n->box[0] + h;
        f4 nx = (f4_load(b + R->near[0]) - R->ox) * R->ix;
        f4 ny = (f4_load(b + R->near[1]) - R->oy) * R->iy;
        f4 nz = (f4_load(b + R->near[2]) - R->oz) * R->iz;
        f4 fx = (f4_load(b + R->far[0]) - R->ox) * R->ix;
        f4 fy = (f4_load(b + R->far[1]) - R->oy) * R->iy;
        f4 fz = (f4_load(b + R->far[2]) - R->oz) * R->iz;
        f4 t0 = f4_max_num(nx, f4_max_num(ny, f4_max_num(nz, f4_set1(0.0f))));
        f4 t1 = f4_min_num(fx, f4_min_num(fy, f4_min_num(fz, f4_set1(tmax))));
        f4_store(tn + h, t0);
        m |= i4_bits(t0 <= t1 * f4_set1(FAR_SCALE)) << h;
    }
    return m;
}

/* The smallest float above x (x >= 0; infinity stays). */
static float next_up(float x)
{
    if (x == INFINITY)
        return x;
    uint32_t u;
    memcpy(&u, &x, 4);
    u++;
    memcpy(&x, &u, 4);
    return x;
}

static int better(const hit_state *H, float t, uint32_t prim)
{
    return t < H->best || (t == H->best && prim < H->key);
}

static void record(hit_state *H, float t, uint32_t prim, float a, float b)
{
    H->best = t;
    H->key = prim;
    H->found = 1;
    H->hit->t = t; H->hit->prim = prim; H->hit->plane = FR_NONE; H->hit->a = a; H->hit->b = b;
}

/* Test the lanes of one leaf block.  `lanes` says which lanes hold
 * triangles to test.  With `any`, return 1 at the first hit. */
static inline __attribute__((always_inline)) int block_test(const fr_bvh_leaf *L, const ray4 *R, unsigned lanes,
                                                            hit_state *H, int any)
{
    const float *p = L->v[0];   /* vertex k's rows start at p + 12 k */
    f4 az = f4_load(p + R->kz) - R->okz;
    f4 bz = f4_load(p + 12 + R->kz) - R->okz;
    f4 cz = f4_load(p + 24 + R->kz) - R->okz;
    f4 ax = (f4_load(p + R->kx) - R->okx) - R->sx * az;
    f4 ay = (f4_load(p + R->ky) - R->oky) - R->sy * az;
    f4 bx = (f4_load(p + 12 + R->kx) - R->okx) - R->sx * bz;
    f4 by = (f4_load(p + 12 + R->ky) - R->oky) - R->sy * bz;
    f4 cx = (f4_load(p + 24 + R->kx) - R->okx) - R->sx * cz;
    f4 cy = (f4_load(p + 24 + R->ky) - R->oky) - R->sy * cz;
    f4 u = cx * by - cy * bx, v = ax * cy - ay * cx, w = bx * ay - by * ax;
    f4 zero = f4_set1(0.0f);
    /* Inside or on the boundary when u, v and w share a sign: their min is
     * >= 0 or their max <= 0.  (A NaN lane may pass; its t is NaN and fails
     * the distance test below, as in geo_triangle.) */
    unsigned m = i4_bits((f4_min_num(u, f4_min_num(v, w)) >= zero) | (f4_max_num(u, f4_max_num(v, w)) <= zero)) & lanes;
    if (!m)
        return 0;
    unsigned edge = i4_bits((u == zero) | (v == zero) | (w == zero)) & m;
    if (edge) {
        for (int i = 0; edge; i++, edge >>= 1) {
            if (!(edge & 1))
                continue;
            /* On an edge in single precision: decide in double, as geo_triangle. */
            u[i] = (float)((double)cx[i] * by[i] - (double)cy[i] * bx[i]);
            v[i] = (float)((double)ax[i] * cy[i] - (double)ay[i] * cx[i]);
            w[i] = (float)((double)bx[i] * ay[i] - (double)by[i] * ax[i]);
        }
        i4 outside = ((u < zero) | (v < zero) | (w < zero)) & ((u > zero) | (v > zero) | (w > zero));
        m &= i4_bits(~outside);
    }
    f4 det = u + v + w;
    m &= i4_bits(det != zero);
    if (!m)
        return 0;
    f4 t = R->sz * (u * az + v * bz + w * cz) / det;
    m &= i4_bits((t > zero) & (t <= f4_set1(H->best)));
    if (!m)
        return 0;
    /* As geo_triangle: not a hit unless t exceeds its rounding error
     * (which is >= 0, so the test above only saves work). */
    f4 err = GEO_TRI_ERROR(f4, f4_abs, f4_max_num, ax, bx, cx, ay, by, cy, az, bz, cz, u, v, w, R->sz, det);
    m &= i4_bits(t > err);
    for (int i = 0; m; i++, m >>= 1) {
        if (!(m & 1) || !better(H, t[i], L->prim[i]))
            continue;
        if (any)
            return 1;
        record(H, t[i], L->prim[i], v[i] / det[i], w[i] / det[i]);
    }
    return 0;
}

/* Intersect a leaf of `meta` (count | flags) blocks starting at `first`. */
static inline __attribute__((always_inline)) int leaf_test(const fr_scene *s, const fr_ray *r, const ray4 *R,
                                                           uint32_t first, uint32_t meta, hit_state *H, int any,
                                                           uint32_t skip)
{
    uint32_t end = first + (meta & FR_BVH_LEAF_MAX);
    for (uint32_t j = first; j < end; j++) {
        const fr_bvh_leaf *L = &s->leaves[j];
        i4 prim;
        memcpy(&prim, L->prim, sizeof prim);
        unsigned lanes = i4_bits((prim != i4_set1((int32_t)FR_NONE)) & (prim != i4_set1((int32_t)skip)));
        if (meta & FR_BVH_MIXED) {
            for (int i = 0; i < 4; i++) {
                if (!(lanes & (1u << i)) || s->prims[L->prim[i]].kind == FR_PRIM_TRIANGLE)
                    continue;
                lanes &= ~(1u << i);
                float a, b, t = trace_prim(s, L->prim[i], r, next_up(H->best), &a, &b);
                if (t > 0.0f && better(H, t, L->prim[i])) {
                    if (any)
                        return 1;
                    record(H, t, L->prim[i], a, b);
                }
            }
        }
        if (block_test(L, R, lanes, H, any))
            return 1;
    }
    return 0;
}

typedef struct { uint32_t child, leaf; float t; } stack_entry;

/* Walk the BVH; with `any` set, return at the first hit.  Prim `skip` is
 * ignored (FR_NONE: none).  Inlined into its two callers so each gets a
 * loop without the other's tests. */
static inline __attribute__((always_inline)) int walk(const fr_scene *s, const fr_ray *r, float tmax, fr_hit *hit,
                                                      int any, uint32_t skip)
{
    hit_state H = {tmax, 0, hit, 0};
    for (uint32_t i = 0; i < s->n_planes; i++) {
        float t = geo_plane(&s->planes[i], r, H.best);
        if (t > 0.0f) {
            if (any)
                return 1;
            H.best = t;
            H.found = 1;
            hit->t = t; hit->prim = FR_NONE; hit->plane = i; hit->a = hit->b = 0.0f;
        }
    }
    /* A ray with an infinite or NaN coordinate (from a degenerate surface)
     * would make every box test true, empty slots included: it hits
     * nothing in the BVH.  x * 0 is 0 for finite x, NaN otherwise. */
    float nonfinite = r->o.x * 0.0f + r->o.y * 0.0f + r->o.z * 0.0f + r->d.x * 0.0f + r->d.y * 0.0f + r->d.z * 0.0f;
    if (s->n_nodes == 0 || nonfinite != 0.0f)
        return H.found;
    ray4 R;
    ray_setup(&R, r);
    stack_entry stack[BVH_STACK];
    int sp = 0;
    uint32_t child = 0, leaf = 0;   /* what is visited now: the root node */
    for (;;) {
        if (!leaf) {
            const fr_bvh_node *n = &s->nodes[child];
            float tn[FR_BVH_WIDTH];
            unsigned m = node_hits(n, &R, H.best, tn);
            if (m) {
                /* Visit the nearest child entered next and stack the others,
                 * farthest first (ties by slot; any-hit skips the order). */
                unsigned a = (unsigned)__builtin_ctz(m);
                m &= m - 1;
                if (!m) {
                    child = n->child[a];
                    leaf = n->leaf[a];
                    continue;
                }
                unsigned b = (unsigned)__builtin_ctz(m);
                m &= m - 1;
                if (!any && tn[b] < tn[a]) {
                    unsigned t = a; a = b; b = t;
                }
                if (!m) {
                    stack[sp++] = (stack_entry){n->child[b], n->leaf[b], tn[b]};
                    child = n->child[a];
                    leaf = n->leaf[a];
                    continue;
                }
                unsigned e[FR_BVH_WIDTH] = {a, b};
                int k = 2;
                for (; m; m &= m - 1) {
                    unsigned c = (unsigned)__builtin_ctz(m);
                    int j = k++;
                    if (!any)
                        for (; j > 0 && tn[e[j - 1]] > tn[c]; j--)
                            e[j] = e[j - 1];
                    e[j] = c;
                }
                while (k > 1) {
                    unsigned c = e[--k];
                    stack[sp++] = (stack_entry){n->child[c], n->leaf[c], tn[c]};
                }
                child = n->child[e[0]];
                leaf = n->leaf[e[0]];
                continue;
            }
        } else if (leaf_test(s, r, &R, child, leaf, &H, any, skip)) {
            return 1;
        }
        /* Pop the next subtree the ray can still reach before the best hit. */
        for (;;) {
            if (sp == 0)
                return H.found;
            stack_entry x = stack[--sp];
            if (!any && !(x.t <= H.best * FAR_SCALE))
                continue;
            child = x.child;
            leaf = x.leaf;
            break;
        }
    }
}

int trace_closest(const fr_scene *s, const fr_ray *r, float tmax, fr_hit *hit)
{
    return walk(s, r, tmax, hit, 0, FR_NONE);
}

int trace_occluded(const fr_scene *s, const fr_ray *r, float tmax, uint32_t skip)
{
    fr_hit h = {0};
    return walk(s, r, tmax, &h, 1, skip);
}

void trace_surface(const fr_scene *s, const fr_ray *r, const fr_hit *hit, fr_surface *out)
{
    if (hit->prim == FR_NONE) {
        const fr_plane *pl = &s->planes[hit->plane];
        out->p = geo_plane_point(pl, r, hit->t, &out->perr);
        out->ng = out->ns = pl->normal;
        vec3 t, b;
        v3_basis(pl->normal, &t, &b);
        vec3 rel = v3_sub(out->p, pl->point);
        out->uv = (vec2){v3_dot(rel, t), v3_dot(rel, b)};
        out->dpdu = t;
        out->dpdv = b;
        out->material = pl->material;
        out->light = FR_NONE;
        return;
    }
    const fr_prim *p = &s->prims[hit->prim];
    out->material = p->material;
    out->light = p->light;
    if (p->kind == FR_PRIM_SPHERE) {
        const fr_sphere *sp = &s->spheres[p->index];
        vec3 n = v3_scale(v3_sub(v3_madd(r->o, r->d, hit->t), sp->center), 1.0f / sp->radius);
        out->ng = out->ns = v3_norm(n);
        /* Re-project onto the surface: removes most of the hit point's error. */
        out->p = geo_sphere_point(sp, out->ng, &out->perr);
        /* Longitude and latitude, seen from outside as an image is seen:
         * u grows eastward (+x toward -z), v from 0 at the -y pole to 1 at
         * +y, so cross(dpdu, dpdv) faces out and an image is not mirrored. */
        float phi = fm_atan2f(-out->ng.z, out->ng.x);
        out->uv = (vec2){(phi + FM_PI) * FM_INV_2PI, 1.0f - fm_acosf(out->ng.y) * FM_INV_PI};
        vec3 rel = v3_sub(out->p, sp->center);
        float rxz = sqrtf(rel.x * rel.x + rel.z * rel.z);
        out->dpdu = v3(2.0f * FM_PI * rel.z, 0.0f, -2.0f * FM_PI * rel.x);
        out->dpdv = rxz > 0.0f ? v3_scale(v3(rel.x * rel.y / rxz, -rxz, rel.z * rel.y / rxz), -FM_PI)
                               : v3(0.0f, 0.0f, 0.0f);
    } else if (p->kind == FR_PRIM_RECT) {
        const fr_rect *q = &s->rects[p->index];
        out->ng = out->ns = v3_norm(v3_cross(q->edge_u, q->edge_v));
        out->p = geo_rect_point(q, hit->a, hit->b, &out->perr);
        out->uv = (vec2){hit->a, hit->b};
        out->dpdu = q->edge_u;
        out->dpdv = q->edge_v;
    } else {
        const fr_triangle *t = &s->triangles[p->index];
        vec3 p0 = s->positions[t->v[0]], p1 = s->positions[t->v[1]], p2 = s->positions[t->v[2]];
        float b0 = 1.0f - hit->a - hit->b;
        out->p = geo_triangle_point(p0, p1, p2, hit->a, hit->b, &out->perr);
        out->ng = v3_norm(v3_cross(v3_sub(p1, p0), v3_sub(p2, p0)));
        out->ns = out->ng;
        if (t->flags & FR_TRI_NORMALS) {
            vec3 n = v3_add(v3_add(v3_scale(s->normals[t->v[0]], b0), v3_scale(s->normals[t->v[1]], hit->a)),
                            v3_scale(s->normals[t->v[2]], hit->b));
            if (v3_len2(n) > 0.0f) {
                n = v3_norm(n);
                out->ns = v3_dot(n, out->ng) < 0.0f ? v3_neg(n) : n;
            }
        }
        if (t->flags & FR_TRI_UVS) {
            vec2 u0 = s->uvs[t->v[0]], u1 = s->uvs[t->v[1]], u2 = s->uvs[t->v[2]];
            out->uv = (vec2){b0 * u0.u + hit->a * u1.u + hit->b * u2.u, b0 * u0.v + hit->a * u1.v + hit->b * u2.v};
            /* Solve [dp1 dp2] = [dpdu dpdv] [duv1 duv2] for the tangents. */
            float du1 = u1.u - u0.u, dv1 = u1.v - u0.v, du2 = u2.u - u0.u, dv2 = u2.v - u0.v;
            float det = du1 * dv2 - dv1 * du2;
            vec3 e1 = v3_sub(p1, p0), e2 = v3_sub(p2, p0);
            if (fabsf(det) > 1e-20f) {
                float inv = 1.0f / det;
                out->dpdu = v3_scale(v3_sub(v3_scale(e1, dv2), v3_scale(e2, dv1)), inv);
                out->dpdv = v3_scale(v3_sub(v3_scale(e2, du1), v3_scale(e1, du2)), inv);
            } else {
                v3_basis(out->ng, &out->dpdu, &out->dpdv);
            }
        } else {
            out->uv = (vec2){hit->a, hit->b};
            out->dpdu = v3_sub(p1, p0);
            out->dpdv = v3_sub(p2, p0);
        }
    }
}
