/* test_microfacet.c -- GGX lobes: closed forms, sampling fit, furnaces, albedo
 * tables.
 *
 * Microfacet lobes (common/microfacet.h): closed forms of the distribution,
 * masking and Fresnel factors; chi-square goodness of fit of every sampler
 * against its pdf, from normal to grazing incidence and roughness 0.05 to 1;
 * reciprocity; white furnaces with and without energy compensation; the
 * compiled albedo tables against an independent quadrature. */
#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bsdf.h"
#include "check.h"
#include "stats.h"
#include "microfacet.h"
#include "microfacet_table.h"
#include "sampler.h"

/* ---- random numbers and statistics -------------------------------------- */

static uint32_t rng_state = 1;
static float rnd(void)
{
    rng_state = smp_hash(rng_state + 0x9e3779b9u);
    return (float)(rng_state >> 8) * 0x1p-24f;
}

/* Deterministic random numbers make each p-value fixed; the threshold is a
 * 1 % test level shared by the ~100 tests here. */
#define P_MIN 1e-4

/* ---- directions binned around a lobe ------------------------------------- */

/* The sphere parameterized around an axis so that a lobe of angular width w
 * there spreads over many bins and the rest of the sphere still gets bins
 * of reasonable size: theta = w (exp(k u) - 1) with k = log(1 + pi / w)
 * (theta from 0 to pi as u goes from 0 to 1), phi = 2 pi v. */
typedef struct {
    double ax[3], t[3], b[3];
    double w, k;
} lobe_map;

static lobe_map map_make(vec3 axis, double w)
{
    lobe_map m;
    double a[3] = {axis.x, axis.y, axis.z}, n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    for (int i = 0; i < 3; i++)
        m.ax[i] = a[i] / n;
    double h[3] = {1, 0, 0};
    if (fabs(m.ax[0]) > 0.9) {
        h[0] = 0;
        h[1] = 1;
    }
    double d = h[0] * m.ax[0] + h[1] * m.ax[1] + h[2] * m.ax[2], tl = 0;
    for (int i = 0; i < 3; i++) {
        m.t[i] = h[i] - d * m.ax[i];
        tl += m.t[i] * m.t[i];
    }
    for (int i = 0; i < 3; i++)
        m.t[i] /= sqrt(tl);
    m.b[0] = m.ax[1] * m.t[2] - m.ax[2] * m.t[1];
    m.b[1] = m.ax[2] * m.t[0] - m.ax[0] * m.t[2];
    m.b[2] = m.ax[0] * m.t[1] - m.ax[1] * m.t[0];
    m.w = w;
    m.k = log(1 + M_PI / w);
    return m;
}

/* Direction at (u, v) and the solid angle per unit u v there. */
static void map_dir(const lobe_map *m, double u, double v, double d[3], double *jac)
{
    double th = m->w * (exp(m->k * u) - 1), ph = 2 * M_PI * v;
    double st = sin(th), ct = cos(th), cp = cos(ph), sp = sin(ph);
    for (int i = 0; i < 3; i++)
        d[i] = st * cp * m->t[i] + st * sp * m->b[i] + ct * m->ax[i];
    *jac = st * m->k * (th + m->w) * 2 * M_PI;
}

static void map_uv(const lobe_map *m, vec3 d, double *u, double *v)
{
    double x = d.x * m->t[0] + d.y * m->t[1] + d.z * m->t[2];
    double y = d.x * m->b[0] + d.y * m->b[1] + d.z * m->b[2];
    double z = d.x * m->ax[0] + d.y * m->ax[1] + d.z * m->ax[2];
    double th = atan2(sqrt(x * x + y * y), z), ph = atan2(y, x);
    if (ph < 0)
        ph += 2 * M_PI;
    *u = log(1 + th / m->w) / m->k;
    *v = ph / (2 * M_PI);
}

/* A lobe under test: its sampler and its pdf (and f, for energy). */
typedef struct model model;
struct model {
    int (*sample)(const model *md, vec3 wo, float uc, float u1, float u2, mf_sample *s);
    vec3 (*eval)(const model *md, vec3 wo, vec3 wi, float *pdf);
    mf_conductor cond;
    mf_dielectric diel;
    mf_principled prin;
    mf_alpha alpha;    /* for visible normals */
    float eta;
};

static int vndf_sample(const model *md, vec3 wo, float uc, float u1, float u2, mf_sample *s)
{
    (void)uc;
    s->wi = mf_sample_visible(md->alpha, wo, u1, u2);
    s->pdf = mf_pdf_visible(md->alpha, wo, s->wi);
    return s->pdf > 0.0f;
}
static vec3 vndf_eval(const model *md, vec3 wo, vec3 m, float *pdf)
{
    *pdf = mf_pdf_visible(md->alpha, wo, m);
    return v3s(0.0f);
}
static int cond_sample(const model *md, vec3 wo, float uc, float u1, float u2, mf_sample *s)
{
    return mf_conductor_sample(&md->cond, wo, uc, u1, u2, s);
}
static vec3 cond_eval(const model *md, vec3 wo, vec3 wi, float *pdf) { return mf_conductor_eval(&md->cond, wo, wi, pdf); }
static int diel_sample(const model *md, vec3 wo, float uc, float u1, float u2, mf_sample *s)
{
    return mf_dielectric_sample(&md->diel, md->eta, wo, uc, u1, u2, s);
}
static vec3 diel_eval(const model *md, vec3 wo, vec3 wi, float *pdf)
{
    return mf_dielectric_eval(&md->diel, md->eta, wo, wi, pdf);
}
static int prin_sample(const model *md, vec3 wo, float uc, float u1, float u2, mf_sample *s)
{
    return mf_principled_sample(&md->prin, md->eta, wo, uc, u1, u2, s);
}
static vec3 prin_eval(const model *md, vec3 wo, vec3 wi, float *pdf)
{
    return mf_principled_eval(&md->prin, md->eta, wo, wi, pdf);
}

