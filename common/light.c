/* light.c -- lights for next-event estimation and as the start of light paths
 * (see light.h). */

#include "light.h"

#include <float.h>

#include "envmap.h"
#include "fmath.h"
#include "lanes.h"
#include "spherical.h"
#include "texture.h"

vec3 lgt_emitted(const fr_material *m, vec3 ng, vec3 w)
{
    if (m->two_sided || v3_dot(ng, w) > 0.0f)
        return m->emission;
    return v3s(0.0f);
}

/* Emitted radiance le of light primitive `prim` at its point p, times the
 * material's emission texture there (a, b: the rect's edge coordinates or
 * the triangle's barycentrics of p1, p2, as trace_surface takes them). */
static inline __attribute__((always_inline)) vec3 textured(const fr_scene *s, const fr_material *m, uint32_t prim, vec3 p,
                                                           float a, float b, vec3 le)
{
    if (m->tex_emission == FR_NONE || v3_is_zero(le))
        return le;
    fr_hit h = {0.0f, prim, FR_NONE, a, b, 0};
    fr_ray r = {p, v3s(0.0f), 0.0f};
    fr_surface sf;
    trace_surface(s, &r, &h, &sf);
    return tex_emission(s, m, sf.uv);
}

/* The first light whose cdf exceeds u (the last light when none does, or
 * u is NaN), by a binary search whose steps depend only on the number of
 * lights: each step selects instead of branching, since u is random and
 * a branch on it is mispredicted half the time. */
uint32_t lgt_pick(const fr_scene *s, float u)
{
    uint32_t base = 0, len = s->n_lights - 1;
    if (len == 0)
        return 0;
    while (len > 1) {
        uint32_t half = len / 2;
        base = !(u < s->lights[base + half].cdf) ? base + half : base;
        len -= half;
    }
    return base + !(u < s->lights[base].cdf);
}

static int is_distant(const fr_light *l) { return l->kind == FR_LIGHT_SUN || l->kind == FR_LIGHT_ENV; }

uint32_t lgt_n_distant(const fr_scene *s)
{
    uint32_t n = 0;
    while (n < s->n_lights && is_distant(&s->lights[n]))
        n++;
    return n;
}

/* ---- the light tree (scene.h, fr_light_node) ------------------------------ */

/* cos(max(0, a - b)) of angles a, b in [0, pi] given by their sines and
 * cosines: no inverse trigonometry (pbrt-v4's bounds of the importance). */
static inline float cos_sub_clamped(float sa, float ca, float sb, float cb) { return ca > cb ? 1.0f : ca * cb + sa * sb; }

/* The importance node n gives point p with unit normal nrm (zero: a point
 * in a medium, which takes light from every direction): its power times a
 * bound on the cosine between the lights' emission and the direction to p,
 * times a bound on the cosine at p (|cos|: both sides of a surface may
 * take light), over the squared distance to the node's centre (at least a
 * sixteenth of its bounding sphere's squared radius); 0 where no light of
 * the node can send light to p (Conty Estevez and Kulla 2018).
 *
 * The smallest angle between the cone's axis w and a direction p - q from
 * a point q of the node's box to p has cosine at most
 * max w.(p - q) / min |p - q| over the box, when that maximum is positive
 * (else at most max w.(p - q) / max |p - q|): w.(p - c) + sum |w_k| e_k
 * over the distance from p to the box (c its centre, e its half extent).
 * Unlike the bounding sphere's angle (pbrt-v4), this bound stays tight
 * for flat clusters, such as lamps at one height seen from the ground.
 * That angle less the cone's spread bounds the angle at the lights; the
 * same bound with nrm, the angle at p.  Cosines of differences come from
 * cos_sub_clamped: + - * / and sqrt only. */
static inline float min2(float a, float b) { return a < b ? a : b; }
static inline float max2(float a, float b) { return a > b ? a : b; }

