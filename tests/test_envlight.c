/* test_envlight.c -- the environment light's sampling, pdf, furnace and
 * orientation.
 *
 * The environment light: its sampling against its pdf (chi-square over the
 * map's texels, binned with libm's own mapping of directions), the pdf
 * against the radiance it follows, a constant environment as a furnace,
 * light-only / BSDF-only / MIS agreement, and the documented orientation
 * of the map (a bright texel shows up at the pixels the convention says). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "estimate.h"
#include "stats.h"
#include "envmap.h"
#include "fmath.h"
#include "light.h"
#include "pathtrace.h"
#include "pfmmap.h"
#include "sampler.h"
#include "scenes.h"

static char dir[] = "/tmp/franja-envXXXXXX";

/* The test map, W x H, top row first: a smooth sky, a black band, and a
 * small bright "sun" texel. */
enum { W = 24, H = 12 };
static float map[W * H * 3];

static void make_map(void)
{
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            float *p = map + (j * W + i) * 3;
            float g = 0.2f + 0.8f * (float)(H - j) / H;
            p[0] = 0.3f * g + 0.02f * (float)i;
            p[1] = 0.5f * g;
            p[2] = g;
            if (j == 8 || (j == 9 && i < 6)) /* black below the horizon, part of a row black */
                p[0] = p[1] = p[2] = 0.0f;
        }
    float *sun = map + (3 * W + 17) * 3;
    sun[0] = 400.0f; sun[1] = 380.0f; sun[2] = 300.0f;
}

/* A scene around a grey sphere lit by the map (or a constant colour),
 * with the given filter and rotation (degrees). */
static void env_scene(const char *filter, float rotation, const char *extra_shapes, const char *extra_mats,
                      uint32_t w, uint32_t h, uint32_t depth, fr_scene *s)
{
    char json[4096], file[256];
    snprintf(file, sizeof file, "%s/scene.json", dir);
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %u, \"height\": %u, \"spp\": 1, \"max_depth\": %u},"
             " \"camera\": {\"position\": [0, 1, -4], \"target\": [0, 0.5, 0], \"fov\": 50},"
             " \"textures\": {\"sky\": {\"type\": \"image\", \"file\": \"sky.pfm\", \"filter\": \"%s\"}},"
             " \"environment\": {\"color\": \"sky\", \"strength\": 0.5, \"rotation\": %g},"
             " \"materials\": {\"grey\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}%s},"
             " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0.5, 0], \"radius\": 0.5, \"material\": \"grey\"}%s]}",
             w, h, depth, filter, (double)rotation, extra_mats, extra_shapes);
    test_scene_with(json, file, &pfm_hooks, s);
}

/* libm's version of the documented mapping: the texel (i, j) (row j from
 * the top) and the place inside it (fu, fv) that direction d looks up,
 * after the turn by rot degrees about +y. */
static void texel_of(vec3 d, double rot, int *i, int *j, int *sub)
{
    double c = cos(rot * M_PI / 180), s = sin(rot * M_PI / 180);
    double x = c * d.x + s * d.z, y = d.y, z = c * d.z - s * d.x;
    double u = 0.5 + atan2(z, x) / (2 * M_PI), t = acos(y < -1 ? -1 : y > 1 ? 1 : y) / M_PI;
    double fu = u * W, ft = t * H;
    *i = (int)fu;
    *j = (int)ft;
    if (*i >= W) *i = W - 1;
    if (*j >= H) *j = H - 1;
    *sub = (fu - *i >= 0.5) + 2 * (ft - *j >= 0.5);
}

/* Sampling against env_pdf, chi-square over the quarters of every texel.
 * Expected counts integrate env_pdf over each quarter (midpoint rule in
 * (theta, phi); pdf x sin(theta) is constant inside a texel, so the rule
 * is exact up to rounding); observed ones bin the samples with texel_of. */