/* Integral of g over the rectangle [u0,u1) x [v0,v1) of a map: a 4 x 4
 * midpoint rule, refined where it disagrees with a 2 x 2 rule by more than
 * @p tol (narrow peaks), and where g is zero at some points and not at
 * others (the horizon, total internal reflection: there the rule would be
 * off by the cut's share of a cell).  The test for a cut looks at the
 * corners and edges as well, so a cut near a cell's border is seen. */
typedef double (*sphere_fn)(const void *ctx, vec3 d);
static vec3 from_d(const double d[3]) { return v3((float)d[0], (float)d[1], (float)d[2]); }

static double adapt(sphere_fn g, const void *ctx, const lobe_map *m, double u0, double u1, double v0, double v1,
                    double tol, int depth)
{
    enum { K = 4 };
    double fine = 0, coarse = 0, top = 0;
    int zero = 0, n = 0;
    for (int a = 0; a <= 2 * K; a++)
        for (int b = 0; b <= 2 * K; b++) {
            int mid = (a & 1) && (b & 1), quarter = (a == 2 || a == 6) && (b == 2 || b == 6);
            if (!mid && depth == 0)
                continue;
            double d[3], jac;
            map_dir(m, u0 + (u1 - u0) * a / (2 * K), v0 + (v1 - v0) * b / (2 * K), d, &jac);
            double y = g(ctx, from_d(d));
            zero += y == 0;
            n++;
            top = fmax(top, y * jac);
            if (mid)
                fine += y * jac;
            if (quarter)
                coarse += y * jac;
        }
    double area = (u1 - u0) * (v1 - v0);
    fine *= area / (K * K);
    coarse *= area / 4;
    /* A cut costs at most the cell's largest value over its area. */
    int cut = zero != 0 && zero != n && top * area > tol;
    if (depth == 0 || (!cut && fabs(fine - coarse) <= tol))
        return fine;
    double um = 0.5 * (u0 + u1), vm = 0.5 * (v0 + v1);
    return adapt(g, ctx, m, u0, um, v0, vm, tol, depth - 1) + adapt(g, ctx, m, um, u1, v0, vm, tol, depth - 1) +
           adapt(g, ctx, m, u0, um, vm, v1, tol, depth - 1) + adapt(g, ctx, m, um, u1, vm, v1, tol, depth - 1);
}

/* Integral of g over the sphere, on n x n cells of a map. */
static double integrate(const lobe_map *m, sphere_fn g, const void *ctx, int n)
{
    double acc = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            acc += adapt(g, ctx, m, (double)i / n, (i + 1.0) / n, (double)j / n, (j + 1.0) / n, 1e-6, 6);
    return acc;
}

enum { NU = 16, NV = 32, NB = NU * NV };

typedef struct { const model *md; vec3 wo; int side; } pdf_ctx;
static double g_pdf(const void *c, vec3 wi)
{
    const pdf_ctx *x = c;
    if ((x->side > 0) != (wi.z > 0) || wi.z == 0)
        return 0;
    float pdf;
    x->md->eval(x->md, x->wo, wi, &pdf);
    return pdf;
}

/* Integral of the model's pdf over each bin of a map, restricted to one
 * side of the surface (side > 0: wi.z > 0). */
static double expected_bins(const model *md, vec3 wo, const lobe_map *m, int side, double *expct)
{
    pdf_ctx x = {md, wo, side};
    double total = 0;
    for (int iu = 0; iu < NU; iu++)
        for (int iv = 0; iv < NV; iv++) {
            double e = adapt(g_pdf, &x, m, (double)iu / NU, (iu + 1.0) / NU, (double)iv / NV, (iv + 1.0) / NV, 1e-6, 7);
            expct[iu * NV + iv] = e;
            total += e;
        }
    return total;
}

/* Chi-square test of a sampler against its pdf: samples above the surface
 * are binned around axis_up, those below around axis_down (when the lobe
 * transmits), void samples in a bin of their own. */
static void chi2_model(const char *name, const model *md, vec3 wo, vec3 axis_up, vec3 axis_down, double w,
                       int transmits, int nsamples)
{
    static double obs[2 * NB + 1], expct[2 * NB + 1];
    memset(obs, 0, sizeof obs);
    memset(expct, 0, sizeof expct);
    lobe_map up = map_make(axis_up, w), down = map_make(axis_down, w);
    double total = expected_bins(md, wo, &up, 1, expct);
    if (transmits)
        total += expected_bins(md, wo, &down, -1, expct + NB);
    int bad = 0;
    rng_state = 12345;
    for (int i = 0; i < nsamples; i++) {
        mf_sample s;
        float uc = rnd(), u1 = rnd(), u2 = rnd();
        if (!md->sample(md, wo, uc, u1, u2, &s)) {
            obs[2 * NB]++;
            continue;
        }
        double u, v;
        const lobe_map *m = s.wi.z > 0 ? &up : &down;
        map_uv(m, s.wi, &u, &v);
        int iu = (int)(u * NU), iv = (int)(v * NV);
        iu = iu < 0 ? 0 : iu >= NU ? NU - 1 : iu;
        iv = iv < 0 ? 0 : iv >= NV ? NV - 1 : iv;
        obs[(s.wi.z > 0 ? 0 : NB) + iu * NV + iv]++;
        /* The pdf a sample reports is the pdf eval gives for it. */
        float pe;
        md->eval(md, wo, s.wi, &pe);
        if (fabsf(pe - s.pdf) > 1e-4f * pe && bad++ < 3)
            printf("%s: sample pdf %g, eval pdf %g\n", name, s.pdf, pe);
    }
    CHECK(bad == 0, "%s: %d samples report a pdf other than eval's", name, bad);
    for (int i = 0; i < 2 * NB; i++)
        expct[i] *= nsamples;
    expct[2 * NB] = fmax(0.0, 1.0 - total) * nsamples;
    double p = st_chi2_test(obs, expct, 2 * NB + 1, 10.0);
    if (getenv("MF_DEBUG") && p <= P_MIN)
        for (int i = 0; i <= 2 * NB; i++)
            if (fabs(obs[i] - expct[i]) > 4 * sqrt(expct[i] + 1))
                printf("  bin %d (%s u %d v %d): observed %.0f expected %.1f\n", i, i >= NB ? "down" : "up",
                       (i % NB) / NV, i % NV, obs[i], expct[i]);
    CHECK(p > P_MIN, "%s: chi-square p-value %.3g (pdf integral %.5f, void %.5f)", name, p, total,
          obs[2 * NB] / nsamples);
    printf("%-58s p = %.3f  (pdf mass %.4f, void %.4f)\n", name, p, total, obs[2 * NB] / nsamples);
}