static inline float node_importance(const fr_light_node *n, vec3 p, vec3 nrm)
{
    vec3 e = v3_scale(v3_sub(n->hi, n->lo), 0.5f), d = v3_sub(p, v3_add(n->lo, e));
    float d2 = v3_len2(d), r2 = v3_len2(e), cos_p = 1.0f, cos_i = 1.0f;
    vec3 out = v3_vmax(v3_sub(v3_abs(d), e), v3s(0.0f));
    float db2 = v3_len2(out);
    if (db2 > 0.0f) {
        float inv = 1.0f / sqrtf(db2);
        float wd = v3_dot(n->axis, d), we = v3_dot(v3_abs(n->axis), e);
        if (n->flags & FR_LNODE_TWO_SIDED)
            wd = fabsf(wd);
        /* Behind every point of the box: over the farthest distance. */
        float cm = wd + we > 0.0f ? min2(1.0f, (wd + we) * inv) : (wd + we) / (sqrtf(d2) + sqrtf(r2));
        /* cos(max(0, angle - spread)); a single direction (cos_o = 1)
         * and every direction (cos_o = -1) need no sines. */
        if (n->cos_o >= 1.0f) {
            cos_p = cm;
        } else if (n->cos_o > -1.0f) {
            float sm = sqrtf(max2(0.0f, 1.0f - cm * cm)), so = sqrtf(max2(0.0f, 1.0f - n->cos_o * n->cos_o));
            cos_p = cos_sub_clamped(sm, cm, so, n->cos_o);
        }
        if (cos_p < n->cos_e)
            return 0.0f;
        if (!v3_is_zero(nrm))
            cos_i = min2(1.0f, (fabsf(v3_dot(nrm, d)) + v3_dot(v3_abs(nrm), e)) * inv);
    }
    /* Floors on the cosines: a spot whose light spreads past 90 degrees
     * reaches p at a negative cos_p too, and rounding must not make a
     * light that reaches p impossible to pick. */
    float imp = n->power * max2(cos_p, 1e-3f) * max2(cos_i, 1e-3f) / max2(max2(d2, 0.0625f * r2), 1e-30f);
    return imp < 1e30f ? imp : n->power > 0.0f ? 1e30f : 0.0f;
}

/* The probabilities of the children of inner node n from p: each one's
 * importance over their sum; both 0 when neither reaches p.  lgt_choose
 * and lgt_pick_pdf both take them from here, so a light's pdf is the
 * product of the same numbers in the same order either way. */
static inline void branch(const fr_scene *s, const fr_light_node *n, vec3 p, vec3 nrm, float *p0, float *p1)
{
    float i0 = node_importance(&s->light_nodes[n->child[0]], p, nrm);
    float i1 = node_importance(&s->light_nodes[n->child[1]], p, nrm);
    float sum = i0 + i1;
    if (!(sum <= FLT_MAX)) {
        /* An importance past a float's range (lights of enormous power, a
         * point at a light): the infinite ones share the branch. */
        i0 = i0 > FLT_MAX ? 1.0f : 0.0f;
        i1 = i1 > FLT_MAX ? 1.0f : 0.0f;
        sum = i0 + i1;
    }
    *p0 = sum > 0.0f ? i0 / sum : 0.0f;
    *p1 = sum > 0.0f ? i1 / sum : 0.0f;
}

/* x clamped to [0, 1): rescaled numbers can round to 1. */
static inline float unit(float x) { return x < 0.0f ? 0.0f : x < 1.0f ? x : 0x1.fffffep-1f; }

/* The share of the local lights (the tree): all but the distant lights'
 * picks in the power table. */
static inline float tree_share(const fr_scene *s, uint32_t nd) { return nd ? 1.0f - s->lights[nd - 1].cdf : 1.0f; }

/* Inlined where it is called (always_inline): a path vertex's light pick
 * then costs no call, and its number and pick stay in registers. */
__attribute__((always_inline)) inline uint32_t lgt_choose(const fr_scene *s, vec3 from, vec3 nrm, float *u, float *pick)
{
    if (s->n_lights == 0)
        return FR_NONE;
    uint32_t nd = lgt_n_distant(s);
    float x = *u;
    if ((nd && x < s->lights[nd - 1].cdf) || s->n_light_nodes == 0) {
        uint32_t li = lgt_pick(s, x);
        float lo = li ? s->lights[li - 1].cdf : 0.0f;
        *pick = s->lights[li].pick;
        *u = unit((x - lo) / (s->lights[li].cdf - lo));
        return li;
    }
    float share = tree_share(s, nd), pk = share;
    x = unit((x - (nd ? s->lights[nd - 1].cdf : 0.0f)) / share);
    uint32_t nl = s->n_lights - nd, n = s->n_light_nodes - 1;
    while (n >= nl) {
        const fr_light_node *t = &s->light_nodes[n];
        float p0, p1;
        branch(s, t, from, nrm, &p0, &p1);
        if (x < p0) {
            x = unit(x / p0);
            pk *= p0;
            n = t->child[0];
        } else if (p1 > 0.0f) {
            x = unit((x - p0) / p1);
            pk *= p1;
            n = t->child[1];
        } else {
            return FR_NONE;
        }
    }
    *pick = pk;
    *u = x;
    return nd + n;
}

