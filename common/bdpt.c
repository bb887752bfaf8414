/* bdpt.c -- bidirectional path tracing: camera and light subpaths joined with
 * MIS weights (see bdpt.h). */

#include "bdpt.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "bsdf.h"
#include "camera.h"
#include "fmath.h"
#include "light.h"
#include "pathtrace.h"
#include "sampler.h"
#include "splat.h"
#include "texture.h"

/* Scattering vertices a subpath passes before Russian roulette may end it:
 * the fourth and later may, as in pathtrace.c. */
#define RR_DEPTH 3
/* First dimension pair of a light subpath's numbers (bdpt.h). */
#define LIGHT_DIM 65536u

enum { BD_CAMERA, BD_LIGHT, BD_SURFACE };

/* Where a subpath's numbers come from: a pixel sample's sampler, or a
 * caller's stream (bd_path, for primary-sample-space Metropolis). */
typedef struct {
    fr_sampler *smp;
    const bd_stream *st;
} rnd;

static inline void rnd_2d(rnd *r, float *u, float *v)
{
    if (r->smp) {
        smp_2d(r->smp, u, v);
        return;
    }
    *u = r->st->next(r->st->ctx);
    *v = r->st->next(r->st->ctx);
}

static inline float rnd_1(rnd *r) { return r->smp ? smp_random(r->smp) : r->st->next(r->st->ctx); }

/* A pair that this subpath does not use (smp_skip); a stream skips nothing. */
static inline void rnd_skip(rnd *r)
{
    if (r->smp)
        smp_skip(r->smp);
}

/* A subpath vertex.  pdf_fwd is the area density with which its own
 * subpath reached it, pdf_rev the one with which the other direction
 * would (from the next vertex of its subpath).  A genuine 0 (a direction
 * that the BSDF never samples though it reflects light there, as below the
 * shading hemisphere) stays 0, so the strategy that would need it does not
 * count.
 *
 * Delta lobes (mirror, smooth glass) make chains: a vertex a that is not
 * delta, the delta vertices, and the next vertex b that is not.  The chain
 * is sampled at one end, by a direction there, and the other end is
 * determined; the delta vertices themselves count 1 both ways (their delta
 * factor is the same for every strategy that can make the path) and are
 * skipped in the ratios.  The density of b reached from a is the
 * direction's density at a times the generalized geometry term of the chain
 * (cos_a cos_b / d^2 unfolded, with the spreading by the curved surfaces
 * in d) over cos_a; from b to a the same with the ends swapped.  Every
 * strategy that can make the path has both densities in its ratios or
 * neither (a connection never ends on a delta vertex), so the common
 * factor cancels and is left out: b's pdf_fwd is p_a(w) * cos_b and a's
 * pdf_rev is p_b(w') * cos_a (chain_pdf).  Converting only the first
 * segment to area measure instead (density 1 for the rest) misweighs
 * caustics badly: a floor point next to the glass ball makes the glass
 * look near and the camera path hitting the lamp through it look far
 * likelier than light tracing, which is the better strategy there by the
 * ratio of the lamp's area density to the camera's. */
typedef struct {
    int type;                  /* BD_* */
    int delta;                 /* surface: the subpath left it by a delta lobe */
    int delta_light;           /* light: no path can hit it (point, spot, a sun without a disk) */
    int distant;               /* light: the sun and environment, a direction rather than a point */
    int connectible;           /* a connection may end here (camera, light, a smooth lobe) */
    vec3 p;                    /* position (not for distant lights) */
    vec3 ng, ns;               /* geometric and shading normal; 0 off surfaces (camera, point light) */
    vec3 wo;                   /* surface: unit direction to the previous vertex of its subpath;
                                  distant light: unit direction from the scene toward it */
    vec3 beta;                 /* subpath throughput up to here */
    float pdf_fwd, pdf_rev;
    uint32_t light;            /* light: index into lights; surface: its area light or FR_NONE */
    float u[3];                /* camera subpath: light pick and point for s = 1; light subpath: lens point */
    vec3 weight;               /* surface: the weight of the bounce that left it (the render passes' albedo) */
    const fr_camera *camera;   /* camera: the camera at the sample's time (cam_at) */
    fr_surface sf;
    fr_material m;             /* as textured at sf */
} vert;

struct bd_work {
    uint32_t cap;
    vert *cam, *lgt;
    int ncam;                  /* the vertices of the last sample's camera subpath */
    float time;                /* the last sample's time across the shutter, which all its rays carry */
    fr_camera at;              /* the camera at that time */
};

int bd_supported(const fr_scene *s, fr_error *err)
{
    /* Fog, or a shape whose material holds a medium or bounds one. */
    int media = s->volume.fog || s->volume.camera_medium;
    for (uint32_t i = 0; i < s->n_prims && !media; i++) {
        const fr_material *m = &s->materials[s->prims[i].material];
        media = m->medium || m->interface;
    }
    for (uint32_t i = 0; i < s->n_planes && !media; i++) {
        const fr_material *m = &s->materials[s->planes[i].material];
        media = m->medium || m->interface;
    }
    if (media)
        return fr_fail(err, "the scene has participating media (fog or a medium inside a shape), which the "
                            "bidirectional integrator does not support; render it with the path integrator");
    return 0;
}

bd_work *bd_work_new(const fr_scene *s)
{
    bd_work *w = malloc(sizeof *w);
    if (!w)
        return NULL;
    w->cap = s->settings.max_depth + 2;
    w->cam = malloc(sizeof(vert) * w->cap);
    w->lgt = malloc(sizeof(vert) * w->cap);
    if (!w->cam || !w->lgt) {
        bd_work_free(w);
        return NULL;
    }
    return w;
}

void bd_work_free(bd_work *w)
{
    if (!w)
        return;
    free(w->cam);
    free(w->lgt);
    free(w);
}