static vec3 incident(float theta_deg)
{
    double t = theta_deg * M_PI / 180;
    return v3((float)sin(t), 0.0f, (float)cos(t));
}

static const float ROUGH[] = {0.05f, 0.2f, 0.5f, 1.0f};
static const float THETA[] = {0.0f, 45.0f, 75.0f, 88.0f};

static double lobe_width(mf_alpha a) { return fmax(2.0 * sqrt(a.ax * a.ay), 1e-3); }

static void test_chi2_vndf(void)
{
    char name[128];
    model md = {.sample = vndf_sample, .eval = vndf_eval};
    for (int r = 0; r < 4; r++)
        for (int t = 0; t < 4; t++) {
            md.alpha = mf_alpha_iso(ROUGH[r]);
            snprintf(name, sizeof name, "visible normals r=%.2f theta=%.0f", ROUGH[r], THETA[t]);
            chi2_model(name, &md, incident(THETA[t]), v3(0, 0, 1), v3(0, 0, -1), lobe_width(md.alpha) / 2, 0,
                       200000);
        }
    md.alpha = mf_alpha_aniso(0.5f, 0.8f);
    chi2_model("visible normals anisotropic r=0.5 a=0.8 theta=60", &md, v3_norm(v3(0.6f, 0.5f, 0.6f)), v3(0, 0, 1),
               v3(0, 0, -1), lobe_width(md.alpha) / 2, 0, 200000);
}

static void test_chi2_conductor(void)
{
    char name[128];
    model md = {.sample = cond_sample, .eval = cond_eval};
    for (int r = 0; r < 4; r++)
        for (int t = 0; t < 4; t++)
            for (int comp = 0; comp < 2; comp++) {
                if (comp && r == 0)
                    continue;
                mf_conductor c = {mf_alpha_iso(ROUGH[r]), (uint32_t)(t & 1), MF_FRESNEL_SCHLICK, v3(0.9f, 0.6f, 0.3f),
                                  v3s(0), v3s(0), comp, v3s(0)};
                mf_conductor_init(&c);
                md.cond = c;
                vec3 wo = incident(THETA[t]);
                snprintf(name, sizeof name, "conductor r=%.2f theta=%.0f %s%s", ROUGH[r], THETA[t],
                         (t & 1) ? "separable" : "correlated", comp ? " compensated" : "");
                chi2_model(name, &md, wo, v3(-wo.x, -wo.y, wo.z), v3(0, 0, -1), lobe_width(c.alpha), 0, 200000);
            }
    mf_conductor c = {mf_alpha_aniso(0.4f, -0.7f), MF_SMITH_CORRELATED, MF_FRESNEL_CONDUCTOR, v3s(1),
                      v3(0.2f, 0.9f, 1.1f), v3(3.9f, 2.4f, 2.2f), 1, v3s(0)};
    mf_conductor_init(&c);
    md.cond = c;
    vec3 wo = v3_norm(v3(0.3f, -0.8f, 0.5f));
    chi2_model("conductor anisotropic complex IOR compensated", &md, wo, v3(-wo.x, -wo.y, wo.z), v3(0, 0, -1),
               lobe_width(c.alpha), 0, 200000);
}

/* Refraction of wo through the normal, or straight down on total internal
 * reflection (only an axis for the bins). */
static vec3 refract_axis(vec3 wo, float eta)
{
    float ct;
    bsdf_fresnel(wo.z, eta, &ct);
    if (ct <= 0.0f)
        return v3(0, 0, -1);
    return v3_norm(v3_add(v3_scale(wo, -1.0f / eta), v3(0, 0, wo.z / eta - ct)));
}

static void test_chi2_dielectric(void)
{
    char name[128];
    model md = {.sample = diel_sample, .eval = diel_eval};
    const float etas[] = {1.5f, 1.0f / 1.5f};
    for (int r = 0; r < 4; r++)
        for (int t = 0; t < 4; t++)
            for (int e = 0; e < 2; e++)
                for (int macro = 0; macro < 2; macro++) {
                    /* Cycles' Fresnel placement at two roughnesses, normal
                     * and oblique incidence. */
                    if (macro && ((t != 0 && t != 2) || (r != 1 && r != 3)))
                        continue;
                    mf_dielectric d = {mf_alpha_iso(ROUGH[r]), (uint32_t)((t + e) & 1), (uint32_t)macro, v3s(1),
                                       v3(0.9f, 0.8f, 0.7f), r == 2};
                    md.diel = d;
                    md.eta = etas[e];
                    vec3 wo = incident(THETA[t]);
                    snprintf(name, sizeof name, "dielectric r=%.2f theta=%.0f eta=%.3f %s%s", ROUGH[r], THETA[t],
                             etas[e], macro ? "macro" : "micro", d.compensate ? " compensated" : "");
                    chi2_model(name, &md, wo, v3(-wo.x, -wo.y, wo.z), refract_axis(wo, etas[e]), lobe_width(d.alpha),
                               1, 200000);
                }
    mf_dielectric d = {mf_alpha_aniso(0.3f, 0.6f), MF_SMITH_CORRELATED, MF_DIELECTRIC_MICRO, v3s(1), v3s(1), 0};
    md.diel = d;
    md.eta = 2.4f;
    vec3 wo = v3_norm(v3(-0.4f, 0.4f, 0.7f));
    chi2_model("dielectric anisotropic eta=2.4", &md, wo, v3(-wo.x, -wo.y, wo.z), refract_axis(wo, 2.4f),
               lobe_width(d.alpha), 1, 300000);
}

