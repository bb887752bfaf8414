/* trace.c -- the closest hit and shadow-ray queries over the BVH and the
 * planes (see trace.h). */

#include "trace.h"

#include <string.h>

#include "fmath.h"
#include "lanes.h"
#include "motion.h"
#include "simd4.h"

/* x86-64 with GCC: copies of the traversal for AVX2 and AVX-512 processors. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define TRACE_WIDE 1
#include <cpuid.h>
#include <immintrin.h>
#else
#define TRACE_WIDE 0
#endif

/* Traversal's stack: at most FR_BVH_WIDTH - 1 entries wait per level of a
 * tree no deeper than FR_BVH_MAX_DEPTH (the loader refuses deeper ones). */
#define BVH_STACK ((FR_BVH_WIDTH - 1) * FR_BVH_MAX_DEPTH + 1)

static float instance_prim(const fr_scene *s, uint32_t i, const fr_ray *r, float tmax, float *a, float *b);

/* trace_prim of primitive p when it is not an instance: inlined in the
 * walk's leaves (which test instances on their own), without a call per
 * sphere or rectangle. */
static inline __attribute__((always_inline)) float shape_prim(const fr_scene *s, const fr_prim *p, const fr_ray *r,
                                                              float tmax, float *a, float *b)
{
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

float trace_prim(const fr_scene *s, uint32_t i, const fr_ray *r, float tmax, float *a, float *b)
{
    const fr_prim *p = &s->prims[i];
    if (p->kind == FR_PRIM_INSTANCE)
        return instance_prim(s, i, r, tmax, a, b);
    return shape_prim(s, p, r, tmax, a, b);
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
 * result would depend on the visiting order.  The walk multiplies 1/direction
 * by it once per ray for the exit planes, instead of each exit distance:
 * that moves them by a few ulps, far inside the margin. */
#define FAR_SCALE 1.0000153f

/* Bytes of nodes and leaf blocks above which traversal prefetches the
 * children it enters (a smaller tree stays in the first-level cache). */
#define WALK_PREFETCH_MIN 16384

/* The axes of the watertight triangle test's frame for a ray direction:
 * kz is the axis of the largest |d| (the first of x, y, z on ties), kx
 * and ky follow it cyclically, swapped when d along kz is negative to keep
 * the winding.  Indexed by kz and that sign. */
static const uint8_t frame_axes[3][2][2] = {{{1, 2}, {2, 1}}, {{2, 0}, {0, 2}}, {{0, 1}, {1, 0}}};

/* The byte offsets in a node's box[][] of the rows a ray enters and
 * leaves a child's box by, along x, y and z, indexed by the signs of its
 * direction (bit a set where axis a is negative): entry rows first (the
 * lower bound where the direction is positive), then exit rows. */
#define ROW(a) ((size_t)(a) * sizeof(float[FR_BVH_WIDTH]))
#define ROWS(nx, ny, nz) \
    {ROW(0 + 3 * nx), ROW(1 + 3 * ny), ROW(2 + 3 * nz), ROW(3 - 3 * nx), ROW(4 - 3 * ny), ROW(5 - 3 * nz)}
static const size_t box_rows[8][6] = {ROWS(0, 0, 0), ROWS(1, 0, 0), ROWS(0, 1, 0), ROWS(1, 1, 0),
                                      ROWS(0, 0, 1), ROWS(1, 0, 1), ROWS(0, 1, 1), ROWS(1, 1, 1)};
#undef ROWS
#undef ROW

/* Where the best hit so far is; `key` is the primitive that wins a tie at
 * t == best (lower indices win; 0 while nothing or only a plane was hit,
 * so nothing wins a tie with the ray's own tmax). */
typedef struct {
    float best;
    float far;                 /* best * FAR_SCALE, for the box tests */
    uint32_t key;
    fr_hit *hit;
    int found;
} hit_state;

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

static inline int better(const hit_state *H, float t, uint32_t prim)
{
    return t < H->best || (t == H->best && prim < H->key);
}

static inline void record(hit_state *H, float t, uint32_t prim, float a, float b)
{
    H->best = t;
    H->far = t * FAR_SCALE;
    H->key = prim;
    H->found = 1;
    H->hit->t = t; H->hit->prim = prim; H->hit->plane = FR_NONE; H->hit->a = a; H->hit->b = b; H->hit->inst = 0;
}

/* A world-space ray in an instance's object space: origin and direction by
 * the inverse transform m, the direction not renormalised, so a point at t
 * along one is the point at t along the other. */
static inline void instance_ray(const float (*m)[4], const fr_ray *r, fr_ray *o)
{
    vec3 p = r->o, d = r->d;
    o->o = v3(m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
              m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
              m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]);
    o->d = v3(m[0][0] * d.x + m[0][1] * d.y + m[0][2] * d.z, m[1][0] * d.x + m[1][1] * d.y + m[1][2] * d.z,
              m[2][0] * d.x + m[2][1] * d.y + m[2][2] * d.z);
    o->time = r->time;
}

/* instance_ray for a moving instance: by the inverse of its transform at
 * the ray's time (motion.h).  Only moving instances come here, so still
 * ones pay nothing for motion. */
static __attribute__((noinline)) void instance_ray_moving(const fr_scene *s, const fr_instance *in, const fr_ray *r,
                                                          fr_ray *o)
{
    instance_ray(motion_at_cached(&s->inst_motions[in->motion - 1], in->motion - 1, r->time)->inv, r, o);
}

typedef struct { uint32_t child, leaf; float t; } stack_entry;

/* The portable traversal: SSE2, NEON or plain C. */
#define W(name) name##_base
#define WALK_WIDE 0
#include "trace_walk.inc"
#undef W
#undef WALK_WIDE

/* Each walk is a function of its own, so that trace_closest and
 * trace_occluded stay a test and a jump: with a walk inlined into them,
 * every call paid that walk's entry and exit (its saved registers, its
 * aligned frame) before reaching the other copy. */
static __attribute__((noinline)) int closest_base(const fr_scene *s, const fr_ray *r, float tmax, fr_hit *hit)
{
    return walk_base(s, NULL, r, tmax, hit, 0, FR_NONE);
}

static __attribute__((noinline)) int occluded_base(const fr_scene *s, const fr_ray *r, float tmax, uint32_t skip)
{
    return walk_base(s, NULL, r, tmax, NULL, 1, skip);
}

#if TRACE_WIDE
/* The same traversal with eight-lane box tests, for x86-64 processors with
 * AVX2, chosen at run time. */
#pragma GCC push_options
#pragma GCC target("avx2")
#define W(name) name##_wide
#define WALK_WIDE 1
#include "trace_walk.inc"
#undef W
#undef WALK_WIDE

static __attribute__((noinline)) int closest_wide(const fr_scene *s, const fr_ray *r, float tmax, fr_hit *hit)
{
    return walk_wide(s, NULL, r, tmax, hit, 0, FR_NONE);
}

static __attribute__((noinline)) int occluded_wide(const fr_scene *s, const fr_ray *r, float tmax, uint32_t skip)
{
    return walk_wide(s, NULL, r, tmax, NULL, 1, skip);
}
#pragma GCC pop_options

/* And once more for AVX-512 (x86-64-v4: F, VL, BW and DQ): the same
 * eight-lane tests with comparisons into mask registers, 32 vector
 * registers, and a node's children ordered by a sorting network and
 * stacked by vector stores. */
#pragma GCC push_options
#pragma GCC target("avx512f,avx512vl,avx512bw,avx512dq")
#define W(name) name##_v4
#define WALK_WIDE 2
#include "trace_walk.inc"
#undef W
#undef WALK_WIDE

static __attribute__((noinline)) int closest_v4(const fr_scene *s, const fr_ray *r, float tmax, fr_hit *hit)
{
    return walk_v4(s, NULL, r, tmax, hit, 0, FR_NONE);
}

static __attribute__((noinline)) int occluded_v4(const fr_scene *s, const fr_ray *r, float tmax, uint32_t skip)
{
    return walk_v4(s, NULL, r, tmax, NULL, 1, skip);
}
#pragma GCC pop_options

/* What the processor has and its OS saves on a context switch: CPUID for
 * the instructions, XGETBV for the registers' state (SSE and AVX: XCR0
 * bits 1-2; AVX-512's mask registers and upper halves of zmm0-31: bits
 * 5-7).  An OS that does not save a state makes its instructions fault. */
static unsigned cpu_walks(void)
{
    unsigned a, b, c, d, walks = 1u << TRACE_WALK_PORTABLE;
    if (!__get_cpuid(1, &a, &b, &c, &d) || !(c & bit_OSXSAVE) || !(c & bit_AVX))
        return walks;
    unsigned lo, hi;
    __asm__("xgetbv" : "=a"(lo), "=d"(hi) : "c"(0));
    if ((lo & 0x6) != 0x6 || !__get_cpuid_count(7, 0, &a, &b, &c, &d))
        return walks;
    if (b & bit_AVX2)
        walks |= 1u << TRACE_WALK_AVX2;
    unsigned v4 = bit_AVX512F | bit_AVX512VL | bit_AVX512BW | bit_AVX512DQ;
    if ((b & bit_AVX2) && (b & v4) == v4 && (lo & 0xe6) == 0xe6)
        walks |= 1u << TRACE_WALK_AVX512;
    return walks;
}

static unsigned walks_ok;
static int walk_on;

__attribute__((constructor)) static void trace_init(void)
{
    walks_ok = cpu_walks();
    walk_on = walks_ok >> TRACE_WALK_AVX512 & 1 ? TRACE_WALK_AVX512
              : walks_ok >> TRACE_WALK_AVX2 & 1 ? TRACE_WALK_AVX2
                                                : TRACE_WALK_PORTABLE;
}
#else
static const unsigned walks_ok = 1u << TRACE_WALK_PORTABLE;
static const int walk_on = TRACE_WALK_PORTABLE;
#endif

unsigned trace_walks(void)
{
    return walks_ok;
}

int trace_walk(void)
{
    return walk_on;
}

int trace_set_walk(int k)
{
#if TRACE_WIDE
    if (k >= 0 && k < TRACE_WALKS && (walks_ok >> k & 1))
        walk_on = k;
#else
    (void)k;
#endif
    return walk_on;
}

static const char *const walk_names[TRACE_WALKS] = {"portable", "avx2", "avx512"};

const char *trace_walk_name(int k)
{
    return k >= 0 && k < TRACE_WALKS ? walk_names[k] : NULL;
}

int trace_walk_choose(const char *name, fr_error *err)
{
    if (!name || !name[0])
        return 0;
    for (int k = 0; k < TRACE_WALKS; k++) {
        if (strcmp(name, walk_names[k]))
            continue;
        if (!(walks_ok >> k & 1))
            return fr_fail(err, "FRANJA_WALK=%s: this processor (or its OS) cannot run the %s walk", name, name);
        trace_set_walk(k);
        return 0;
    }
    return fr_fail(err, "FRANJA_WALK=%.40s: expected portable, avx2 or avx512", name);
}

int trace_closest(const fr_scene *s, const fr_ray *r, float tmax, fr_hit *hit)
{
#if TRACE_WIDE
    if (walk_on == TRACE_WALK_AVX512)
        return closest_v4(s, r, tmax, hit);
    if (walk_on == TRACE_WALK_AVX2)
        return closest_wide(s, r, tmax, hit);
#endif
    return closest_base(s, r, tmax, hit);
}

int trace_occluded(const fr_scene *s, const fr_ray *r, float tmax, uint32_t skip)
{
#if TRACE_WIDE
    if (walk_on == TRACE_WALK_AVX512)
        return occluded_v4(s, r, tmax, skip);
    if (walk_on == TRACE_WALK_AVX2)
        return occluded_wide(s, r, tmax, skip);
#endif
    return occluded_base(s, r, tmax, skip);
}

/* Nearest hit on instance prim i (trace_prim): its mesh's nearest
 * triangle, barycentrics in object space. */
static float instance_prim(const fr_scene *s, uint32_t i, const fr_ray *r, float tmax, float *a, float *b)
{
    fr_hit best = {0};
    hit_state H = {tmax, tmax * FAR_SCALE, 0, &best, 0};
#if TRACE_WIDE
    if (walk_on == TRACE_WALK_AVX512)
        instance_test_v4(s, i, r, &H, 0);
    else if (walk_on == TRACE_WALK_AVX2)
        instance_test_wide(s, i, r, &H, 0);
    else
#endif
        instance_test_base(s, i, r, &H, 0);
    *a = best.a;
    *b = best.b;
    return H.found ? best.t : 0.0f;
}

static inline void no_uv(fr_surface *out)
{
    out->uv = (vec2){0.0f, 0.0f};
    out->dpdu = out->dpdv = v3s(0.0f);
}

static void instance_surface(const fr_scene *s, const fr_ray *r, const fr_hit *hit, fr_surface *out, int uv);

/* The surface at a hit, uv, dpdu and dpdv only when `uv` is not 0. */
static inline __attribute__((always_inline)) void surface(const fr_scene *s, const fr_ray *r, const fr_hit *hit,
                                                          fr_surface *out, int uv)
{
    out->footprint = 0.0f;
    out->time = r->time;
    if (__builtin_expect(hit->inst != 0, 0)) {
        instance_surface(s, r, hit, out, uv);
        out->element = s->n_prims + s->n_planes + hit->inst - 1;
        return;
    }
    if (hit->prim == FR_NONE) {
        const fr_plane *pl = &s->planes[hit->plane];
        out->element = s->n_prims + hit->plane;
        out->p = geo_plane_point(pl, r, hit->t, &out->perr);
        out->ng = out->ns = pl->normal;
        out->material = pl->material;
        out->light = FR_NONE;
        if (!uv) {
            no_uv(out);
            return;
        }
        vec3 t, b;
        v3_basis(pl->normal, &t, &b);
        vec3 rel = v3_sub(out->p, pl->point);
        out->uv = (vec2){v3_dot(rel, t), v3_dot(rel, b)};
        out->dpdu = t;
        out->dpdv = b;
        return;
    }
    const fr_prim *p = &s->prims[hit->prim];
    out->material = p->material;
    out->light = p->light;
    out->element = hit->prim;
    if (p->kind == FR_PRIM_SPHERE) {
        const fr_sphere *sp = &s->spheres[p->index];
        vec3 n = v3_scale(v3_sub(v3_madd(r->o, r->d, hit->t), sp->center), 1.0f / sp->radius);
        out->ng = out->ns = v3_norm(n);
        /* Re-project onto the surface: removes most of the hit point's error. */
        out->p = geo_sphere_point(sp, out->ng, &out->perr);
        if (!uv) {
            no_uv(out);
            return;
        }
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
        if (!uv) {
            no_uv(out);
            return;
        }
        out->uv = (vec2){hit->a, hit->b};
        out->dpdu = q->edge_u;
        out->dpdv = q->edge_v;
    } else {
        const fr_triangle *t = &s->triangles[p->index];
        float b0 = 1.0f - hit->a - hit->b;
        /* geo_triangle_point and v3_norm(v3_cross(p1 - p0, p2 - p0)),
         * their operations in the same order, three lanes at a time. */
        f4 q0 = ln_from(s->positions[t->v[0]]), q1 = ln_from(s->positions[t->v[1]]),
           q2 = ln_from(s->positions[t->v[2]]);
        f4 w0 = q0 * f4_set1(b0), w1 = q1 * f4_set1(hit->a), w2 = q2 * f4_set1(hit->b);
        out->p = ln_vec(w0 + w1 + w2);
        out->perr = ln_vec((f4_abs(w0) + f4_abs(w1) + f4_abs(w2)) * f4_set1(GEO_GAMMA(7)));
        f4 e1 = q1 - q0, e2 = q2 - q0;
        out->ng = ln_vec(ln_norm(ln_cross(e1, e2)));
        out->ns = out->ng;
        if (t->flags & FR_TRI_NORMALS) {
            vec3 n = v3_add(v3_add(v3_scale(s->normals[t->v[0]], b0), v3_scale(s->normals[t->v[1]], hit->a)),
                            v3_scale(s->normals[t->v[2]], hit->b));
            if (v3_len2(n) > 0.0f) {
                n = v3_norm(n);
                out->ns = v3_dot(n, out->ng) < 0.0f ? v3_neg(n) : n;
            }
        }
        if (!uv)
            no_uv(out);
        else if (t->flags & FR_TRI_UVS) {
            vec2 u0 = s->uvs[t->v[0]], u1 = s->uvs[t->v[1]], u2 = s->uvs[t->v[2]];
            out->uv = (vec2){b0 * u0.u + hit->a * u1.u + hit->b * u2.u, b0 * u0.v + hit->a * u1.v + hit->b * u2.v};
            /* Solve [dp1 dp2] = [dpdu dpdv] [duv1 duv2] for the tangents. */
            float du1 = u1.u - u0.u, dv1 = u1.v - u0.v, du2 = u2.u - u0.u, dv2 = u2.v - u0.v;
            float det = du1 * dv2 - dv1 * du2;
            if (fabsf(det) > 1e-20f) {
                f4 inv = f4_set1(1.0f / det);
                out->dpdu = ln_vec((e1 * f4_set1(dv2) - e2 * f4_set1(dv1)) * inv);
                out->dpdv = ln_vec((e2 * f4_set1(du1) - e1 * f4_set1(du2)) * inv);
            } else {
                v3_basis(out->ng, &out->dpdu, &out->dpdv);
            }
        } else {
            out->uv = (vec2){hit->a, hit->b};
            out->dpdu = ln_vec(e1);
            out->dpdv = ln_vec(e2);
        }
    }
}

/* The linear part of a 3x4 transform applied to v (rows of m), or its
 * transpose (columns). */
static inline vec3 lin(const float (*m)[4], vec3 v)
{
    return v3(m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
              m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z);
}

static inline vec3 lin_t(const float (*m)[4], vec3 v)
{
    return v3(m[0][0] * v.x + m[1][0] * v.y + m[2][0] * v.z, m[0][1] * v.x + m[1][1] * v.y + m[2][1] * v.z,
              m[0][2] * v.x + m[1][2] * v.y + m[2][2] * v.z);
}

static inline vec3 v3_absv(vec3 v) { return v3(fabsf(v.x), fabsf(v.y), fabsf(v.z)); }

/* The surface of an instanced triangle: found in object space, then taken
 * to the world: the point by the transform, normals by the inverse
 * transpose (the transpose of inv), tangents by the linear part.  The
 * point's error bound covers the object-space bound carried through the
 * transform, the transform's own rounding and, four times over, the
 * rounding of taking a ray leaving the point back into object space. */
static __attribute__((noinline)) void instance_surface(const fr_scene *s, const fr_ray *r, const fr_hit *hit,
                                                       fr_surface *out, int uv)
{
    const fr_instance *in = &s->instances[hit->inst - 1];
    fr_instance at;
    if (in->motion) {
        const motion_pose *p = motion_at_cached(&s->inst_motions[in->motion - 1], in->motion - 1, r->time);
        memcpy(at.xf, p->xf, sizeof at.xf);
        memcpy(at.inv, p->inv, sizeof at.inv);
        in = &at;
    }
    fr_hit h = *hit;
    h.inst = 0;
    fr_surface o;
    surface(s, r, &h, &o, uv);
    const float (*m)[4] = in->xf;
    vec3 t = v3(m[0][3], m[1][3], m[2][3]);
    *out = o;
    out->p = v3_add(lin(m, o.p), t);
    float g = GEO_GAMMA(4);
    vec3 am[3] = {v3_absv(v3(m[0][0], m[0][1], m[0][2])), v3_absv(v3(m[1][0], m[1][1], m[1][2])),
                  v3_absv(v3(m[2][0], m[2][1], m[2][2]))};
    vec3 e = v3_add(o.perr, v3_scale(v3_absv(o.p), g));
    vec3 slack = v3_scale(v3_add(v3_absv(t), v3_absv(out->p)), 4.0f * g);
    out->perr = v3_add(v3(v3_dot(am[0], e), v3_dot(am[1], e), v3_dot(am[2], e)), slack);
    out->ng = v3_norm(lin_t(in->inv, o.ng));
    vec3 ns = lin_t(in->inv, o.ns);
    ns = v3_len2(ns) > 0.0f ? v3_norm(ns) : out->ng;
    out->ns = v3_dot(ns, out->ng) < 0.0f ? v3_neg(ns) : ns;
    if (uv) {
        out->dpdu = lin(m, o.dpdu);
        out->dpdv = lin(m, o.dpdv);
    }
}

void trace_surface(const fr_scene *s, const fr_ray *r, const fr_hit *hit, fr_surface *out)
{
    surface(s, r, hit, out, 1);
}

/* Inlined where a path's hit point is made (always_inline): the hit and the
 * surface are then the caller's locals, not memory behind a call. */
__attribute__((always_inline)) inline void trace_surface_uv(const fr_scene *s, const fr_ray *r, const fr_hit *hit,
                                                             fr_surface *out, int uv)
{
    surface(s, r, hit, out, uv);
}
