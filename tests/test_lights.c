/* test_lights.c -- sun, spot, point and area lights against closed forms.
 *
 * Sun, spot and point lights against closed forms; rays leaving lights
 * (their densities and the power they carry); pick probabilities of many
 * area lights; the JSON errors of the lights. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "compile/builder_light.h"
#include "check.h"
#include "stats.h"
#include "compile/freeze.h"
#include "light.h"
#include "pathtrace.h"
#include "sampler.h"
#include "scenes.h"

typedef struct { double mean, se; } estimate;

/* The single pixel's green channel over spp samples, with its standard error. */
static estimate pixel(const fr_scene *s, pt_strategy strategy, uint32_t spp)
{
    double sum = 0, sum2 = 0;
    for (uint32_t i = 0; i < spp; i++) {
        double v = pt_sample(s, strategy, 0, 0, i).y;
        sum += v;
        sum2 += v * v;
    }
    estimate e = {sum / spp, sqrt(fmax(0, sum2 / spp - (sum / spp) * (sum / spp)) / spp)};
    return e;
}

/* A narrow camera looking straight down at point (x, 0, 0) of a Lambert
 * plane of albedo 0.6 (direct light only), lit by `light` (JSON), with an
 * optional extra shape. */
static void plane_scene(float x, const char *light, const char *shape, fr_scene *s)
{
    char json[2048];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 1, \"height\": 1, \"spp\": 1, \"max_depth\": 1},"
             " \"camera\": {\"position\": [%g, 5, 0.001], \"target\": [%g, 0, 0], \"up\": [0, 0, 1], \"fov\": 0.01},"
             " \"materials\": {\"floor\": {\"type\": \"lambert\", \"albedo\": [0.6, 0.6, 0.6]}},"
             " \"lights\": [%s],"
             " \"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"}%s]}",
             (double)x, (double)x, light, shape);
    test_scene(json, s);
}

/* A sun at 30 degrees from the zenith, irradiance E: the plane's radiance
 * is albedo/pi * E cos 30, with a delta sun and with a 10-degree disk
 * (fully above the horizon, so the cosine-weighted disk integrates to the
 * same); each sampling strategy agrees.  A sphere between the point and
 * the sun shadows it completely. */
static void sun_on_plane(void)
{
    const double E = 3.0, expect = 0.6 / M_PI * E * cos(M_PI / 6);
    char light[256];
    const char *dirn = "[-0.5, -0.8660254, 0]";
    snprintf(light, sizeof light, "{\"type\": \"sun\", \"direction\": %s, \"irradiance\": [%g, %g, %g]}", dirn, E, E,
             E);
    fr_scene s;
    plane_scene(0, light, "", &s);
    estimate e = pixel(&s, PT_MIS, 64);
    CHECK(fabs(e.mean - expect) < 1e-4 * expect, "delta sun on a plane: %.6f, expected %.6f", e.mean, expect);
    scn_free(&s);
    plane_scene(0, light, ", {\"type\": \"sphere\", \"center\": [1, 1.732, 0], \"radius\": 0.3, \"material\": \"floor\"}",
                &s);
    e = pixel(&s, PT_MIS, 16);
    CHECK(e.mean == 0.0, "delta sun behind a sphere: %g, expected 0", e.mean);
    scn_free(&s);
    snprintf(light, sizeof light,
             "{\"type\": \"sun\", \"direction\": %s, \"irradiance\": [%g, %g, %g], \"angle\": 10}", dirn, E, E, E);
    plane_scene(0, light, "", &s);
    static const pt_strategy strategies[3] = {PT_MIS, PT_LIGHT_ONLY, PT_BSDF_ONLY};
    static const char *const names[3] = {"MIS", "light only", "BSDF only"};
    static const uint32_t spp[3] = {4096, 4096, 400000};
    for (int k = 0; k < 3; k++) {
        e = pixel(&s, strategies[k], spp[k]);
        CHECK(fabs(e.mean - expect) < 4 * e.se + 2e-4 * expect, "sun disk on a plane (%s): %.6f +- %.6f, expected %.6f",
              names[k], e.mean, e.se, expect);
    }
    scn_free(&s);
}

/* A spot 2 above the plane pointing down, cone angles 20 and 40 degrees:
 * at angle a from its axis the plane's radiance is albedo/pi * I f(a)
 * cos(a)^3 / h^2, with glTF's falloff f: 1 inside 20, 0 outside 40,
 * ((cos a - cos 40) / (cos 20 - cos 40))^2 between. */
