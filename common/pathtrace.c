/* pathtrace.c -- the path tracer: camera rays, one pixel sample, and rows of
 * an image (see pathtrace.h). */

#include "pathtrace.h"

#include "camera.h"
#include "passes.h"
#include "texture.h"
#include "vertex.h"

/* Scattering vertices a path passes before Russian roulette may end it.
 * On the noise benches (tests/bench/noise.sh), starting at the second
 * vertex, as Cycles does, saves time but leaves more noise per sample;
 * from the fourth on, with the policy below, the mirror and glass box is
 * both less noisy and faster than with the former policy (cap 0.95, no
 * square root, from the fifth vertex)
 * (tests/bench/README.md, "Russian roulette's start"). */
#define RR_DEPTH 3

/* Russian roulette: the path survives with probability
 * q = min(1, sqrt(max channel of its throughput)) and survivors are
 * reweighted by 1 / q.  The square root lets dim paths live longer than
 * q = throughput would, and with no cap below 1 a bright path (through
 * glass, say) is never ended by chance.  sqrtf is correctly rounded
 * (IEEE 754), so the decision has the same bits on every host.  Returns 0
 * when the path ends. */
static int roulette(fr_sampler *smp, uint32_t depth, vec3 *beta)
{
    if (depth < RR_DEPTH)
        return 1;
    float m = v3_max(*beta), u = smp_random(smp);
    if (m >= 1.0f)
        return 1;
    float q = sqrtf(m);
    if (!(u < q))
        return 0;
    *beta = v3_scale(*beta, 1.0f / q);
    return 1;
}

/* The light of a light sample from point `from` (normal nrm, zero in a
 * medium) and the numbers of its
 * point: one stratified pair whose first number picks the light
 * (lgt_choose, when `choose`; else no light, *light FR_NONE) and,
 * rescaled, places the point on it too; a second pair for the point only
 * where the picked light is too unlikely for that (below 2^-8, where the
 * rescaled number would keep fewer than 16 significant bits). */
static void light_numbers(const fr_scene *s, vec3 from, vec3 nrm, int choose, fr_sampler *smp, uint32_t *light,
                          float *pick, float *u1, float *u2)
{
    smp_2d(smp, u1, u2);
    *light = FR_NONE;
    if (!choose)
        return;
    float u = *u1;
    *light = lgt_choose(s, from, nrm, &u, pick);
    if (*light == FR_NONE)
        return;
    if (*pick >= 0x1p-8f)
        *u1 = u;
    else
        smp_2d(smp, u1, u2);
}

fr_ray pt_camera_ray_from(const fr_scene *s, const fr_camera *c, uint32_t x, uint32_t y, float px, float py,
                          float lx, float ly)
{
    float w = (float)s->settings.width, h = (float)s->settings.height;
    float sx = (2.0f * ((float)x + px) - w) / h * c->tan_half;
    float sy = (h - 2.0f * ((float)y + py)) / h * c->tan_half;
    vec3 d = v3_add(c->forward, v3_add(v3_scale(c->right, sx), v3_scale(c->upv, sy)));
    fr_ray r = {c->position, d, 0.0f};
    if (c->aperture > 0.0f) {
        /* A point on the lens disk (camera.h), aimed at the point of the
         * focal plane the pinhole ray reaches, `focus` along the view axis. */
        vec3 focus = v3_madd(c->position, d, c->focus);
        r.o = v3_add(c->position, cam_lens(c, lx, ly));
        r.d = v3_sub(focus, r.o);
    }
    r.d = v3_norm(r.d);
    return r;
}

fr_ray pt_camera_ray(const fr_scene *s, uint32_t x, uint32_t y, float px, float py, float lx, float ly)
{
    return pt_camera_ray_from(s, &s->camera, x, y, px, py, lx, ly);
}