static void test_chi2_principled(void)
{
    char name[160];
    model md = {.sample = prin_sample, .eval = prin_eval};
    struct { float rough, metal, trans, eta, theta; } cases[] = {
        {0.3f, 0.0f, 0.0f, 1.5f, 30}, {0.5f, 1.0f, 0.0f, 1.5f, 70}, {0.6f, 0.5f, 0.0f, 1.5f, 10},
        {0.2f, 0.3f, 0.6f, 1.5f, 50}, {0.4f, 0.0f, 1.0f, 1.0f / 1.45f, 20}, {0.8f, 0.7f, 0.2f, 1.5f, 80},
        {0.1f, 0.0f, 0.0f, 1.5f, 85}, {0.7f, 0.2f, 0.0f, 1.5f, 60},
        /* Cycles' Principled BSDF */
        {0.35f, 0.5f, 0.0f, 1.5f, 40}, {0.5f, 0.0f, 1.0f, 1.45f, 30}, {0.9f, 0.0f, 0.0f, 1.5f, 75},
        {0.3f, 0.2f, 0.5f, 1.0f / 1.5f, 60},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        uint32_t coupling = i >= 8 ? MF_COUPLE_CYCLES : i >= 6 ? MF_COUPLE_GLTF : MF_COUPLE_ALBEDO;
        mf_principled p = {mf_alpha_iso(cases[i].rough), (uint32_t)(i / 2 & 1), coupling, v3(0.8f, 0.5f, 0.2f),
                           cases[i].metal, cases[i].trans, 1.5f, (int)(i & 1) && i < 8, cases[i].rough};
        md.prin = p;
        md.eta = cases[i].eta;
        vec3 wo = incident(cases[i].theta);
        snprintf(name, sizeof name, "principled r=%.1f metal=%.1f transm=%.1f eta=%.2f theta=%.0f%s%s",
                 cases[i].rough, cases[i].metal, cases[i].trans, cases[i].eta, cases[i].theta,
                 p.compensate ? " comp" : "", p.coupling == MF_COUPLE_GLTF ? " glTF" : p.coupling ? " Cycles" : "");
        chi2_model(name, &md, wo, v3(-wo.x, -wo.y, wo.z), refract_axis(wo, cases[i].eta), lobe_width(p.alpha), 1,
                   300000);
    }
}

/* ---- closed forms ------------------------------------------------------- */

typedef struct { mf_alpha a; vec3 wo; } dist_ctx;
static double g_projected(const void *c, vec3 m)
{
    const dist_ctx *x = c;
    return m.z > 0 ? mf_D(x->a, m) * m.z : 0;
}
static double g_visible(const void *c, vec3 m)
{
    const dist_ctx *x = c;
    double cm = v3_dot(x->wo, m);
    return m.z > 0 && cm > 0 ? mf_D(x->a, m) * cm : 0;
}

static void test_distribution(void)
{
    const mf_alpha alphas[] = {mf_alpha_iso(0.05f), mf_alpha_iso(0.3f), mf_alpha_iso(1.0f), mf_alpha_aniso(0.5f, 0.9f),
                               mf_alpha_aniso(0.7f, -0.5f)};
    double worst_d = 0, worst_l = 0;
    for (size_t i = 0; i < sizeof alphas / sizeof alphas[0]; i++) {
        dist_ctx c = {alphas[i], v3(0, 0, 1)};
        lobe_map m = map_make(v3(0, 0, 1), sqrt(alphas[i].ax * alphas[i].ay));
        double nd = integrate(&m, g_projected, &c, 32);
        worst_d = fmax(worst_d, fabs(nd - 1));
        /* Smith's Lambda makes the visible projected area of the
         * microfacets equal the macro surface's: G1(wo) int D (wo.m)+ dm = wo.z. */
        for (int t = 0; t < 4; t++) {
            c.wo = v3_norm(v3(sinf(THETA[t] * 0.0174533f), 0.3f * sinf(THETA[t] * 0.0174533f), cosf(THETA[t] * 0.0174533f)));
            double vis = integrate(&m, g_visible, &c, 32) * mf_G1(c.a, c.wo);
            worst_l = fmax(worst_l, fabs(vis / c.wo.z - 1));
        }
    }
    CHECK(worst_d < 2e-3, "GGX D is not normalized: worst |int D cos - 1| = %g", worst_d);
    CHECK(worst_l < 2e-3, "Smith G1 does not match D: worst relative error %g", worst_l);
    printf("D normalization error %.2g, G1 projected-area error %.2g\n", worst_d, worst_l);
    /* Separable and height-correlated forms agree for one direction at the
     * pole and differ otherwise, the correlated one being larger. */
    mf_alpha a = mf_alpha_iso(0.7f);
    vec3 wo = incident(60), wi = v3_norm(v3(-0.5f, 0.2f, 0.4f));
    float gs = mf_G2(a, MF_SMITH_SEPARABLE, wo, wi), gc = mf_G2(a, MF_SMITH_CORRELATED, wo, wi);
    CHECK(fabsf(gs - mf_G1(a, wo) * mf_G1(a, wi)) < 1e-6f && gc > gs,
          "G2 forms: separable %g, correlated %g, G1 G1 %g", gs, gc, mf_G1(a, wo) * mf_G1(a, wi));
    CHECK(mf_G1(a, v3(0, 0, 1)) == 1.0f && mf_lambda(a, v3(1, 0, 0)) == INFINITY, "G1 at the pole / horizon");
    /* Lambda closed form: (sqrt(1 + alpha^2 tan^2) - 1) / 2. */
    double t2 = (1.0 - 0.25) / 0.25, lam = (sqrt(1 + 0.49 * 0.49 * t2) - 1) / 2;
    CHECK(fabs(mf_lambda(a, v3((float)sqrt(0.75), 0, 0.5f)) - lam) < 1e-6, "Lambda at 60 degrees");
}