static void spot_falloff(void)
{
    const double I = 40.0, h = 2.0, ci = cos(20 * M_PI / 180), co = cos(40 * M_PI / 180);
    static const double angles[] = {0, 10, 19.9, 25, 30, 35, 39.9, 40.1, 60};
    for (size_t k = 0; k < sizeof angles / sizeof angles[0]; k++) {
        double a = angles[k] * M_PI / 180, x = h * tan(a), c = cos(a);
        double t = (c - co) / (ci - co), f = t <= 0 ? 0 : t >= 1 ? 1 : t * t;
        double expect = 0.6 / M_PI * I * f * c * c * c / (h * h);
        char light[256];
        snprintf(light, sizeof light,
                 "{\"type\": \"spot\", \"position\": [0, %g, 0], \"direction\": [0, -1, 0], \"intensity\": [%g, %g, %g],"
                 " \"inner_angle\": 20, \"outer_angle\": 40}", h, I, I, I);
        fr_scene s;
        plane_scene((float)x, light, "", &s);
        estimate e = pixel(&s, PT_MIS, 16);
        CHECK(fabs(e.mean - expect) <= 2e-3 * expect + 1e-6, "spot at %g degrees: %.6f, expected %.6f", angles[k],
              e.mean, expect);
        /* lgt_spot_falloff itself. */
        float fl = lgt_spot_falloff(&s.lights[0], (float)c);
        CHECK(fabs(fl - f) < 1e-5, "falloff at %g degrees: %g, expected %g", angles[k], (double)fl, f);
        scn_free(&s);
    }
    /* "target" instead of "direction", aimed off to the side. */
    fr_scene s;
    plane_scene(1.0f, "{\"type\": \"spot\", \"position\": [0, 2, 0], \"target\": [1, 0, 0], \"intensity\": [9, 9, 9],"
                      " \"outer_angle\": 5}", "", &s);
    double r2 = 5.0, c = 2.0 / sqrt(r2);
    estimate e = pixel(&s, PT_MIS, 16);
    CHECK(fabs(e.mean - 0.6 / M_PI * 9 * c / r2) < 1e-3 * e.mean, "spot aimed at its target: %g", e.mean);
    scn_free(&s);
}

/* The power a light's rays carry, E[Le |cos| / (pdf_pos pdf_dir)] over
 * lgt_sample_emit's rays, against the closed form; and lgt_pdf_emit gives
 * every ray the densities it was sampled with. */
static void emitted_power(const char *what, const char *lights, const char *extra_mats, const char *shapes,
                          const char *env, double expect)
{
    char json[2048];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 4, \"height\": 4},"
             " \"camera\": {\"position\": [0, 0, -5], \"target\": [0, 0, 0], \"fov\": 40},"
             " \"materials\": {\"grey\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}%s},"
             " \"lights\": [%s], %s"
             " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"grey\"}%s]}",
             extra_mats, lights, env, shapes);
    fr_scene s;
    test_scene(json, &s);
    if (strstr(what, "distant"))
        expect *= M_PI * s.world.radius * s.world.radius;
    uint32_t st = 99;
    double sum = 0, sum2 = 0;
    int bad = 0;
    enum { N = 200000 };
    for (int k = 0; k < N; k++) {
        fr_light_emit em;
        float u[5];
        for (int i = 0; i < 5; i++)
            u[i] = (float)st_rnd(&st);
        double v = 0;
        if (lgt_sample_emit(&s, u[0], u[1], u[2], u[3], u[4], &em)) {
            double c = em.prim != FR_NONE ? fabs(v3_dot(em.n, em.ray.d)) : 1.0;
            v = v3_luma(em.Le) * c / (em.pdf_pos * em.pdf_dir);
            float pp, pd;
            lgt_pdf_emit(&s, em.light, em.ray.o, em.n, em.ray.d, &pp, &pd);
            if (fabsf(pp - em.pdf_pos) > 1e-4f * em.pdf_pos || (!em.delta_dir && fabsf(pd - em.pdf_dir) > 1e-3f * em.pdf_dir))
                bad++;
            if (fabsf(v3_len(em.ray.d) - 1.0f) > 1e-5f)
                bad++;
            /* A distant light's rays start outside the scene's bounds. */
            if (em.distant && v3_len(v3_sub(em.ray.o, s.world.center)) < s.world.radius * 0.999f)
                bad++;
        }
        sum += v;
        sum2 += v * v;
    }
    double mean = sum / N, se = sqrt(fmax(0, sum2 / N - mean * mean) / N);
    CHECK(fabs(mean - expect) < 4 * se + 1e-4 * expect, "%s: emitted power %.5f +- %.5f, expected %.5f", what, mean,
          se, expect);
    CHECK(bad == 0, "%s: %d rays whose densities lgt_pdf_emit does not reproduce, or not unit, or inside", what, bad);
    scn_free(&s);
}

