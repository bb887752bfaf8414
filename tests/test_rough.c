/* test_rough.c -- rough materials in the renderer: syntax, sampling, furnaces,
 * MIS.
 *
 * The microfacet materials in the renderer: the scene syntax (what is
 * accepted, what is refused and where), textured roughness and metallic,
 * bsdf_sample against bsdf_eval in tilted shading frames (chi-square and
 * per-sample agreement, no light through the wrong side), rendered white
 * furnaces with and without energy compensation, and light sampling, BSDF
 * sampling and MIS agreeing on a scene of rough materials. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bsdf.h"
#include "check.h"
#include "estimate.h"
#include "microfacet.h"
#include "pathtrace.h"
#include "sampler.h"
#include "scenes.h"
#include "texture.h"

/* ---- scene syntax --------------------------------------------------------- */

/* Parse a scene whose material "m" is `mat` (with `extra` top-level members
 * before "materials"); the error message, "" on success.  *m_out gets the
 * parsed material when given. */
static const char *parse(const char *extra, const char *mat, fr_material *m_out)
{
    static fr_error err;
    char json[4096];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 4, \"height\": 4},"
             " \"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"fov\": 40},"
             " %s%s \"materials\": {\"m\": %s, \"lamp\": {\"type\": \"emitter\", \"emission\": [1, 1, 1]}},"
             " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"m\"},"
             "   {\"type\": \"sphere\", \"center\": [0, 3, 0], \"radius\": 0.5, \"material\": \"lamp\"}]}",
             extra, extra[0] ? "," : "", mat);
    fr_builder b;
    bld_init(&b);
    int rc = json_scene_parse(json, "(test)", NULL, &b, &err);
    if (rc == 0 && m_out)
        *m_out = ((const fr_material *)b.materials.data)[0];
    bld_free(&b);
    return rc == 0 ? "" : err.msg;
}

static void refused(const char *what, const char *msg, const char *const *parts)
{
    if (!msg[0]) {
        CHECK(0, "%s: accepted", what);
        return;
    }
    for (int i = 0; parts[i]; i++)
        CHECK(strstr(msg, parts[i]) != NULL, "%s: message '%s' lacks '%s'", what, msg, parts[i]);
}
#define REFUSED(what, msg, ...) refused(what, msg, (const char *const[]){__VA_ARGS__, NULL})

#define CHECKER "\"textures\": {\"mr\": {\"type\": \"checker\", \"colors\": [[0, 0.5, 0.25], [0, 1, 1]]}," \
                " \"tr\": {\"type\": \"checker\", \"colors\": [[0.5, 0, 0], [1, 0, 0]]}}"