/* Conductor Fresnel by complex arithmetic (double). */
static double conductor_ref(double c, double eta, double k)
{
    double complex n = eta + k * I, n2 = n * n;
    double s2 = 1 - c * c;
    double complex r = csqrt(n2 - s2);
    double rs = cabs((c - r) / (c + r)), rp = cabs((n2 * c - r) / (n2 * c + r));
    return 0.5 * (rs * rs + rp * rp);
}

static void test_fresnel(void)
{
    /* gold and aluminium at 650/550/450 nm, and a dielectric (k = 0) */
    const float nk[][2] = {{0.17f, 3.6f}, {0.43f, 2.45f}, {1.5f, 1.9f}, {1.2f, 7.3f}, {1.5f, 0.0f}, {2.4f, 0.0f}};
    double worst = 0;
    for (size_t i = 0; i < sizeof nk / sizeof nk[0]; i++)
        for (int j = 1; j <= 100; j++) {
            float c = j / 100.0f;
            float f = mf_fresnel_conductor(c, v3s(nk[i][0]), v3s(nk[i][1])).x;
            worst = fmax(worst, fabs(f - conductor_ref(c, nk[i][0], nk[i][1])));
        }
    CHECK(worst < 2e-6, "conductor Fresnel vs complex arithmetic: worst %g", worst);
    float e = 0.17f, k = 3.6f;
    float f0 = mf_fresnel_conductor(1.0f, v3s(e), v3s(k)).x;
    float f0ref = ((e - 1) * (e - 1) + k * k) / ((e + 1) * (e + 1) + k * k);
    CHECK(fabsf(f0 - f0ref) < 1e-6f, "conductor F0 %g, closed form %g", f0, f0ref);
    /* With k = 0 it is the dielectric's exact Fresnel. */
    float ct, worst_d = 0;
    for (int j = 1; j <= 100; j++) {
        float c = j / 100.0f;
        worst_d = fmaxf(worst_d, fabsf(mf_fresnel_conductor(c, v3s(1.5f), v3s(0)).x - bsdf_fresnel(c, 1.5f, &ct)));
    }
    CHECK(worst_d < 1e-6f, "k = 0 conductor vs dielectric Fresnel: %g", worst_d);
    CHECK(fabsf(mf_fresnel_conductor(1e-7f, v3s(e), v3s(k)).x - 1.0f) < 1e-5f, "conductor Fresnel at grazing -> 1");
    /* Schlick: F0 at normal incidence, 1 at grazing, the closed form between. */
    vec3 f = mf_fresnel_schlick(v3(0.04f, 0.5f, 1.0f), 0.5f);
    CHECK(fabsf(f.x - (0.04f + 0.96f / 32)) < 1e-7f && fabsf(f.y - (0.5f + 0.5f / 32)) < 1e-7f && f.z == 1.0f,
          "Schlick at cos 0.5: %g %g %g", f.x, f.y, f.z);
    CHECK(mf_fresnel_schlick(v3s(0.04f), 1.0f).x == 0.04f && mf_fresnel_schlick(v3s(0.04f), 0.0f).x == 1.0f,
          "Schlick at the ends");
    CHECK(fabsf(mf_f0_from_ior(1.5f) - 0.04f) < 1e-7f, "F0 of IOR 1.5: %g", mf_f0_from_ior(1.5f));
    /* Averages: closed forms against a fine quadrature in double. */
    vec3 eta = v3(0.17f, 0.43f, 1.5f), kk = v3(3.6f, 2.45f, 1.9f), col = v3(0.9f, 0.5f, 0.2f);
    vec3 av = mf_fresnel_average(MF_FRESNEL_CONDUCTOR, v3s(1), eta, kk);
    vec3 as = mf_fresnel_average(MF_FRESNEL_SCHLICK, col, eta, kk);
    double rc[3] = {0, 0, 0}, rs[3] = {0, 0, 0};
    const float ev[3] = {eta.x, eta.y, eta.z}, kv[3] = {kk.x, kk.y, kk.z}, cv[3] = {col.x, col.y, col.z};
    enum { N = 20000 };
    for (int i = 0; i < N; i++) {
        double mu = (i + 0.5) / N;
        for (int ch = 0; ch < 3; ch++) {
            rc[ch] += 2 * conductor_ref(mu, ev[ch], kv[ch]) * mu / N;
            rs[ch] += 2 * (cv[ch] + (1 - cv[ch]) * pow(1 - mu, 5)) * mu / N;
        }
    }
    CHECK(fabs(av.x - rc[0]) < 1e-4 && fabs(av.y - rc[1]) < 1e-4 && fabs(av.z - rc[2]) < 1e-4,
          "conductor F_avg %g %g %g vs %g %g %g", av.x, av.y, av.z, rc[0], rc[1], rc[2]);
    CHECK(fabs(as.x - rs[0]) < 1e-5 && fabs(as.y - rs[1]) < 1e-5 && fabs(as.z - rs[2]) < 1e-5,
          "Schlick F_avg %g %g %g vs %g %g %g", as.x, as.y, as.z, rs[0], rs[1], rs[2]);
    vec3 an = mf_fresnel_average(MF_FRESNEL_NONE, col, eta, kk);
    CHECK(an.x == col.x && an.z == col.z, "F_avg without Fresnel is the colour");
}