static void emission(void)
{
    const double I = 5.0, ci = cos(15 * M_PI / 180), co = cos(35 * M_PI / 180);
    emitted_power("point", "{\"type\": \"point\", \"position\": [0, 3, 0], \"intensity\": [5, 5, 5]}", "", "", "",
                  4 * M_PI * I);
    /* 2 pi I (integral of the falloff over cos from co to 1). */
    double spot = 2 * M_PI * I * ((1 - ci) + (ci - co) / 3);
    emitted_power("spot", "{\"type\": \"spot\", \"position\": [0, 3, 0], \"direction\": [0.3, -1, 0.2],"
                  " \"intensity\": [5, 5, 5], \"inner_angle\": 15, \"outer_angle\": 35}", "", "", "", spot);
    emitted_power("distant: sun", "{\"type\": \"sun\", \"direction\": [0.3, -1, 0.2], \"irradiance\": [2, 2, 2]}",
                  "", "", "", 2.0);
    /* A disk of half-angle a has radiance E / (pi sin^2 a) over the solid
     * angle 2 pi (1 - cos a): per unit area across each ray, 2 E / (1 + cos a). */
    emitted_power("distant: sun disk", "{\"type\": \"sun\", \"direction\": [0.3, -1, 0.2], \"irradiance\": [2, 2, 2],"
                  " \"angle\": 30}", "", "", "", 2.0 * 2.0 / (1.0 + cos(15 * M_PI / 180)));
    emitted_power("distant: environment", "", "", "", "\"environment\": {\"color\": [0.5, 0.5, 0.5]},",
                  4 * M_PI * 0.5);
    /* A rectangle of radiance 3 and area 2, one-sided: pi Le A; a
     * two-sided triangle of area 1: twice pi Le A. */
    emitted_power("rectangle", "", ", \"lamp\": {\"type\": \"emitter\", \"emission\": [3, 3, 3]}",
                  ", {\"type\": \"rect\", \"origin\": [2, 2, 2], \"edge_u\": [1, 0, 0], \"edge_v\": [0, 0, 2],"
                  " \"material\": \"lamp\"}", "", M_PI * 3 * 2);
    emitted_power("two-sided triangle", "",
                  ", \"lamp\": {\"type\": \"emitter\", \"emission\": [3, 3, 3], \"two_sided\": true}",
                  ", {\"type\": \"triangle\", \"vertices\": [[2, 2, 2], [3, 2, 2], [2, 4, 2]], \"material\": \"lamp\"}",
                  "", 2 * M_PI * 3 * 1);
    emitted_power("sphere", "", ", \"lamp\": {\"type\": \"emitter\", \"emission\": [3, 3, 3]}",
                  ", {\"type\": \"sphere\", \"center\": [3, 0, 0], \"radius\": 0.3, \"material\": \"lamp\"}", "",
                  M_PI * 3 * 4 * M_PI * 0.09);
}

/* Two thousand emissive triangles of different brightness and size: each
 * is an area light picked in proportion to its power, lgt_pick returns
 * light i for numbers in [cdf[i-1], cdf[i]), and the lights are listed in
 * the order the triangles were added, whatever order the BVH put them in. */
