/* test_sampling.c -- smooth and Phong BSDF sampling against pdf, Fresnel and
 * reciprocity.
 *
 * BSDF sampling against its pdf (chi-square goodness of fit), exact
 * Fresnel values, reciprocity and energy of the smooth lobes. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bsdf.h"
#include "compile/builder.h"
#include "check.h"
#include "stats.h"
#include "fmath.h"
#include "sampler.h"

enum { NT = 16, NP = 32, NSAMPLES = 400000 };

/* Bins over (cos theta in [-1,1], phi) of a local frame with z up. */
static int bin_of(vec3 d)
{
    double ct = d.z < -1 ? -1 : d.z > 1 ? 1 : d.z;
    int it = (int)((ct + 1.0) * 0.5 * NT);
    double ph = atan2(d.y, d.x);
    if (ph < 0) ph += 2 * M_PI;
    int ip = (int)(ph / (2 * M_PI) * NP);
    if (it >= NT) it = NT - 1;
    if (ip >= NP) ip = NP - 1;
    return it * NP + ip;
}

/* Local sampler with a closed-form integral of its pdf over a bin. */
static void chi2_local(const char *name, vec3 (*sample)(float, float, float), float param,
                       double (*cdf_cos)(double, float))
{
    static double obs[NT * NP], expct[NT * NP];
    memset(obs, 0, sizeof obs);
    uint32_t st = 12345;
    for (int i = 0; i < NSAMPLES; i++)
        obs[bin_of(sample(param, (float)st_rnd(&st), (float)st_rnd(&st)))]++;
    for (int it = 0; it < NT; it++) {
        double c0 = -1.0 + 2.0 * it / NT, c1 = -1.0 + 2.0 * (it + 1) / NT;
        for (int ip = 0; ip < NP; ip++)
            expct[it * NP + ip] = NSAMPLES * (cdf_cos(c1, param) - cdf_cos(c0, param)) / NP;
    }
    double p = st_chi2_test(obs, expct, NT * NP, 0);
    CHECK(p > 1e-3, "%s: chi-square p-value %.3g", name, p);
    printf("%s: chi-square p = %.3f\n", name, p);
}

static vec3 cosine_sampler(float unused, float u1, float u2) { (void)unused; return bsdf_sample_cosine(u1, u2); }
/* Integral over phi in [0, 2pi) and cos theta in [-1, c] of the pdf, per 2pi. */
static double cosine_cdf(double c, float unused) { (void)unused; return c <= 0 ? 0 : c * c; }
static vec3 phong_sampler(float n, float u1, float u2) { return bsdf_sample_phong(n, u1, u2); }
static double phong_cdf(double c, float n) { return c <= 0 ? 0 : pow(c, n + 1.0); }

/* The whole material sampler (lobe choice included) against bsdf_eval's
 * pdf, integrated numerically over each bin.  Void samples (the Phong lobe
 * dips below the surface) must be as frequent as the pdf's missing mass. */
static void chi2_material(const char *name, const fr_material *m, vec3 wo)
{
    static double obs[NT * NP + 1], expct[NT * NP + 1];
    memset(obs, 0, sizeof obs);
    memset(expct, 0, sizeof expct);
    fr_surface sf;
    memset(&sf, 0, sizeof sf);
    sf.ng = sf.ns = v3(0, 0, 1);
    uint32_t st = 777;
    for (int i = 0; i < NSAMPLES; i++) {
        fr_bsdf_sample bs;
        if (bsdf_sample(m, &sf, wo, (float)st_rnd(&st), (float)st_rnd(&st), (float)st_rnd(&st), &bs))
            obs[bin_of(bs.wi)]++;
        else
            obs[NT * NP]++;
    }
    double total = 0;
    enum { SUB = 12 };
    for (int it = NT / 2; it < NT; it++)
        for (int ip = 0; ip < NP; ip++) {
            double acc = 0;
            for (int a = 0; a < SUB; a++)
                for (int b = 0; b < SUB; b++) {
                    double ct = -1.0 + 2.0 * (it + (a + 0.5) / SUB) / NT;
                    double ph = 2 * M_PI * (ip + (b + 0.5) / SUB) / NP;
                    double s = sqrt(1 - ct * ct);
                    float pdf;
                    bsdf_eval(m, &sf, wo, v3((float)(s * cos(ph)), (float)(s * sin(ph)), (float)ct), &pdf);
                    acc += pdf;
                }
            /* Bin solid angle = (2/NT) * (2pi/NP). */
            double e = acc / (SUB * SUB) * (2.0 / NT) * (2 * M_PI / NP);
            expct[it * NP + ip] = e * NSAMPLES;
            total += e;
        }
    expct[NT * NP] = (1.0 - total) * NSAMPLES;
    double p = st_chi2_test(obs, expct, NT * NP + 1, 0);
    CHECK(p > 1e-3, "%s: chi-square p-value %.3g", name, p);
    printf("%s: chi-square p = %.3f (void fraction %.4f)\n", name, p, obs[NT * NP] / NSAMPLES);
}

