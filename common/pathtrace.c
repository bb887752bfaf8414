#include "pathtrace.h"

#include "bsdf.h"
#include "fmath.h"
#include "light.h"
#include "medium.h"
#include "sampler.h"

/* Bounces before Russian roulette may end a path. */
#define RR_DEPTH 4
#include "texture.h"

/* Power heuristic with beta = 2 (Veach 1997). */
static float power_heuristic(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

/* Russian roulette after a few bounces: the path survives with a
 * probability that follows its throughput, and survivors are reweighted.
 * Returns 0 when the path ends. */
static int roulette(fr_sampler *smp, uint32_t depth, vec3 *beta)
{
    if (depth < RR_DEPTH)
        return 1;
    float m = v3_max(*beta), q = m < 0.95f ? m : 0.95f;
    if (!(smp_random(smp) < q))
        return 0;
    *beta = v3_scale(*beta, 1.0f / q);
    return 1;
}

fr_ray pt_camera_ray(const fr_scene *s, uint32_t x, uint32_t y, float px, float py, float lx, float ly)
{
    const fr_camera *c = &s->camera;
    float w = (float)s->settings.width, h = (float)s->settings.height;
    float sx = (2.0f * ((float)x + px) - w) / h * c->tan_half;
    float sy = (h - 2.0f * ((float)y + py)) / h * c->tan_half;
    vec3 d = v3_add(c->forward, v3_add(v3_scale(c->right, sx), v3_scale(c->upv, sy)));
    fr_ray r = {c->position, d};
    if (c->aperture > 0.0f) {
        /* Uniform point on the lens disk (concentric mapping keeps the
         * stratification of lx, ly); aim at the point of the focal plane the
         * pinhole ray reaches, `focus` along the view axis. */
        float a = 2.0f * lx - 1.0f, b = 2.0f * ly - 1.0f, rad, phi;
        if (a == 0.0f && b == 0.0f) {
            rad = 0.0f; phi = 0.0f;
        } else if (fabsf(a) > fabsf(b)) {
            rad = a; phi = 0.25f * FM_PI * (b / a);
        } else {
            rad = b; phi = 0.5f * FM_PI - 0.25f * FM_PI * (a / b);
        }
        float sn, cs;
        fm_sincosf(phi, &sn, &cs);
        rad *= c->aperture;
        vec3 lens = v3_add(v3_scale(c->right, rad * cs), v3_scale(c->upv, rad * sn));
        vec3 focus = v3_madd(c->position, d, c->focus);
        r.o = v3_add(c->position, lens);
        r.d = v3_sub(focus, r.o);
    }
    r.d = v3_norm(r.d);
    return r;
}

/* Equiangular sampling toward a point light over one medium segment
 * (o + t d, t in [0, tmax), medium `medium`, throughput beta at o): the
 * single-scattering estimate of light picked by upick, at a distance chosen
 * by u, weighted by MIS against the free-flight sampling that the path
 * itself does on the same segment (its vertices' point-light estimates take
 * the complementary weight).  Area lights are left to the path's vertices. */
static vec3 equiangular(const fr_scene *s, uint32_t medium, const fr_ray *ray, float tmax, vec3 beta, float upick,
                        float u)
{
    const fr_medium *md = &s->media[medium - 1];
    const fr_light *l = &s->lights[lgt_pick(s, upick)];
    float t, pe;
    if (l->kind != FR_LIGHT_POINT || v3_is_zero(md->sigma_s) ||
        !med_equiangular(ray->o, ray->d, tmax, l->position, u, &t, &pe))
        return v3s(0.0f);
    vec3 x = v3_madd(ray->o, ray->d, t), to = v3_sub(l->position, x);
    float d2 = v3_len2(to), d = sqrtf(d2);
    fr_ray shadow = {x, v3_scale(to, 1.0f / d)};
    vec3 tr = med_shadow(s, medium, &shadow, d, FR_NONE);
    if (v3_is_zero(tr))
        return v3s(0.0f);
    float pd = med_distance_pdf(md, beta, t);
    float w = power_heuristic(pe, pd) * med_phase(md->g, v3_dot(ray->d, shadow.d)) / (pe * l->pick * d2);
    vec3 f = v3_mul(v3_mul(med_transmittance(md, t), md->sigma_s), v3_mul(tr, l->intensity));
    return v3_scale(v3_mul(beta, f), w);
}

vec3 pt_sample(const fr_scene *s, pt_strategy strategy, uint32_t x, uint32_t y, uint32_t index)
{
    fr_sampler smp;
    smp_start(&smp, x, y, index, s->settings.seed);
    float px, py, lx, ly;
    smp_2d(&smp, &px, &py);
    smp_2d(&smp, &lx, &ly);
    fr_ray ray = pt_camera_ray(s, x, y, px, py, lx, ly);

    vec3 L = v3s(0.0f), beta = v3s(1.0f);
    float prev_pdf = 0.0f;     /* solid-angle pdf of the last BSDF sample */
    int prev_delta = 1;        /* the camera ray counts as a delta event */
    vec3 prev_p = ray.o;
    uint32_t medium = s->volume.camera_medium;   /* the ray's medium: 1 + index, 0 = vacuum */
    int equi = strategy == PT_MIS || strategy == PT_LIGHT_ONLY;
    for (uint32_t depth = 0;; depth++) {
        fr_hit hit;
        fr_surface sf;
        int found = trace_closest(s, &ray, INFINITY, &hit);
        if (s->n_media) {
            /* Media (medium.h): sample each medium segment up to the next
             * surface, crossing invisible media boundaries, until the path
             * scatters in a medium or reaches a real surface. */
            int scattered = 0;
            fr_ray seg = ray;          /* the segment the path scattered on */
            vec3 seg_beta = beta;      /* and the throughput at its start */
            float seg_tmax = 0.0f, t = 0.0f;
            for (uint32_t crossings = 0;; crossings++) {
                float tmax = found ? hit.t : INFINITY;
                if (medium) {
                    const fr_medium *md = &s->media[medium - 1];
                    float uch, ud, ueq_pick, ueq;
                    smp_2d(&smp, &uch, &ud);
                    smp_2d(&smp, &ueq_pick, &ueq);
                    if (equi && depth < s->settings.max_depth && s->n_lights)
                        L = v3_add(L, equiangular(s, medium, &ray, tmax, beta, ueq_pick, ueq));
                    vec3 w;
                    scattered = med_sample_distance(md, tmax, beta, uch, ud, &t, &w);
                    if (scattered) {
                        seg = ray;
                        seg_beta = beta;
                        seg_tmax = tmax;
                    }
                    beta = v3_mul(beta, w);
                    if (scattered)
                        break;
                }
                if (!found)
                    break;
                trace_surface(s, &ray, &hit, &sf);
                const fr_material *mb = &s->materials[sf.material];
                if (!mb->interface)
                    break;
                if (crossings == 64) {
                    found = 0;
                    break;
                }
                medium = med_after(s, medium, mb, sf.ng, ray.d);
                ray.o = geo_offset(sf.p, sf.ng, ray.d);
                found = trace_closest(s, &ray, INFINITY, &hit);
            }
            if (scattered) {
                /* A scattering vertex in the medium: light sampling (MIS
                 * against phase sampling for area lights, against
                 * equiangular sampling for point lights), then a new
                 * direction from the phase function. */
                if (depth >= s->settings.max_depth)
                    break;
                const fr_medium *md = &s->media[medium - 1];
                vec3 p = v3_madd(seg.o, seg.d, t);
                /* The same dimensions as a surface vertex (the lobe
                 * number goes unused). */
                float upick, unused, u1, u2, v1, v2;
                smp_2d(&smp, &upick, &unused);
                smp_2d(&smp, &u1, &u2);
                smp_2d(&smp, &v1, &v2);
                fr_light_sample ls;
                if (strategy != PT_BSDF_ONLY && lgt_sample(s, p, upick, u1, u2, &ls)) {
                    fr_ray shadow = {p, ls.wi};
                    vec3 tr = med_shadow(s, medium, &shadow, ls.dist, ls.prim);
                    float ph = med_phase(md->g, v3_dot(seg.d, ls.wi)), w = 1.0f;
                    if (ls.delta && equi)
                        w = power_heuristic(med_distance_pdf(md, seg_beta, t),
                                            med_equiangular_pdf(seg.o, seg.d, seg_tmax, ls.p, t));
                    else if (!ls.delta && strategy != PT_LIGHT_ONLY)
                        w = power_heuristic(ls.pdf, ph);
                    L = v3_add(L, v3_scale(v3_mul(beta, v3_mul(tr, ls.radiance)), w * ph / ls.pdf));
                }
                ray.o = p;
                ray.d = med_sample_phase(md->g, seg.d, v1, v2);
                prev_pdf = med_phase(md->g, v3_dot(seg.d, ray.d));
                prev_delta = 0;
                prev_p = p;
                if (!roulette(&smp, depth, &beta))
                    break;
                continue;
            }
            if (!found)
                break;
        } else {
            if (!found)
                break;
            trace_surface(s, &ray, &hit, &sf);
        }
        fr_material textured;
        const fr_material *m = tex_material(s, &s->materials[sf.material], &sf, &textured);
        vec3 wo = v3_neg(ray.d);

        /* Light reached by the BSDF sample (or seen directly). */
        if (sf.light != FR_NONE) {
            vec3 le = lgt_emitted(m, sf.ng, wo);
            if (!v3_is_zero(le)) {
                float w = 1.0f;
                if (!prev_delta) {
                    if (strategy == PT_LIGHT_ONLY)
                        w = 0.0f;
                    else if (strategy != PT_BSDF_ONLY)
                        w = power_heuristic(prev_pdf, lgt_pdf(s, sf.light, prev_p, sf.p, sf.ng));
                }
                L = v3_add(L, v3_scale(v3_mul(beta, le), w));
            }
        }
        if (depth >= s->settings.max_depth)
            break;

        float upick, ulobe, u1, u2, v1, v2;
        smp_2d(&smp, &upick, &ulobe);
        smp_2d(&smp, &u1, &u2);
        smp_2d(&smp, &v1, &v2);

        /* Next-event estimation toward one light. */
        fr_light_sample ls;
        if (strategy != PT_BSDF_ONLY && bsdf_has_smooth(m) && lgt_sample(s, sf.p, upick, u1, u2, &ls)) {
            float bpdf;
            vec3 f = bsdf_eval(m, &sf, wo, ls.wi, &bpdf);
            if (!v3_is_zero(f)) {
                fr_ray shadow = {geo_offset(sf.p, sf.ng, ls.wi), ls.wi};
                float tmax = v3_dot(v3_sub(ls.p, shadow.o), ls.wi);
                vec3 tr = v3s(1.0f);
                if (s->n_media && tmax > 0.0f)
                    tr = med_shadow(s, med_after(s, medium, m, sf.ng, ls.wi), &shadow, tmax, ls.prim);
                if (tmax > 0.0f && !v3_is_zero(tr) && (s->n_media || !trace_occluded(s, &shadow, tmax, ls.prim))) {
                    float w = (ls.delta || strategy == PT_LIGHT_ONLY) ? 1.0f : power_heuristic(ls.pdf, bpdf);
                    float cosi = fabsf(v3_dot(ls.wi, sf.ns));
                    L = v3_add(L, v3_scale(v3_mul(beta, v3_mul(v3_mul(tr, f), ls.radiance)), w * cosi / ls.pdf));
                }
            }
        }

        /* Continue the path by sampling the BSDF. */
        fr_bsdf_sample bs;
        if (!bsdf_sample(m, &sf, wo, ulobe, v1, v2, &bs))
            break;
        beta = v3_mul(beta, bs.weight);
        prev_pdf = bs.pdf;
        prev_delta = bs.delta;
        prev_p = sf.p;
        medium = med_after(s, medium, m, sf.ng, bs.wi);
        ray.o = geo_offset(sf.p, sf.ng, bs.wi);
        ray.d = bs.wi;

        if (!roulette(&smp, depth, &beta))
            break;
    }
    /* A NaN or infinity from a degenerate configuration would poison the
     * pixel; drop the sample instead (it happens the same way everywhere). */
    if (!isfinite(L.x) || !isfinite(L.y) || !isfinite(L.z))
        return v3s(0.0f);
    return L;
}

void pt_render_rows(const fr_scene *s, pt_strategy strategy, uint32_t y0, uint32_t y1, float *rgb)
{
    uint32_t w = s->settings.width, spp = s->settings.spp;
    for (uint32_t y = y0; y < y1; y++) {
        for (uint32_t x = 0; x < w; x++) {
            double acc[3] = {0, 0, 0};
            for (uint32_t i = 0; i < spp; i++) {
                vec3 c = pt_sample(s, strategy, x, y, i);
                acc[0] += c.x; acc[1] += c.y; acc[2] += c.z;
            }
            float *px = rgb + ((size_t)(y - y0) * w + x) * 3;
            px[0] = (float)(acc[0] / spp);
            px[1] = (float)(acc[1] / spp);
            px[2] = (float)(acc[2] / spp);
        }
    }
}