static void many_area_lights(void)
{
    fr_builder b;
    bld_init(&b);
    b.settings = (fr_settings){.width = 8, .height = 8, .spp = 1, .max_depth = 2};
    b.camera.position = v3(0, 0, -5);
    b.camera.target = v3(0, 0, 0);
    b.camera.up = v3(0, 1, 0);
    b.camera.vfov = 0.7f;
    b.camera.focus = 5;
    enum { N = 2000 };
    for (int i = 0; i < N; i++) {
        fr_material m;
        bld_material_init(&m);
        m.emission = v3s(1.0f + (float)(i % 7));
        bld_push(&b.materials, &m);
        int g = i * 37 % N; /* spread over the grid, so the BVH has to reorder them */
        float x = (float)(g % 50) * 0.1f, y = (float)(g / 50) * 0.1f, sz = 0.02f + 0.001f * (float)(i % 13);
        bld_triangle(&b, v3(x, y, 0), v3(x + sz, y, 0), v3(x, y + sz, 0), (uint32_t)i);
    }
    fr_scene s;
    fr_error err;
    int rc = frz_scene(&b, &s, &err);
    CHECK(rc == 0, "freeze: %s", rc ? err.msg : "");
    if (rc == 0) {
        CHECK(s.n_lights == N, "%u lights, expected %d", s.n_lights, N);
        double ratio0 = 0, worst = 0, prev = 0;
        int order = 1, picks = 1, added = 1, moved = 0;
        for (uint32_t i = 0; i < s.n_lights; i++) {
            const fr_light *l = &s.lights[i];
            added &= s.prims[l->prim].material == i;
            moved |= l->prim != i;
            const fr_material *m = &s.materials[s.prims[l->prim].material];
            double power = M_PI * v3_luma(m->emission) * l->area, ratio = l->pick / power;
            if (i == 0)
                ratio0 = ratio;
            worst = fmax(worst, fabs(ratio / ratio0 - 1));
            order &= l->cdf >= prev;
            float lo = i ? s.lights[i - 1].cdf : 0.0f;
            if (l->cdf > lo)
                picks &= lgt_pick(&s, lo) == i && lgt_pick(&s, nextafterf(l->cdf, 0.0f)) == i;
            prev = l->cdf;
        }
        CHECK(worst < 1e-5, "pick / power varies by %.2e", worst);
        CHECK(order && s.lights[N - 1].cdf == 1.0f, "running sums not increasing to 1");
        CHECK(picks, "lgt_pick does not return the light whose interval holds u");
        CHECK(added, "area lights are not in the order their triangles were added");
        CHECK(moved, "the BVH kept every triangle in place: the order check above proves nothing");
        scn_free(&s);
    }
    bld_free(&b);
}

/* Area lights with an emission texture: their power follows the texture
 * on them (a triangle on a black square of a checkerboard gets the floor,
 * a thousandth of the checkerboard's mean, half the white: 1/2000 of the
 * chance of one on a white square, never none), and light-only,
 * BSDF-only and MIS estimates of a floor lit by such a panel agree. */