static void test_syntax(void)
{
    fr_material m;
    const char *e;
    e = parse("", "{\"type\": \"conductor\", \"roughness\": 0.3, \"reflectance\": [0.9, 0.7, 0.4]}", &m);
    CHECK(!e[0] && m.model == FR_MAT_CONDUCTOR && m.fresnel == FR_FRESNEL_SCHLICK && m.roughness == 0.3f &&
              m.specular.y == 0.7f && m.mf_flags == 0 && bsdf_has_smooth(&m),
          "Schlick conductor: %s", e);
    e = parse("", "{\"type\": \"conductor\", \"eta\": [0.2, 0.4, 1.5], \"k\": [3, 2.5, 2], \"masking\": \"separable\","
                  " \"compensate\": true, \"anisotropy\": -0.5}", &m);
    CHECK(!e[0] && m.fresnel == FR_FRESNEL_EXACT && m.specular.x == 1.0f && m.anisotropy == -0.5f &&
              m.mf_flags == (FR_MF_SEPARABLE | FR_MF_COMPENSATE) && m.fresnel_avg.x > 0.5f && m.fresnel_avg.x < 1.0f,
          "exact conductor: %s (F_avg %g)", e, m.fresnel_avg.x);
    e = parse("", "{\"type\": \"conductor\", \"roughness\": 0.5, \"reflectance\": [0.8, 0.8, 0.8], \"fresnel\": \"none\"}", &m);
    CHECK(!e[0] && m.fresnel == FR_FRESNEL_NONE, "conductor without Fresnel: %s", e);
    e = parse("", "{\"type\": \"glass\", \"ior\": 1.4}", &m);
    CHECK(!e[0] && m.model == FR_MAT_LOBES && m.transmit.x == 1.0f, "smooth glass stays the lobe glass: %s", e);
    e = parse("", "{\"type\": \"glass\", \"roughness\": 0.2, \"fresnel\": \"normal\", \"tint\": [1, 0.9, 0.8]}", &m);
    CHECK(!e[0] && m.model == FR_MAT_DIELECTRIC && m.mf_flags == FR_MF_MACRO_FRESNEL && m.ior == 1.5f &&
              m.transmit.z == 0.8f,
          "rough glass: %s", e);
    e = parse("", "{\"type\": \"principled\"}", &m);
    CHECK(!e[0] && m.model == FR_MAT_PRINCIPLED && m.metallic == 1.0f && m.roughness == 1.0f && m.diffuse.x == 1.0f &&
              m.ior == 1.5f && m.transmission == 0.0f,
          "principled takes glTF's defaults: %s", e);
    e = parse(CHECKER, "{\"type\": \"principled\", \"base_color\": [0.5, 0.2, 0.1], \"metallic\": {\"texture\": \"mr\","
                       " \"factor\": 0.5}, \"roughness\": \"mr\", \"transmission\": 0.3, \"ior\": 1.33,"
                       " \"coupling\": \"gltf\"}", &m);
    CHECK(!e[0] && m.tex_metallic != FR_NONE && m.tex_roughness == m.tex_metallic && m.metallic == 0.5f &&
              m.roughness == 1.0f && m.mf_flags == FR_MF_GLTF_COUPLING,
          "textured principled: %s", e);

    REFUSED("roughness out of range", parse("", "{\"type\": \"conductor\", \"roughness\": 1.5, \"reflectance\": [1, 1, 1]}", NULL),
            "materials.m.roughness", "[0, 1]");
    REFUSED("roughness factor out of range",
            parse(CHECKER, "{\"type\": \"principled\", \"roughness\": {\"texture\": \"mr\", \"factor\": -1}}", NULL),
            "materials.m.roughness.factor", "[0, 1]");
    REFUSED("roughness of the wrong kind", parse("", "{\"type\": \"principled\", \"roughness\": [0.1]}", NULL),
            "materials.m.roughness", "texture name");
    REFUSED("unknown roughness texture", parse("", "{\"type\": \"principled\", \"roughness\": \"oak\"}", NULL),
            "materials.m.roughness", "no texture named 'oak'");
    REFUSED("anisotropy", parse("", "{\"type\": \"conductor\", \"anisotropy\": 2, \"reflectance\": [1, 1, 1]}", NULL),
            "materials.m.anisotropy", "[-1, 1]");
    REFUSED("masking", parse("", "{\"type\": \"conductor\", \"masking\": \"smith\", \"reflectance\": [1, 1, 1]}", NULL),
            "materials.m.masking", "correlated");
    REFUSED("compensate", parse("", "{\"type\": \"conductor\", \"compensate\": 1, \"reflectance\": [1, 1, 1]}", NULL),
            "materials.m.compensate", "true or false");
    REFUSED("conductor without colour", parse("", "{\"type\": \"conductor\", \"roughness\": 0.2}", NULL),
            "materials.m.reflectance", "missing");
    REFUSED("exact without k", parse("", "{\"type\": \"conductor\", \"eta\": [1, 1, 1]}", NULL), "materials.m.k",
            "missing");
    REFUSED("eta with Schlick", parse("", "{\"type\": \"conductor\", \"fresnel\": \"schlick\", \"eta\": [1, 1, 1],"
                                          " \"k\": [1, 1, 1], \"reflectance\": [1, 1, 1]}", NULL),
            "materials.m.eta", "\"exact\"");
    REFUSED("negative k", parse("", "{\"type\": \"conductor\", \"eta\": [1, 1, 1], \"k\": [1, -1, 1]}", NULL),
            "materials.m.k", ">= 0");
    REFUSED("zero eta", parse("", "{\"type\": \"conductor\", \"eta\": [1, 0, 1], \"k\": [1, 1, 1]}", NULL),
            "materials.m.eta", "> 0");
    REFUSED("bad Fresnel mode", parse("", "{\"type\": \"conductor\", \"fresnel\": \"dielectric\", \"reflectance\": [1, 1, 1]}", NULL),
            "materials.m.fresnel", "schlick");
    REFUSED("conductor too bright", parse("", "{\"type\": \"conductor\", \"reflectance\": [1.2, 1, 1]}", NULL),
            "materials.m", "> 1");
    REFUSED("albedo on a conductor", parse("", "{\"type\": \"conductor\", \"reflectance\": [1, 1, 1], \"albedo\": [1, 1, 1]}", NULL),
            "materials.m.albedo", "not a member of a conductor");
    REFUSED("metallic on a conductor", parse("", "{\"type\": \"conductor\", \"reflectance\": [1, 1, 1], \"metallic\": 1}", NULL),
            "materials.m.metallic", "not a member of a conductor");
    REFUSED("roughness on lambert", parse("", "{\"type\": \"lambert\", \"albedo\": [1, 1, 1], \"roughness\": 0.5}", NULL),
            "materials.m.roughness", "not a member of a lambert");
    REFUSED("metallic on glass", parse("", "{\"type\": \"glass\", \"roughness\": 0.5, \"metallic\": 0.5}", NULL),
            "materials.m.metallic", "not a member of a glass");
    REFUSED("options on a smooth glass", parse("", "{\"type\": \"glass\", \"masking\": \"separable\"}", NULL),
            "materials.m.masking", "rough glass");
    REFUSED("glass Fresnel mode", parse("", "{\"type\": \"glass\", \"roughness\": 0.1, \"fresnel\": \"exact\"}", NULL),
            "materials.m.fresnel", "microfacet");
    REFUSED("transmission", parse("", "{\"type\": \"principled\", \"transmission\": 2}", NULL),
            "materials.m.transmission", "[0, 1]");
    REFUSED("metallic", parse("", "{\"type\": \"principled\", \"metallic\": -0.1}", NULL), "materials.m.metallic",
            "[0, 1]");
    REFUSED("principled ior 1", parse("", "{\"type\": \"principled\", \"ior\": 1}", NULL), "materials.m.ior", "not 1");
    REFUSED("coupling", parse("", "{\"type\": \"principled\", \"coupling\": \"disney\"}", NULL), "materials.m.coupling",
            "albedo");
    REFUSED("Cycles coupling compensated",
            parse("", "{\"type\": \"principled\", \"coupling\": \"cycles\", \"compensate\": true}", NULL),
            "materials.m.compensate", "cycles");
    e = parse("", "{\"type\": \"principled\", \"coupling\": \"cycles\", \"masking\": \"separable\"}", &m);
    CHECK(!e[0] && m.mf_flags == (FR_MF_CYCLES_COUPLING | FR_MF_SEPARABLE), "Cycles coupling: %s", e);
    REFUSED("base colour", parse("", "{\"type\": \"principled\", \"base_color\": [1, -1, 1]}", NULL), "materials.m",
            ">= 0");
    REFUSED("unknown type", parse("", "{\"type\": \"metal\"}", NULL), "materials.m.type", "conductor", "principled");
    REFUSED("unknown member", parse("", "{\"type\": \"principled\", \"specular\": 0.5}", NULL), "materials.m.specular",
            "not a member of a principled");
}

