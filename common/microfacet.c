/* microfacet.c -- GGX distribution, Smith masking, visible-normal sampling,
 * Fresnel factors and the rough conductor, dielectric and metallic-roughness
 * lobes (see microfacet.h for conventions). */
#include "microfacet.h"

#include "fmath.h"
#include "microfacet_table.h"

static inline float clampf(float x, float lo, float hi) { return x < lo ? lo : x > hi ? hi : x; }

/* ---- distribution and masking ------------------------------------------ */

mf_alpha mf_alpha_iso(float roughness)
{
    float r = clampf(roughness, 0.0f, 1.0f);
    float a = r * r;
    if (!(a >= MF_ALPHA_MIN))
        a = MF_ALPHA_MIN;
    mf_alpha al = {a, a};
    return al;
}

mf_alpha mf_alpha_aniso(float roughness, float anisotropy)
{
    float r = clampf(roughness, 0.0f, 1.0f), an = clampf(anisotropy, -1.0f, 1.0f);
    float a = r * r, aspect = sqrtf(1.0f - 0.9f * fabsf(an));
    float ax = clampf(a / aspect, MF_ALPHA_MIN, 1.0f), ay = clampf(a * aspect, MF_ALPHA_MIN, 1.0f);
    mf_alpha al = {ax, ay};
    if (an < 0.0f) {
        al.ax = ay;
        al.ay = ax;
    }
    return al;
}

float mf_D(mf_alpha a, vec3 m)
{
    if (m.z <= 0.0f)
        return 0.0f;
    /* Written with the slopes' components, not 1 - z^2, so narrow
     * distributions keep their precision near the peak. */
    float x = m.x / a.ax, y = m.y / a.ay;
    float t = x * x + y * y + m.z * m.z;
    return 1.0f / (FM_PI * a.ax * a.ay * t * t);
}

float mf_lambda(mf_alpha a, vec3 w)
{
    float x = a.ax * w.x, y = a.ay * w.y, z2 = w.z * w.z;
    float t = (x * x + y * y) / z2;          /* alpha^2 tan^2 */
    if (!(t < INFINITY))
        return INFINITY;
    /* (sqrt(1 + t) - 1) / 2 without the cancellation at small t. */
    return t / (2.0f * (1.0f + sqrtf(1.0f + t)));
}

float mf_G1(mf_alpha a, vec3 w) { return 1.0f / (1.0f + mf_lambda(a, w)); }

float mf_G2(mf_alpha a, uint32_t masking, vec3 wo, vec3 wi)
{
    float lo = mf_lambda(a, wo), li = mf_lambda(a, wi);
    if (masking == MF_SMITH_SEPARABLE)
        return 1.0f / ((1.0f + lo) * (1.0f + li));
    return 1.0f / (1.0f + lo + li);
}

vec3 mf_sample_visible(mf_alpha a, vec3 wo, float u1, float u2)
{
    /* Stretch the view to the configuration where the distribution is a
     * hemisphere of unit radius; there the visible normals are uniform on
     * the projected disk, half of which is foreshortened by the view's
     * cosine. */
    vec3 vh = v3_norm(v3(a.ax * wo.x, a.ay * wo.y, wo.z));
    float l2 = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = l2 > 0.0f ? v3_scale(v3(-vh.y, vh.x, 0.0f), 1.0f / sqrtf(l2)) : v3(1.0f, 0.0f, 0.0f);
    vec3 t2 = v3_cross(vh, t1);
    float r = sqrtf(u1), s, c;
    fm_sincosf(2.0f * FM_PI * u2, &s, &c);
    float p1 = r * c, p2 = r * s;
    float h = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - h) * sqrtf(fmaxf(0.0f, 1.0f - p1 * p1)) + h * p2;
    float p3 = sqrtf(fmaxf(0.0f, 1.0f - p1 * p1 - p2 * p2));
    vec3 nh = v3_add(v3_add(v3_scale(t1, p1), v3_scale(t2, p2)), v3_scale(vh, p3));
    /* Back to the rough configuration (normals transform by the inverse
     * transpose of the stretch). */
    return v3_norm(v3(a.ax * nh.x, a.ay * nh.y, fmaxf(0.0f, nh.z)));
}

float mf_pdf_visible(mf_alpha a, vec3 wo, vec3 m)
{
    float c = v3_dot(wo, m);
    if (c <= 0.0f || wo.z <= 0.0f)
        return 0.0f;
    return mf_G1(a, wo) * c * mf_D(a, m) / wo.z;
}