static void textured_area_lights(void)
{
    fr_builder b;
    bld_init(&b);
    b.settings = (fr_settings){.width = 8, .height = 8, .spp = 1, .max_depth = 2};
    b.camera.position = v3(0, 0, -5);
    b.camera.target = v3(0, 0, 0);
    b.camera.up = v3(0, 1, 0);
    b.camera.vfov = 0.7f;
    b.camera.focus = 5;
    fr_texture t;
    memset(&t, 0, sizeof t);
    t.kind = FR_TEX_CHECKER;
    t.color0 = v3s(1.0f);
    t.color1 = v3s(0.0f);
    t.scale = (vec2){4, 4};
    bld_push(&b.textures, &t);
    fr_material m;
    bld_material_init(&m);
    m.emission = v3s(2.0f);
    m.tex_emission = 0;
    bld_push(&b.materials, &m);
    /* uv squares of 1/4: [0, 1/4)^2 is colour0 (white), [1/4, 1/2) x [0, 1/4) black. */
    const vec3 p[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const vec2 white[3] = {{0.05f, 0.05f}, {0.2f, 0.05f}, {0.05f, 0.2f}};
    const vec2 black[3] = {{0.3f, 0.05f}, {0.45f, 0.05f}, {0.3f, 0.2f}};
    bld_triangle_uv(&b, p, white, 0);
    const vec3 q[3] = {{2, 0, 0}, {3, 0, 0}, {2, 1, 0}};
    bld_triangle_uv(&b, q, black, 0);
    fr_scene s;
    fr_error err;
    int rc = frz_scene(&b, &s, &err);
    CHECK(rc == 0, "freeze: %s", rc ? err.msg : "");
    if (rc == 0) {
        const fr_light *lw = &s.lights[0], *lb = &s.lights[1];
        if (s.prims[lw->prim].material == 0 && s.triangles[s.prims[lw->prim].index].v[0] != 0) {
            const fr_light *x = lw;
            lw = lb;
            lb = x;
        }
        double ratio = lw->pick / lb->pick;
        CHECK(s.n_lights == 2 && ratio > 1900 && ratio < 2100, "white / black pick ratio %.2f, expected about 2000",
              ratio);
        scn_free(&s);
    }
    bld_free(&b);
    static const char json[] =
        "{\"image\": {\"width\": 1, \"height\": 1, \"spp\": 1, \"max_depth\": 1},"
        " \"camera\": {\"position\": [0.5, 5, 2.001], \"target\": [0.5, 0, 2], \"up\": [0, 0, 1], \"fov\": 0.01},"
        " \"textures\": {\"checks\": {\"type\": \"checker\", \"colors\": [[1, 1, 1], [0, 0, 0]], \"scale\": 3}},"
        " \"materials\": {\"floor\": {\"type\": \"lambert\", \"albedo\": [0.6, 0.6, 0.6]},"
        "   \"screen\": {\"type\": \"emitter\", \"emission\": {\"texture\": \"checks\", \"factor\": [5, 5, 5]}}},"
        " \"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"},"
        "   {\"type\": \"quad\", \"vertices\": [[-1, 1, -1], [1, 1, -1], [1, 1, 1], [-1, 1, 1]], \"material\": \"screen\"},"
        "   {\"type\": \"quad\", \"vertices\": [[1.5, 0.5, -1], [2.5, 0.5, -1], [2.5, 0.5, 1], [1.5, 0.5, 1]],"
        "    \"material\": \"screen\"}]}";
    test_scene(json, &s);
    estimate mis = pixel(&s, PT_MIS, 20000), light = pixel(&s, PT_LIGHT_ONLY, 20000), bsdf = pixel(&s, PT_BSDF_ONLY, 80000);
    double d1 = fabs(mis.mean - light.mean), s1 = hypot(mis.se, light.se);
    double d2 = fabs(mis.mean - bsdf.mean), s2 = hypot(mis.se, bsdf.se);
    printf("textured panels: MIS %.5f +- %.5f, light %.5f +- %.5f, BSDF %.5f +- %.5f\n", mis.mean, mis.se, light.mean, light.se,
           bsdf.mean, bsdf.se);
    CHECK(mis.mean > 0 && d1 < 4 * s1 && d2 < 4 * s2, "textured panels: MIS %.5f, light %.5f, BSDF %.5f (+- %.5f %.5f %.5f)",
          mis.mean, light.mean, bsdf.mean, mis.se, light.se, bsdf.se);
    scn_free(&s);
}