static void chi_square(const char *filter, float rot)
{
    fr_scene s;
    env_scene(filter, rot, "", "", 8, 8, 2, &s);
    enum { NB = W * H * 4, N = 400000, Q = 4 };
    static double obs[NB], expct[NB];
    memset(obs, 0, sizeof obs);
    memset(expct, 0, sizeof expct);
    uint32_t st = 77;
    int bad_pdf = 0;
    for (int k = 0; k < N; k++) {
        float pdf;
        vec3 rad;
        vec3 d = env_sample(&s, (float)st_rnd(&st), (float)st_rnd(&st), &pdf, &rad);
        float again = env_pdf(&s, d);
        if (!(pdf > 0.0f) || fabsf(again - pdf) > 1e-3f * pdf + 1e-6f)
            bad_pdf++;
        int i, j, sub;
        texel_of(d, rot, &i, &j, &sub);
        obs[(j * W + i) * 4 + sub]++;
    }
    CHECK(bad_pdf < N / 2000, "%s: %d samples whose pdf is 0 or disagrees with env_pdf", filter, bad_pdf);
    double c = cos(rot * M_PI / 180), sn = sin(rot * M_PI / 180), total = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++)
            for (int q = 0; q < 2 * Q; q++)
                for (int p = 0; p < 2 * Q; p++) {
                    double th = M_PI * (j + (q + 0.5) / (2 * Q)) / H, ph = 2 * M_PI * ((i + (p + 0.5) / (2 * Q)) / W - 0.5);
                    /* The map-frame direction, turned back into the world. */
                    double x = sin(th) * cos(ph), y = cos(th), z = sin(th) * sin(ph);
                    vec3 d = v3((float)(c * x - sn * z), (float)y, (float)(sn * x + c * z));
                    double area = sin(th) * (M_PI / H / (2 * Q)) * (2 * M_PI / W / (2 * Q));
                    double e = env_pdf(&s, d) * area;
                    expct[(j * W + i) * 4 + (p >= Q) + 2 * (q >= Q)] += N * e;
                    total += e;
                }
    CHECK(fabs(total - 1.0) < 2e-3, "%s: env_pdf integrates to %.5f over the sphere", filter, total);
    double pv = st_chi2_test(obs, expct, NB, 0);
    CHECK(pv > 1e-4, "%s rot %g: chi-square p-value %.2e", filter, (double)rot, pv);
    scn_free(&s);
}

/* The pdf follows the radiance: with the nearest filter pdf * 2 pi^2
 * sin(theta) is the same multiple of the luminance times the sin(theta)
 * of the texel's centre everywhere (and 0 where the map is black); with bilinear it is never 0 where light is.
 * And E[L / pdf] over samples is the integral of L over the sphere. */