float lgt_pick_pdf(const fr_scene *s, uint32_t light, vec3 from, vec3 nrm)
{
    uint32_t nd = lgt_n_distant(s);
    if (light < nd || s->n_light_nodes == 0)
        return s->lights[light].pick;
    /* The path from the root to the light's leaf, walked down as
     * lgt_choose walks it. */
    uint32_t path[FR_BVH_MAX_DEPTH], k = 0;
    for (uint32_t n = light - nd; s->light_nodes[n].parent != FR_NONE; n = s->light_nodes[n].parent)
        path[k++] = n;
    float pk = tree_share(s, nd);
    uint32_t n = s->n_light_nodes - 1;
    while (k > 0) {
        uint32_t c = path[--k];
        float p0, p1;
        branch(s, &s->light_nodes[n], from, nrm, &p0, &p1);
        pk *= c == s->light_nodes[n].child[0] ? p0 : p1;
        n = c;
    }
    return pk;
}

float lgt_spot_falloff(const fr_light *l, float c)
{
    float d = l->cone_aux - l->cone_cos;
    float t = (c - l->cone_cos) / (d > 0.001f ? d : 0.001f);
    t = t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
    return t * t;
}

/* Intensity (W/sr) that a point or spot light sends toward unit direction w. */
static vec3 lgt_intensity(const fr_light *l, vec3 w)
{
    if (l->kind != FR_LIGHT_SPOT)
        return l->intensity;
    return v3_scale(l->intensity, lgt_spot_falloff(l, v3_dot(l->axis, w)));
}

/* 1 - cos of the half-angle of the cone a sphere subtends from distance d,
 * written without the cancellation of 1 - sqrt(1 - x) for small x. */
static float cone_one_minus_cos(float r2, float d2)
{
    float sin2 = r2 / d2;
    return sin2 / (1.0f + sqrtf(fmaxf(0.0f, 1.0f - sin2)));
}

/* A direction uniform in the cone of unit axis w whose half-angle has
 * 1 - cos = omc. */
static vec3 cone_sample(vec3 w, float omc, float u1, float u2)
{
    float one_minus_ct = u1 * omc, ct = 1.0f - one_minus_ct;
    float st = sqrtf(fmaxf(0.0f, one_minus_ct * (2.0f - one_minus_ct))), sn, cs;
    fm_sincosf(2.0f * FM_PI * u2, &sn, &cs);
    vec3 t, b;
    v3_basis(w, &t, &b);
    return v3_norm(v3_from_local(v3(st * cs, st * sn, ct), t, b, w));
}

/* Is unit d inside the cone of unit axis a with 1 - cos = omc?  Compared
 * as |d - a|^2 = 2 (1 - cos), exact for small cones. */
static int in_cone(vec3 d, vec3 a, float omc) { return v3_len2(v3_sub(d, a)) <= 2.0f * omc; }

/* Radiance of a sun's disk: its irradiance over pi sin^2 of the half-angle. */
static vec3 sun_radiance(const fr_light *l)
{
    float sin2 = l->cone_aux * (1.0f + l->cone_cos);
    return v3_scale(l->intensity, 1.0f / (FM_PI * sin2));
}

/* Below this area over the squared distance from the point to the
 * light's centre (about its solid angle seen face-on), next-event
 * estimation samples a rectangle or triangle light by area: area
 * sampling's density (squared distance over the light's cosine) then varies
 * over the light by less than about a factor of 2, which the stratified
 * numbers of a pixel's samples integrate well already, and solid-angle
 * sampling's cost (square roots, divisions and an arctangent or four
 * arccosines a sample) would outweigh its lower noise.  This keeps it to
 * points within about 3.2 times the square root of the light's area from
 * its centre (tests/bench/README.md, "Solid-angle sampling of area
 * lights"). */
#define SOLID_MIN_SIZE 0.1f

/* Whether rectangle or triangle light l (primitive pr) is near enough to
 * `from` for solid-angle sampling (SOLID_MIN_SIZE): a few operations, done
 * before anything of solid_setup. */