/* Bad light definitions: an error naming the place, never a crash. */
static void json_errors(void)
{
    static const struct { const char *lights, *want; } cases[] = {
        {"{\"type\": \"spot\", \"position\": [0, 1, 0], \"direction\": [0, -1, 0], \"intensity\": [1, 1, 1],"
         " \"inner_angle\": 30, \"outer_angle\": 20}", "lights[0].inner_angle"},
        {"{\"type\": \"spot\", \"position\": [0, 1, 0], \"intensity\": [1, 1, 1]}", "lights[0]: expected either"},
        {"{\"type\": \"spot\", \"position\": [0, 1, 0], \"direction\": [0, 0, 0], \"intensity\": [1, 1, 1]}",
         "lights[0].direction"},
        {"{\"type\": \"spot\", \"position\": [0, 1, 0], \"target\": [0, 1, 0], \"intensity\": [1, 1, 1]}",
         "lights[0].target"},
        {"{\"type\": \"sun\", \"direction\": [0, -1, 0], \"irradiance\": [1, 1, 1], \"angle\": 200}",
         "lights[0].angle"},
        {"{\"type\": \"sun\", \"direction\": [0, -1, 0], \"irradiance\": [-1, 1, 1]}", "lights[0].irradiance"},
        {"{\"type\": \"sun\", \"irradiance\": [1, 1, 1]}", "lights[0].direction"},
        {"{\"type\": \"sun\", \"direction\": [0, -1, 0], \"irradiance\": [1, 1, 1], \"size\": 3}", "size"},
        {"{\"type\": \"area\"}", "lights[0].type"},
        {"{\"type\": \"point\", \"position\": [0, 1, 0], \"intensity\": [0, 0, 0]}", "lights[0].intensity"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char json[1024];
        snprintf(json, sizeof json,
                 "{\"image\": {\"width\": 4, \"height\": 4}, \"camera\": {\"position\": [0, 0, -5], \"target\": [0, 0, 0],"
                 " \"fov\": 40}, \"materials\": {\"g\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}},"
                 " \"lights\": [%s], \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1,"
                 " \"material\": \"g\"}]}", cases[k].lights);
        fr_builder b;
        fr_error err = {{0}};
        bld_init(&b);
        int rc = json_scene_parse(json, "x.json", NULL, &b, &err);
        CHECK(rc < 0 && strstr(err.msg, cases[k].want) && strstr(err.msg, "x.json"), "case %zu: %s (want '%s')", k,
              rc < 0 ? err.msg : "accepted", cases[k].want);
        bld_free(&b);
    }
    /* Environment errors: a checker is no map; fog with distant lights. */
    static const struct { const char *extra, *want; } env_cases[] = {
        {"\"textures\": {\"c\": {\"type\": \"checker\", \"colors\": [[0, 0, 0], [1, 1, 1]]}},"
         " \"environment\": {\"color\": \"c\"},", "environment"},
        {"\"environment\": {\"color\": [1, 1, 1], \"strength\": 0},", "environment.strength"},
        {"\"environment\": {\"color\": [0, 0, 0]},", "environment.color"},
        {"\"environment\": {\"strength\": 2},", "environment.color"},
        {"\"environment\": {\"color\": [1, 1, 1]}, \"media\": {\"f\": {\"sigma_s\": 0.1}}, \"medium\": \"f\",",
         "fog"},
    };
    for (size_t k = 0; k < sizeof env_cases / sizeof env_cases[0]; k++) {
        char json[1024];
        snprintf(json, sizeof json,
                 "{\"image\": {\"width\": 4, \"height\": 4}, \"camera\": {\"position\": [0, 0, -5], \"target\": [0, 0, 0],"
                 " \"fov\": 40}, \"materials\": {\"g\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}}, %s"
                 " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"g\"}]}",
                 env_cases[k].extra);
        fr_builder b;
        fr_error err = {{0}};
        fr_scene s;
        bld_init(&b);
        int rc = json_scene_parse(json, "x.json", NULL, &b, &err);
        if (rc == 0) {
            rc = frz_scene(&b, &s, &err);
            if (rc == 0)
                scn_free(&s);
        }
        CHECK(rc < 0 && strstr(err.msg, env_cases[k].want), "environment case %zu: %s (want '%s')", k,
              rc < 0 ? err.msg : "accepted", env_cases[k].want);
        bld_free(&b);
    }
    /* The builder refuses a second environment. */
    fr_builder b;
    fr_error err;
    bld_init(&b);
    CHECK(bld_environment(&b, v3s(1), FR_NONE, 0, &err) == 0, "first environment refused: %s", err.msg);
    CHECK(bld_environment(&b, v3s(1), FR_NONE, 0, &err) < 0 && strstr(err.msg, "already"), "second environment");
    bld_free(&b);
}

/* lgt_pick against its definition, the first light whose cdf exceeds u
 * (the last when none does), for 1 to 9 lights with repeated cdfs (lights
 * of no power), at every cdf, next to it, and at 0, 1, above 1 and NaN. */
static void pick_definition(void)
{
    fr_light lights[9];
    int bad = 0;
    for (uint32_t n = 1; n <= 9; n++) {
        for (uint32_t i = 0; i < n; i++) {
            lights[i] = (fr_light){0};
            lights[i].cdf = i + 1 == n ? 1.0f : (float)((i + 1) / 2 * 2) / (float)n;
        }
        fr_scene s = {0};
        s.lights = lights;
        s.n_lights = n;
        float us[40];
        int nu = 0;
        us[nu++] = 0.0f; us[nu++] = 1.0f; us[nu++] = 1.5f; us[nu++] = NAN; us[nu++] = 0.4999f;
        for (uint32_t i = 0; i < n; i++) {
            us[nu++] = lights[i].cdf;
            us[nu++] = nextafterf(lights[i].cdf, 0.0f);
            us[nu++] = nextafterf(lights[i].cdf, 2.0f);
        }
        for (int k = 0; k < nu; k++) {
            uint32_t want = n - 1;
            for (uint32_t i = 0; i < n; i++)
                if (us[k] < lights[i].cdf) {
                    want = i;
                    break;
                }
            if (lgt_pick(&s, us[k]) != want && bad++ < 5)
                CHECK(0, "%u lights, u = %a: light %u, expected %u", n, us[k], lgt_pick(&s, us[k]), want);
        }
    }
    CHECK(bad == 0, "lgt_pick differs from its definition %d times", bad);
}

int main(void)
{
    sun_on_plane();
    spot_falloff();
    emission();
    many_area_lights();
    pick_definition();
    textured_area_lights();
    json_errors();
    return check_done();
}