/* ---- reciprocity -------------------------------------------------------- */

static vec3 flip(vec3 d) { return v3(d.x, d.y, -d.z); }
static vec3 random_up(void)
{
    for (;;) {
        vec3 d = v3(2 * rnd() - 1, 2 * rnd() - 1, rnd());
        float l = v3_len2(d);
        if (l > 1e-4f && l <= 1.0f && d.z > 1e-3f)
            return v3_scale(d, 1.0f / sqrtf(l));
    }
}

static float rel(float a, float b) { return fabsf(a - b) / fmaxf(fmaxf(fabsf(a), fabsf(b)), 1e-20f); }

static void test_reciprocity(void)
{
    rng_state = 4242;
    float worst_c = 0, worst_r = 0, worst_t = 0, worst_p = 0;
    int transmitted = 0;
    for (int i = 0; i < 20000; i++) {
        float rough = 0.05f + 0.95f * rnd();
        uint32_t masking = i & 1;
        vec3 a = random_up(), b = random_up();
        mf_conductor c = {mf_alpha_aniso(rough, 2 * rnd() - 1), masking, (uint32_t)(i % 3), v3(0.9f, 0.7f, 0.4f),
                          v3(0.2f, 0.9f, 1.1f), v3(3.9f, 2.4f, 2.2f), 0, v3s(0)};
        mf_conductor_init(&c);
        float p;
        vec3 fab = mf_conductor_eval(&c, a, b, &p), fba = mf_conductor_eval(&c, b, a, &p);
        if (fab.x > 1e-6f)
            worst_c = fmaxf(worst_c, fmaxf(rel(fab.x, fba.x), rel(fab.z, fba.z)));
        mf_dielectric d = {mf_alpha_aniso(rough, 2 * rnd() - 1), masking, MF_DIELECTRIC_MICRO, v3s(1), v3s(1), 0};
        float eta = i & 2 ? 1.33f : 1.0f / 1.7f;
        fab = mf_dielectric_eval(&d, eta, a, b, &p);
        fba = mf_dielectric_eval(&d, eta, b, a, &p);
        if (fab.x > 1e-6f)
            worst_r = fmaxf(worst_r, rel(fab.x, fba.x));
        /* Transmission: a refracted direction from the sampler, then
         * f(wo, wi) / eta_o^2 = f(wi, wo) / eta_i^2, f(wi, wo) being the
         * same boundary seen from the other side (frame flipped, 1/eta). */
        mf_sample s;
        if (mf_dielectric_sample(&d, eta, a, 0.9999f, rnd(), rnd(), &s) && s.wi.z < 0) {
            vec3 ft = mf_dielectric_eval(&d, eta, a, s.wi, &p);
            vec3 fr = mf_dielectric_eval(&d, 1.0f / eta, flip(s.wi), flip(a), &p);
            if (ft.x > 1e-6f) {
                transmitted++;
                worst_t = fmaxf(worst_t, rel(ft.x, fr.x / (eta * eta)));
            }
        }
        mf_principled pr = {mf_alpha_iso(rough), masking, (uint32_t)((i >> 1) % 3), v3(0.8f, 0.6f, 0.3f), rnd(),
                            0.0f, 1.3f + rnd(), 0, rough};
        fab = mf_principled_eval(&pr, 1.5f, a, b, &p);
        fba = mf_principled_eval(&pr, 1.5f, b, a, &p);
        worst_p = fmaxf(worst_p, rel(fab.y, fba.y));
    }
    CHECK(worst_c < 1e-4f, "conductor f(wo,wi) != f(wi,wo): relative %g", worst_c);
    /* Fresnel factors near total internal reflection and refraction near
     * grazing lose digits in single precision (their slope is unbounded
     * there), so the dielectric's tolerances are wider; a wrong factor of
     * eta^2 would be off by 40 % and more. */
    CHECK(worst_r < 1e-3f, "dielectric reflection not reciprocal: relative %g", worst_r);
    CHECK(transmitted > 10000 && worst_t < 1e-2f, "dielectric transmission: generalized reciprocity off by %g (%d pairs)",
          worst_t, transmitted);
    CHECK(worst_p < 1e-4f, "principled (opaque) not reciprocal: relative %g", worst_p);
    printf("reciprocity: conductor %.2g, dielectric reflection %.2g, transmission %.2g (%d pairs), principled %.2g\n",
           worst_c, worst_r, worst_t, transmitted, worst_p);
}

/* ---- energy -------------------------------------------------------------- */

/* Directional albedo by sampling (flux: transmitted weights times eta^2). */
static double albedo(const model *md, vec3 wo, int n, double *max_weight)
{
    double acc = 0;
    *max_weight = 0;
    rng_state = 99;
    for (int i = 0; i < n; i++) {
        mf_sample s;
        if (!md->sample(md, wo, rnd(), rnd(), rnd(), &s))
            continue;
        double w = s.weight.x * (s.wi.z < 0 ? md->eta * md->eta : 1.0f);
        acc += w;
        *max_weight = fmax(*max_weight, w);
    }
    return acc / n;
}