/* ---- textured roughness and metallic --------------------------------------- */

static void test_textures(void)
{
    fr_scene s;
    test_scene("{\"image\": {\"width\": 4, \"height\": 4},"
               " \"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"fov\": 40},"
               " " CHECKER ","
               " \"materials\": {\"m\": {\"type\": \"principled\", \"metallic\": {\"texture\": \"mr\", \"factor\": 0.8},"
               "   \"roughness\": {\"texture\": \"mr\", \"factor\": 0.6},"
               "   \"transmission\": {\"texture\": \"tr\", \"factor\": 0.9}},"
               "  \"lamp\": {\"type\": \"emitter\", \"emission\": [1, 1, 1]}},"
               " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"m\"},"
               "   {\"type\": \"sphere\", \"center\": [0, 3, 0], \"radius\": 0.5, \"material\": \"lamp\"}]}",
               &s);
    fr_surface sf;
    memset(&sf, 0, sizeof sf);
    sf.ng = sf.ns = v3(0, 0, 1);
    fr_material tmp;
    /* The checker's square at the UV origin is (0, 0.5, 0.25): roughness
     * from G, metallic from B; the other square (0, 1, 1). */
    sf.uv.u = sf.uv.v = 0.25f;
    const fr_material *m = tex_material(&s, &s.materials[0], &sf, &tmp);
    CHECK(fabsf(m->roughness - 0.3f) < 1e-6f && fabsf(m->metallic - 0.2f) < 1e-6f,
          "metallicRoughness texel (0, 0.5, 0.25): roughness %g (expected 0.3), metallic %g (expected 0.2)",
          m->roughness, m->metallic);
    CHECK(fabsf(m->transmission - 0.45f) < 1e-6f, "transmission texel R 0.5: %g (expected 0.45)", m->transmission);
    sf.uv.u = 1.25f;
    m = tex_material(&s, &s.materials[0], &sf, &tmp);
    CHECK(fabsf(m->roughness - 0.6f) < 1e-6f && fabsf(m->metallic - 0.8f) < 1e-6f,
          "metallicRoughness texel (0, 1, 1): roughness %g, metallic %g", m->roughness, m->metallic);
    CHECK(fabsf(m->transmission - 0.9f) < 1e-6f, "transmission texel R 1: %g (expected 0.9)", m->transmission);
    scn_free(&s);
}