static inline int solid_near(const fr_scene *s, const fr_light *l, const fr_prim *pr, vec3 from)
{
    vec3 c;
    if (pr->kind == FR_PRIM_RECT) {
        const fr_rect *q = &s->rects[pr->index];
        c = v3_add(q->origin, v3_scale(v3_add(q->edge_u, q->edge_v), 0.5f));
    } else if (pr->kind == FR_PRIM_TRIANGLE) {
        const fr_triangle *t = &s->triangles[pr->index];
        c = v3_scale(v3_add(s->positions[t->v[0]], v3_add(s->positions[t->v[1]], s->positions[t->v[2]])),
                     1.0f / 3.0f);
    } else {
        return 0;
    }
    return l->area >= SOLID_MIN_SIZE * v3_len2(v3_sub(c, from));
}

/* A rectangle or triangle light seen from a point, set up for sampling
 * uniformly in solid angle (spherical.h). */
typedef union {
    spherical_rect rect;
    spherical_tri tri;
} solid_view;

/* Whether next-event estimation from `from` samples emitting primitive pr
 * (material m) uniformly in its solid angle, with *v set up and
 * v's solid angle in *omega; else it samples by area.  Solid angle for
 * rectangles and triangles where spherical.h's setups accept the point,
 * except from behind a one-sided emitter (which sends nothing there: the
 * cheaper area sample finds that out); called where solid_near holds.
 * The sampler and the pdf
 * (pdf_picked) both decide here, from the same inputs: the same decision
 * and the same density, bit for bit. */
static int solid_setup(const fr_scene *s, const fr_prim *pr, const fr_material *m, vec3 from, solid_view *v,
                       float *omega)
{
    if (pr->kind == FR_PRIM_RECT) {
        const fr_rect *q = &s->rects[pr->index];
        if (!m->two_sided && !(v3_dot(v3_sub(from, q->origin), q->normal) > 0.0f))
            return 0;
        if (!spherical_rect_setup(from, q->origin, q->edge_u, q->edge_v, &v->rect))
            return 0;
        *omega = v->rect.solid;
        return 1;
    }
    if (pr->kind == FR_PRIM_TRIANGLE) {
        const fr_triangle *t = &s->triangles[pr->index];
        vec3 p0 = s->positions[t->v[0]], p1 = s->positions[t->v[1]], p2 = s->positions[t->v[2]];
        if (!m->two_sided && !(v3_dot(v3_sub(from, p0), v3_cross(v3_sub(p1, p0), v3_sub(p2, p0))) > 0.0f))
            return 0;
        if (!spherical_tri_setup(from, p0, p1, p2, &v->tri))
            return 0;
        *omega = v->tri.solid;
        return 1;
    }
    return 0;
}

/* Solid-angle pdf of point p (normal n) of area light `light`, picked
 * with probability pick, from `from`: with `solid`, the density of
 * lgt_sample_chosen (solid_setup's choice), else of lgt_sample_table
 * (rectangles and triangles by area). */
static float pdf_picked(const fr_scene *s, uint32_t light, float pick, vec3 from, vec3 p, vec3 n, int solid)
{
    const fr_light *l = &s->lights[light];
    const fr_prim *pr = &s->prims[l->prim];
    if (pr->kind == FR_PRIM_SPHERE) {
        const fr_sphere *sp = &s->spheres[pr->index];
        float d2 = v3_len2(v3_sub(sp->center, from)), r2 = sp->radius * sp->radius;
        if (d2 > r2 * 1.0001f)
            return pick / (2.0f * FM_PI * cone_one_minus_cos(r2, d2));
    }
    solid_view v;
    float omega;
    if (solid && solid_near(s, l, pr, from) && solid_setup(s, pr, &s->materials[pr->material], from, &v, &omega))
        return pick / omega;
    vec3 d = v3_sub(p, from);
    float dist2 = v3_len2(d);
    float cosl = fabsf(v3_dot(n, d)) / sqrtf(dist2);
    if (cosl <= 0.0f)
        return 0.0f;
    return pick * dist2 / (cosl * l->area);
}

float lgt_pdf(const fr_scene *s, uint32_t light, vec3 from, vec3 nrm, vec3 p, vec3 n)
{
    return pdf_picked(s, light, lgt_pick_pdf(s, light, from, nrm), from, p, n, 1);
}

float lgt_pdf_table(const fr_scene *s, uint32_t light, vec3 from, vec3 p, vec3 n)
{
    return pdf_picked(s, light, s->lights[light].pick, from, p, n, 0);
}

