/* vertex.c -- path vertices: the next vertex through media, light samples,
 * scattering (see vertex.h). */

#include "vertex.h"

#include "fmath.h"
#include "medium.h"
#include "texture.h"

/* Interfaces a path may cross between two vertices before it is given up
 * (a ray caught between coincident boundaries). */
#define MAX_CROSSINGS 64

/* The surface at a path's vertex: uv, dpdu and dpdv only where shading
 * the material reads them, which its textures, bump and normal maps do
 * (tex_material) and an anisotropic roughness does (the BSDF's frame
 * follows dpdu); else 0. */
static inline __attribute__((always_inline)) void shading_surface(const fr_scene *s, const fr_ray *ray,
                                                                 const fr_hit *hit, fr_surface *sf)
{
    const fr_material *m = &s->materials[trace_hit_material(s, hit)];
    trace_surface_uv(s, ray, hit, sf, tex_material_textured(m) || m->anisotropy != 0.0f);
}

float vtx_power_heuristic(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

/* The power heuristic among three techniques: a^2 / (a^2 + b^2 + c^2); 0
 * when all are 0. */
static float vtx_power_heuristic3(float a, float b, float c)
{
    float a2 = a * a, sum = a2 + b * b + c * c;
    return sum > 0.0f ? a2 / sum : 0.0f;
}

/* Equiangular sampling over one medium segment (o + t d, t in [0, tmax),
 * medium `medium`, throughput beta at o): the light picked by upick, its
 * point first (lgt_fixed_point with (ul1, ul2): a point or spot light's
 * position, a point of a rectangle or triangle), then a distance by u with
 * density proportional to the inverse squared distance to that point; the
 * single-scattering estimate of the light, weighted by MIS against the
 * free-flight sampling that the path itself does on the same segment (its
 * medium vertex's light sample, and for area lights the phase sample that
 * hits the light when mis.area), which take the complementary weights
 * (vtx_direct_medium, vtx_medium_hit_weight).  Lights sampled by where
 * they are seen from (spheres) and distant lights are left to the path's
 * vertices. */
static vec3 equiangular(const fr_scene *s, uint32_t medium, const fr_ray *ray, float tmax, vec3 beta, vtx_mis mis,
                        float upick, float u, float ul1, float ul2)
{
    const fr_medium *md = &s->media[medium - 1];
    vec3 c, x;
    float t, pe;
    fr_light_sample ls;
    if (v3_is_zero(md->sigma_s) || !lgt_fixed_point(s, lgt_pick(s, upick), ul1, ul2, &c) ||
        !med_equiangular(ray->o, ray->d, tmax, c, u, &t, &pe))
        return v3s(0.0f);
    /* The same light and point, now seen from the scattering point: its
     * direction, distance, radiance and solid-angle pdf there, with the
     * power table's pick (the light was picked before the point was known). */
    x = v3_madd(ray->o, ray->d, t);
    if (!lgt_sample_table(s, x, upick, ul1, ul2, &ls))
        return v3s(0.0f);
    fr_ray shadow = {x, ls.wi, ray->time};
    vec3 tr = med_shadow(s, medium, &shadow, ls.dist, ls.prim);
    if (v3_is_zero(tr))
        return v3s(0.0f);
    float pd = med_distance_pdf(md, beta, t), ph = med_phase(md->g, v3_dot(ray->d, ls.wi));
    /* Densities of the (distance, light point) pair, each technique's
     * pdf of the point in solid angle at x: equiangular pe * pl (the
     * table's pick, the point by area), the vertex's light sample pd * pl'
     * (the tree's pick from x, and on a rectangle or triangle the density
     * of lgt_sample_chosen, which may sample its solid angle: lgt_pdf),
     * its phase sample pd * ph. */
    float pl_tree = ls.prim != FR_NONE ? lgt_pdf(s, ls.light, x, v3s(0.0f), ls.p, ls.n)
                                       : ls.pdf / ls.pick * lgt_pick_pdf(s, ls.light, x, v3s(0.0f));
    float w = ls.delta ? vtx_power_heuristic(pe * ls.pdf, pd * pl_tree)
                       : vtx_power_heuristic3(pe * ls.pdf, pd * pl_tree, mis.area ? pd * ph : 0.0f);
    vec3 f = v3_mul(v3_mul(med_transmittance(md, t), md->sigma_s), v3_mul(tr, ls.radiance));
    return v3_scale(v3_mul(beta, f), w * ph / (pe * ls.pdf));
}

float vtx_medium_hit_weight(const fr_scene *s, const vtx_vertex *v, uint32_t medium, vtx_mis mis, uint32_t light,
                            vec3 p, float phase_pdf, float light_pdf, float light_pdf_table)
{
    float pe = 0.0f;
    if (mis.equiangular && lgt_has_fixed_point(s, light))
        pe = med_equiangular_pdf(v->seg.o, v->seg.d, v->seg_tmax, p, v->t);
    if (pe == 0.0f)
        return vtx_power_heuristic(phase_pdf, light_pdf);
    float pd = med_distance_pdf(&s->media[medium - 1], v->seg_beta, v->t);
    return vtx_power_heuristic3(pd * phase_pdf, pd * light_pdf, pe * light_pdf_table);
}

int vtx_next(const fr_scene *s, fr_sampler *smp, fr_ray *ray, uint32_t *medium, vec3 *beta, vtx_mis mis,
             vec3 *equi_L, vtx_vertex *v)
{
    fr_hit hit;
    int found = trace_closest(s, ray, INFINITY, &hit);
    v->kind = VTX_ESCAPED;
    if (!s->n_media) {
        if (!found)
            return VTX_ESCAPED;
        shading_surface(s, ray, &hit, &v->sf);
        return v->kind = VTX_SURFACE;
    }
    /* Sample each medium segment up to the next surface, crossing
     * invisible media boundaries, until the path scatters in a medium or
     * reaches a real surface. */
    for (uint32_t crossings = 0;; crossings++) {
        float tmax = found ? hit.t : INFINITY;
        if (*medium) {
            const fr_medium *md = &s->media[*medium - 1];
            float uch, ud, ueq_pick, ueq, ul1, ul2, t;
            smp_2d(smp, &uch, &ud);
            smp_2d(smp, &ueq_pick, &ueq);
            smp_2d(smp, &ul1, &ul2);
            if (equi_L)
                *equi_L = v3_add(*equi_L, equiangular(s, *medium, ray, tmax, *beta, mis, ueq_pick, ueq, ul1, ul2));
            vec3 w;
            int scattered = med_sample_distance(md, tmax, *beta, uch, ud, &t, &w);
            if (scattered) {
                v->seg = *ray;
                v->seg_beta = *beta;
                v->seg_tmax = tmax;
                v->t = t;
            }
            *beta = v3_mul(*beta, w);
            if (scattered) {
                v->p = v3_madd(v->seg.o, v->seg.d, t);
                return v->kind = VTX_MEDIUM;
            }
        }
        if (!found)
            return VTX_ESCAPED;
        shading_surface(s, ray, &hit, &v->sf);
        const fr_material *mb = &s->materials[v->sf.material];
        if (!mb->interface)
            return v->kind = VTX_SURFACE;
        if (crossings == MAX_CROSSINGS)
            return v->kind = VTX_LOST;
        *medium = med_after(s, *medium, mb, v->sf.ng, ray->d);
        ray->o = geo_offset(v->sf.p, v->sf.perr, v->sf.ng, ray->d);
        found = trace_closest(s, ray, INFINITY, &hit);
    }
}

vtx_origin vtx_origin_at(const fr_surface *sf, vec3 wo)
{
    int below = v3_dot(sf->ng, wo) < 0.0f;
    return (vtx_origin){geo_offset_side(sf->p, sf->perr, sf->ng, below), below};
}

/* The origin of a ray leaving surface vertex sf along dir: *org's when on
 * its side (geo_offset's bits either way). */
static inline vec3 origin(const vtx_origin *org, const fr_surface *sf, vec3 dir)
{
    int below = v3_dot(sf->ng, dir) < 0.0f;
    return below == org->below ? org->o : geo_offset_side(sf->p, sf->perr, sf->ng, below);
}

int vtx_direct_surface(const fr_scene *s, const fr_material *m, const fr_surface *sf, vec3 wo, uint32_t medium,
                       vec3 beta, vtx_mis mis, uint32_t light, float pick, float u1, float u2, const vtx_origin *org,
                       vtx_direct *out)
{
    fr_light_sample *ls = &out->ls;
    out->unshadowed = v3s(0.0f);
    if (light == FR_NONE || !bsdf_has_smooth(m) || !lgt_sample_chosen(s, light, pick, sf->p, u1, u2, ls))
        return 0;
    vec3 f = bsdf_eval(m, sf, wo, ls->wi, &out->scatter_pdf);
    if (v3_is_zero(f))
        return 0;
    fr_ray shadow = {origin(org, sf, ls->wi), ls->wi, sf->time};
    float tmax = ls->distant ? INFINITY : v3_dot(v3_sub(ls->p, shadow.o), ls->wi);
    out->weight = (ls->delta || !mis.area) ? 1.0f : vtx_power_heuristic(ls->pdf, out->scatter_pdf);
    float cosi = fabsf(v3_dot(ls->wi, sf->ns));
    if (!(tmax > 0.0f))
        return 0;
    /* Without media the transmittance is 1 and L is the unshadowed light
     * (1 * f is f, bit for bit): one product for both. */
    float k = out->weight * cosi / ls->pdf;
    out->unshadowed = v3_scale(v3_mul(beta, v3_mul(f, ls->radiance)), k);
    if (!s->n_media) {
        if (trace_occluded(s, &shadow, tmax, ls->prim))
            return 0;
        out->L = out->unshadowed;
        return 1;
    }
    vec3 tr = med_shadow(s, med_after(s, medium, m, sf->ng, ls->wi), &shadow, tmax, ls->prim);
    if (v3_is_zero(tr))
        return 0;
    out->L = v3_scale(v3_mul(beta, v3_mul(v3_mul(tr, f), ls->radiance)), k);
    return 1;
}

int vtx_direct_medium(const fr_scene *s, const vtx_vertex *v, uint32_t medium, vec3 beta, vtx_mis mis, uint32_t light,
                      float pick, float u1, float u2, vtx_direct *out)
{
    fr_light_sample *ls = &out->ls;
    if (light == FR_NONE || !lgt_sample_chosen(s, light, pick, v->p, u1, u2, ls))
        return 0;
    const fr_medium *md = &s->media[medium - 1];
    fr_ray shadow = {v->p, ls->wi, v->seg.time};
    vec3 tr = med_shadow(s, medium, &shadow, ls->dist, ls->prim);
    float ph = med_phase(md->g, v3_dot(v->seg.d, ls->wi));
    out->scatter_pdf = ph;
    out->weight = 1.0f;
    float pe = 0.0f;
    if (mis.equiangular && lgt_has_fixed_point(s, ls->light))
        pe = med_equiangular_pdf(v->seg.o, v->seg.d, v->seg_tmax, ls->p, v->t);
    /* Equiangular sampling picks its light by the power table, and a point
     * of a rectangle or triangle by area (lgt_pdf_table), where this
     * sample may have sampled its solid angle. */
    float pl_table = pe == 0.0f          ? 0.0f
                     : ls->prim != FR_NONE ? lgt_pdf_table(s, ls->light, v->p, ls->p, ls->n)
                                           : ls->pdf / ls->pick * s->lights[ls->light].pick;
    if (ls->delta && pe > 0.0f)
        out->weight = vtx_power_heuristic(med_distance_pdf(md, v->seg_beta, v->t) * ls->pdf, pe * pl_table);
    else if (!ls->delta && pe > 0.0f) {
        float pd = med_distance_pdf(md, v->seg_beta, v->t);
        out->weight = vtx_power_heuristic3(pd * ls->pdf, mis.area ? pd * ph : 0.0f, pe * pl_table);
    } else if (!ls->delta && mis.area)
        out->weight = vtx_power_heuristic(ls->pdf, ph);
    out->L = v3_scale(v3_mul(beta, v3_mul(tr, ls->radiance)), out->weight * ph / ls->pdf);
    return 1;
}

void vtx_scatter_medium(const fr_scene *s, const vtx_vertex *v, uint32_t medium, float u1, float u2, fr_ray *next,
                        float *pdf)
{
    const fr_medium *md = &s->media[medium - 1];
    next->o = v->p;
    next->d = med_sample_phase(md->g, v->seg.d, u1, u2);
    *pdf = med_phase(md->g, v3_dot(v->seg.d, next->d));
}

int vtx_scatter_surface(const fr_scene *s, const fr_material *m, const fr_surface *sf, vec3 wo, float ulobe,
                        float u1, float u2, const vtx_origin *org, fr_bsdf_sample *bs, fr_ray *next, uint32_t *medium)
{
    if (!bsdf_sample(m, sf, wo, ulobe, u1, u2, bs))
        return 0;
    *medium = med_after(s, *medium, m, sf->ng, bs->wi);
    next->o = origin(org, sf, bs->wi);
    next->d = bs->wi;
    return 1;
}