static int on_surface(const vert *v) { return !v3_is_zero(v->ng); }

/* A density to divide by: 0 (a grazing step, rounding) as 1. */
static float remap0(float f) { return f != 0.0f ? f : 1.0f; }

/* Density of a distant light's ray origin on the disk it starts from (the
 * world's cross-section): directions stand for distant light vertices, so
 * the vertex after one is reached with this density times its cosine. */
static float disk_pdf(const fr_scene *s) { return 1.0f / (FM_PI * s->world.radius * s->world.radius); }

/* Whether a light path of distant light vertex l can reach point p: its
 * rays start on the disk of the world's radius one radius back from the
 * centre, so p must lie within that radius of the axis through the centre
 * and in front of the disk (with a little slack for rounding).  A point
 * of an unbounded plane far out is reached by no light path: its density
 * from the light is 0, so the strategies that would need one do not count
 * (weighing them as if they could made such points too dark). */
static int disk_reaches(const fr_scene *s, const vert *l, vec3 p)
{
    vec3 q = v3_sub(p, s->world.center);
    float along = -v3_dot(q, l->wo), r = s->world.radius * 1.001f;
    return along >= -r && v3_len2(q) - along * along <= r * r;
}

/* The density of the step from vertex `from` to vertex `to`, given as a
 * solid-angle pdf at `from`, in the measure of `to`: area (times the
 * cosine at `to` over the squared distance), or solid angle when `to` is
 * a distant light; after a distant light, the disk's density times the
 * cosine at `to` (pdf unused), 0 where no ray from the disk reaches. */
static float to_area(const fr_scene *s, float pdf, const vert *from, const vert *to)
{
    if (to->distant)
        return pdf;
    if (from->distant)
        return disk_reaches(s, from, to->p) ? disk_pdf(s) * (on_surface(to) ? fabsf(v3_dot(to->ng, from->wo)) : 1.0f)
                                            : 0.0f;
    vec3 d = v3_sub(to->p, from->p);
    float d2 = v3_len2(d);
    if (!(d2 > 0.0f))
        return 0.0f;
    float inv = 1.0f / d2;
    if (on_surface(to))
        pdf *= fabsf(v3_dot(to->ng, d)) * sqrtf(inv);
    return pdf * inv;
}

/* The density of the far end `to` of a chain of delta vertices that
 * starts at `from` with solid-angle density pdf, in the measure that
 * leaves out the chain's geometry term over the cosines (the comment on
 * vert): pdf times the cosine at `to` of unit direction w (the chain's
 * segment at `to`), the disk's density instead of pdf after a distant
 * light, pdf itself at a distant light. */
static float chain_pdf(const fr_scene *s, float pdf, const vert *from, const vert *to, vec3 w)
{
    if (to->distant)
        return pdf;
    float c = on_surface(to) ? fabsf(v3_dot(to->ng, w)) : 1.0f;
    return (from->distant ? disk_pdf(s) : pdf) * c;
}

/* Unit direction from vertex a toward vertex b (toward the light for a
 * distant b, away from it for a distant a). */
static vec3 dir_to(const vert *a, const vert *b)
{
    if (b->distant)
        return b->wo;
    if (a->distant)
        return v3_neg(a->wo);
    return v3_norm(v3_sub(b->p, a->p));
}

/* Veach's adjoint correction for shading normals, for importance carried
 * from wo to wi (1 when the shading normal is the geometric one). */
static float shading_fix(const fr_surface *sf, vec3 wo, vec3 wi)
{
    float num = fabsf(v3_dot(wo, sf->ns)) * fabsf(v3_dot(wi, sf->ng));
    float den = fabsf(v3_dot(wo, sf->ng)) * fabsf(v3_dot(wi, sf->ns));
    return den > 0.0f ? num / den : 0.0f;
}

/* The BSDF at surface vertex v for light between its subpath's previous
 * vertex and direction w, always as radiance flows (toward the camera
 * side: bsdf.h's wo is the camera side), so that both subpaths weigh a
 * path alike even where a BSDF is not symmetric (below the shading
 * hemisphere, Lambert is 0 for wi only).  On a light subpath it is
 * f(w, wo) with Veach's shading-normal correction. */
static vec3 vert_f(const vert *v, vec3 w, int importance)
{
    float pdf;
    if (!importance)
        return bsdf_eval(&v->m, &v->sf, v->wo, w, &pdf);
    vec3 f = bsdf_eval(&v->m, &v->sf, w, v->wo, &pdf);
    return v3_is_zero(f) ? f : v3_scale(f, shading_fix(&v->sf, v->wo, w));
}

/* The density with which the light subpath would start at emitter vertex
 * v: by area on its light (with the pick), for a distant light the
 * density of its direction, summed over the distant lights (with their
 * picks; any of them may shine from that direction). */
static float emit_pdf_origin(const fr_scene *s, const vert *v)
{
    if (v->distant) {
        float sum = 0.0f, pdf;
        for (uint32_t i = 0, n = lgt_n_distant(s); i < n; i++) {
            lgt_distant(s, i, v->wo, &pdf);
            sum += pdf;
        }
        return sum;
    }
    float pos, dir;
    lgt_pdf_emit(s, v->light, v->p, v->ng, v->ng, &pos, &dir);
    return pos;
}

/* Solid-angle density of light leaving local emitter vertex v along w. */
static float emit_pdf_dir(const fr_scene *s, const vert *v, vec3 w)
{
    float pos, dir;
    lgt_pdf_emit(s, v->light, v->p, v->ng, w, &pos, &dir);
    return dir;
}

/* Solid-angle density at v of the step from v toward next, given that the
 * path came to v from prev (unused at the camera and at lights); 0 at a
 * distant light (its next vertex has the disk's density: to_area's). */