vec3 lgt_distant(const fr_scene *s, uint32_t light, vec3 dir, float *pdf)
{
    const fr_light *l = &s->lights[light];
    *pdf = 0.0f;
    if (l->kind == FR_LIGHT_ENV) {
        float d;
        vec3 le = env_eval(s, dir, &d);
        *pdf = l->pick * d;
        return le;
    }
    if (l->kind != FR_LIGHT_SUN || l->cone_aux == 0.0f || !in_cone(dir, l->axis, l->cone_aux))
        return v3s(0.0f);
    *pdf = l->pick / (2.0f * FM_PI * l->cone_aux);
    return sun_radiance(l);
}

/* Point the sample from `from` at out->p: fills dist and wi, returns the
 * squared distance (0 when the two points coincide, wi then unset). */
static float aim(fr_light_sample *out, vec3 from)
{
    vec3 d = v3_sub(out->p, from);
    float d2 = v3_len2(d);
    if (d2 > 0.0f) {
        out->dist = sqrtf(d2);
        out->wi = v3_scale(d, 1.0f / out->dist);
    }
    return d2;
}

/* Light samples of the lights that are not primitives. */
static int sample_other(const fr_scene *s, const fr_light *l, float pick, vec3 from, float u1, float u2,
                        fr_light_sample *out)
{
    out->prim = FR_NONE;
    if (l->kind == FR_LIGHT_POINT || l->kind == FR_LIGHT_SPOT) {
        out->p = l->position;
        float d2 = aim(out, from);
        if (!(d2 > 0.0f))
            return 0;
        out->radiance = v3_scale(lgt_intensity(l, v3_neg(out->wi)), 1.0f / d2);
        out->pdf = pick;
        out->n = v3_neg(out->wi);
        out->delta = 1;
        out->distant = 0;
        return !v3_is_zero(out->radiance);
    }
    out->dist = INFINITY;
    out->distant = 1;
    out->p = from;
    if (l->kind == FR_LIGHT_SUN) {
        out->delta = l->cone_aux == 0.0f;
        if (out->delta) {
            out->wi = l->axis;
            out->radiance = l->intensity;
            out->pdf = pick;
        } else {
            out->wi = cone_sample(l->axis, l->cone_aux, u1, u2);
            out->radiance = sun_radiance(l);
            out->pdf = pick / (2.0f * FM_PI * l->cone_aux);
        }
    } else {
        float pdf;
        out->delta = 0;
        out->wi = env_sample(s, u1, u2, &pdf, &out->radiance);
        out->pdf = pick * pdf;
        if (!(out->pdf > 0.0f))
            return 0;
    }
    out->n = v3_neg(out->wi);
    return !v3_is_zero(out->radiance);
}

/* The point of triangle t with barycentrics b0, b1, b2 (of p0, p1, p2),
 * its unit geometric normal, and when err is not NULL a bound on its error
 * per coordinate. */
static inline __attribute__((always_inline)) void tri_point(const fr_scene *s, const fr_triangle *t, float b0,
                                                            float b1, float b2, vec3 *p, vec3 *n, vec3 *err)
{
    vec3 p0 = s->positions[t->v[0]], p1 = s->positions[t->v[1]], p2 = s->positions[t->v[2]];
    /* p0 b0 + p1 b1 + p2 b2 and v3_norm(v3_cross(p1 - p0, p2 - p0)),
     * three lanes at a time in the same order (lanes.h). */
    f4 q0 = ln_from(p0), q1 = ln_from(p1), q2 = ln_from(p2);
    *p = ln_vec(q0 * f4_set1(b0) + q1 * f4_set1(b1) + q2 * f4_set1(b2));
    *n = ln_vec(ln_norm(ln_cross(q1 - q0, q2 - q0)));
    if (err)
        geo_triangle_point(p0, p1, p2, b1, b2, err);
}

/* A point uniform by area on primitive `pr` from (u1, u2): its position,
 * unit geometric normal, the coordinates trace_surface takes, and when err
 * is not NULL a bound on the point's error per coordinate (the
 * geo_*_point functions give the bound; the point is computed here as
 * light sampling always has). */
