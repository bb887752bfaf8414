#include "bsdf.h"

#include "fmath.h"
#include "microfacet.h"

int bsdf_has_smooth(const fr_material *m) { return m->p_lobe[1] > 0.0f; }

void bsdf_lobe_probs(fr_material *m)
{
    /* Lobes are picked in proportion to their brightest channel, so a lobe
     * that reflects little is rarely followed. */
    float w[4] = {v3_max(m->diffuse), v3_max(m->glossy), v3_max(m->specular), v3_max(m->transmit)};
    float sum = w[0] + w[1] + w[2] + w[3], acc = 0.0f;
    for (int i = 0; i < 4; i++) {
        acc += sum > 0.0f ? w[i] / sum : 0.0f;
        m->p_lobe[i] = acc;
    }
    if (sum > 0.0f)
        m->p_lobe[3] = 1.0f;
}

vec3 bsdf_sample_cosine(float u1, float u2) { return mf_sample_cosine(u1, u2); }

vec3 bsdf_sample_phong(float exponent, float u1, float u2)
{
    /* cos(alpha) = u^(1/(n+1)) inverts the cdf of (n+1)/(2 pi) cos^n. */
    float cz = fm_powf(u1, 1.0f / (exponent + 1.0f));
    float sz = sqrtf(fmaxf(0.0f, 1.0f - cz * cz)), s, c;
    fm_sincosf(2.0f * FM_PI * u2, &s, &c);
    return v3(sz * c, sz * s, cz);
}

float bsdf_phong_pdf(float exponent, float cos_alpha)
{
    if (cos_alpha <= 0.0f)
        return 0.0f;
    return (exponent + 1.0f) * FM_INV_2PI * fm_powf(cos_alpha, exponent);
}

float bsdf_fresnel(float cos_i, float eta, float *cos_t) { return mf_fresnel_dielectric(cos_i, eta, cos_t); }

/* Shading normal turned to wo's side of the geometric surface. */
static vec3 facing_normal(const fr_surface *sf, vec3 wo)
{
    return v3_dot(wo, sf->ng) >= 0.0f ? sf->ns : v3_neg(sf->ns);
}

/* Smooth lobes: f and pdf.  p_d and p_g are the lobe probabilities. */
static vec3 smooth_eval(const fr_material *m, vec3 n, vec3 wo, vec3 wi, float *pdf)
{
    float p_d = m->p_lobe[0], p_g = m->p_lobe[1] - m->p_lobe[0];
    float cos_i = v3_dot(wi, n);
    *pdf = 0.0f;
    if (cos_i <= 0.0f)
        return v3s(0.0f);
    vec3 f = v3_scale(m->diffuse, FM_INV_PI);
    *pdf = p_d * cos_i * FM_INV_PI;
    if (p_g > 0.0f) {
        vec3 r = v3_sub(v3_scale(n, 2.0f * v3_dot(wo, n)), wo);
        float ca = v3_dot(wi, r);
        if (ca > 0.0f) {
            float lobe = fm_powf(ca, m->exponent);
            f = v3_add(f, v3_scale(m->glossy, (m->exponent + 2.0f) * FM_INV_2PI * lobe));
            *pdf += p_g * (m->exponent + 1.0f) * FM_INV_2PI * lobe;
        }
    }
    return f;
}

vec3 bsdf_eval(const fr_material *m, const fr_surface *sf, vec3 wo, vec3 wi, float *pdf)
{
    /* Both directions must be on the same side of the geometric surface. */
    if (v3_dot(wo, sf->ng) * v3_dot(wi, sf->ng) <= 0.0f) {
        *pdf = 0.0f;
        return v3s(0.0f);
    }
    return smooth_eval(m, facing_normal(sf, wo), wo, wi, pdf);
}

float bsdf_pdf(const fr_material *m, const fr_surface *sf, vec3 wo, vec3 wi)
{
    float pdf;
    bsdf_eval(m, sf, wo, wi, &pdf);
    return pdf;
}

float bsdf_adjoint_scale(const fr_material *m, const fr_surface *sf, vec3 wo, vec3 wi)
{
    float side = v3_dot(wo, sf->ng);
    if (side * v3_dot(wi, sf->ng) >= 0.0f)
        return 1.0f;
    float eta = side >= 0.0f ? m->ior : 1.0f / m->ior;  /* index on wi's side / index on wo's side */
    return eta * eta;
}

int bsdf_sample(const fr_material *m, const fr_surface *sf, vec3 wo, float ulobe, float u1, float u2,
                fr_bsdf_sample *out)
{
    vec3 n = facing_normal(sf, wo);
    float side = v3_dot(wo, sf->ng);
    if (ulobe < m->p_lobe[1]) {
        vec3 t, b, l;
        if (ulobe < m->p_lobe[0]) {
            v3_basis(n, &t, &b);
            l = bsdf_sample_cosine(u1, u2);
            out->wi = v3_from_local(l, t, b, n);
        } else {
            vec3 r = v3_sub(v3_scale(n, 2.0f * v3_dot(wo, n)), wo);
            v3_basis(r, &t, &b);
            l = bsdf_sample_phong(m->exponent, u1, u2);
            out->wi = v3_from_local(l, t, b, r);
        }
        if (v3_dot(out->wi, sf->ng) * side <= 0.0f)
            return 0;
        vec3 f = smooth_eval(m, n, wo, out->wi, &out->pdf);
        if (out->pdf <= 0.0f)
            return 0;
        out->weight = v3_scale(f, v3_dot(out->wi, n) / out->pdf);
        out->delta = 0;
        return 1;
    }
    out->pdf = 0.0f;
    out->delta = 1;
    if (ulobe < m->p_lobe[2]) {
        out->wi = v3_sub(v3_scale(n, 2.0f * v3_dot(wo, n)), wo);
        out->weight = v3_scale(m->specular, 1.0f / (m->p_lobe[2] - m->p_lobe[1]));
        return v3_dot(out->wi, sf->ng) * side > 0.0f;
    }
    if (ulobe >= m->p_lobe[3])
        return 0;
    /* Dielectric: Fresnel decides between reflection and refraction, so its
     * factor cancels from the weight. */
    float eta = side >= 0.0f ? m->ior : 1.0f / m->ior;  /* index behind / index in front */
    float cos_o = v3_dot(wo, n), cos_t;
    float fr = bsdf_fresnel(cos_o, eta, &cos_t);
    vec3 w = v3_scale(m->transmit, 1.0f / (m->p_lobe[3] - m->p_lobe[2]));
    if (u1 < fr) {
        out->wi = v3_sub(v3_scale(n, 2.0f * cos_o), wo);
        out->weight = w;
        return v3_dot(out->wi, sf->ng) * side > 0.0f;
    }
    /* Snell: wi = -wo/eta + (cos_o/eta - cos_t) n; radiance is compressed
     * by 1/eta^2 entering a denser medium and expanded leaving it. */
    out->wi = v3_norm(v3_add(v3_scale(wo, -1.0f / eta), v3_scale(n, cos_o / eta - cos_t)));
    out->weight = v3_scale(w, 1.0f / (eta * eta));
    return v3_dot(out->wi, sf->ng) * side < 0.0f;
}