static float dir_pdf(const fr_scene *s, const vert *v, const vert *prev, const vert *next)
{
    float pdf;
    if (v->distant)
        pdf = 0.0f;
    else if (v->type == BD_CAMERA)
        cam_importance(s, v->camera, v->p, dir_to(v, next), &pdf, NULL, NULL);
    else if (v->type == BD_LIGHT)
        pdf = emit_pdf_dir(s, v, dir_to(v, next));
    else
        pdf = bsdf_pdf(&v->m, &v->sf, dir_to(v, prev), dir_to(v, next));
    return pdf;
}

/* Density at `next` (to_area's measure) of the step from v to next. */
static float vert_pdf(const fr_scene *s, const vert *v, const vert *prev, const vert *next)
{
    return to_area(s, dir_pdf(s, v, prev, next), v, next);
}

/* The reverse density of the step from path[i] back to path[i - 1],
 * leaving path[i] (or `v`, standing in for it) with solid-angle density
 * pdf: at path[i - 1], or, when path[i - 1] is a delta vertex, 1 there
 * and chain_pdf's density at the chain's first end.  The pdf_rev values it
 * changes are saved in save[0..1] (with their vertices in at[]) first;
 * returns how many. */
static int set_rev_back(const fr_scene *s, vert *path, int i, const vert *v, float pdf, vert *at[2], float save[2])
{
    vert *prev = &path[i - 1];
    at[0] = prev;
    save[0] = prev->pdf_rev;
    if (!prev->delta) {
        prev->pdf_rev = to_area(s, pdf, v, prev);
        return 1;
    }
    prev->pdf_rev = 1.0f;
    int a = i - 2;
    while (a > 0 && path[a].delta)
        a--;
    at[1] = &path[a];
    save[1] = path[a].pdf_rev;
    /* From a distant light, the chain starts at prev: the disk must reach it. */
    path[a].pdf_rev = v->distant && !disk_reaches(s, v, prev->p) ? 0.0f
                                                                : chain_pdf(s, pdf, v, &path[a], path[a + 1].wo);
    return 2;
}

/* Russian roulette on a subpath whose throughput went from beta0 to *beta
 * (the ratio m of their largest channels is what its scattering kept), as
 * pathtrace.c plays it: survival q = min(1, sqrt(m)), survivors reweighted
 * by 1 / q.  Returns 0 when it ends. */
static int roulette(rnd *smp, uint32_t depth, vec3 beta0, vec3 *beta)
{
    if (depth < RR_DEPTH)
        return 1;
    float m = v3_max(*beta) / v3_max(beta0), u = rnd_1(smp);
    if (m >= 1.0f)
        return 1;
    float q = sqrtf(m);
    if (!(u < q))
        return 0;
    *beta = v3_scale(*beta, 1.0f / q);
    return 1;
}

/* Extend the subpath path[0] along ray (throughput beta, leaving path[0]
 * with solid-angle density pdf_dir) to at most maxv vertices in all;
 * importance: a light subpath.  A camera subpath that leaves the scene
 * ends on a distant light vertex when the scene has distant lights.
 * Returns the number of vertices. */
static int walk(const fr_scene *s, rnd *smp, fr_ray ray, vec3 beta, float pdf_dir, int importance, vert *path,
                int maxv)
{
    vec3 beta0 = beta;
    int n = 1, delta_in = 0;
    /* The first end of the current chain of delta vertices and the density
     * of the direction it left by (the comment on vert). */
    int anchor = 0;
    float anchor_pdf = pdf_dir;
    /* A camera subpath's ray cone for textures' mip levels, as the path
     * tracer's (pathtrace.c): its angle until a non-delta bounce, its width. */
    float spread = importance ? 0.0f : cam_pixel_spread(s), cone = 0.0f;
    for (uint32_t depth = 0; n < maxv; depth++) {
        fr_hit hit;
        vert *v = &path[n], *prev = &path[n - 1];
        if (!trace_closest(s, &ray, INFINITY, &hit)) {
            if (!importance && lgt_n_distant(s)) {
                v->type = BD_LIGHT;
                v->delta = v->delta_light = 0;
                v->distant = 1;
                v->connectible = 0;    /* only for s = 0 */
                v->ng = v->ns = v->p = v3s(0.0f);
                v->wo = ray.d;
                v->beta = beta;
                v->light = FR_NONE;
                v->pdf_fwd = delta_in ? anchor_pdf : pdf_dir;
                v->pdf_rev = 0.0f;
                n++;
            }
            break;
        }
        trace_surface(s, &ray, &hit, &v->sf);
        if (spread > 0.0f) {
            cone += spread * hit.t;
            v->sf.footprint = cam_footprint(cone, v->sf.ng, ray.d);
        }
        v->m = *tex_material(s, &s->materials[v->sf.material], &v->sf, &v->m);
        v->type = BD_SURFACE;
        v->delta = v->delta_light = v->distant = 0;
        v->connectible = bsdf_has_smooth(&v->m);
        v->p = v->sf.p;
        v->ng = v->sf.ng;
        v->ns = v->sf.ns;
        v->wo = v3_neg(ray.d);
        v->beta = beta;
        v->light = v->sf.light;
        if (delta_in) {
            v->pdf_fwd = chain_pdf(s, anchor_pdf, &path[anchor], v, ray.d);
        } else {
            v->pdf_fwd = to_area(s, pdf_dir, prev, v);
            anchor = n - 1;
            anchor_pdf = pdf_dir;
        }
        v->pdf_rev = 0.0f;
        n++;
        /* Three pairs per vertex: camera side (light pick, lobe), light
         * point, direction; light side (lobe, -), direction, lens point. */
        float ulobe, unused, u1, u2, a, b;
        if (importance) {
            rnd_2d(smp, &ulobe, &unused);
            rnd_2d(smp, &u1, &u2);
            rnd_2d(smp, &a, &b);
            v->u[0] = a;
            v->u[1] = b;
        } else {
            rnd_2d(smp, &v->u[0], &ulobe);
            rnd_2d(smp, &v->u[1], &v->u[2]);
            rnd_2d(smp, &u1, &u2);
        }
        if (n >= maxv)
            break;
        fr_bsdf_sample bs;
        if (!bsdf_sample(&v->m, &v->sf, v->wo, ulobe, u1, u2, &bs))
            break;
        vec3 weight = bs.weight;
        if (importance) {
            /* A light subpath: the BSDF as radiance flows back along it,
             * f(wi, wo), and the adjoint corrections; a delta lobe cannot
             * be evaluated, so its radiance weight is rescaled. */
            float fix = shading_fix(&v->sf, v->wo, bs.wi);
            if (bs.delta) {
                weight = v3_scale(weight, bsdf_adjoint_scale(&v->m, &v->sf, v->wo, bs.wi) * fix);
            } else {
                float unused_pdf;
                vec3 f = bsdf_eval(&v->m, &v->sf, bs.wi, v->wo, &unused_pdf);
                weight = v3_scale(f, fabsf(v3_dot(bs.wi, v->sf.ns)) * fix / bs.pdf);
            }
        }
        v->weight = weight;
        beta = v3_mul(beta, weight);
        v->delta = delta_in = bs.delta;
        pdf_dir = bs.pdf;
        if (!bs.delta)
            spread = 0.0f;
        if (bs.delta) {
            prev->pdf_rev = 1.0f;
        } else {
            vert *at[2];
            float save[2];
            set_rev_back(s, path, n - 1, v, bsdf_pdf(&v->m, &v->sf, bs.wi, v->wo), at, save);
        }
        ray.o = geo_offset(v->p, v->sf.perr, v->ng, bs.wi);
        ray.d = bs.wi;
        if (v3_is_zero(beta) || !roulette(smp, depth, beta0, &beta))
            break;
    }
    return n;
}