static inline __attribute__((always_inline)) void prim_point(const fr_scene *s, const fr_prim *pr, float u1, float u2,
                                                             vec3 *p, vec3 *n, float *ua, float *ub, vec3 *err)
{
    if (pr->kind == FR_PRIM_SPHERE) {
        const fr_sphere *sp = &s->spheres[pr->index];
        float z = 1.0f - 2.0f * u1, r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), sn, cs;
        fm_sincosf(2.0f * FM_PI * u2, &sn, &cs);
        *n = v3(r * cs, r * sn, z);
        *p = v3_madd(sp->center, *n, sp->radius);
        if (err)
            geo_sphere_point(sp, *n, err);
        *ua = *ub = 0.0f;
    } else if (pr->kind == FR_PRIM_RECT) {
        const fr_rect *q = &s->rects[pr->index];
        *p = v3_add(q->origin, v3_add(v3_scale(q->edge_u, u1), v3_scale(q->edge_v, u2)));
        *n = v3_norm(q->normal);
        if (err)
            geo_rect_point(q, u1, u2, err);
        *ua = u1;
        *ub = u2;
    } else {
        float su = sqrtf(u1), b1 = u2 * su, b0 = 1.0f - su, b2 = 1.0f - b0 - b1;
        tri_point(s, &s->triangles[pr->index], b0, b1, b2, p, n, err);
        *ua = b1;
        *ub = b2;
    }
}

int lgt_has_fixed_point(const fr_scene *s, uint32_t light)
{
    const fr_light *l = &s->lights[light];
    return l->kind == FR_LIGHT_POINT || l->kind == FR_LIGHT_SPOT ||
           (l->kind == FR_LIGHT_PRIM && s->prims[l->prim].kind != FR_PRIM_SPHERE);
}

int lgt_fixed_point(const fr_scene *s, uint32_t light, float u1, float u2, vec3 *p)
{
    const fr_light *l = &s->lights[light];
    if (!lgt_has_fixed_point(s, light))
        return 0;
    if (l->kind != FR_LIGHT_PRIM) {
        *p = l->position;
        return 1;
    }
    vec3 n;
    float ua, ub;
    prim_point(s, &s->prims[l->prim], u1, u2, p, &n, &ua, &ub, NULL);
    return 1;
}

/* lgt_sample_chosen, with rectangles and triangles sampled in solid angle
 * where solid_setup says so when `solid`, else by area.  Inlined where it
 * is called, with prim_point and textured (always_inline): the light
 * sample's vectors stay in registers instead of going through the stack at
 * each call. */
static inline __attribute__((always_inline)) int sample_chosen(const fr_scene *s, uint32_t li, float pick, vec3 from,
                                                               float u1, float u2, int solid, fr_light_sample *out)
{
    const fr_light *l = &s->lights[li];
    out->light = li;
    out->pick = pick;
    if (l->kind != FR_LIGHT_PRIM)
        return sample_other(s, l, pick, from, u1, u2, out);
    const fr_prim *pr = &s->prims[l->prim];
    const fr_material *m = &s->materials[pr->material];
    out->delta = 0;
    out->distant = 0;
    out->prim = l->prim;
    if (pr->kind == FR_PRIM_SPHERE) {
        const fr_sphere *sp = &s->spheres[pr->index];
        vec3 dc = v3_sub(sp->center, from);
        float d2 = v3_len2(dc), r2 = sp->radius * sp->radius;
        if (d2 > r2 * 1.0001f) {
            /* Uniform in the cone of directions that hit the sphere. */
            float omc = cone_one_minus_cos(r2, d2);
            out->wi = cone_sample(v3_scale(dc, 1.0f / sqrtf(d2)), omc, u1, u2);
            /* Nearest intersection of the ray with the sphere, from the
             * projected half-chord. */
            float proj = v3_dot(dc, out->wi);
            float h2 = fmaxf(0.0f, r2 - (d2 - proj * proj));
            out->dist = proj - sqrtf(h2);
            out->p = v3_madd(from, out->wi, out->dist);
            out->n = v3_norm(v3_sub(out->p, sp->center));
            out->pdf = pick / (2.0f * FM_PI * omc);
            out->radiance = textured(s, m, l->prim, out->p, 0.0f, 0.0f, lgt_emitted(m, out->n, v3_neg(out->wi)));
            return out->pdf > 0.0f && !v3_is_zero(out->radiance);
        }
    }
    float ua, ub, omega;
    solid_view v;
    if (solid && solid_near(s, l, pr, from) && solid_setup(s, pr, m, from, &v, &omega)) {
        /* Uniform in the solid angle the rectangle or triangle subtends:
         * its coordinates of the point that direction reaches. */
        if (pr->kind == FR_PRIM_RECT) {
            spherical_rect_sample(&v.rect, u1, u2, &ua, &ub);
            prim_point(s, pr, ua, ub, &out->p, &out->n, &ua, &ub, NULL);
        } else {
            spherical_tri_sample(&v.tri, u1, u2, &ua, &ub);
            tri_point(s, &s->triangles[pr->index], 1.0f - ua - ub, ua, ub, &out->p, &out->n, NULL);
        }
        if (!(aim(out, from) > 0.0f))
            return 0;
        out->pdf = pick / omega;
        out->radiance = textured(s, m, l->prim, out->p, ua, ub, lgt_emitted(m, out->n, v3_neg(out->wi)));
        return out->pdf > 0.0f && !v3_is_zero(out->radiance);
    }
    /* Uniform by area (a sphere seen from inside: over its whole surface). */
    prim_point(s, pr, u1, u2, &out->p, &out->n, &ua, &ub, NULL);
    float d2 = aim(out, from);
    if (!(d2 > 0.0f))
        return 0;
    float cosl = fabsf(v3_dot(out->n, out->wi));
    if (cosl <= 0.0f)
        return 0;
    out->pdf = pick * d2 / (cosl * l->area);
    out->radiance = textured(s, m, l->prim, out->p, ua, ub, lgt_emitted(m, out->n, v3_neg(out->wi)));
    return !v3_is_zero(out->radiance);
}