static void pdf_follows_radiance(const char *filter)
{
    fr_scene s;
    env_scene(filter, 30.0f, "", "", 8, 8, 2, &s);
    uint32_t st = 5;
    double ratio0 = -1, worst = 0;
    int missing = 0;
    for (int k = 0; k < 20000; k++) {
        double z = 1 - 2 * st_rnd(&st), r = sqrt(1 - z * z), ph = 2 * M_PI * st_rnd(&st);
        vec3 d = v3((float)(r * cos(ph)), (float)z, (float)(r * sin(ph)));
        double y = v3_luma(env_radiance(&s, d)), pdf = env_pdf(&s, d);
        if (y > 0 && !(pdf > 0))
            missing++;
        if (!strcmp(filter, "nearest") && y > 0 && r > 1e-3) {
            int i, j, sub;
            texel_of(d, 30.0, &i, &j, &sub);
            double ratio = pdf * 2 * M_PI * M_PI * r / (y * sin(M_PI * (j + 0.5) / H));
            if (ratio0 < 0)
                ratio0 = ratio;
            worst = fmax(worst, fabs(ratio / ratio0 - 1));
        }
    }
    CHECK(missing == 0, "%s: %d directions with light but pdf 0", filter, missing);
    if (!strcmp(filter, "nearest"))
        CHECK(worst < 1e-4, "nearest: pdf / luminance varies by %.2e", worst);
    /* Quadrature of the luminance over a fine (theta, phi) grid. */
    double quad = 0;
    enum { NT = 960, NP = 1920 };
    for (int a = 0; a < NT; a++) {
        double th = M_PI * (a + 0.5) / NT;
        for (int b = 0; b < NP; b++) {
            double ph = 2 * M_PI * (b + 0.5) / NP;
            vec3 d = v3((float)(sin(th) * cos(ph)), (float)cos(th), (float)(sin(th) * sin(ph)));
            quad += v3_luma(env_radiance(&s, d)) * sin(th) * (M_PI / NT) * (2 * M_PI / NP);
        }
    }
    double sum = 0, sum2 = 0;
    enum { N = 200000 };
    for (int k = 0; k < N; k++) {
        float pdf;
        vec3 rad;
        env_sample(&s, (float)st_rnd(&st), (float)st_rnd(&st), &pdf, &rad);
        double v = pdf > 0 ? v3_luma(rad) / pdf : 0;
        sum += v;
        sum2 += v * v;
    }
    double mean = sum / N, se = sqrt((sum2 / N - mean * mean) / N);
    CHECK(fabs(mean - quad) < 4 * se + 2e-3 * quad, "%s: E[L/pdf] %.4f +- %.4f, quadrature %.4f", filter, mean, se,
          quad);
    scn_free(&s);
}


/* A white Lambert sphere inside a constant environment looks like the
 * environment (one bounce off a convex shape sees only the sky). */
static void furnace(void)
{
    static const char json[] =
        "{\"image\": {\"width\": 12, \"height\": 12, \"spp\": 1, \"max_depth\": 4},"
        " \"camera\": {\"position\": [0, 0, -3], \"target\": [0, 0, 0], \"fov\": 60},"
        " \"environment\": {\"color\": [0.6, 0.8, 1.0], \"strength\": 1.5},"
        " \"materials\": {\"white\": {\"type\": \"lambert\", \"albedo\": [1, 1, 1]}},"
        " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"white\"}]}";
    fr_scene s;
    test_scene(json, &s);
    static const pt_strategy strategies[3] = {PT_MIS, PT_LIGHT_ONLY, PT_BSDF_ONLY};
    static const char *const names[3] = {"MIS", "light only", "BSDF only"};
    for (int k = 0; k < 3; k++) {
        estimate e = est_region(&s, strategies[k], 64, 4, 8, 4, 8); /* on the sphere */
        CHECK(fabs(e.mean - 1.2) < 4 * e.se + 1e-4, "furnace (%s): %.5f +- %.5f, expected 1.2", names[k], e.mean,
              e.se);
        CHECK(k != 0 || e.se < 0.01, "furnace (%s): noise %.4f", names[k], e.se);
    }
    /* The background is the environment itself, exactly. */
    vec3 bg = pt_sample(&s, PT_MIS, 0, 0, 0);
    CHECK(fabsf(bg.x - 0.9f) < 1e-6f && fabsf(bg.y - 1.2f) < 1e-6f && fabsf(bg.z - 1.5f) < 1e-6f, "background %g %g %g", (double)bg.x, (double)bg.y,
          (double)bg.z);
    scn_free(&s);
}

/* From inside a box of absorbing medium the environment is seen through
 * it: a narrow camera at the centre of a cube of side 2 looking at a face
 * sees L e^(-sigma_a) (the ray leaves through the face, distance 1). */