/* The camera subpath of pixel (x, y); from a stream (smp->st), the first
 * two numbers place it anywhere in the image instead, and *rx, *ry (when
 * not NULL) receive its raster position.  *time receives the sample's
 * time across the shutter (0 without motion, where no pair is drawn for
 * it), which every ray of the sample carries, the light subpath's too. */
static int camera_subpath(const fr_scene *s, rnd *smp, uint32_t x, uint32_t y, vert *cam, int maxv, float *rx,
                          float *ry, float *time, fr_camera *at)
{
    float px, py, lx = 0.0f, ly = 0.0f, pdf_dir;
    rnd_2d(smp, &px, &py);
    if (!smp->smp) {
        float fx = px * (float)s->settings.width, fy = py * (float)s->settings.height;
        x = fx < (float)s->settings.width ? (uint32_t)fx : s->settings.width - 1;
        y = fy < (float)s->settings.height ? (uint32_t)fy : s->settings.height - 1;
        px = fx - (float)x;
        py = fy - (float)y;
        if (rx) {
            *rx = fx;
            *ry = fy;
        }
    }
    if (s->camera.aperture > 0.0f)
        rnd_2d(smp, &lx, &ly);
    else
        rnd_skip(smp);         /* a pinhole has no lens to sample */
    *time = 0.0f;
    if (s->motion.flags) {
        /* As the path tracer draws it (pathtrace.c). */
        float unused;
        rnd_2d(smp, time, &unused);
    }
    cam_at(s, *time, at);
    fr_ray ray = pt_camera_ray_from(s, at, x, y, px, py, lx, ly);
    ray.time = *time;
    cam_importance(s, at, ray.o, ray.d, &pdf_dir, NULL, NULL);
    vert *c = &cam[0];
    c->type = BD_CAMERA;
    c->delta = c->delta_light = c->distant = 0;
    c->connectible = 1;
    c->p = ray.o;
    c->ng = c->ns = c->wo = v3s(0.0f);
    c->beta = v3s(1.0f);
    c->pdf_fwd = c->pdf_rev = 0.0f;
    c->light = FR_NONE;
    c->camera = at;
    return walk(s, smp, ray, c->beta, pdf_dir, 0, cam, maxv);
}

/* The light subpath, its rays at the camera subpath's time. */
static int light_subpath(const fr_scene *s, rnd *smp, vert *lgt, int maxv, float time)
{
    float upick, unused, u1, u2, u3, u4;
    rnd_2d(smp, &upick, &unused);
    rnd_2d(smp, &u1, &u2);
    rnd_2d(smp, &u3, &u4);
    fr_light_emit e;
    if (!lgt_sample_emit(s, upick, u1, u2, u3, u4, &e))
        return 0;
    vert *l = &lgt[0];
    int local = !e.distant && !e.delta_pos;   /* an area light: a point on a surface */
    l->type = BD_LIGHT;
    l->delta = 0;
    l->delta_light = e.delta_pos || e.delta_dir;
    l->distant = e.distant;
    l->connectible = 1;
    l->p = e.ray.o;
    l->ng = l->ns = local ? e.n : v3s(0.0f);
    l->wo = e.distant ? v3_neg(e.ray.d) : v3s(0.0f);
    l->sf.perr = e.perr;
    l->beta = v3_scale(e.Le, 1.0f / e.pdf_pos);
    l->light = e.light;
    l->pdf_rev = 0.0f;
    /* A distant light's vertex is its direction: its density is that of
     * the direction (emit_pdf_origin), and the disk's goes to the next
     * vertex (to_area). */
    l->pdf_fwd = e.distant ? emit_pdf_origin(s, l) : e.pdf_pos;
    float cosl = local ? fabsf(v3_dot(e.n, e.ray.d)) : 1.0f;
    vec3 beta = v3_scale(e.Le, cosl / (e.pdf_pos * e.pdf_dir));
    fr_ray ray = {local ? geo_offset(e.ray.o, e.perr, e.n, e.ray.d) : e.ray.o, e.ray.d, time};
    return walk(s, smp, ray, beta, e.pdf_dir, 1, lgt, maxv);
}