/* ---- the materials through bsdf.c ------------------------------------------ */

static uint32_t rng_state = 7;
static float rnd(void)
{
    rng_state = smp_hash(rng_state + 0x9e3779b9u);
    return (float)(rng_state >> 8) * 0x1p-24f;
}

static double chi2_pvalue(double x, int k)
{
    double z = (pow(x / k, 1.0 / 3.0) - (1.0 - 2.0 / (9.0 * k))) / sqrt(2.0 / (9.0 * k));
    return 0.5 * erfc(z / sqrt(2.0));
}

/* A material of each model, to test in a frame where the shading normal
 * leans away from the geometric one and dpdu is oblique. */
static fr_material make(uint32_t model, float rough, float aniso, uint32_t flags)
{
    fr_material m;
    bld_material_init(&m);
    m.model = model;
    m.roughness = rough;
    m.anisotropy = aniso;
    m.mf_flags = flags;
    if (model == FR_MAT_CONDUCTOR) {
        m.fresnel = FR_FRESNEL_EXACT;
        m.specular = v3s(1.0f);
        m.eta = v3(0.2f, 0.9f, 1.1f);
        m.k = v3(3.9f, 2.4f, 2.2f);
    } else if (model == FR_MAT_DIELECTRIC) {
        m.transmit = v3(1.0f, 0.9f, 0.8f);
        m.ior = 1.5f;
    } else {
        m.diffuse = v3(0.8f, 0.5f, 0.2f);
        m.metallic = 0.4f;
        m.transmission = 0.5f;
        m.ior = 1.45f;
    }
    bsdf_material_finish(&m);
    return m;
}

enum { NT = 24, NP = 48, NB = NT * NP };

/* Bins over (cos theta, phi) around the geometric normal z. */
static int bin_of(vec3 d)
{
    double ct = d.z < -1 ? -1 : d.z > 1 ? 1 : d.z;
    int it = (int)((ct + 1.0) * 0.5 * NT);
    double ph = atan2(d.y, d.x);
    if (ph < 0)
        ph += 2 * M_PI;
    int ip = (int)(ph / (2 * M_PI) * NP);
    return (it >= NT ? NT - 1 : it) * NP + (ip >= NP ? NP - 1 : ip);
}

