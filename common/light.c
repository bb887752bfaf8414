#include "light.h"

#include "fmath.h"
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
static vec3 textured(const fr_scene *s, const fr_material *m, uint32_t prim, vec3 p, float a, float b, vec3 le)
{
    if (m->tex_emission == FR_NONE || v3_is_zero(le))
        return le;
    fr_hit h = {0.0f, prim, FR_NONE, a, b};
    fr_ray r = {p, v3s(0.0f)};
    fr_surface sf;
    trace_surface(s, &r, &h, &sf);
    return tex_emission(s, m, sf.uv);
}

uint32_t lgt_pick(const fr_scene *s, float u)
{
    uint32_t lo = 0, hi = s->n_lights - 1;
    while (lo < hi) {
        uint32_t mid = (lo + hi) / 2;
        if (u < s->lights[mid].cdf)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* 1 - cos of the half-angle of the cone a sphere subtends from distance d,
 * written without the cancellation of 1 - sqrt(1 - x) for small x. */
static float cone_one_minus_cos(float r2, float d2)
{
    float sin2 = r2 / d2;
    return sin2 / (1.0f + sqrtf(fmaxf(0.0f, 1.0f - sin2)));
}

float lgt_pdf(const fr_scene *s, uint32_t light, vec3 from, vec3 p, vec3 n)
{
    const fr_light *l = &s->lights[light];
    const fr_prim *pr = &s->prims[l->prim];
    if (pr->kind == FR_PRIM_SPHERE) {
        const fr_sphere *sp = &s->spheres[pr->index];
        float d2 = v3_len2(v3_sub(sp->center, from)), r2 = sp->radius * sp->radius;
        if (d2 > r2 * 1.0001f)
            return l->pick / (2.0f * FM_PI * cone_one_minus_cos(r2, d2));
    }
    vec3 d = v3_sub(p, from);
    float dist2 = v3_len2(d);
    float cosl = fabsf(v3_dot(n, d)) / sqrtf(dist2);
    if (cosl <= 0.0f)
        return 0.0f;
    return l->pick * dist2 / (cosl * l->area);
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

int lgt_sample(const fr_scene *s, vec3 from, float upick, float u1, float u2, fr_light_sample *out)
{
    if (s->n_lights == 0)
        return 0;
    uint32_t li = lgt_pick(s, upick);
    const fr_light *l = &s->lights[li];
    if (l->kind == FR_LIGHT_POINT) {
        out->p = l->position;
        float d2 = aim(out, from);
        if (!(d2 > 0.0f))
            return 0;
        out->radiance = v3_scale(l->intensity, 1.0f / d2);
        out->pdf = l->pick;
        out->n = v3_neg(out->wi);
        out->prim = FR_NONE;
        out->delta = 1;
        return 1;
    }
    const fr_prim *pr = &s->prims[l->prim];
    const fr_material *m = &s->materials[pr->material];
    out->delta = 0;
    out->prim = l->prim;
    float ua, ub;              /* the sampled point's coordinates on its primitive */
    if (pr->kind == FR_PRIM_SPHERE) {
        const fr_sphere *sp = &s->spheres[pr->index];
        vec3 dc = v3_sub(sp->center, from);
        float d2 = v3_len2(dc), r2 = sp->radius * sp->radius;
        if (d2 > r2 * 1.0001f) {
            /* Uniform in the cone of directions that hit the sphere. */
            float omc = cone_one_minus_cos(r2, d2);
            float one_minus_ct = u1 * omc, ct = 1.0f - one_minus_ct;
            float st = sqrtf(fmaxf(0.0f, one_minus_ct * (2.0f - one_minus_ct))), sn, cs;
            fm_sincosf(2.0f * FM_PI * u2, &sn, &cs);
            float dlen = sqrtf(d2);
            vec3 w = v3_scale(dc, 1.0f / dlen), t, b;
            v3_basis(w, &t, &b);
            out->wi = v3_norm(v3_from_local(v3(st * cs, st * sn, ct), t, b, w));
            /* Nearest intersection of the ray with the sphere, from the
             * projected half-chord. */
            float proj = v3_dot(dc, out->wi);
            float h2 = fmaxf(0.0f, r2 - (d2 - proj * proj));
            out->dist = proj - sqrtf(h2);
            out->p = v3_madd(from, out->wi, out->dist);
            out->n = v3_norm(v3_sub(out->p, sp->center));
            out->pdf = l->pick / (2.0f * FM_PI * omc);
            out->radiance = textured(s, m, l->prim, out->p, 0.0f, 0.0f, lgt_emitted(m, out->n, v3_neg(out->wi)));
            return out->pdf > 0.0f && !v3_is_zero(out->radiance);
        }
        /* Inside the sphere: uniform on its surface. */
        float z = 1.0f - 2.0f * u1, r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), sn, cs;
        fm_sincosf(2.0f * FM_PI * u2, &sn, &cs);
        out->n = v3(r * cs, r * sn, z);
        out->p = v3_madd(sp->center, out->n, sp->radius);
        ua = ub = 0.0f;
    } else if (pr->kind == FR_PRIM_RECT) {
        const fr_rect *q = &s->rects[pr->index];
        out->p = v3_add(q->origin, v3_add(v3_scale(q->edge_u, u1), v3_scale(q->edge_v, u2)));
        out->n = v3_norm(q->normal);
        ua = u1;
        ub = u2;
    } else {
        const fr_triangle *t = &s->triangles[pr->index];
        vec3 p0 = s->positions[t->v[0]], p1 = s->positions[t->v[1]], p2 = s->positions[t->v[2]];
        float su = sqrtf(u1), b1 = u2 * su, b0 = 1.0f - su;
        out->p = v3_add(v3_add(v3_scale(p0, b0), v3_scale(p1, b1)), v3_scale(p2, 1.0f - b0 - b1));
        out->n = v3_norm(v3_cross(v3_sub(p1, p0), v3_sub(p2, p0)));
        ua = b1;
        ub = 1.0f - b0 - b1;
    }
    float d2 = aim(out, from);
    if (!(d2 > 0.0f))
        return 0;
    float cosl = fabsf(v3_dot(out->n, out->wi));
    if (cosl <= 0.0f)
        return 0;
    out->pdf = l->pick * d2 / (cosl * l->area);
    out->radiance = textured(s, m, l->prim, out->p, ua, ub, lgt_emitted(m, out->n, v3_neg(out->wi)));
    return !v3_is_zero(out->radiance);
}