/* 1 if nothing blocks the segment from surface vertex a to surface
 * vertex b.  The segment leaves a pushed off its surface (geo_offset) and
 * ends short of b by a bound on how far the rounding of a hit distance can
 * put b's own surface in front of b (a few dozen ulps of the coordinates
 * involved), so that b's surface does not hide b.  At the sample's time. */
static int visible(const fr_scene *s, const vert *a, const vert *b, float time)
{
    vec3 o = geo_offset(a->p, a->sf.perr, a->ng, v3_sub(b->p, a->p)), d = v3_sub(b->p, o);
    float len = v3_len(d);
    float margin = (v3_max(v3_abs(o)) + v3_max(v3_abs(b->p)) + v3_max(b->sf.perr)) * GEO_GAMMA(32);
    if (!(len > margin))
        return 1;
    fr_ray r = {o, v3_scale(d, 1.0f / len), time};
    return !trace_occluded(s, &r, len - margin, FR_NONE);
}

/* Power-heuristic weight of strategy (s_, t) for the path it made, by the
 * ratios of each neighbouring strategy's density to this one's (pbrt-v3's
 * MISWeight with squared ratios, and chains of delta vertices as the
 * comment on vert says).  `sampled` is the vertex the strategy sampled
 * itself (s_ = 1: a light point, t = 1: a lens point). */
static float mis_weight(const fr_scene *s, vert *cam, vert *lgt, const vert *sampled, int s_, int t)
{
    if (s_ + t == 2)
        return 1.0f;
    vert *qs = s_ > 0 ? &lgt[s_ - 1] : NULL, *pt = &cam[t - 1];
    vert *qs_m = s_ > 1 ? &lgt[s_ - 2] : NULL, *pt_m = t > 1 ? &cam[t - 2] : NULL;
    /* The strategy's own view of its end vertices, swapped in and out. */
    vert saved;
    vert *slot = s_ == 1 ? qs : t == 1 ? pt : NULL;
    if (slot) {
        saved = *slot;
        *slot = *sampled;
    }
    /* The reverse densities at the connection and behind its ends: up to
     * six pdf_rev values, restored at the end. */
    vert *at[6];
    float save[6];
    int n = 0;
    int pt_delta = pt->delta, qs_delta = qs ? qs->delta : 0;
    pt->delta = 0;
    if (qs)
        qs->delta = 0;
    at[n] = pt;
    save[n++] = pt->pdf_rev;
    pt->pdf_rev = s_ > 0 ? vert_pdf(s, qs, qs_m, pt) : emit_pdf_origin(s, pt);
    if (pt_m) {
        /* s = 0: pt is an emitter the camera subpath found, seen as the
         * start of a light subpath. */
        float pdf = s_ > 0 ? dir_pdf(s, pt, qs, pt_m) : pt->distant ? 0.0f : emit_pdf_dir(s, pt, dir_to(pt, pt_m));
        n += set_rev_back(s, cam, t - 1, pt, pdf, at + n, save + n);
    }
    if (qs) {
        at[n] = qs;
        save[n++] = qs->pdf_rev;
        qs->pdf_rev = vert_pdf(s, pt, pt_m, qs);
    }
    if (qs_m)
        n += set_rev_back(s, lgt, s_ - 1, qs, dir_pdf(s, qs, pt, qs_m), at + n, save + n);

    /* Delta vertices count 1 both ways: skipped. */
    float sum = 0.0f, r = 1.0f;
    for (int i = t - 1; i > 0; i--) {
        if (cam[i].delta)
            continue;
        r *= cam[i].pdf_rev / remap0(cam[i].pdf_fwd);
        if (!cam[i - 1].delta)
            sum += r * r;
    }
    r = 1.0f;
    for (int i = s_ - 1; i >= 0; i--) {
        if (lgt[i].delta)
            continue;
        r *= lgt[i].pdf_rev / remap0(lgt[i].pdf_fwd);
        int delta_before = i > 0 ? lgt[i - 1].delta : lgt[0].delta_light;
        if (!delta_before)
            sum += r * r;
    }

    /* Restore in reverse order: a vertex saved twice gets its first value. */
    while (n > 0) {
        n--;
        at[n]->pdf_rev = save[n];
    }
    pt->delta = pt_delta;
    if (qs)
        qs->delta = qs_delta;
    if (slot)
        *slot = saved;
    return 1.0f / (1.0f + sum);
}

/* The unweighted contribution of strategy (s_, t), 0 when it makes no
 * path; *sampled receives the vertex it sampled (s_ = 1 or t = 1) and, for
 * t = 1, *rx, *ry the raster position. */