static void through_medium(void)
{
    static const char json[] =
        "{\"image\": {\"width\": 1, \"height\": 1, \"spp\": 1, \"max_depth\": 4},"
        " \"camera\": {\"position\": [0, 0, 0], \"target\": [0, 0, 1], \"fov\": 0.01},"
        " \"environment\": {\"color\": [0.5, 1.0, 2.0]},"
        " \"media\": {\"ink\": {\"sigma_a\": [0.5, 1.0, 2.0]}},"
        " \"materials\": {\"ink\": {\"type\": \"interface\", \"medium\": \"ink\"}},"
        " \"shapes\": [{\"type\": \"box\", \"min\": [-1, -1, -1], \"max\": [1, 1, 1], \"material\": \"ink\"}]}";
    fr_scene s;
    test_scene(json, &s);
    vec3 L = pt_sample(&s, PT_MIS, 0, 0, 0);
    double e[3] = {0.5 * exp(-0.5), 1.0 * exp(-1.0), 2.0 * exp(-2.0)};
    CHECK(fabs(L.x - e[0]) < 1e-4 && fabs(L.y - e[1]) < 1e-4 && fabs(L.z - e[2]) < 1e-4,
          "environment through an absorbing box: %g %g %g, expected %g %g %g", (double)L.x, (double)L.y, (double)L.z,
          e[0], e[1], e[2]);
    scn_free(&s);
}

/* Light-only, BSDF-only and MIS estimate the same image of a map-lit
 * scene with a glossy floor. */
static void mis_agree(void)
{
    fr_scene s;
    env_scene("bilinear", 60.0f,
              ", {\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"}",
              ", \"floor\": {\"type\": \"phong\", \"diffuse\": [0.3, 0.3, 0.3], \"glossy\": [0.5, 0.5, 0.5], "
              "\"exponent\": 40}", 12, 9, 3, &s);
    estimate mis = est_region(&s, PT_MIS, 256, 0, 12, 0, 9);
    estimate light = est_region(&s, PT_LIGHT_ONLY, 256, 0, 12, 0, 9);
    estimate bsdf = est_region(&s, PT_BSDF_ONLY, 1024, 0, 12, 0, 9);
    printf("env MIS %.5f +- %.5f, light only %.5f +- %.5f, BSDF only %.5f +- %.5f\n", mis.mean, mis.se, light.mean,
           light.se, bsdf.mean, bsdf.se);
    double d1 = fabs(mis.mean - light.mean), s1 = hypot(mis.se, light.se);
    double d2 = fabs(mis.mean - bsdf.mean), s2 = hypot(mis.se, bsdf.se);
    CHECK(d1 < 4 * s1, "env: MIS and light sampling differ by %.5f (%.1f sigma)", d1, d1 / s1);
    CHECK(d2 < 4 * s2, "env: MIS and BSDF sampling differ by %.5f (%.1f sigma)", d2, d2 / s2);
    CHECK(mis.se < bsdf.se, "env: MIS noise %.5f not below BSDF sampling's %.5f", mis.se, bsdf.se);
    scn_free(&s);
}

/* The documented orientation: a map black but for texel (i, j) = (8, 3) of
 * 16 x 8 (u in [0.5, 0.5625]: just past +x toward +z; v from the top in
 * [3/8, 1/2]: just above the horizon).  A camera at the origin looking
 * along +x (image right = +z, image up = +y) sees it up and to the right
 * of the centre, nowhere else; turned by 90 degrees the map puts it ahead
 * of a camera looking along +z. */