/* ---- Fresnel ------------------------------------------------------------ */

float mf_fresnel_dielectric(float cos_i, float eta, float *cos_t)
{
    float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f) {
        *cos_t = 0.0f;
        return 1.0f;
    }
    float ct = sqrtf(1.0f - sin2_t);
    float rs = (cos_i - eta * ct) / (cos_i + eta * ct);
    float rp = (eta * cos_i - ct) / (eta * cos_i + ct);
    *cos_t = ct;
    return 0.5f * (rs * rs + rp * rp);
}

vec3 mf_sample_cosine(float u1, float u2)
{
    float r = sqrtf(u1), s, c;
    fm_sincosf(2.0f * FM_PI * u2, &s, &c);
    /* 1 - u1 clamped at 0 as fmaxf(0, .) would, without its library call. */
    float z2 = 1.0f - u1;
    return v3(r * c, r * s, sqrtf(z2 > 0.0f ? z2 : 0.0f));
}

static inline float pow5(float x) { float x2 = x * x; return x2 * x2 * x; }

vec3 mf_fresnel_schlick(vec3 f0, float cos_i)
{
    float w = pow5(1.0f - clampf(cos_i, 0.0f, 1.0f));
    return v3_add(f0, v3_scale(v3_sub(v3s(1.0f), f0), w));
}

float mf_f0_from_ior(float eta)
{
    float r = (eta - 1.0f) / (eta + 1.0f);
    return r * r;
}

/* One channel of the conductor's reflectance.  With n = eta + i k and
 * s^2 = 1 - c^2, sqrt(n^2 - s^2) = a + i b; a^2 + b^2 and a follow from the
 * real and imaginary parts of n^2 - s^2, and then
 * Rs = (a^2 + b^2 - 2ac + c^2) / (a^2 + b^2 + 2ac + c^2) and
 * Rp = Rs (c^2 (a^2 + b^2) - 2ac s^2 + s^4) / (c^2 (a^2 + b^2) + 2ac s^2 + s^4). */
static float conductor1(float c, float eta, float k)
{
    float c2 = c * c, s2 = 1.0f - c2;
    float e2 = eta * eta, k2 = k * k;
    float re = e2 - k2 - s2;
    float ab2 = sqrtf(re * re + 4.0f * e2 * k2);
    float a = sqrtf(fmaxf(0.0f, 0.5f * (ab2 + re)));
    float u = ab2 + c2, v = 2.0f * a * c;
    float rs = (u - v) / (u + v);
    float p = c2 * ab2 + s2 * s2, q = v * s2;
    float rp = rs * (p - q) / (p + q);
    return 0.5f * (rs + rp);
}

vec3 mf_fresnel_conductor(float cos_i, vec3 eta, vec3 k)
{
    float c = clampf(cos_i, 1e-7f, 1.0f);
    return v3(conductor1(c, eta.x, k.x), conductor1(c, eta.y, k.y), conductor1(c, eta.z, k.z));
}

vec3 mf_fresnel_average(uint32_t fresnel, vec3 color, vec3 eta, vec3 k)
{
    if (fresnel == MF_FRESNEL_NONE)
        return color;
    if (fresnel == MF_FRESNEL_SCHLICK)   /* 2 int (1 - mu)^5 mu dmu = 1/21 */
        return v3_add(color, v3_scale(v3_sub(v3s(1.0f), color), 1.0f / 21.0f));
    enum { N = 64 };
    vec3 acc = v3s(0.0f);
    for (int i = 0; i < N; i++) {
        float mu = ((float)i + 0.5f) / N;
        acc = v3_add(acc, v3_scale(mf_fresnel_conductor(mu, eta, k), mu));
    }
    return v3_mul(color, v3_scale(acc, 2.0f / N));
}

static vec3 conductor_fresnel(const mf_conductor *c, float cos_i)
{
    if (c->fresnel == MF_FRESNEL_NONE)
        return c->color;
    if (c->fresnel == MF_FRESNEL_SCHLICK)
        return mf_fresnel_schlick(c->color, cos_i);
    return v3_mul(c->color, mf_fresnel_conductor(cos_i, c->eta, c->k));
}

/* ---- albedo tables ------------------------------------------------------ */

static inline float tab(uint16_t v) { return (float)v * (1.0f / 65535.0f); }

/* Table roughness of an alpha pair (sqrt of the geometric mean alpha). */
static inline float tab_roughness(mf_alpha a) { return sqrtf(sqrtf(a.ax * a.ay)); }

