/* bsdf.c -- the lobe materials' scattering: evaluation, pdf and sampling of
 * their BSDFs (see bsdf.h). */

#include "bsdf.h"

#include "fmath.h"
#include "microfacet.h"

int bsdf_has_smooth(const fr_material *m) { return m->p_lobe[1] > 0.0f; }

int bsdf_needs_lobe(const fr_material *m)
{
    if (m->model != FR_MAT_LOBES)
        return 1;
    if (m->p_lobe[0] >= 1.0f)
        return 0;               /* diffuse only, the common case */
    int lobes = m->p_lobe[0] > 0.0f;
    for (int i = 1; i < 4; i++)
        lobes += m->p_lobe[i] > m->p_lobe[i - 1];
    return lobes > 1;
}

void bsdf_lobe_probs(fr_material *m)
{
    if (m->model != FR_MAT_LOBES) {
        m->p_lobe[0] = 0.0f;
        m->p_lobe[1] = m->p_lobe[2] = m->p_lobe[3] = 1.0f;
        return;
    }
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

void bsdf_material_finish(fr_material *m)
{
    bsdf_lobe_probs(m);
    m->fresnel_avg = v3s(0.0f);
    if (m->model == FR_MAT_CONDUCTOR && m->fresnel == FR_FRESNEL_EXACT)
        m->fresnel_avg = mf_fresnel_average(MF_FRESNEL_CONDUCTOR, v3s(1.0f), m->eta, m->k);
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

/* ---- microfacet models ---------------------------------------------------- */

_Static_assert((int)FR_FRESNEL_SCHLICK == (int)MF_FRESNEL_SCHLICK && (int)FR_FRESNEL_EXACT == (int)MF_FRESNEL_CONDUCTOR &&
                   (int)FR_FRESNEL_NONE == (int)MF_FRESNEL_NONE,
               "scene.h's Fresnel modes are microfacet.h's");

/* The shading frame: n (the shading normal on wo's side), t along dpdu for
 * anisotropic roughness, else any tangent. */
typedef struct { vec3 t, b, n; } frame;

static frame shading_frame(const fr_material *m, const fr_surface *sf, vec3 n)
{
    frame f = {.n = n};
    if (m->anisotropy != 0.0f) {
        vec3 tu = v3_sub(sf->dpdu, v3_scale(n, v3_dot(n, sf->dpdu)));
        float l2 = v3_len2(tu);
        if (l2 > 0.0f && isfinite(l2)) {
            f.t = v3_scale(tu, 1.0f / sqrtf(l2));
            f.b = v3_cross(n, f.t);
            return f;
        }
    }
    v3_basis(n, &f.t, &f.b);
    return f;
}

static vec3 to_local(const frame *f, vec3 w) { return v3(v3_dot(w, f->t), v3_dot(w, f->b), v3_dot(w, f->n)); }

static mf_alpha material_alpha(const fr_material *m)
{
    return m->anisotropy != 0.0f ? mf_alpha_aniso(m->roughness, m->anisotropy) : mf_alpha_iso(m->roughness);
}

/* The material as microfacet.h's lobes (colours already textured). */
typedef union {
    mf_conductor c;
    mf_dielectric d;
    mf_principled p;
} mf_lobe;

static void micro_lobe(const fr_material *m, mf_lobe *l)
{
    mf_alpha a = material_alpha(m);
    uint32_t masking = (m->mf_flags & FR_MF_SEPARABLE) ? MF_SMITH_SEPARABLE : MF_SMITH_CORRELATED;
    int comp = (m->mf_flags & FR_MF_COMPENSATE) != 0;
    if (m->model == FR_MAT_CONDUCTOR) {
        mf_conductor c = {a, masking, m->fresnel, m->specular, m->eta, m->k, comp, v3s(0.0f)};
        c.favg = m->fresnel == FR_FRESNEL_EXACT ? v3_mul(m->specular, m->fresnel_avg)
                                                : mf_fresnel_average(m->fresnel, m->specular, m->eta, m->k);
        l->c = c;
    } else if (m->model == FR_MAT_DIELECTRIC) {
        mf_dielectric d = {a, masking, (m->mf_flags & FR_MF_MACRO_FRESNEL) ? MF_DIELECTRIC_MACRO : MF_DIELECTRIC_MICRO,
                           m->transmit, m->transmit, comp};
        l->d = d;
    } else {
        uint32_t coupling = (m->mf_flags & FR_MF_CYCLES_COUPLING) ? MF_COUPLE_CYCLES
                            : (m->mf_flags & FR_MF_GLTF_COUPLING)  ? MF_COUPLE_GLTF
                                                                   : MF_COUPLE_ALBEDO;
        mf_principled p = {a, masking, coupling, m->diffuse, m->metallic, m->transmission, m->ior, comp, m->roughness};
        l->p = p;
    }
}

/* Reflected directions must leave on wo's side of the geometric surface
 * and above the shading frame, transmitted ones on the other side and
 * below it; anything else is no scattering at all. */
static int sides_agree(float side_o, float side_i, float local_z)
{
    return side_o * side_i > 0.0f ? local_z > 0.0f : side_o * side_i < 0.0f && local_z < 0.0f;
}

static vec3 micro_eval(const fr_material *m, const fr_surface *sf, vec3 wo, vec3 wi, float *pdf)
{
    float so = v3_dot(wo, sf->ng);
    frame f = shading_frame(m, sf, facing_normal(sf, wo));
    vec3 lo = to_local(&f, wo), li = to_local(&f, wi);
    *pdf = 0.0f;
    if (!sides_agree(so, v3_dot(wi, sf->ng), li.z))
        return v3s(0.0f);
    float eta = so >= 0.0f ? m->ior : 1.0f / m->ior;
    mf_lobe l;
    micro_lobe(m, &l);
    if (m->model == FR_MAT_CONDUCTOR)
        return mf_conductor_eval(&l.c, lo, li, pdf);
    if (m->model == FR_MAT_DIELECTRIC)
        return mf_dielectric_eval(&l.d, eta, lo, li, pdf);
    return mf_principled_eval(&l.p, eta, lo, li, pdf);
}

static int micro_sample(const fr_material *m, const fr_surface *sf, vec3 wo, float ulobe, float u1, float u2,
                        fr_bsdf_sample *out)
{
    float so = v3_dot(wo, sf->ng);
    frame f = shading_frame(m, sf, facing_normal(sf, wo));
    vec3 lo = to_local(&f, wo);
    float eta = so >= 0.0f ? m->ior : 1.0f / m->ior;
    mf_lobe l;
    micro_lobe(m, &l);
    mf_sample s;
    int ok;
    if (m->model == FR_MAT_CONDUCTOR)
        ok = mf_conductor_sample(&l.c, lo, ulobe, u1, u2, &s);
    else if (m->model == FR_MAT_DIELECTRIC)
        ok = mf_dielectric_sample(&l.d, eta, lo, ulobe, u1, u2, &s);
    else
        ok = mf_principled_sample(&l.p, eta, lo, ulobe, u1, u2, &s);
    if (!ok)
        return 0;
    out->wi = v3_from_local(s.wi, f.t, f.b, f.n);
    if (!sides_agree(so, v3_dot(out->wi, sf->ng), s.wi.z))
        return 0;
    out->weight = s.weight;
    out->pdf = s.pdf;
    out->delta = 0;
    return 1;
}

/* ---- the material ----------------------------------------------------------- */

vec3 bsdf_eval(const fr_material *m, const fr_surface *sf, vec3 wo, vec3 wi, float *pdf)
{
    if (m->model != FR_MAT_LOBES)
        return micro_eval(m, sf, wo, wi, pdf);
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
    if (m->model != FR_MAT_LOBES)
        return micro_sample(m, sf, wo, ulobe, u1, u2, out);
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