/* Light reached by a BSDF or phase sample (or seen directly) at surface
 * vertex sf of material m, seen along wo: its emission times beta, weighted
 * against light sampling from the previous vertex prev_p (its normal
 * prev_n, zero in a medium), whose scattering
 * sampled this direction with solid-angle density prev_pdf (or a delta
 * event: weight 1); when that vertex was medium vertex prev_v (in medium
 * prev_medium, not 0), against the equiangular sampling of its segment
 * too. */
static vec3 emission(const fr_scene *s, pt_strategy strategy, vtx_mis mis, const fr_material *m, const fr_surface *sf,
                     vec3 wo, vec3 beta, float prev_pdf, int prev_delta, vec3 prev_p, vec3 prev_n,
                     const vtx_vertex *prev_v,
                     uint32_t prev_medium)
{
    vec3 le = lgt_emitted(m, sf->ng, wo);
    if (v3_is_zero(le))
        return le;
    float w = 1.0f;
    if (!prev_delta) {
        if (strategy == PT_LIGHT_ONLY)
            w = 0.0f;
        else if (strategy != PT_BSDF_ONLY) {
            float pl = lgt_pdf(s, sf->light, prev_p, prev_n, sf->p, sf->ng);
            w = prev_medium ? vtx_medium_hit_weight(s, prev_v, prev_medium, mis, sf->light, sf->p, prev_pdf, pl,
                                                    lgt_pdf_table(s, sf->light, prev_p, sf->p, sf->ng))
                            : vtx_power_heuristic(prev_pdf, pl);
        }
    }
    return v3_scale(v3_mul(beta, le), w);
}

/* Light from the distant lights (sun disks, environment) that a ray
 * leaving the scene along unit dir sees, times beta, each weighted against
 * light sampling from the previous vertex as emission() weighs hits; each
 * light's share to its light group in ps when ps is not NULL. */
static vec3 escaped(const fr_scene *s, pt_strategy strategy, vec3 dir, vec3 beta, float prev_pdf, int prev_delta,
                    pass_sample *ps)
{
    vec3 L = v3s(0.0f);
    uint32_t n = lgt_n_distant(s);
    for (uint32_t i = 0; i < n; i++) {
        float pdf;
        vec3 le = lgt_distant(s, i, dir, &pdf);
        if (v3_is_zero(le))
            continue;
        float w = 1.0f;
        if (!prev_delta) {
            if (strategy == PT_LIGHT_ONLY)
                w = 0.0f;
            else if (strategy != PT_BSDF_ONLY)
                w = vtx_power_heuristic(prev_pdf, pdf);
        }
        vec3 e = v3_scale(v3_mul(beta, le), w);
        L = v3_add(L, e);
        if (ps)
            pass_group(ps, s, i, e);
    }
    return L;
}

/* pt_sample, with the pixel's sampler seeds kept in *shared when it is not
 * NULL (smp_start_shared): the same bits either way.  With ps not NULL,
 * what the sample brings to the render passes goes there too (passes.h);
 * the radiance is the same either way. */