static void test_furnace(void)
{
    /* A white conductor at roughness 1: single scattering keeps ~40 % on
     * average; compensation returns everything. */
    model md = {.sample = cond_sample, .eval = cond_eval};
    for (int masking = 0; masking < 2; masking++) {
        double lo = 1, avg_c = 0, avg_u = 0, wmax;
        for (int t = 0; t < 16; t++) {
            double mu = (t + 0.5) / 16;
            vec3 wo = v3((float)sqrt(1 - mu * mu), 0, (float)mu);
            mf_conductor c = {mf_alpha_iso(1.0f), (uint32_t)masking, MF_FRESNEL_NONE, v3s(1), v3s(0), v3s(0), 1,
                              v3s(0)};
            mf_conductor_init(&c);
            md.cond = c;
            double ec = albedo(&md, wo, 100000, &wmax);
            md.cond.compensate = 0;
            double eu = albedo(&md, wo, 100000, &wmax);
            CHECK(wmax <= 1.0 + 1e-5, "single-scattering conductor weight %g > 1", wmax);
            lo = fmin(lo, ec);
            avg_c += 2 * ec * mu / 16;
            avg_u += 2 * eu * mu / 16;
            float et = mf_albedo(c.alpha, (uint32_t)masking, (float)mu);
            CHECK(fabs(eu - et) < 0.01, "conductor albedo at mu=%.3f: sampled %g, table %g", mu, eu, et);
        }
        const char *mn = masking ? "separable" : "correlated";
        CHECK(lo >= 0.98, "white furnace, roughness 1, %s, compensated: lowest albedo %g < 0.98", mn, lo);
        CHECK(avg_c >= 0.98 && avg_c <= 1.01, "white furnace compensated (%s): %g", mn, avg_c);
        CHECK(avg_u < 0.5, "white furnace uncompensated (%s): %g, expected well below 1", mn, avg_u);
        printf("white conductor r=1 %s: furnace %.4f uncompensated, %.4f compensated (lowest %.4f)\n", mn, avg_u,
               avg_c, lo);
    }
    /* Compensation leaves smooth surfaces alone. */
    mf_conductor c = {mf_alpha_iso(0.1f), MF_SMITH_CORRELATED, MF_FRESNEL_NONE, v3s(1), v3s(0), v3s(0), 0, v3s(0)};
    mf_conductor_init(&c);
    md.cond = c;
    double wmax, e0 = albedo(&md, incident(30), 100000, &wmax);
    md.cond.compensate = 1;
    double e1 = albedo(&md, incident(30), 100000, &wmax);
    CHECK(e0 > 0.99 && fabs(e1 - e0) < 0.005, "roughness 0.1: %g uncompensated, %g compensated", e0, e1);
}

static void test_dielectric_energy(void)
{
    model md = {.sample = diel_sample, .eval = diel_eval};
    double worst_hi = 0, worst_comp = 0, lowest = 1;
    const float etas[] = {1.33f, 1.5f, 2.4f, 1.0f / 1.33f, 1.0f / 1.5f, 1.0f / 2.4f};
    for (int r = 0; r < 4; r++)
        for (int e = 0; e < 6; e++)
            for (int t = 0; t < 4; t++) {
                vec3 wo = incident(THETA[t] == 0 ? 10.0f : THETA[t]);
                mf_dielectric d = {mf_alpha_iso(ROUGH[r]), (uint32_t)(e & 1), MF_DIELECTRIC_MICRO, v3s(1), v3s(1), 0};
                md.diel = d;
                md.eta = etas[e];
                double wmax, rt = albedo(&md, wo, 50000, &wmax);
                worst_hi = fmax(worst_hi, rt - 1);
                lowest = fmin(lowest, rt);
                float et = mf_dielectric_albedo(d.alpha, d.masking, etas[e], wo.z);
                CHECK(fabs(rt - et) < 0.01, "dielectric r=%.2f eta=%.3f mu=%.3f: R+T %g sampled, table %g", ROUGH[r],
                      etas[e], wo.z, rt, et);
                CHECK(wmax <= 1.0 + 1e-5, "dielectric flux weight %g > 1", wmax);
                md.diel.compensate = 1;
                double rc = albedo(&md, wo, 50000, &wmax);
                worst_comp = fmax(worst_comp, fabs(rc - 1));
            }
    CHECK(worst_hi <= 1e-6, "rough dielectric creates energy: R+T exceeds 1 by %g", worst_hi);
    CHECK(worst_comp < 0.01, "compensated dielectric: R+T off 1 by %g", worst_comp);
    CHECK(lowest < 0.8, "uncompensated R+T never drops below %g: is roughness 1 rough?", lowest);
    printf("dielectric R+T: lowest %.4f, highest %.4f uncompensated; within %.4f of 1 compensated\n", lowest,
           1 + worst_hi, worst_comp);
    /* Principled with a white base: never more than it receives, except
     * with glTF's own coupling, which gains at grazing angles. */
    model mp = {.sample = prin_sample, .eval = prin_eval};
    double worst_p = 0, gltf = 0;
    for (int r = 0; r < 4; r++)
        for (int t = 0; t < 4; t++)
            for (int k = 0; k < 4; k++) {
                mf_principled p = {mf_alpha_iso(ROUGH[r]), MF_SMITH_CORRELATED, k == 3, v3s(1), k == 1 ? 1.0f : 0.0f,
                                   k == 2 ? 1.0f : 0.0f, 1.5f, 1, ROUGH[r]};
                mp.prin = p;
                mp.eta = 1.5f;
                double wmax, e = albedo(&mp, incident(THETA[t]), 50000, &wmax);
                if (k == 3)
                    gltf = fmax(gltf, e);
                else
                    worst_p = fmax(worst_p, e);
            }
    CHECK(worst_p < 1.01, "principled with white base reflects %g", worst_p);
    CHECK(gltf > 1.2, "glTF coupling: highest albedo %g (it is known to gain at grazing angles)", gltf);
    printf("principled white base: highest albedo %.4f (glTF's fresnel_mix: %.4f)\n", worst_p, gltf);
}

/* ---- the compiled tables ------------------------------------------------ */

typedef struct { const model *md; vec3 wo; int below; } alb_ctx;
static double g_albedo(const void *c, vec3 wi)
{
    const alb_ctx *x = c;
    if ((wi.z < 0) != x->below || wi.z == 0)
        return 0;
    float p;
    vec3 f = x->md->eval(x->md, x->wo, wi, &p);
    return f.x * fabs(wi.z) * (wi.z < 0 ? x->md->eta * x->md->eta : 1.0);
}

