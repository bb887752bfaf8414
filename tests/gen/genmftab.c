/* genmftab.c -- integrates the albedo tables of microfacet energy compensation
 * and prints them as C source:
 *
 *   bin/gen/genmftab > common/microfacet_table.c
 *
 * Each entry is the single-scattering albedo of a GGX surface for one
 * incidence cosine and roughness (and relative index, for dielectrics),
 * integrated over a stratified grid of visible normals (mf_sample_visible):
 * a reflection through a visible normal m carries F(wo.m) G2 / G1(wo), a
 * refraction (1 - F) G2 / G1(wo) (flux, so without the 1/eta^2 of
 * radiance).  Reflectors are integrated with F = 1 (E) and with
 * F = (1 - wo.m)^5 (E5: Schlick's factor is F0 E + (1 - F0) E5).  The grids
 * are described in microfacet_table.h.  The program is deterministic (about
 * a minute); the output only changes when the model does, and
 * tests/test_microfacet.c checks entries against an independent
 * quadrature. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "microfacet.h"
#include "microfacet_table.h"

/* Strata per dimension of the (u1, u2) grid. */
enum { N_COND = 256, N_DIEL = 128 };

static vec3 incident(double mu) { return v3((float)sqrt(1.0 - mu * mu), 0.0f, (float)mu); }

/* The cosine of grid node i of n. */
static double node_mu(int i, int n) { double x = (double)i / (n - 1); return i ? x * x : MF_TAB_MU0; }

/* Albedo of a reflector with F = 1 (power 0) or F = (1 - wo.m)^5 (power 5). */
static double albedo_conductor(float roughness, uint32_t masking, double mu, int power)
{
    mf_alpha a = mf_alpha_iso(roughness);
    vec3 wo = incident(mu);
    double g1 = mf_G1(a, wo), acc = 0;
    for (int i = 0; i < N_COND; i++)
        for (int j = 0; j < N_COND; j++) {
            vec3 m = mf_sample_visible(a, wo, (i + 0.5f) / N_COND, (j + 0.5f) / N_COND);
            vec3 wi = v3_sub(v3_scale(m, 2.0f * v3_dot(wo, m)), wo);
            if (wi.z > 0.0f) {
                double f = power ? pow(1.0 - v3_dot(wo, m), 5) : 1.0;
                acc += f * mf_G2(a, masking, wo, wi) / g1;
            }
        }
    return acc / ((double)N_COND * N_COND);
}

/* Reflection plus transmission of a dielectric boundary of relative index
 * eta, Fresnel per microfacet. */
static double albedo_dielectric(float roughness, uint32_t masking, float eta, double mu)
{
    mf_alpha a = mf_alpha_iso(roughness);
    vec3 wo = incident(mu);
    double g1 = mf_G1(a, wo), acc = 0;
    for (int i = 0; i < N_DIEL; i++)
        for (int j = 0; j < N_DIEL; j++) {
            vec3 m = mf_sample_visible(a, wo, (i + 0.5f) / N_DIEL, (j + 0.5f) / N_DIEL);
            float c = v3_dot(wo, m), ct;
            if (c <= 0.0f)
                continue;
            float f = mf_fresnel_dielectric(c, eta, &ct);
            vec3 r = v3_sub(v3_scale(m, 2.0f * c), wo);
            if (r.z > 0.0f)
                acc += f * mf_G2(a, masking, wo, r) / g1;
            if (ct > 0.0f) {
                vec3 t = v3_norm(v3_add(v3_scale(wo, -1.0f / eta), v3_scale(m, c / eta - ct)));
                if (t.z < 0.0f)
                    acc += (1.0f - f) * mf_G2(a, masking, wo, t) / g1;
            }
        }
    return acc / ((double)N_DIEL * N_DIEL);
}

static unsigned quantize(double v)
{
    v = v < 0 ? 0 : v > 1 ? 1 : v;
    return (unsigned)(v * 65535.0 + 0.5);
}