__attribute__((always_inline)) inline int lgt_sample_chosen(const fr_scene *s, uint32_t li, float pick, vec3 from,
                                                            float u1, float u2, fr_light_sample *out)
{
    return sample_chosen(s, li, pick, from, u1, u2, 1, out);
}

int lgt_sample(const fr_scene *s, vec3 from, vec3 nrm, float upick, float u1, float u2, fr_light_sample *out)
{
    float pick;
    uint32_t li = lgt_choose(s, from, nrm, &upick, &pick);
    return li != FR_NONE && lgt_sample_chosen(s, li, pick, from, u1, u2, out);
}

/* By area, not in solid angle: bidirectional path tracing weighs its
 * connection to a light (s = 1) against the strategies that reach the same
 * light vertex otherwise with that vertex's density as a light subpath's
 * origin, the table's pick over the light's area (lgt_pdf_emit); sampling
 * it in solid angle here would need that density changed in every
 * strategy's weight for the sum of the weights to stay 1.  Equiangular
 * sampling picks the same point first by area (lgt_fixed_point).  The path
 * tracer's own next-event estimation (lgt_sample_chosen) and its MIS
 * (lgt_pdf) are the ones that change. */
int lgt_sample_table(const fr_scene *s, vec3 from, float upick, float u1, float u2, fr_light_sample *out)
{
    if (s->n_lights == 0)
        return 0;
    uint32_t li = lgt_pick(s, upick);
    return sample_chosen(s, li, s->lights[li].pick, from, u1, u2, 0, out);
}

/* ---- rays leaving lights ------------------------------------------------ */

/* A direction uniform over the sphere. */
static vec3 sphere_dir(float u1, float u2)
{
    float z = 1.0f - 2.0f * u1, r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), sn, cs;
    fm_sincosf(2.0f * FM_PI * u2, &sn, &cs);
    return v3(r * cs, r * sn, z);
}

/* The origin of a ray travelling along unit d into the world from outside
 * it: a point uniform on the disk of the world's radius facing d, one
 * radius back from the centre. */
static vec3 disk_origin(const fr_world *w, vec3 d, float u1, float u2)
{
    vec3 t, b;
    v3_basis(d, &t, &b);
    float r = sqrtf(u1) * w->radius, sn, cs;
    fm_sincosf(2.0f * FM_PI * u2, &sn, &cs);
    vec3 c = v3_madd(w->center, d, -w->radius);
    return v3_add(c, v3_add(v3_scale(t, r * cs), v3_scale(b, r * sn)));
}