static void orientation(void)
{
    static float m[16 * 8 * 3];
    memset(m, 0, sizeof m);
    m[(3 * 16 + 8) * 3 + 0] = m[(3 * 16 + 8) * 3 + 1] = m[(3 * 16 + 8) * 3 + 2] = 5.0f;
    char path[256], file[256], json[2048];
    snprintf(path, sizeof path, "%s/dot.pfm", dir);
    snprintf(file, sizeof file, "%s/dot.json", dir);
    CHECK(pfm_write(path, 16, 8, m) == 0, "write %s", path);
    static const struct { float rot; const char *target, *up; } views[2] = {{0, "[1, 0, 0]", "[0, 1, 0]"},
                                                                            {90, "[0, 0, 1]", "[0, 1, 0]"}};
    for (int v = 0; v < 2; v++) {
        snprintf(json, sizeof json,
                 "{\"image\": {\"width\": 32, \"height\": 32, \"spp\": 1, \"max_depth\": 0},"
                 " \"camera\": {\"position\": [0, 0, 0], \"target\": %s, \"up\": %s, \"fov\": 60},"
                 " \"textures\": {\"dot\": {\"type\": \"image\", \"file\": \"dot.pfm\", \"filter\": \"nearest\"}},"
                 " \"environment\": {\"color\": \"dot\", \"rotation\": %g},"
                 " \"materials\": {\"m\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}},"
                 " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, -100, 0], \"radius\": 1, \"material\": \"m\"}]}",
                 views[v].target, views[v].up, (double)views[v].rot);
        fr_scene s;
        test_scene_with(json, file, &pfm_hooks, &s);
        /* The texel spans 0 to 22.5 degrees right and up of the view axis:
         * pixels 16..26 of 32 across (tan 22.5 / tan 30 = 0.72 of the half
         * width), rows 5..15 down from the top. */
        float up_right = pt_sample(&s, PT_MIS, 21, 10, 0).y, up_left = pt_sample(&s, PT_MIS, 10, 10, 0).y;
        float down_right = pt_sample(&s, PT_MIS, 21, 21, 0).y, down_left = pt_sample(&s, PT_MIS, 10, 21, 0).y;
        float far = pt_sample(&s, PT_MIS, 29, 2, 0).y;
        CHECK(up_right == 5.0f, "rotation %g: the bright texel is not up and right (%g)", (double)views[v].rot,
              (double)up_right);
        CHECK(up_left == 0.0f && down_right == 0.0f && down_left == 0.0f && far == 0.0f,
              "rotation %g: light elsewhere: %g %g %g %g", (double)views[v].rot, (double)up_left,
              (double)down_right, (double)down_left, (double)far);
        vec2 uv = env_uv(&s, v3_norm(v3(1, 0.2f, 0.1f)));
        if (v == 0)
            CHECK(uv.u > 0.5f && uv.u < 0.5625f && uv.v > 0.5f && uv.v < 0.625f, "env_uv %g %g", (double)uv.u,
                  (double)uv.v);
        scn_free(&s);
    }
    /* The landmarks of the convention, without rotation. */
    fr_scene s;
    env_scene("nearest", 0, "", "", 8, 8, 2, &s);
    static const struct { vec3 d; float u, v; } marks[] = {
        {{-1, 0, 0}, 0.0f, 0.5f}, {{0, 0, -1}, 0.25f, 0.5f}, {{1, 0, 0}, 0.5f, 0.5f},
        {{0, 0, 1}, 0.75f, 0.5f}, {{0, 1, 0}, 0.5f, 1.0f}, {{0, -1, 0}, 0.5f, 0.0f}};
    for (size_t k = 0; k < sizeof marks / sizeof marks[0]; k++) {
        vec2 uv = env_uv(&s, marks[k].d);
        float du = fabsf(uv.u - marks[k].u);
        du = fminf(du, 1.0f - du);
        CHECK(du < 1e-6f && fabsf(uv.v - marks[k].v) < 1e-6f, "direction %g %g %g: uv %g %g, expected %g %g",
              (double)marks[k].d.x, (double)marks[k].d.y, (double)marks[k].d.z, (double)uv.u, (double)uv.v,
              (double)marks[k].u, (double)marks[k].v);
    }
    scn_free(&s);
}

int main(void)
{
    if (!mkdtemp(dir)) {
        printf("FAIL mkdtemp\n");
        return 1;
    }
    char path[256];
    snprintf(path, sizeof path, "%s/sky.pfm", dir);
    make_map();
    CHECK(pfm_write(path, W, H, map) == 0, "write %s", path);
    chi_square("nearest", 0.0f);
    chi_square("bilinear", 37.0f);
    pdf_follows_radiance("nearest");
    pdf_follows_radiance("bilinear");
    furnace();
    through_medium();
    mis_agree();
    orientation();
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        printf("(could not remove %s)\n", dir);
    return check_done();
}