static void test_fresnel(void)
{
    float ct;
    float f0 = bsdf_fresnel(1.0f, 1.5f, &ct);
    CHECK(fabsf(f0 - 0.04f) < 1e-6f, "Fresnel at normal incidence: %g, expected 0.04", f0);
    float c80 = fm_cosf(80.0f * FM_PI / 180.0f);
    float f80 = bsdf_fresnel(c80, 1.5f, &ct);
    CHECK(fabsf(f80 - 0.3877f) < 5e-4f, "Fresnel at 80 degrees: %g, expected 0.3877", f80);
    float angle = acosf(ct) * 180.0f / FM_PI;
    CHECK(fabsf(angle - 41.036f) < 2e-3f, "refraction angle at 80 degrees: %g, expected 41.036", angle);
    /* From inside glass beyond the critical angle (41.8 degrees): total
     * internal reflection. */
    float ftir = bsdf_fresnel(fm_cosf(45.0f * FM_PI / 180.0f), 1.0f / 1.5f, &ct);
    CHECK(ftir == 1.0f && ct == 0.0f, "total internal reflection at 45 degrees inside glass");
    /* Reciprocity of the interface: F is the same seen from both sides for
     * the matching pair of angles (Stokes relations). */
    float cin = fm_cosf(30.0f * FM_PI / 180.0f), ctr;
    float fa = bsdf_fresnel(cin, 1.5f, &ctr);
    float fb = bsdf_fresnel(ctr, 1.0f / 1.5f, &ct);
    CHECK(fabsf(fa - fb) < 1e-6f && fabsf(ct - cin) < 1e-6f, "Fresnel reciprocal: %g vs %g", fa, fb);
}

static void test_reciprocity_energy(const fr_material *m, const char *name)
{
    fr_surface sf;
    memset(&sf, 0, sizeof sf);
    sf.ng = sf.ns = v3(0, 0, 1);
    uint32_t st = 99;
    float worst = 0;
    for (int i = 0; i < 10000; i++) {
        vec3 a = bsdf_sample_cosine((float)st_rnd(&st), (float)st_rnd(&st));
        vec3 b = bsdf_sample_cosine((float)st_rnd(&st), (float)st_rnd(&st));
        float p;
        vec3 fab = bsdf_eval(m, &sf, a, b, &p), fba = bsdf_eval(m, &sf, b, a, &p);
        float d = fabsf(fab.x - fba.x) / fmaxf(1e-6f, fabsf(fab.x));
        if (d > worst) worst = d;
    }
    CHECK(worst < 1e-4f, "%s: f(wo,wi) != f(wi,wo), relative %g", name, worst);
    /* Albedo by Monte Carlo at normal incidence equals the lobe albedos. */
    double albedo = 0;
    enum { N = 200000 };
    for (int i = 0; i < N; i++) {
        fr_bsdf_sample bs;
        if (bsdf_sample(m, &sf, v3(0, 0, 1), (float)st_rnd(&st), (float)st_rnd(&st), (float)st_rnd(&st), &bs))
            albedo += bs.weight.x;
    }
    albedo /= N;
    double expect = m->diffuse.x + m->glossy.x;
    CHECK(fabs(albedo - expect) < 0.01, "%s: albedo at normal incidence %g, expected %g", name, albedo, expect);
}

int main(void)
{
    chi2_local("cosine hemisphere", cosine_sampler, 0, cosine_cdf);
    chi2_local("Phong lobe n=1", phong_sampler, 1, phong_cdf);
    chi2_local("Phong lobe n=20", phong_sampler, 20, phong_cdf);
    chi2_local("Phong lobe n=300", phong_sampler, 300, phong_cdf);

    fr_material lam, pho;
    memset(&lam, 0, sizeof lam);
    lam.diffuse = v3s(0.8f);
    bsdf_lobe_probs(&lam);
    memset(&pho, 0, sizeof pho);
    pho.diffuse = v3s(0.3f);
    pho.glossy = v3s(0.6f);
    pho.exponent = 15;
    bsdf_lobe_probs(&pho);
    chi2_material("Lambert material", &lam, v3_norm(v3(0.3f, 0.1f, 1.0f)));
    chi2_material("Phong material, wo at 60 degrees", &pho, v3_norm(v3(1.7320508f, 0, 1)));

    test_fresnel();
    test_reciprocity_energy(&lam, "Lambert");
    test_reciprocity_energy(&pho, "Phong");
    return check_done();
}