static void test_bsdf(const char *name, const fr_material *m, vec3 wo, int n)
{
    fr_surface sf;
    memset(&sf, 0, sizeof sf);
    sf.ng = v3(0, 0, 1);
    sf.ns = v3_norm(v3(0.25f, -0.15f, 1.0f));
    sf.dpdu = v3(0.8f, 0.6f, 0.3f);
    sf.dpdv = v3(-0.6f, 0.8f, 0.0f);
    static double obs[NB + 1], expct[NB + 1];
    memset(obs, 0, sizeof obs);
    int bad_pdf = 0, bad_side = 0, bad_weight = 0;
    float side_o = v3_dot(wo, sf.ng);
    rng_state = 1234;
    for (int i = 0; i < n; i++) {
        fr_bsdf_sample bs;
        if (!bsdf_sample(m, &sf, wo, rnd(), rnd(), rnd(), &bs)) {
            obs[NB]++;
            continue;
        }
        obs[bin_of(bs.wi)]++;
        float pdf;
        vec3 f = bsdf_eval(m, &sf, wo, bs.wi, &pdf);
        if (bs.delta || !(fabsf(pdf - bs.pdf) <= 1e-3f * pdf)) {
            if (bad_pdf++ < 3)
                printf("%s: wi (%g %g %g) sampled with pdf %.7g, eval %.7g\n", name, bs.wi.x, bs.wi.y, bs.wi.z,
                       bs.pdf, pdf);
        }
        float cs = fabsf(v3_dot(bs.wi, side_o >= 0 ? sf.ns : v3_neg(sf.ns)));
        if (!(fabsf(f.y * cs / pdf - bs.weight.y) <= 1e-3f * bs.weight.y + 1e-6f))
            bad_weight++;
        /* A transmission must cross the geometric surface; a reflection
         * must not. */
        float so = v3_dot(wo, sf.ng), si = v3_dot(bs.wi, sf.ng);
        float shade = v3_dot(bs.wi, sf.ns) * (so >= 0 ? 1.0f : -1.0f);
        if ((so * si > 0) != (shade > 0))
            bad_side++;
    }
    CHECK(bad_pdf == 0 && bad_weight == 0 && bad_side == 0,
          "%s: %d samples with eval's pdf off, %d with a weight other than f cos / pdf, %d on the wrong side", name,
          bad_pdf, bad_weight, bad_side);
    enum { SUB = 6 };
    double total = 0;
    for (int it = 0; it < NT; it++)
        for (int ip = 0; ip < NP; ip++) {
            double acc = 0;
            for (int a = 0; a < SUB; a++)
                for (int b = 0; b < SUB; b++) {
                    double ct = -1.0 + 2.0 * (it + (a + 0.5) / SUB) / NT;
                    double ph = 2 * M_PI * (ip + (b + 0.5) / SUB) / NP, st = sqrt(1 - ct * ct);
                    float pdf;
                    bsdf_eval(m, &sf, wo, v3((float)(st * cos(ph)), (float)(st * sin(ph)), (float)ct), &pdf);
                    acc += pdf;
                }
            double e = acc / (SUB * SUB) * (2.0 / NT) * (2 * M_PI / NP);
            expct[it * NP + ip] = e * n;
            total += e;
        }
    expct[NB] = fmax(0.0, 1.0 - total) * n;
    double stat = 0, pool_o = 0, pool_e = 0;
    int dof = -1;
    for (int i = 0; i <= NB; i++) {
        if (expct[i] < 20) {
            pool_o += obs[i];
            pool_e += expct[i];
            continue;
        }
        stat += (obs[i] - expct[i]) * (obs[i] - expct[i]) / expct[i];
        dof++;
    }
    if (pool_e >= 20) {
        stat += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        dof++;
    }
    /* Midpoint quadrature over these bins is good to a fraction of a
     * percent of each bin for the rough lobes tested here. */
    double p = dof > 0 ? chi2_pvalue(stat, dof) : 0;
    CHECK(p > 1e-4, "%s: chi-square p-value %.3g (pdf mass %.4f, void %.4f)", name, p, total, obs[NB] / n);
    printf("%-52s p = %.3f (pdf mass %.4f, void %.4f)\n", name, p, total, obs[NB] / n);
}