static inline __attribute__((always_inline)) vec3 pt_sample_seeded(const fr_scene *s, pt_strategy strategy, uint32_t x,
                                                                   uint32_t y, uint32_t index, smp_shared *shared,
                                                                   pass_sample *ps)
{
    fr_sampler smp;
    if (shared)
        smp_start_shared(&smp, shared, x, y, index, s->settings.seed);
    else
        smp_start(&smp, x, y, index, s->settings.seed);
    float px, py, lx = 0.0f, ly = 0.0f;
    smp_2d(&smp, &px, &py);
    if (s->camera.aperture > 0.0f)
        smp_2d(&smp, &lx, &ly);
    else
        smp_skip(&smp);        /* a pinhole has no lens to sample */
    fr_camera at;
    const fr_camera *cam = &s->camera;
    float tu = 0.0f;
    if (s->motion.flags) {
        /* The sample's time across the shutter (scenes without motion
         * draw no pair here: their numbers stay as they were); every ray
         * of the path carries it (fr_ray.time). */
        float unused;
        smp_2d(&smp, &tu, &unused);
        cam_at(s, tu, &at);
        cam = &at;
    }
    fr_ray ray = pt_camera_ray_from(s, cam, x, y, px, py, lx, ly);
    ray.time = tu;
    vec3 camera = ray.o;
    if (ps)
        pass_start(ps);

    vec3 L = v3s(0.0f), beta = v3s(1.0f);
    float prev_pdf = 0.0f;     /* solid-angle pdf of the last BSDF or phase sample */
    int prev_delta = 1;        /* the camera ray counts as a delta event */
    vec3 prev_p = ray.o, prev_n = v3s(0.0f);
    vtx_vertex prev_v;         /* the last vertex, when it was in a medium */
    uint32_t prev_medium = 0;  /* its medium (1 + index); 0: the last vertex was not in a medium */
    uint32_t medium = s->volume.camera_medium;   /* the ray's medium: 1 + index, 0 = vacuum */
    const uint32_t max_depth = s->settings.max_depth;
    vtx_mis mis = {strategy != PT_LIGHT_ONLY, strategy == PT_MIS || strategy == PT_LIGHT_ONLY};
    int light_sampling = strategy != PT_BSDF_ONLY;
    /* The ray cone (camera.h) for textures' mip levels: its angle, until
     * the path leaves a surface other than by a delta lobe (from then on,
     * 0: textures at their finest level), and its width at prev_p. */
    float spread = cam_pixel_spread(s), cone = 0.0f;
    for (uint32_t depth = 0;; depth++) {
        vtx_vertex v;
        int equi = mis.equiangular && depth < max_depth && s->n_lights;
        vec3 before = L;
        int kind = vtx_next(s, &smp, &ray, &medium, &beta, mis, equi ? &L : NULL, &v);
        if (ps) {
            /* Light scattered in a medium on the way: one more bounce. */
            pass_light(ps, depth + 1, v3_sub(L, before));
            pass_group(ps, s, FR_NONE, v3_sub(L, before));
            if (depth == 0 && (kind == VTX_SURFACE || kind == VTX_MEDIUM))
                pass_first_hit(ps, kind == VTX_SURFACE ? v.sf.p : v.p,
                               kind == VTX_SURFACE ? v.sf.material : FR_NONE,
                               kind == VTX_SURFACE ? pass_object(s, &v.sf) : 0, camera);
        }
        if (kind == VTX_ESCAPED) {
            vec3 e = escaped(s, strategy, ray.d, beta, prev_pdf, prev_delta, ps);
            L = v3_add(L, e);
            if (ps)
                pass_light(ps, depth, e);
        }
        if (kind == VTX_ESCAPED || kind == VTX_LOST)
            break;
        /* Each vertex draws a pair for the light (light_numbers), one for
         * the scattered direction, and before them one for the lobe
         * choice where the material has lobes to choose from. */
        float pick = 0.0f, ulobe = 0.5f, u1, u2, v1, v2;
        uint32_t light;
        vtx_direct d;
        if (kind == VTX_MEDIUM) {
            spread = 0.0f;
            if (depth >= max_depth)
                break;
            light_numbers(s, v.p, v3s(0.0f), light_sampling, &smp, &light, &pick, &u1, &u2);
            smp_2d(&smp, &v1, &v2);
            if (vtx_direct_medium(s, &v, medium, beta, mis, light, pick, u1, u2, &d)) {
                L = v3_add(L, d.L);
                if (ps) {
                    pass_light(ps, depth + 1, d.L);
                    pass_group(ps, s, light, d.L);
                }
            }
            vtx_scatter_medium(s, &v, medium, v1, v2, &ray, &prev_pdf);
            if (ps && depth == 0)
                pass_first_kind(ps, NULL, NULL, v3s(0.0f), ray.d, 0.0f);
            if (ps)
                ps->albedo_done = 1;
            prev_delta = 0;
            prev_p = v.p;
            prev_n = v3s(0.0f);
            prev_v = v;
            prev_medium = medium;
        } else {
            fr_material textured;
            if (spread > 0.0f) {
                cone += spread * v3_len(v3_sub(v.sf.p, prev_p));
                v.sf.footprint = cam_footprint(cone, v.sf.ng, ray.d);
            }
            const fr_material *m = tex_material(s, &s->materials[v.sf.material], &v.sf, &textured);
            vec3 wo = v3_neg(ray.d);
            if (ps && !ps->albedo_done)
                pass_albedo_at(ps, m, &v.sf, ray.d);
            if (v.sf.light != FR_NONE) {
                vec3 e = emission(s, strategy, mis, m, &v.sf, wo, beta, prev_pdf, prev_delta, prev_p, prev_n, &prev_v,
                                  prev_medium);
                L = v3_add(L, e);
                if (ps) {
                    pass_light(ps, depth, e);
                    pass_group(ps, s, v.sf.light, e);
                }
            }
            if (depth >= max_depth)
                break;
            if (bsdf_needs_lobe(m)) {
                float unused;
                smp_2d(&smp, &ulobe, &unused);
            }
            light_numbers(s, v.sf.p, v.sf.ns, light_sampling && bsdf_has_smooth(m), &smp, &light, &pick, &u1, &u2);
            smp_2d(&smp, &v1, &v2);
            vtx_origin org = vtx_origin_at(&v.sf, wo);
            int lit = vtx_direct_surface(s, m, &v.sf, wo, medium, beta, mis, light, pick, u1, u2, &org, &d);
            if (ps && depth == 0)
                pass_shadow(ps, lit ? d.L : v3s(0.0f), d.unshadowed);
            if (lit) {
                L = v3_add(L, d.L);
                if (ps && depth == 0)
                    pass_light_first(ps, m, &v.sf, wo, d.ls.wi, d.L);
                else if (ps)
                    pass_light(ps, depth + 1, d.L);
                if (ps)
                    pass_group(ps, s, light, d.L);
            }
            fr_bsdf_sample bs;
            if (!vtx_scatter_surface(s, m, &v.sf, wo, ulobe, v1, v2, &org, &bs, &ray, &medium))
                break;
            if (ps && depth == 0)
                pass_first_kind(ps, m, &v.sf, wo, bs.wi, ulobe);
            if (ps && !ps->albedo_done)
                pass_albedo_through(ps, bs.weight);
            beta = v3_mul(beta, bs.weight);
            prev_pdf = bs.pdf;
            prev_delta = bs.delta;
            if (!bs.delta)
                spread = 0.0f;
            prev_p = v.sf.p;
            prev_n = v.sf.ns;
            prev_medium = 0;
        }
        if (!roulette(&smp, depth, &beta))
            break;
    }
    /* A NaN or infinity from a degenerate configuration would poison the
     * pixel; drop the sample instead (it happens the same way everywhere). */
    if (!isfinite(L.x) || !isfinite(L.y) || !isfinite(L.z)) {
        if (ps)
            pass_drop_light(ps);
        return v3s(0.0f);
    }
    if (ps)
        ps->beauty = L;
    return L;
}