/* Cell and fraction of x in [0, 1] on a grid of n nodes. */
static inline void cell(float x, int n, int *i, float *t)
{
    float f = clampf(x, 0.0f, 1.0f) * (float)(n - 1);
    int k = (int)f;
    if (k > n - 2)
        k = n - 2;
    *i = k;
    *t = f - (float)k;
}

static inline float lerp(float a, float b, float t) { return a + (b - a) * t; }

static float bilinear(const uint16_t (*e)[MF_TAB_MU], mf_alpha a, float mu)
{
    int i, j;
    float ti, tj;
    cell(sqrtf(fmaxf(mu, 0.0f)), MF_TAB_MU, &i, &ti);
    cell(tab_roughness(a), MF_TAB_R, &j, &tj);
    return lerp(lerp(tab(e[j][i]), tab(e[j][i + 1]), ti), lerp(tab(e[j + 1][i]), tab(e[j + 1][i + 1]), ti), tj);
}

static float linear(const uint16_t *e, mf_alpha a)
{
    int j;
    float tj;
    cell(tab_roughness(a), MF_TAB_R, &j, &tj);
    return lerp(tab(e[j]), tab(e[j + 1]), tj);
}

float mf_albedo(mf_alpha a, uint32_t masking, float mu)
{
    return bilinear(mf_tab_e[masking == MF_SMITH_SEPARABLE], a, mu);
}

float mf_albedo_schlick(mf_alpha a, uint32_t masking, float f0, float mu, float *avg)
{
    int s = masking == MF_SMITH_SEPARABLE;
    *avg = f0 * linear(mf_tab_eavg[s], a) + (1.0f - f0) * linear(mf_tab_e5avg[s], a);
    return f0 * bilinear(mf_tab_e[s], a, mu) + (1.0f - f0) * bilinear(mf_tab_e5[s], a, mu);
}

float mf_dielectric_albedo(mf_alpha a, uint32_t masking, float eta, float mu)
{
    int leaving = eta < 1.0f;
    float e = leaving ? 1.0f / eta : eta;
    int i, j, k;
    float ti, tj, tk;
    cell(sqrtf(fmaxf(mu, 0.0f)), MF_TAB_DMU, &i, &ti);
    cell(tab_roughness(a), MF_TAB_DR, &j, &tj);
    cell(2.0f * (e - 1.0f) / (e + 1.0f), MF_TAB_DETA, &k, &tk);
    const uint16_t (*t)[MF_TAB_DR][MF_TAB_DMU] = mf_tab_ed[masking == MF_SMITH_SEPARABLE][leaving];
    float v[2];
    for (int dk = 0; dk < 2; dk++) {
        const uint16_t (*r)[MF_TAB_DMU] = t[k + dk];
        v[dk] = lerp(lerp(tab(r[j][i]), tab(r[j][i + 1]), ti), lerp(tab(r[j + 1][i]), tab(r[j + 1][i + 1]), ti), tj);
    }
    return lerp(v[0], v[1], tk);
}

/* ---- rough conductor ---------------------------------------------------- */

void mf_conductor_init(mf_conductor *c) { c->favg = mf_fresnel_average(c->fresnel, c->color, c->eta, c->k); }

/* The factor that gives back a reflector's multiply scattered light:
 * 1 + F_avg (1 - E) / E per channel. */
static vec3 ms_scale(vec3 favg, float e)
{
    if (!(e > 0.0f))
        return v3s(1.0f);
    float g = (1.0f - e) / e;
    return v3(1.0f + favg.x * g, 1.0f + favg.y * g, 1.0f + favg.z * g);
}

vec3 mf_conductor_eval(const mf_conductor *c, vec3 wo, vec3 wi, float *pdf)
{
    *pdf = 0.0f;
    if (wo.z <= 0.0f || wi.z <= 0.0f)
        return v3s(0.0f);
    vec3 h = v3_norm(v3_add(wo, wi));
    float d = mf_D(c->alpha, h);
    float spec = d * mf_G2(c->alpha, c->masking, wo, wi) / (4.0f * wo.z * wi.z);
    vec3 f = v3_scale(conductor_fresnel(c, v3_dot(wo, h)), spec);
    if (c->compensate)
        f = v3_mul(f, ms_scale(c->favg, mf_albedo(c->alpha, c->masking, wo.z)));
    *pdf = mf_G1(c->alpha, wo) * d / (4.0f * wo.z);
    return f;
}