static vec3 connect(const fr_scene *s, bd_work *w, int s_, int t, vert *sampled, float *rx, float *ry)
{
    const vec3 zero = v3s(0.0f);
    if (s_ == 0) {
        const vert *pt = &w->cam[t - 1];
        if (pt->distant) {
            vec3 le = zero;
            float pdf;
            for (uint32_t i = 0, n = lgt_n_distant(s); i < n; i++)
                le = v3_add(le, lgt_distant(s, i, pt->wo, &pdf));
            return v3_mul(pt->beta, le);
        }
        if (pt->type != BD_SURFACE || pt->light == FR_NONE)
            return zero;
        return v3_mul(pt->beta, lgt_emitted(&pt->m, pt->ng, pt->wo));
    }
    if (t == 1) {
        const vert *qs = &w->lgt[s_ - 1];
        if (!qs->connectible)
            return zero;
        const fr_camera *c = &w->at;
        vec3 lens = v3_add(c->position, cam_lens(c, qs->u[0], qs->u[1]));
        vec3 d = v3_sub(qs->p, lens);
        float d2 = v3_len2(d);
        if (!(d2 > 0.0f))
            return zero;
        float dist = sqrtf(d2), pdf_dir;
        vec3 wc = v3_scale(d, 1.0f / dist), wi = v3_neg(wc);
        float we = cam_importance(s, c, lens, wc, &pdf_dir, rx, ry);
        if (!(we > 0.0f))
            return zero;
        /* The lens point was sampled by area: the solid-angle density at
         * qs is d^2 / (cos lens_area). */
        float g = we * v3_dot(wc, c->forward) * cam_lens_area(c) / d2;
        vec3 L = v3_scale(v3_mul(qs->beta, vert_f(qs, wi, 1)), fabsf(v3_dot(wi, qs->ns)) * g);
        if (v3_is_zero(L))
            return zero;
        fr_ray r = {geo_offset(qs->p, qs->sf.perr, qs->ng, wi), wi, w->time};
        if (trace_occluded(s, &r, v3_len(v3_sub(lens, r.o)), FR_NONE))
            return zero;
        sampled->type = BD_CAMERA;
        sampled->delta = sampled->delta_light = sampled->distant = 0;
        sampled->connectible = 1;
        sampled->p = lens;
        sampled->ng = sampled->ns = sampled->wo = zero;
        sampled->light = FR_NONE;
        sampled->camera = c;
        sampled->pdf_fwd = sampled->pdf_rev = 0.0f;
        return L;
    }
    vert *pt = &w->cam[t - 1];
    if (!pt->connectible)
        return zero;
    if (s_ == 1) {
        fr_light_sample ls;
        /* The power table's pick, as the light subpaths start by: the
         * strategies' densities of this vertex (emit_pdf_origin) are its. */
        if (!lgt_sample_table(s, pt->p, pt->u[0], pt->u[1], pt->u[2], &ls))
            return zero;
        vec3 L = v3_mul(v3_mul(pt->beta, vert_f(pt, ls.wi, 0)), ls.radiance);
        L = v3_scale(L, fabsf(v3_dot(ls.wi, pt->ns)) / ls.pdf);
        if (v3_is_zero(L))
            return zero;
        fr_ray r = {geo_offset(pt->p, pt->sf.perr, pt->ng, ls.wi), ls.wi, w->time};
        float tmax = ls.distant ? INFINITY : v3_dot(v3_sub(ls.p, r.o), ls.wi);
        if (!(tmax > 0.0f) || trace_occluded(s, &r, tmax, ls.prim))
            return zero;
        int area = !ls.distant && ls.prim != FR_NONE;
        sampled->type = BD_LIGHT;
        sampled->delta = 0;
        sampled->delta_light = ls.delta;
        sampled->distant = ls.distant;
        sampled->connectible = 1;
        sampled->p = ls.p;
        sampled->ng = sampled->ns = area ? ls.n : zero;
        sampled->wo = ls.distant ? ls.wi : zero;
        sampled->light = ls.light;
        sampled->pdf_fwd = emit_pdf_origin(s, sampled);
        sampled->pdf_rev = 0.0f;
        return L;
    }
    const vert *qs = &w->lgt[s_ - 1];
    if (!qs->connectible)
        return zero;
    vec3 d = v3_sub(pt->p, qs->p);
    float d2 = v3_len2(d);
    if (!(d2 > 0.0f))
        return zero;
    vec3 wq = v3_scale(d, 1.0f / sqrtf(d2));   /* from qs toward pt */
    vec3 fq = vert_f(qs, wq, 1), fp = vert_f(pt, v3_neg(wq), 0);
    float g = fabsf(v3_dot(wq, qs->ns)) * fabsf(v3_dot(wq, pt->ns)) / d2;
    vec3 L = v3_scale(v3_mul(v3_mul(qs->beta, fq), v3_mul(fp, pt->beta)), g);
    if (v3_is_zero(L) || !visible(s, qs, pt, w->time))
        return zero;
    return L;
}

