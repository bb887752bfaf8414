#include "render.h"

#include "bsdf.h"
#include "fmath.h"
#include "light.h"
#include "sampler.h"
#include "texture.h"

/* Power heuristic with beta = 2 (Veach 1997). */
static float power_heuristic(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
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
    for (uint32_t depth = 0;; depth++) {
        fr_hit hit;
        if (!trace_closest(s, &ray, INFINITY, &hit))
            break;
        fr_surface sf;
        trace_surface(s, &ray, &hit, &sf);
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
                    else if (strategy == PT_MIS)
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
                if (tmax > 0.0f && !trace_occluded(s, &shadow, tmax, ls.prim)) {
                    float w = (ls.delta || strategy == PT_LIGHT_ONLY) ? 1.0f : power_heuristic(ls.pdf, bpdf);
                    float cosi = fabsf(v3_dot(ls.wi, sf.ns));
                    L = v3_add(L, v3_scale(v3_mul(beta, v3_mul(f, ls.radiance)), w * cosi / ls.pdf));
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
        ray.o = geo_offset(sf.p, sf.ng, bs.wi);
        ray.d = bs.wi;

        /* Russian roulette after a few bounces: survive with a probability
         * that follows the path's throughput, reweight survivors. */
        if (depth >= 3) {
            float q = fminf(0.95f, v3_max(beta));
            if (!(smp_random(&smp) < q))
                break;
            beta = v3_scale(beta, 1.0f / q);
        }
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