int lgt_sample_emit(const fr_scene *s, float upick, float u1, float u2, float u3, float u4, fr_light_emit *out)
{
    if (s->n_lights == 0)
        return 0;
    uint32_t li = lgt_pick(s, upick);
    const fr_light *l = &s->lights[li];
    out->light = li;
    out->prim = FR_NONE;
    out->perr = v3s(0.0f);
    out->delta_pos = out->delta_dir = out->distant = 0;
    if (l->kind == FR_LIGHT_POINT || l->kind == FR_LIGHT_SPOT) {
        out->delta_pos = 1;
        out->ray.o = l->position;
        out->pdf_pos = l->pick;
        if (l->kind == FR_LIGHT_POINT) {
            out->ray.d = sphere_dir(u3, u4);
            out->pdf_dir = 1.0f / (4.0f * FM_PI);
        } else {
            float omc = 1.0f - l->cone_cos;
            out->ray.d = cone_sample(l->axis, omc, u3, u4);
            out->pdf_dir = 1.0f / (2.0f * FM_PI * omc);
        }
        out->n = out->ray.d;
        out->Le = lgt_intensity(l, out->ray.d);
        return !v3_is_zero(out->Le);
    }
    if (l->kind == FR_LIGHT_SUN || l->kind == FR_LIGHT_ENV) {
        const fr_world *w = &s->world;
        vec3 toward;           /* from the scene toward the light */
        out->distant = 1;
        if (l->kind == FR_LIGHT_ENV) {
            float pdf;
            toward = env_sample(s, u3, u4, &pdf, &out->Le);
            out->pdf_dir = pdf;
            if (!(pdf > 0.0f))
                return 0;
        } else if (l->cone_aux == 0.0f) {
            toward = l->axis;
            out->delta_dir = 1;
            out->pdf_dir = 1.0f;
            out->Le = l->intensity;
        } else {
            toward = cone_sample(l->axis, l->cone_aux, u3, u4);
            out->pdf_dir = 1.0f / (2.0f * FM_PI * l->cone_aux);
            out->Le = sun_radiance(l);
        }
        out->ray.d = v3_neg(toward);
        out->ray.o = disk_origin(w, out->ray.d, u1, u2);
        out->n = out->ray.d;
        out->pdf_pos = l->pick / (FM_PI * w->radius * w->radius);
        return !v3_is_zero(out->Le);
    }
    const fr_prim *pr = &s->prims[l->prim];
    const fr_material *m = &s->materials[pr->material];
    float ua, ub;
    vec3 p, n;
    prim_point(s, pr, u1, u2, &p, &n, &ua, &ub, &out->perr);
    float side_pdf = 1.0f;
    if (m->two_sided) {
        side_pdf = 0.5f;
        if (u3 < 0.5f) {
            u3 = 2.0f * u3;
        } else {
            u3 = 2.0f * u3 - 1.0f;
            n = v3_neg(n);
        }
    }
    /* Cosine-weighted about n. */
    float r = sqrtf(u3), sn, cs;
    fm_sincosf(2.0f * FM_PI * u4, &sn, &cs);
    float z = sqrtf(fmaxf(0.0f, 1.0f - u3));
    vec3 t, b;
    v3_basis(n, &t, &b);
    out->ray.o = p;
    out->ray.d = v3_norm(v3_from_local(v3(r * cs, r * sn, z), t, b, n));
    out->n = n;
    out->prim = l->prim;
    out->pdf_pos = l->pick / l->area;
    out->pdf_dir = side_pdf * z * FM_INV_PI;
    out->Le = textured(s, m, l->prim, p, ua, ub, lgt_emitted(m, n, out->ray.d));
    return out->pdf_dir > 0.0f && !v3_is_zero(out->Le);
}

void lgt_pdf_emit(const fr_scene *s, uint32_t light, vec3 p, vec3 n, vec3 dir, float *pdf_pos, float *pdf_dir)
{
    const fr_light *l = &s->lights[light];
    (void)p;
    switch (l->kind) {
    case FR_LIGHT_POINT:
        *pdf_pos = l->pick;
        *pdf_dir = 1.0f / (4.0f * FM_PI);
        return;
    case FR_LIGHT_SPOT:
        *pdf_pos = l->pick;
        *pdf_dir = v3_dot(dir, l->axis) >= l->cone_cos ? 1.0f / (2.0f * FM_PI * (1.0f - l->cone_cos)) : 0.0f;
        return;
    case FR_LIGHT_SUN:
    case FR_LIGHT_ENV:
        *pdf_pos = l->pick / (FM_PI * s->world.radius * s->world.radius);
        if (l->kind == FR_LIGHT_ENV)
            *pdf_dir = env_pdf(s, v3_neg(dir));
        else
            *pdf_dir = l->cone_aux > 0.0f && in_cone(v3_neg(dir), l->axis, l->cone_aux)
                           ? 1.0f / (2.0f * FM_PI * l->cone_aux) : 0.0f;
        return;
    default: {
        const fr_material *m = &s->materials[s->prims[l->prim].material];
        float c = v3_dot(n, dir);
        if (m->two_sided)
            c = 0.5f * fabsf(c);
        *pdf_pos = l->pick / l->area;
        *pdf_dir = c > 0.0f ? c * FM_INV_PI : 0.0f;
    }
    }
}