vec3 pt_sample(const fr_scene *s, pt_strategy strategy, uint32_t x, uint32_t y, uint32_t index)
{
    return pt_sample_seeded(s, strategy, x, y, index, NULL, NULL);
}

/* Adaptive sampling: a pixel's error is estimated after every block of
 * this many samples (whole blocks keep the sampler's stratification
 * whole: each block of 16 indices is a well-spread point set). */
#define ADAPT_BLOCK 16u

/* Samples every pixel takes before its error is first estimated: a
 * sixteenth of spp, at least one block, so that a pixel whose few first
 * samples missed a rare bright path is not stopped on them. */
static uint32_t adapt_min(uint32_t spp)
{
    uint32_t m = spp / 16u;
    m = m < ADAPT_BLOCK ? ADAPT_BLOCK : m - m % ADAPT_BLOCK;
    return m;
}

/* Whether the mean of n luminance samples (sum, sum of squares) has a
 * relative standard error at most e: sqrt(var / n) <= e * mean, squared
 * (no square root needed).  Means below 1e-3 are compared as 1e-3, so
 * that near-black pixels, invisible once tone-mapped, stop early. */
static int adapt_done(double sum, double sum2, uint32_t n, float e)
{
    double mean = sum / n, var = (sum2 - sum * mean) / (n - 1), ref = mean > 1e-3 ? mean : 1e-3;
    return var / n <= (double)e * e * ref * ref;
}