static inline vec3 reflect_about(vec3 wo, vec3 m) { return v3_sub(v3_scale(m, 2.0f * v3_dot(wo, m)), wo); }

int mf_conductor_sample(const mf_conductor *c, vec3 wo, float uc, float u1, float u2, mf_sample *s)
{
    (void)uc;
    if (wo.z <= 0.0f)
        return 0;
    s->wi = reflect_about(wo, mf_sample_visible(c->alpha, wo, u1, u2));
    if (s->wi.z <= 0.0f)
        return 0;
    vec3 f = mf_conductor_eval(c, wo, s->wi, &s->pdf);
    if (!(s->pdf > 0.0f))
        return 0;
    s->weight = v3_scale(f, s->wi.z / s->pdf);
    return 1;
}

/* ---- rough dielectric --------------------------------------------------- */

vec3 mf_dielectric_eval(const mf_dielectric *d, float eta, vec3 wo, vec3 wi, float *pdf)
{
    *pdf = 0.0f;
    if (wo.z <= 0.0f || wi.z == 0.0f)
        return v3s(0.0f);
    float unused, fmacro = 0.0f;
    if (d->fresnel_at == MF_DIELECTRIC_MACRO)
        fmacro = mf_fresnel_dielectric(wo.z, eta, &unused);
    vec3 f;
    if (wi.z > 0.0f) {
        vec3 h = v3_norm(v3_add(wo, wi));
        float oh = v3_dot(wo, h);
        float fr = d->fresnel_at == MF_DIELECTRIC_MACRO ? fmacro : mf_fresnel_dielectric(oh, eta, &unused);
        float dh = mf_D(d->alpha, h);
        f = v3_scale(d->reflect_tint, fr * dh * mf_G2(d->alpha, d->masking, wo, wi) / (4.0f * wo.z * wi.z));
        *pdf = fr * mf_G1(d->alpha, wo) * dh / (4.0f * wo.z);
    } else {
        /* Walter et al. 2007: the half vector of a refraction is
         * -(eta_o wo + eta_i wi), turned to the normal's side; radiance
         * leaving toward wo carries eta_o^2 / (eta_i wi.h + eta_o wo.h)^2
         * with eta_o = 1, eta_i = eta. */
        vec3 h = v3_neg(v3_add(wo, v3_scale(wi, eta)));
        float len = v3_len(h);
        if (!(len > 1e-6f))
            return v3s(0.0f);
        h = v3_scale(h, (h.z < 0.0f ? -1.0f : 1.0f) / len);
        float oh = v3_dot(wo, h), ih = v3_dot(wi, h);
        if (oh <= 0.0f || ih >= 0.0f)
            return v3s(0.0f);
        float ft = d->fresnel_at == MF_DIELECTRIC_MACRO ? fmacro : mf_fresnel_dielectric(oh, eta, &unused);
        float den = oh + eta * ih, den2 = den * den;
        if (!(den2 > 0.0f) || ft >= 1.0f)
            return v3s(0.0f);
        float dh = mf_D(d->alpha, h);
        float g2 = mf_G2(d->alpha, d->masking, wo, wi);
        f = v3_scale(d->transmit_tint, (1.0f - ft) * dh * g2 * oh * -ih / (wo.z * -wi.z * den2));
        *pdf = (1.0f - ft) * mf_G1(d->alpha, wo) * oh * dh / wo.z * (eta * eta * -ih / den2);
    }
    if (d->compensate && d->fresnel_at == MF_DIELECTRIC_MICRO) {
        float e = mf_dielectric_albedo(d->alpha, d->masking, eta, wo.z);
        if (e > 0.0f)
            f = v3_scale(f, 1.0f / e);
    }
    return f;
}

int mf_dielectric_sample(const mf_dielectric *d, float eta, vec3 wo, float uc, float u1, float u2, mf_sample *s)
{
    if (wo.z <= 0.0f)
        return 0;
    vec3 m = mf_sample_visible(d->alpha, wo, u1, u2);
    float c = v3_dot(wo, m), cos_t, unused;
    if (c <= 0.0f)
        return 0;
    float fm = mf_fresnel_dielectric(c, eta, &cos_t);
    float fr = d->fresnel_at == MF_DIELECTRIC_MACRO ? mf_fresnel_dielectric(wo.z, eta, &unused) : fm;
    if (uc < fr) {
        s->wi = reflect_about(wo, m);
        if (s->wi.z <= 0.0f)
            return 0;
    } else {
        if (cos_t <= 0.0f)   /* total internal reflection at this microfacet */
            return 0;
        s->wi = v3_norm(v3_add(v3_scale(wo, -1.0f / eta), v3_scale(m, c / eta - cos_t)));
        if (s->wi.z >= 0.0f)
            return 0;
    }
    vec3 f = mf_dielectric_eval(d, eta, wo, s->wi, &s->pdf);
    if (!(s->pdf > 0.0f))
        return 0;
    s->weight = v3_scale(f, fabsf(s->wi.z) / s->pdf);
    return 1;
}