static void test_materials(void)
{
    vec3 front = v3_norm(v3(0.5f, 0.3f, 0.8f)), back = v3_norm(v3(-0.2f, 0.4f, -0.9f));
    fr_material c = make(FR_MAT_CONDUCTOR, 0.5f, 0.0f, 0);
    test_bsdf("conductor r=0.5", &c, front, 200000);
    c = make(FR_MAT_CONDUCTOR, 0.6f, 0.7f, FR_MF_SEPARABLE | FR_MF_COMPENSATE);
    test_bsdf("conductor r=0.6 anisotropic, compensated", &c, front, 200000);
    fr_material d = make(FR_MAT_DIELECTRIC, 0.5f, 0.0f, 0);
    test_bsdf("rough glass r=0.5 from outside", &d, front, 200000);
    test_bsdf("rough glass r=0.5 from inside", &d, back, 200000);
    d = make(FR_MAT_DIELECTRIC, 0.7f, -0.5f, FR_MF_MACRO_FRESNEL | FR_MF_COMPENSATE);
    test_bsdf("rough glass r=0.7 Cycles Fresnel, anisotropic", &d, back, 200000);
    fr_material p = make(FR_MAT_PRINCIPLED, 0.5f, 0.0f, 0);
    test_bsdf("principled r=0.5", &p, front, 200000);
    p = make(FR_MAT_PRINCIPLED, 0.8f, 0.3f, FR_MF_GLTF_COUPLING | FR_MF_COMPENSATE);
    test_bsdf("principled r=0.8 glTF coupling, from inside", &p, back, 200000);
}

/* ---- rendered furnaces ------------------------------------------------------ */

/* Mean radiance of a 16x16 image of a sphere filling the view, lit by a
 * constant white environment of radiance 1. */
static double furnace(const char *material, uint32_t spp)
{
    char json[1024];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 16, \"height\": 16, \"spp\": 1, \"max_depth\": 64},"
             " \"camera\": {\"position\": [0, 0, 3], \"target\": [0, 0, 0], \"fov\": 20},"
             " \"environment\": {\"color\": [1, 1, 1]},"
             " \"materials\": {\"m\": %s},"
             " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"m\"}]}",
             material);
    fr_scene s;
    test_scene(json, &s);
    double acc = 0;
    for (uint32_t y = 0; y < 16; y++)
        for (uint32_t x = 0; x < 16; x++)
            for (uint32_t i = 0; i < spp; i++)
                acc += pt_sample(&s, PT_MIS, x, y, i).y;
    scn_free(&s);
    return acc / (256.0 * spp);
}

static void test_furnaces(void)
{
    double u = furnace("{\"type\": \"conductor\", \"roughness\": 1, \"reflectance\": [1, 1, 1], \"fresnel\": \"none\"}", 64);
    double c = furnace("{\"type\": \"conductor\", \"roughness\": 1, \"reflectance\": [1, 1, 1], \"fresnel\": \"none\","
                       " \"compensate\": true}", 64);
    printf("white conductor, roughness 1, in a white furnace: %.4f uncompensated, %.4f compensated\n", u, c);
    CHECK(c >= 0.98 && c <= 1.01, "compensated white conductor returns %g of the light", c);
    CHECK(u < 0.6, "uncompensated white conductor at roughness 1 returns %g (expected well below 1)", u);
    double g = furnace("{\"type\": \"glass\", \"roughness\": 0.7, \"ior\": 1.5, \"compensate\": true}", 64);
    double gu = furnace("{\"type\": \"glass\", \"roughness\": 0.7, \"ior\": 1.5}", 64);
    printf("rough glass sphere, roughness 0.7: %.4f uncompensated, %.4f compensated\n", gu, g);
    CHECK(fabs(g - 1) < 0.02, "compensated rough glass in a white furnace: %g", g);
    CHECK(gu < g - 0.02, "uncompensated rough glass loses nothing measurable: %g vs %g", gu, g);
    double p = furnace("{\"type\": \"principled\", \"base_color\": [1, 1, 1], \"metallic\": 0, \"roughness\": 0.5}", 64);
    printf("white principled dielectric: %.4f\n", p);
    CHECK(p <= 1.005 && p > 0.9, "white principled dielectric in a white furnace: %g", p);
}