void pt_render_rows(const fr_scene *s, pt_strategy strategy, uint32_t y0, uint32_t y1, float *rgb)
{
    pt_render_rows_passes(s, strategy, y0, y1, rgb, 0, NULL);
}

void pt_render_rows_passes(const fr_scene *s, pt_strategy strategy, uint32_t y0, uint32_t y1, float *rgb,
                           uint32_t passes, float *out)
{
    uint32_t nch = pass_channels(passes);
    pass_sample sample, *ps = passes ? &sample : NULL;
    uint32_t w = s->settings.width, spp = s->settings.spp;
    float e = s->settings.noise_threshold;
    uint32_t first_check = e > 0.0f ? adapt_min(spp) : spp;
    smp_shared shared = {0};
    for (uint32_t y = y0; y < y1; y++) {
        for (uint32_t x = 0; x < w; x++) {
            /* The decision to stop reads this pixel's own samples only, so
             * a slab renders the same bits whatever the split. */
            double acc[3] = {0, 0, 0}, lsum = 0, lsum2 = 0, pacc[PASS_MAX_ACC] = {0};
            uint32_t n = 0;
            while (n < spp) {
                /* Two copies of the sample: without passes, none of their tests. */
                vec3 c = ps ? pt_sample_seeded(s, strategy, x, y, n, &shared, ps)
                            : pt_sample_seeded(s, strategy, x, y, n, &shared, NULL);
                if (ps)
                    pass_accumulate(pacc, passes, ps, n);
                n++;
                acc[0] += c.x; acc[1] += c.y; acc[2] += c.z;
                if (first_check < spp) {
                    double l = 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
                    lsum += l;
                    lsum2 += l * l;
                    if (n >= first_check && n % ADAPT_BLOCK == 0 && n < spp && adapt_done(lsum, lsum2, n, e))
                        break;
                }
            }
            float *px = rgb + ((size_t)(y - y0) * w + x) * 3;
            px[0] = (float)(acc[0] / n);
            px[1] = (float)(acc[1] / n);
            px[2] = (float)(acc[2] / n);
            if (ps)
                pass_finish(pacc, passes, n, out + ((size_t)(y - y0) * w + x) * nch);
        }
    }
}

void pt_render_rows_sums(const fr_scene *s, pt_strategy strategy, uint32_t y0, uint32_t y1, uint32_t first,
                         double *sums, float *rgb)
{
    /* The loop of pt_render_rows without adaptive stops, from sample
     * `first` on: the same additions in the same order, so the same bits. */
    uint32_t w = s->settings.width, spp = s->settings.spp;
    smp_shared shared = {0};
    for (uint32_t y = y0; y < y1; y++) {
        for (uint32_t x = 0; x < w; x++) {
            size_t k = ((size_t)(y - y0) * w + x) * 3;
            double acc[3] = {sums[k], sums[k + 1], sums[k + 2]};
            for (uint32_t n = first; n < spp; n++) {
                vec3 c = pt_sample_seeded(s, strategy, x, y, n, &shared, NULL);
                acc[0] += c.x; acc[1] += c.y; acc[2] += c.z;
            }
            for (int i = 0; i < 3; i++) {
                sums[k + i] = acc[i];
                rgb[k + i] = (float)(acc[i] / spp);
            }
        }
    }
}