/* ---- glTF metallic-roughness -------------------------------------------- */

/* What a principled evaluation needs that depends on wo alone: the
 * lobe-selection weights (so the pdf of a direction is the same mixture
 * whichever lobe drew it) and the specular layer's albedo. */
typedef struct {
    float wm, wd, wt;                  /* metal, opaque dielectric, refracting dielectric shares */
    float f0;                          /* the specular layer's */
    float es_o, es_avg;                /* its albedo at mu_o and average (MF_COUPLE_ALBEDO) */
    float spec, cosine, refract, sum;  /* sampling weights: GGX reflection, cosine, dielectric */
    vec3 cspec0;                       /* MF_COUPLE_CYCLES: the specular colour at normal incidence */
} principled_ctx;

/* Cycles' interpolation weight: the dielectric Fresnel factor rescaled from
 * [F0, 1] to [0, 1]. */
static float cycles_fresnel_weight(float ior, float f0, float cos_h)
{
    float unused;
    return f0 < 1.0f ? (mf_fresnel_dielectric(cos_h, ior, &unused) - f0) / (1.0f - f0) : 1.0f;
}

static principled_ctx cycles_setup(const mf_principled *p, principled_ctx c, vec3 wo)
{
    float m = c.wm;
    c.cspec0 = v3_add(v3s(c.f0 * (1.0f - m)), v3_scale(p->base, m));
    float w = cycles_fresnel_weight(p->ior, c.f0, wo.z), lum = fmaxf(0.0f, v3_luma(c.cspec0));
    c.spec = (1.0f - c.wt) * (lum * (1.0f - w) + w);
    c.cosine = c.wd * fmaxf(0.0f, v3_luma(p->base));
    c.refract = c.wt;
    c.sum = c.spec + c.cosine + c.refract;
    return c;
}

/* Disney's diffuse with retro-reflection, as Cycles 3.4 evaluates it,
 * without the base colour and 1/pi. */
static float disney_diffuse(float roughness, vec3 wo, vec3 wi)
{
    float a = 1.0f - wo.z, b = 1.0f - wi.z;
    float fv = a * a * a * a * a, fl = b * b * b * b * b;
    float rr = roughness * (v3_dot(wo, wi) + 1.0f);
    return (1.0f - 0.5f * fv) * (1.0f - 0.5f * fl) + rr * (fl + fv + fl * fv * (rr - 1.0f));
}

static principled_ctx principled_setup(const mf_principled *p, vec3 wo)
{
    principled_ctx c;
    c.wm = clampf(p->metallic, 0.0f, 1.0f);
    c.wt = (1.0f - c.wm) * clampf(p->transmission, 0.0f, 1.0f);
    c.wd = (1.0f - c.wm) - c.wt;
    c.f0 = mf_f0_from_ior(p->ior);
    c.es_o = c.es_avg = 0.0f;
    c.cspec0 = v3s(0.0f);
    if (p->coupling == MF_COUPLE_CYCLES)
        return cycles_setup(p, c, wo);
    float fs = mf_fresnel_schlick(v3s(c.f0), wo.z).x, through;
    if (p->coupling == MF_COUPLE_GLTF) {
        through = 1.0f - fs;
    } else {
        c.es_o = mf_albedo_schlick(p->alpha, p->masking, c.f0, wo.z, &c.es_avg);
        through = 1.0f - c.es_o;
    }
    c.spec = c.wm + c.wd * fs;
    c.cosine = c.wd * through * fmaxf(0.0f, v3_luma(p->base));
    c.refract = c.wt;
    c.sum = c.spec + c.cosine + c.refract;
    return c;
}

static mf_dielectric principled_dielectric(const mf_principled *p)
{
    mf_dielectric d = {p->alpha, p->masking, MF_DIELECTRIC_MICRO, v3s(1.0f), p->base, p->compensate};
    if (p->coupling == MF_COUPLE_CYCLES)
        d.fresnel_at = MF_DIELECTRIC_MACRO;
    return d;
}