/* ---- MIS agreement ---------------------------------------------------------- */

static const char mis_scene[] =
    "{\"image\": {\"width\": 12, \"height\": 9, \"spp\": 1, \"max_depth\": 4},"
    " \"camera\": {\"position\": [0, 1.2, -4], \"target\": [0, 0.6, 3], \"fov\": 35},"
    " \"materials\": {"
    "   \"floor\": {\"type\": \"conductor\", \"roughness\": 0.3, \"reflectance\": [0.9, 0.8, 0.6]},"
    "   \"wall\": {\"type\": \"principled\", \"base_color\": [0.6, 0.5, 0.4], \"metallic\": 0.2, \"roughness\": 0.6},"
    "   \"glass\": {\"type\": \"glass\", \"roughness\": 0.25, \"ior\": 1.5},"
    "   \"panel\": {\"type\": \"emitter\", \"emission\": [4, 4, 4]},"
    "   \"bulb\": {\"type\": \"emitter\", \"emission\": [60, 50, 40]}},"
    " \"shapes\": ["
    "   {\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"},"
    "   {\"type\": \"rect\", \"origin\": [-3, 0, 3], \"edge_u\": [6, 0, 0], \"edge_v\": [0, 4, 0], \"material\": \"wall\"},"
    "   {\"type\": \"sphere\", \"center\": [0.3, 0.7, 0.5], \"radius\": 0.7, \"material\": \"glass\"},"
    "   {\"type\": \"rect\", \"origin\": [-1, 3, -1], \"edge_u\": [2, 0, 0], \"edge_v\": [0, 0, 1], \"material\": \"panel\"},"
    "   {\"type\": \"sphere\", \"center\": [1.2, 2.6, -2], \"radius\": 0.15, \"material\": \"bulb\"}]}";


static void test_mis(void)
{
    fr_scene s;
    test_scene(mis_scene, &s);
    /* Pooled over four seeds: one seed's standard errors are themselves
     * noisy (a few bright paths through the glass rule them), enough for a
     * single seed to show light sampling alone ahead of MIS by chance. */
    enum { SEEDS = 4 };
    estimate mis = {0, 0}, light = {0, 0}, bsdf = {0, 0};
    for (uint32_t seed = 0; seed < SEEDS; seed++) {
        s.settings.seed = seed;
        estimate e[3] = {est_image(&s, PT_MIS, 512), est_image(&s, PT_LIGHT_ONLY, 512),
                         est_image(&s, PT_BSDF_ONLY, 1024)};
        estimate *acc[3] = {&mis, &light, &bsdf};
        for (int k = 0; k < 3; k++) {
            acc[k]->mean += e[k].mean / SEEDS;
            acc[k]->se += e[k].se * e[k].se / (SEEDS * SEEDS);
        }
    }
    mis.se = sqrt(mis.se);
    light.se = sqrt(light.se);
    bsdf.se = sqrt(bsdf.se);
    printf("rough scene: MIS %.5f +- %.5f, light only %.5f +- %.5f, BSDF only %.5f +- %.5f\n", mis.mean, mis.se,
           light.mean, light.se, bsdf.mean, bsdf.se);
    double d1 = fabs(mis.mean - light.mean), s1 = sqrt(mis.se * mis.se + light.se * light.se);
    double d2 = fabs(mis.mean - bsdf.mean), s2 = sqrt(mis.se * mis.se + bsdf.se * bsdf.se);
    CHECK(d1 < 4 * s1, "MIS and light sampling disagree: %g vs %g (%.1f sigma)", mis.mean, light.mean, d1 / s1);
    CHECK(d2 < 4 * s2, "MIS and BSDF sampling disagree: %g vs %g (%.1f sigma)", mis.mean, bsdf.mean, d2 / s2);
    CHECK(mis.se < light.se && mis.se < bsdf.se, "MIS is not the least noisy: %g vs %g, %g", mis.se, light.se, bsdf.se);
    scn_free(&s);
}

int main(void)
{
    test_syntax();
    test_textures();
    test_materials();
    test_furnaces();
    test_mis();
    return check_done();
}