static int finite3(vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

/* bd_sample, also adding each weighted contribution's luminance to
 * by_depth[its depth] when by_depth is not NULL; below > 0 keeps only the
 * depths under it (with st all MIS-weighted) and traces the subpaths no
 * further than they need: a vertex's numbers and pdfs do not depend on
 * the vertices after it, so the paths kept are the same bits. */
static vec3 sample(const fr_scene *s, bd_work *w, const bd_strategy *st, uint32_t x, uint32_t y, uint32_t index,
                   bd_splat_fn splat, void *ctx, double *by_depth, int below)
{
    fr_sampler cs, ls;
    smp_start(&cs, x, y, index, s->settings.seed);
    ls = cs;
    ls.dim = LIGHT_DIM;
    int maxd = (int)s->settings.max_depth;
    if (below > 0 && below - 1 < maxd)
        maxd = below - 1;
    rnd rc = {&cs, NULL}, rl = {&ls, NULL};
    int nc = w->ncam = camera_subpath(s, &rc, x, y, w->cam, maxd + 2, NULL, NULL, &w->time, &w->at);
    int nl = light_subpath(s, &rl, w->lgt, maxd + 1, w->time);
    /* s = 1 samples its own light point: possible even when the light
     * subpath could not start. */
    int smax = nl > 0 ? nl : s->n_lights > 0;
    int use_mis = st->s < 0;
    vec3 L = v3s(0.0f);
    for (int t = 1; t <= nc; t++)
        for (int s_ = 0; s_ <= smax; s_++) {
            int depth = s_ + t - 2;
            if ((s_ == 1 && t == 1) || depth < 0 || depth > maxd)
                continue;
            if (use_mis ? (st->depth >= 0 && depth != st->depth) : (s_ != st->s || t != st->t))
                continue;
            vert sampled;
            float rx = 0.0f, ry = 0.0f;
            vec3 c = connect(s, w, s_, t, &sampled, &rx, &ry);
            if (v3_is_zero(c))
                continue;
            if (use_mis)
                c = v3_scale(c, mis_weight(s, w->cam, w->lgt, &sampled, s_, t));
            if (by_depth && finite3(c))
                by_depth[depth] += v3_luma(c);
            if (t > 1)
                L = v3_add(L, c);
            else if (finite3(c))
                splat(ctx, (uint32_t)rx, (uint32_t)ry, c.x, c.y, c.z);
        }
    return finite3(L) ? L : v3s(0.0f);
}

vec3 bd_sample(const fr_scene *s, bd_work *w, const bd_strategy *st, uint32_t x, uint32_t y, uint32_t index,
               bd_splat_fn splat, void *ctx)
{
    return sample(s, w, st, x, y, index, splat, ctx, NULL, 0);
}

static void no_splat(void *ctx, uint32_t x, uint32_t y, float r, float g, float b)
{
    (void)ctx, (void)x, (void)y, (void)r, (void)g, (void)b;
}

#define NORM_BLOCK 4096u /* samples a block of bd_depth_means_mt */
#define NORM_WAVE 1024u  /* blocks summed before they are added up (2^22 samples) */

/* One bd_depth_means_mt: its samples (sample j is pixel k = j / spp of
 * `used` spread evenly, sample index j % spp) and the wave of blocks being
 * summed, which its threads take one at a time. */
typedef struct {
    const fr_scene *s;
    uint64_t width, pixels, used, spp, total;
    uint32_t nd;
    uint64_t first;            /* the wave's first block */
    uint32_t count;            /* its blocks */
    atomic_uint next;          /* the next of them to take */
    atomic_int failed;         /* a thread ran out of memory */
    double *sums;              /* count * nd: each block's sums per depth */
    bd_stop_fn stop;
    void *ctx;
    atomic_int stopped;        /* stop said so */
} norm_job;

static void *norm_thread(void *arg)
{
    norm_job *j = arg;
    bd_work *w = bd_work_new(j->s);
    if (!w) {
        atomic_store(&j->failed, 1);
        return NULL;
    }
    const bd_strategy all = {-1, -1, -1};
    for (unsigned b; (b = atomic_fetch_add(&j->next, 1)) < j->count;) {
        if (atomic_load(&j->stopped) || (j->stop && j->stop(j->ctx))) {
            atomic_store(&j->stopped, 1);
            break;
        }
        uint64_t j0 = (j->first + b) * NORM_BLOCK, j1 = j0 + NORM_BLOCK < j->total ? j0 + NORM_BLOCK : j->total;
        for (uint64_t q = j0; q < j1; q++) {
            uint64_t p = q / j->spp * j->pixels / j->used;
            sample(j->s, w, &all, (uint32_t)(p % j->width), (uint32_t)(p / j->width), (uint32_t)(q % j->spp),
                   no_splat, NULL, j->sums + (size_t)b * j->nd, 0);
        }
    }
    bd_work_free(w);
    return NULL;
}

int bd_depth_means_mt(const fr_scene *s, uint32_t n, int threads, bd_stop_fn stop, void *ctx, double *by_depth)
{
    norm_job j = {.s = s, .width = s->settings.width, .nd = s->settings.max_depth + 1, .stop = stop, .ctx = ctx};
    j.pixels = j.width * s->settings.height;
    /* Every pixel spp times, or n pixels evenly spread once each. */
    j.spp = n > j.pixels ? (n + j.pixels - 1) / j.pixels : 1;
    j.used = n > j.pixels ? j.pixels : (n ? n : 1);
    j.total = j.used * j.spp;
    uint64_t blocks = (j.total + NORM_BLOCK - 1) / NORM_BLOCK;
    threads = threads < 1 ? 1 : threads;
    j.sums = malloc((size_t)NORM_WAVE * j.nd * sizeof *j.sums);
    pthread_t *tid = malloc((size_t)threads * sizeof *tid);
    int rc = j.sums && tid ? 0 : -1;
    atomic_init(&j.failed, 0);
    atomic_init(&j.stopped, 0);
    for (uint32_t d = 0; d < j.nd; d++)
        by_depth[d] = 0.0;
    for (j.first = 0; rc == 0 && j.first < blocks; j.first += NORM_WAVE) {
        j.count = blocks - j.first < NORM_WAVE ? (uint32_t)(blocks - j.first) : NORM_WAVE;
        memset(j.sums, 0, (size_t)j.count * j.nd * sizeof *j.sums);
        atomic_init(&j.next, 0);
        int started = 0;
        for (int t = 1; t < threads && (uint32_t)t < j.count; t++)
            started += pthread_create(&tid[started], NULL, norm_thread, &j) == 0;
        norm_thread(&j);
        for (int t = 0; t < started; t++)
            pthread_join(tid[t], NULL);
        if (atomic_load(&j.failed))
            rc = -1;
        else if (atomic_load(&j.stopped))
            rc = 1;
        /* In block order, whichever thread summed each block. */
        for (uint32_t b = 0; rc == 0 && b < j.count; b++)
            for (uint32_t d = 0; d < j.nd; d++)
                by_depth[d] += j.sums[(size_t)b * j.nd + d];
    }
    for (uint32_t d = 0; rc == 0 && d < j.nd; d++)
        by_depth[d] /= (double)j.total;
    free(tid);
    free(j.sums);
    return rc;
}

int bd_depth_means(const fr_scene *s, uint32_t n, double *by_depth)
{
    return bd_depth_means_mt(s, n, 1, NULL, NULL, by_depth);
}

vec3 bd_path(const fr_scene *s, bd_work *w, int s_, int t, const bd_stream *cam, const bd_stream *light, float *rx,
             float *ry)
{
    const vec3 zero = v3s(0.0f);
    if (t < 1 || s_ < 0 || (s_ == 1 && t == 1) || s_ + t - 2 > (int)s->settings.max_depth || s_ + t < 2)
        return zero;
    rnd rc = {NULL, cam}, rl = {NULL, light};
    float cx = 0.0f, cy = 0.0f;
    if (camera_subpath(s, &rc, 0, 0, w->cam, t, &cx, &cy, &w->time, &w->at) != t)
        return zero;
    /* s = 1 samples its light point from the camera vertex's numbers. */
    if (s_ > 1 && light_subpath(s, &rl, w->lgt, s_, w->time) != s_)
        return zero;
    if (s_ == 1 && s->n_lights == 0)
        return zero;
    vert sampled;
    float lx = 0.0f, ly = 0.0f;
    vec3 c = connect(s, w, s_, t, &sampled, &lx, &ly);
    if (v3_is_zero(c))
        return zero;
    c = v3_scale(c, mis_weight(s, w->cam, w->lgt, &sampled, s_, t));
    if (!finite3(c))
        return zero;
    *rx = t == 1 ? lx : cx;
    *ry = t == 1 ? ly : cy;
    return c;
}

typedef struct {
    uint64_t *buf;
    uint32_t width;
    float scale;               /* the render's spp over the samples taken (1: the same bits) */
} fixed_splats;

static void add_fixed(void *ctx, uint32_t x, uint32_t y, float r, float g, float b)
{
    fixed_splats *f = ctx;
    uint64_t *p = f->buf + ((size_t)y * f->width + x) * 3;
    spl_add(&p[0], spl_fixed(r * f->scale));
    spl_add(&p[1], spl_fixed(g * f->scale));
    spl_add(&p[2], spl_fixed(b * f->scale));
}

/* The passes of one sample from its camera subpath cam[0..n) (passes.h;
 * bdpt.h says which): the first hit, and albedo and normal at the first
 * surface that is not a perfect mirror or smooth glass. */
static void camera_passes(const fr_scene *s, const vert *cam, int n, pass_sample *p)
{
    pass_start(p);
    if (n < 2 || cam[1].type != BD_SURFACE)
        return;
    pass_first_hit(p, cam[1].p, cam[1].sf.material, pass_object(s, &cam[1].sf), cam[0].p);
    for (int i = 1; i < n && cam[i].type == BD_SURFACE && !p->albedo_done; i++) {
        pass_albedo_at(p, &cam[i].m, &cam[i].sf, v3_neg(cam[i].wo));
        if (!p->albedo_done && i + 1 < n)
            pass_albedo_through(p, cam[i].weight);
    }
}

int bd_render_rows(const fr_scene *s, uint32_t y0, uint32_t y1, float *rgb, uint64_t *splat, fr_error *err)
{
    return bd_render_rows_passes(s, y0, y1, rgb, splat, 0, NULL, err);
}

/* Rows [y0, y1) at spp samples per pixel, depths under below (0: all),
 * splats scaled to the scene's spp (bd_render_rows_passes). */
static int render_rows(const fr_scene *s, uint32_t y0, uint32_t y1, int below, uint32_t spp, float *rgb,
                       uint64_t *splat, uint32_t passes, float *out, fr_error *err)
{
    if (passes & ~BD_PASSES)
        return fr_fail(err, "bidirectional path tracing does not fill render passes beyond the camera subpath's");
    if (bd_supported(s, err) < 0)
        return -1;
    bd_work *w = bd_work_new(s);
    if (!w)
        return fr_fail(err, "out of memory for the bidirectional subpaths");
    const bd_strategy all = {-1, -1, -1};
    fixed_splats f = {splat, s->settings.width, (float)s->settings.spp / (float)spp};
    uint32_t width = s->settings.width;
    uint32_t nch = pass_channels(passes);
    pass_sample ps;
    for (uint32_t y = y0; y < y1; y++)
        for (uint32_t x = 0; x < width; x++) {
            double acc[3] = {0, 0, 0}, pacc[PASS_MAX_ACC] = {0};
            for (uint32_t i = 0; i < spp; i++) {
                vec3 c = sample(s, w, &all, x, y, i, add_fixed, &f, NULL, below);
                acc[0] += c.x; acc[1] += c.y; acc[2] += c.z;
                if (passes) {
                    camera_passes(s, w->cam, w->ncam, &ps);
                    pass_accumulate(pacc, passes, &ps, i);
                }
            }
            float *px = rgb + ((size_t)(y - y0) * width + x) * 3;
            px[0] = (float)(acc[0] / spp);
            px[1] = (float)(acc[1] / spp);
            px[2] = (float)(acc[2] / spp);
            if (passes)
                pass_finish(pacc, passes, spp, out + ((size_t)(y - y0) * width + x) * nch);
        }
    bd_work_free(w);
    return 0;
}

int bd_render_rows_passes(const fr_scene *s, uint32_t y0, uint32_t y1, float *rgb, uint64_t *splat, uint32_t passes,
                          float *out, fr_error *err)
{
    return render_rows(s, y0, y1, 0, s->settings.spp, rgb, splat, passes, out, err);
}

int bd_render_short(const fr_scene *s, uint32_t y0, uint32_t y1, int below, uint32_t spp, float *rgb,
                    uint64_t *splat, fr_error *err)
{
    return render_rows(s, y0, y1, below, spp ? spp : 1, rgb, splat, 0, NULL, err);
}