static vec3 principled_eval(const mf_principled *p, const principled_ctx *c, float eta, vec3 wo, vec3 wi,
                            float *pdf)
{
    vec3 f = v3s(0.0f);
    float pd = 0.0f;
    if (wi.z > 0.0f) {
        vec3 h = v3_norm(v3_add(wo, wi));
        float oh = v3_dot(wo, h), d = mf_D(p->alpha, h);
        float spec = d * mf_G2(p->alpha, p->masking, wo, wi) / (4.0f * wo.z * wi.z);
        if (p->coupling == MF_COUPLE_CYCLES) {
            float w = cycles_fresnel_weight(p->ior, c->f0, oh);
            vec3 fc = v3_add(v3_scale(c->cspec0, 1.0f - w), v3s(w));
            f = v3_add(v3_scale(fc, (1.0f - c->wt) * spec),
                       v3_scale(p->base, c->wd * disney_diffuse(p->roughness, wo, wi) * FM_INV_PI));
        } else {
            /* metal: Schlick with F0 = base colour */
            vec3 metal = v3_scale(mf_fresnel_schlick(p->base, oh), spec);
            if (p->compensate && c->wm > 0.0f) {
                vec3 favg = mf_fresnel_average(MF_FRESNEL_SCHLICK, p->base, v3s(0.0f), v3s(0.0f));
                metal = v3_mul(metal, ms_scale(favg, mf_albedo(p->alpha, p->masking, wo.z)));
            }
            /* dielectric: the specular layer over Lambert */
            float fs = mf_fresnel_schlick(v3s(c->f0), oh).x, through;
            if (p->coupling == MF_COUPLE_GLTF) {
                through = 1.0f - fs;
            } else {
                float unused, es_i = mf_albedo_schlick(p->alpha, p->masking, c->f0, wi.z, &unused);
                through = c->es_avg < 1.0f ? (1.0f - c->es_o) * (1.0f - es_i) / (1.0f - c->es_avg) : 0.0f;
            }
            vec3 diel = v3_add(v3s(fs * spec), v3_scale(p->base, through * FM_INV_PI));
            f = v3_add(v3_scale(metal, c->wm), v3_scale(diel, c->wd));
        }
        pd = c->spec * mf_G1(p->alpha, wo) * d / (4.0f * wo.z) + c->cosine * wi.z * FM_INV_PI;
    }
    if (c->refract > 0.0f) {
        mf_dielectric dl = principled_dielectric(p);
        float pt;
        vec3 ft = mf_dielectric_eval(&dl, eta, wo, wi, &pt);
        f = v3_add(f, v3_scale(ft, c->wt));
        pd += c->refract * pt;
    }
    *pdf = pd / c->sum;
    return f;
}

vec3 mf_principled_eval(const mf_principled *p, float eta, vec3 wo, vec3 wi, float *pdf)
{
    *pdf = 0.0f;
    if (wo.z <= 0.0f || wi.z == 0.0f)
        return v3s(0.0f);
    principled_ctx c = principled_setup(p, wo);
    if (!(c.sum > 0.0f))
        return v3s(0.0f);
    return principled_eval(p, &c, eta, wo, wi, pdf);
}

int mf_principled_sample(const mf_principled *p, float eta, vec3 wo, float uc, float u1, float u2, mf_sample *s)
{
    if (wo.z <= 0.0f)
        return 0;
    principled_ctx c = principled_setup(p, wo);
    if (!(c.sum > 0.0f))
        return 0;
    float u = uc * c.sum;
    if (u < c.spec) {
        s->wi = reflect_about(wo, mf_sample_visible(p->alpha, wo, u1, u2));
        if (s->wi.z <= 0.0f)
            return 0;
    } else if (u < c.spec + c.cosine) {
        s->wi = mf_sample_cosine(u1, u2);
    } else {
        mf_dielectric dl = principled_dielectric(p);
        mf_sample t;
        float ur = clampf((u - c.spec - c.cosine) / c.refract, 0.0f, 0x1.fffffep-1f);
        if (!mf_dielectric_sample(&dl, eta, wo, ur, u1, u2, &t))
            return 0;
        s->wi = t.wi;
    }
    if (s->wi.z == 0.0f)
        return 0;
    vec3 f = principled_eval(p, &c, eta, wo, s->wi, &s->pdf);
    if (!(s->pdf > 0.0f))
        return 0;
    s->weight = v3_scale(f, fabsf(s->wi.z) / s->pdf);
    return 1;
}