/* Table entries at grid nodes against quadrature of f |cos| over
 * directions (no visible-normal sampling involved). */
static void test_tables(void)
{
    double worst = 0;
    model md = {.sample = cond_sample, .eval = cond_eval};
    const int nodes[][2] = {{31, 0}, {31, 31}, {20, 5}, {10, 16}};
    for (size_t n = 0; n < sizeof nodes / sizeof nodes[0]; n++)
        for (int s = 0; s < 2; s++) {
            float rough = nodes[n][0] / (float)(MF_TAB_R - 1), mu = nodes[n][1] ? powf(nodes[n][1] / (MF_TAB_MU - 1.0f), 2) : (float)MF_TAB_MU0;
            mf_conductor c = {mf_alpha_iso(rough), (uint32_t)s, MF_FRESNEL_NONE, v3s(1), v3s(0), v3s(0), 0, v3s(0)};
            md.cond = c;
            alb_ctx x = {&md, v3(sqrtf(1 - mu * mu), 0, mu), 0};
            lobe_map m = map_make(v3(-x.wo.x, 0, mu), lobe_width(c.alpha));
            double e = integrate(&m, g_albedo, &x, 64);
            double t = mf_tab_e[s][nodes[n][0]][nodes[n][1]] / 65535.0;
            worst = fmax(worst, fabs(e - t));
            /* Schlick with F0 = 0 is the factor (1 - wo.h)^5 of E5. */
            md.cond.fresnel = MF_FRESNEL_SCHLICK;
            md.cond.color = v3s(0);
            e = integrate(&m, g_albedo, &x, 64);
            t = mf_tab_e5[s][nodes[n][0]][nodes[n][1]] / 65535.0;
            worst = fmax(worst, fabs(e - t));
        }
    CHECK(worst < 1.5e-3, "conductor albedo table vs quadrature: worst %g", worst);
    printf("conductor table vs quadrature: worst %.2g\n", worst);
    worst = 0;
    model mdl = {.sample = diel_sample, .eval = diel_eval};
    const int dn[][4] = {{0, 15, 7, 3}, {1, 15, 10, 12}, {0, 8, 4, 1}, {1, 3, 9, 4}};
    for (size_t n = 0; n < sizeof dn / sizeof dn[0]; n++)
        for (int s = 0; s < 2; s++) {
            int side = dn[n][0], k = dn[n][1], j = dn[n][2], i = dn[n][3];
            double xk = 0.5 * k / (MF_TAB_DETA - 1);
            float eta = (float)((1 + xk) / (1 - xk));
            if (side)
                eta = 1.0f / eta;
            float rough = j / (float)(MF_TAB_DR - 1), mu = i ? powf(i / (MF_TAB_DMU - 1.0f), 2) : (float)MF_TAB_MU0;
            mf_dielectric d = {mf_alpha_iso(rough), (uint32_t)s, MF_DIELECTRIC_MICRO, v3s(1), v3s(1), 0};
            mdl.diel = d;
            mdl.eta = eta;
            alb_ctx x = {&mdl, v3(sqrtf(1 - mu * mu), 0, mu), 0};
            lobe_map up = map_make(v3(-x.wo.x, 0, mu), lobe_width(d.alpha));
            lobe_map down = map_make(refract_axis(x.wo, eta), lobe_width(d.alpha));
            double e = integrate(&up, g_albedo, &x, 64);
            x.below = 1;
            e += integrate(&down, g_albedo, &x, 64);
            double t = mf_tab_ed[s][side][k][j][i] / 65535.0;
            if (getenv("MF_DEBUG"))
                printf("  dielectric table [%d][%d][%d][%d][%d]: %.5f, quadrature %.5f\n", s, side, k, j, i, t, e);
            worst = fmax(worst, fabs(e - t));
        }
    CHECK(worst < 2e-3, "dielectric albedo table vs quadrature: worst %g", worst);
    printf("dielectric table vs quadrature: worst %.2g\n", worst);
    /* The averages are those of the interpolated rows. */
    double wa = 0;
    for (int s = 0; s < 2; s++)
        for (int j = 0; j < MF_TAB_R; j++) {
            mf_alpha a = mf_alpha_iso(j / (MF_TAB_R - 1.0f));
            double acc1 = 0, acc5 = 0;
            enum { N = 4096 };
            for (int i = 0; i < N; i++) {
                float mu = (i + 0.5f) / N, avg;
                float e1 = mf_albedo_schlick(a, (uint32_t)s, 1.0f, mu, &avg);
                float e5 = mf_albedo_schlick(a, (uint32_t)s, 0.0f, mu, &avg);
                acc1 += 2.0 * e1 * mu / N;
                acc5 += 2.0 * e5 * mu / N;
            }
            wa = fmax(wa, fabs(acc1 - mf_tab_eavg[s][j] / 65535.0));
            wa = fmax(wa, fabs(acc5 - mf_tab_e5avg[s][j] / 65535.0));
        }
    CHECK(wa < 3e-5, "E_avg tables off their rows' averages by %g", wa);
}

#include <time.h>
static void timed(const char *name, void (*f)(void))
{
    clock_t t = clock();
    f();
    if (getenv("MF_TIME"))
        printf("[%s: %.1f s]\n", name, (double)(clock() - t) / CLOCKS_PER_SEC);
}

int main(void)
{
    timed("distribution", test_distribution);
    timed("fresnel", test_fresnel);
    timed("tables", test_tables);
    timed("vndf", test_chi2_vndf);
    timed("conductor", test_chi2_conductor);
    timed("dielectric", test_chi2_dielectric);
    timed("principled", test_chi2_principled);
    timed("reciprocity", test_reciprocity);
    timed("furnace", test_furnace);
    timed("dielectric energy", test_dielectric_energy);
    return check_done();
}