/* 2 int_0^1 E(mu) mu dmu of a row of quantized entries interpolated
 * linearly in x = sqrt(mu) between nodes, exactly: with mu = x^2 it is
 * 4 int E(x) x^3 dx, a quartic on each segment, which three-point
 * Gauss-Legendre integrates exactly. */
static double row_average(const unsigned *q, int n)
{
    static const double gx[3] = {-0.7745966692414834, 0.0, 0.7745966692414834};
    static const double gw[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
    double acc = 0;
    for (int i = 0; i + 1 < n; i++) {
        double a = (double)i / (n - 1), b = (i + 1.0) / (n - 1);
        double ea = q[i] / 65535.0, eb = q[i + 1] / 65535.0;
        for (int g = 0; g < 3; g++) {
            double t = 0.5 * (1 + gx[g]), x = a + (b - a) * t;
            acc += 0.5 * (b - a) * gw[g] * 4 * (ea + (eb - ea) * t) * x * x * x;
        }
    }
    return acc;
}

/* A table of reflector albedos and the row averages. */
static void reflector(const char *name, int power)
{
    static unsigned q[2][MF_TAB_R][MF_TAB_MU];
    printf("const uint16_t mf_tab_%s[2][MF_TAB_R][MF_TAB_MU] = {\n", name);
    for (int s = 0; s < 2; s++) {
        printf("    {\n");
        for (int j = 0; j < MF_TAB_R; j++) {
            printf("        {");
            for (int i = 0; i < MF_TAB_MU; i++) {
                q[s][j][i] = quantize(albedo_conductor((float)j / (MF_TAB_R - 1), (uint32_t)s, node_mu(i, MF_TAB_MU), power));
                printf("%s%u", i ? (i % 12 ? ", " : ",\n         ") : "", q[s][j][i]);
            }
            printf("},\n");
        }
        printf("    },\n");
    }
    printf("};\n\nconst uint16_t mf_tab_%savg[2][MF_TAB_R] = {\n", name);
    for (int s = 0; s < 2; s++) {
        printf("    {");
        for (int j = 0; j < MF_TAB_R; j++)
            printf("%s%u", j ? (j % 12 ? ", " : ",\n     ") : "", quantize(row_average(q[s][j], MF_TAB_MU)));
        printf("},\n");
    }
    printf("};\n\n");
}

int main(void)
{
    printf("/* microfacet_table.c -- written by tests/gen/genmftab.c; do not edit.\n"
           " * Albedo tables of microfacet energy compensation; the grids are in\n"
           " * microfacet_table.h. */\n"
           "#include \"microfacet_table.h\"\n\n");
    reflector("e", 0);
    reflector("e5", 5);
    printf("const uint16_t mf_tab_ed[2][2][MF_TAB_DETA][MF_TAB_DR][MF_TAB_DMU] = {\n");
    for (int s = 0; s < 2; s++) {
        printf("    {\n");
        for (int side = 0; side < 2; side++) {
            printf("        {\n");
            for (int k = 0; k < MF_TAB_DETA; k++) {
                double x = 0.5 * k / (MF_TAB_DETA - 1);
                float eta = (float)((1 + x) / (1 - x));
                if (side)
                    eta = 1.0f / eta;
                printf("            {\n");
                for (int j = 0; j < MF_TAB_DR; j++) {
                    printf("                {");
                    for (int i = 0; i < MF_TAB_DMU; i++) {
                        double v = albedo_dielectric((float)j / (MF_TAB_DR - 1), (uint32_t)s, eta,
                                                     node_mu(i, MF_TAB_DMU));
                        printf("%s%u", i ? ", " : "", quantize(v));
                    }
                    printf("},\n");
                }
                printf("            },\n");
            }
            printf("        },\n");
        }
        printf("    },\n");
    }
    printf("};\n");
    return 0;
}
