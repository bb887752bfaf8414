/* test_passes.c -- render passes: the light passes sum to the beauty, the
 * albedo and normal passes of the Cornell box are its walls' colours and
 * normals, depth and position agree, the beauty keeps its bits, any split
 * of rows gives the same passes, and partial images carry them checked.
 *
 * The sum: emission and the six diffuse/glossy/transmission direct and
 * indirect passes split every sample's light, so their sum is the beauty
 * within float rounding, on scenes with diffuse, Phong, mirror, glass,
 * conductors, emitters and fog. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "compile/json_scene.h"
#include "image.h"
#include "passes.h"
#include "pathtrace.h"
#include "scenes.h"

#define W 40
#define H 30
#define SPP 16

/* Offsets of the passes' channels with every pass on (passes.h order). */
enum {
    C_ALBEDO = 0, C_NORMAL = 3, C_DEPTH = 6, C_POSITION = 7, C_EMISSION = 10, C_LIGHT = 13, C_MATERIAL = 31,
    C_CRYPTO = 32, C_VARIANCE = 44, C_OBJECT = 47, C_CRYPTO_OBJECT = 48, C_GROUPS = 60, C_SHADOW = 84, C_ALL = 87
};

static int load(const char *path, fr_scene *s)
{
    fr_error err;
    if (json_scene_load(path, NULL, s, &err) < 0) {
        printf("FAIL %s: %s\n", path, err.msg);
        return -1;
    }
    s->settings.width = W;
    s->settings.height = H;
    s->settings.spp = SPP;
    return 0;
}

/* The passes' sum against the beauty; which of the light passes got
 * light goes to *seen (bit k for pass PASS_EMISSION + k). */
static void check_sum(const char *name, const float *rgb, const float *pass, unsigned *seen)
{
    double worst = 0;
    int bad = 0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        const float *p = pass + i * C_ALL;
        for (int c = 0; c < 3; c++) {
            double sum = 0;
            for (int k = 0; k < 7; k++) {
                sum += p[C_EMISSION + 3 * k + c];
                if (p[C_EMISSION + 3 * k + c] > 0)
                    *seen |= 1u << k;
                bad += !(p[C_EMISSION + 3 * k + c] >= 0);
            }
            double b = rgb[i * 3 + c], e = fabs(sum - b) / (b > 1e-3 ? b : 1e-3);
            worst = e > worst ? e : worst;
        }
    }
    CHECK(worst < 1e-5, "%s: the light passes sum to the beauty within %g (relative), want < 1e-5", name, worst);
    CHECK(bad == 0, "%s: %d negative light pass values", name, bad);
    /* The light groups too. */
    worst = 0;
    for (size_t i = 0; i < (size_t)W * H; i++)
        for (int c = 0; c < 3; c++) {
            double sum = 0;
            for (int g = 0; g < PASS_LIGHT_GROUPS; g++)
                sum += pass[i * C_ALL + C_GROUPS + 3 * g + c];
            double b = rgb[i * 3 + c], e = fabs(sum - b) / (b > 1e-3 ? b : 1e-3);
            worst = e > worst ? e : worst;
        }
    CHECK(worst < 1e-5, "%s: the light groups sum to the beauty within %g (relative), want < 1e-5", name, worst);
}

/* Every pass of scene s: the beauty's bits, the sum, split invariance;
 * the light per group into group[PASS_LIGHT_GROUPS] (the sum of the
 * pixels' channels) when group is not NULL. */
static void check_passes(const char *path, fr_scene *s, unsigned want_seen, double *group);

static void check_scene(const char *path, unsigned want_seen)
{
    fr_scene s;
    if (load(path, &s) < 0) {
        CHECK(0, "%s loads", path);
        return;
    }
    check_passes(path, &s, want_seen, NULL);
    scn_free(&s);
}

/* Light groups: lights, an emissive material and the environment in
 * groups of their own, a light left in "default"; each group gets light
 * and the groups past the scene's none (the sum: check_sum). */
static void check_groups(void)
{
    static const char json[] =
        "{\"image\": {\"width\": 40, \"height\": 30, \"spp\": 16, \"max_depth\": 4},"
        " \"camera\": {\"position\": [0, 1, -6], \"target\": [0, 1, 0], \"fov\": 45},"
        " \"materials\": {\"wall\": {\"type\": \"lambert\", \"albedo\": [0.7, 0.7, 0.7]},"
        "  \"shiny\": {\"type\": \"phong\", \"diffuse\": [0.3, 0.3, 0.3], \"glossy\": [0.5, 0.5, 0.5],"
        "   \"exponent\": 40},"
        "  \"glass\": {\"type\": \"glass\", \"ior\": 1.5},"
        "  \"lamp\": {\"type\": \"emitter\", \"emission\": [4, 4, 4], \"light_group\": \"panel\"}},"
        " \"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"wall\"},"
        "  {\"type\": \"sphere\", \"center\": [-1, 1, 0], \"radius\": 1, \"material\": \"shiny\"},"
        "  {\"type\": \"sphere\", \"center\": [1.2, 0.8, -0.5], \"radius\": 0.8, \"material\": \"glass\"},"
        "  {\"type\": \"rect\", \"origin\": [-1, 3, -1], \"edge_u\": [2, 0, 0], \"edge_v\": [0, 0, 2],"
        "   \"material\": \"lamp\"}],"
        " \"lights\": [{\"type\": \"point\", \"position\": [2, 3, -2], \"intensity\": [5, 5, 5],"
        "   \"light_group\": \"key\"},"
        "  {\"type\": \"point\", \"position\": [-3, 2, -2], \"intensity\": [2, 2, 2]}],"
        " \"environment\": {\"color\": [0.1, 0.1, 0.15], \"light_group\": \"sky\"}}";
    fr_scene s;
    test_scene(json, &s);
    CHECK(s.n_group_names == 4 && !strcmp(s.group_names[0].name, "default") && s.n_light_groups == s.n_lights,
          "groups: default and three named (%u), one per light (%u of %u)", s.n_group_names, s.n_light_groups,
          s.n_lights);
    double group[PASS_LIGHT_GROUPS] = {0};
    check_passes("(groups)", &s, 1u << 1 | 1u << 3, group);
    int lit = 0, dark = 1;
    for (uint32_t g = 0; g < PASS_LIGHT_GROUPS; g++)
        if (g < s.n_group_names)
            lit += group[g] > 0.0;
        else
            dark &= group[g] == 0.0;
    CHECK(lit == 4 && dark, "every group of the scene has light (%d of 4), the others none", lit);
    scn_free(&s);
    /* A ninth group is refused, naming it. */
    char many[2048];
    int k = snprintf(many, sizeof many, "{\"image\": {\"width\": 4, \"height\": 4},"
                     " \"camera\": {\"position\": [0, 0, -5], \"target\": [0, 0, 0], \"fov\": 50},"
                     " \"materials\": {\"m\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}},"
                     " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"m\"}],"
                     " \"lights\": [");
    for (int i = 0; i < PASS_LIGHT_GROUPS; i++)
        k += snprintf(many + k, sizeof many - (size_t)k, "%s{\"type\": \"point\", \"position\": [0, 3, 0],"
                      " \"intensity\": [1, 1, 1], \"light_group\": \"g%d\"}", i ? ", " : "", i);
    snprintf(many + k, sizeof many - (size_t)k, "]}");
    const char *msg;
    CHECK(test_scene_refused(many, "lights[7].light_group", &msg), "a ninth light group is refused: %s", msg);
}

static void check_passes(const char *path, fr_scene *sp, unsigned want_seen, double *group)
{
    fr_scene s = *sp;
    size_t n = (size_t)W * H;
    float *plain = malloc(n * 3 * sizeof *plain), *rgb = malloc(n * 3 * sizeof *rgb);
    float *pass = malloc(n * C_ALL * sizeof *pass), *split = malloc(n * C_ALL * sizeof *split);
    float *rgb2 = malloc(n * 3 * sizeof *rgb2);
    pt_render_rows(&s, PT_MIS, 0, H, plain);
    pt_render_rows_passes(&s, PT_MIS, 0, H, rgb, PASS_ALL, pass);
    CHECK(!memcmp(plain, rgb, n * 3 * sizeof *rgb), "%s: the beauty has the same bits with passes", path);
    /* Rows in slabs of 7 give the same bits. */
    for (uint32_t y = 0; y < H; y += 7) {
        uint32_t y1 = y + 7 < H ? y + 7 : H;
        pt_render_rows_passes(&s, PT_MIS, y, y1, rgb2 + (size_t)y * W * 3, PASS_ALL, split + (size_t)y * W * C_ALL);
    }
    CHECK(!memcmp(pass, split, n * C_ALL * sizeof *pass), "%s: passes of slabs of 7 rows have the bits of one slab",
          path);
    /* A subset of the passes: the same values at their places. */
    float *sub = malloc(n * 4 * sizeof *sub);
    pt_render_rows_passes(&s, PT_MIS, 0, H, rgb2, 1u << PASS_ALBEDO | 1u << PASS_DEPTH, sub);
    int same = 1;
    for (size_t i = 0; i < n; i++)
        same &= !memcmp(sub + i * 4, pass + i * C_ALL, 3 * sizeof *sub) && sub[i * 4 + 3] == pass[i * C_ALL + C_DEPTH];
    CHECK(same, "%s: albedo and depth alone are the values of all the passes", path);
    unsigned seen = 0;
    check_sum(path, rgb, pass, &seen);
    CHECK((seen & want_seen) == want_seen, "%s: light passes with light %#x, want at least %#x", path, seen,
          want_seen);
    int finite = 1;
    for (size_t i = 0; i < n * C_ALL; i++)
        finite &= isfinite(pass[i]);
    CHECK(finite, "%s: every pass value is finite", path);
    for (size_t i = 0; group && i < n; i++)
        for (int k = 0; k < 3 * PASS_LIGHT_GROUPS; k++)
            group[k / 3] += pass[i * C_ALL + C_GROUPS + k];
    free(sub);
    free(plain);
    free(rgb);
    free(rgb2);
    free(pass);
    free(split);
}

/* The Cornell box: pixels whose 3x3 neighbourhood sees one material (by
 * the material_id pass) have that material's albedo, a unit normal facing
 * the camera (the red wall's is -x, the green's +x, the floor's +y), and a
 * depth that is the distance to their position. */
static void check_cornell(void)
{
    fr_scene s;
    if (load("scenes/cornell.json", &s) < 0) {
        CHECK(0, "cornell loads");
        return;
    }
    size_t n = (size_t)W * H;
    float *rgb = malloc(n * 3 * sizeof *rgb), *pass = malloc(n * C_ALL * sizeof *pass);
    pt_render_rows_passes(&s, PT_MIS, 0, H, rgb, PASS_ALL, pass);
    int interior = 0, albedo_bad = 0, unit_bad = 0, facing_bad = 0, depth_bad = 0, red = 0, red_bad = 0, green = 0,
        green_bad = 0;
    vec3 cam = s.camera.position;
    for (int y = 1; y < H - 1; y++)
        for (int x = 1; x < W - 1; x++) {
            const float *p = pass + ((size_t)y * W + x) * C_ALL;
            float id = p[C_MATERIAL];
            int one = id > 0;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++)
                    one &= pass[((size_t)(y + dy) * W + x + dx) * C_ALL + C_MATERIAL] == id;
            if (!one)
                continue;
            const fr_material *m = &s.materials[(uint32_t)id - 1];
            if (!v3_is_zero(m->emission))
                continue;
            interior++;
            albedo_bad += fabsf(p[C_ALBEDO] - m->diffuse.x) > 1e-6f || fabsf(p[C_ALBEDO + 1] - m->diffuse.y) > 1e-6f ||
                          fabsf(p[C_ALBEDO + 2] - m->diffuse.z) > 1e-6f;
            vec3 nrm = v3(p[C_NORMAL], p[C_NORMAL + 1], p[C_NORMAL + 2]);
            vec3 pos = v3(p[C_POSITION], p[C_POSITION + 1], p[C_POSITION + 2]);
            facing_bad += !(v3_dot(nrm, v3_sub(cam, pos)) > 0.0f);
            depth_bad += fabsf(p[C_DEPTH] - v3_len(v3_sub(pos, cam))) > 1e-4f * p[C_DEPTH];
            /* The coloured walls are one quad each: every sample of such
             * a pixel has the wall's normal (the white surfaces are many,
             * and a pixel on a box's edge averages two normals). */
            if (m->diffuse.x > 0.6f && m->diffuse.y < 0.1f) {
                red++;
                red_bad += fabsf(nrm.x + 1.0f) > 1e-5f;
            }
            if (m->diffuse.y > 0.4f && m->diffuse.x < 0.2f) {
                green++;
                green_bad += fabsf(nrm.x - 1.0f) > 1e-5f;
            }
            if (m->diffuse.y < 0.1f || m->diffuse.x < 0.2f)
                unit_bad += fabsf(v3_len(nrm) - 1.0f) > 1e-5f;
        }
    CHECK(interior > (W - 2) * (H - 2) / 3, "cornell: %d pixels inside one material, want a third at least", interior);
    CHECK(albedo_bad == 0, "cornell: %d pixels whose albedo is not their wall's", albedo_bad);
    CHECK(unit_bad == 0, "cornell: %d pixels whose normal is not unit", unit_bad);
    CHECK(facing_bad == 0, "cornell: %d pixels whose normal faces away from the camera", facing_bad);
    CHECK(depth_bad == 0, "cornell: %d pixels whose depth is not the distance to their position", depth_bad);
    CHECK(red > 20 && red_bad == 0, "cornell: %d red wall pixels, %d not with normal -x", red, red_bad);
    CHECK(green > 20 && green_bad == 0, "cornell: %d green wall pixels, %d not with normal +x", green, green_bad);
    /* The variance of each pixel's mean, from its samples as pt_sample
     * gives them, on a few pixels; and never negative anywhere. */
    int var_bad = 0, var_neg = 0, var_pos = 0;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            float v = pass[i * C_ALL + C_VARIANCE + c];
            var_neg += !(v >= 0.0f);
            var_pos += v > 0.0f;
        }
    for (uint32_t y = 3; y < H; y += 7)
        for (uint32_t x = 2; x < W; x += 9) {
            double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
            for (uint32_t k = 0; k < SPP; k++) {
                vec3 l = pt_sample(&s, PT_MIS, x, y, k);
                for (int c = 0; c < 3; c++) {
                    double v = v3_get(l, c);
                    sum[c] += v;
                    sum2[c] += v * v;
                }
            }
            for (int c = 0; c < 3; c++) {
                double want = (sum2[c] - sum[c] * sum[c] / SPP) / (SPP - 1) / SPP;
                float got = pass[((size_t)y * W + x) * C_ALL + C_VARIANCE + c];
                var_bad += fabs(got - want) > 1e-6 * want + 1e-12;
            }
        }
    CHECK(var_bad == 0, "cornell: %d variance values differ from their samples' variance of the mean", var_bad);
    CHECK(var_neg == 0 && var_pos > (int)n, "cornell: %d negative variances, %d positive", var_neg, var_pos);
    free(rgb);
    free(pass);
    scn_free(&s);
}

/* Partials carry the passes: written, read back to the bits; a damaged
 * block or a non-finite value is refused. */
static void check_partial(void)
{
    uint32_t mask = 1u << PASS_NORMAL | 1u << PASS_MATERIAL_ID, nch = pass_channels(mask);
    CHECK(nch == 4, "normal and material_id: 4 channels, got %u", nch);
    enum { PW = 5, PH = 3 };
    float rgb[PW * PH * 3], pass[PW * PH * 4], back[PW * PH * 4];
    for (int i = 0; i < PW * PH * 3; i++)
        rgb[i] = (float)i / 7.0f;
    for (int i = 0; i < PW * PH * 4; i++)
        pass[i] = (float)(i % 5) - 2.5f;
    img_partial_info info = {0xfeedull, 2, 2 + PH, 4, PW, 9, 0, 0, 0, 0, mask, 0};
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    fr_error err;
    CHECK(img_write_passes(f, &info, rgb, pass, &err) == 0, "img_write_passes: %s", err.msg);
    fclose(f);
    img_partial_info got;
    float *px = NULL;
    int rc = img_read_partial((unsigned char *)buf, len, &got, &px, &err);
    CHECK(rc == 0, "a partial with passes reads back: %s", err.msg);
    if (rc == 0) {
        img_passes_get((unsigned char *)buf, &got, back);
        CHECK(got.passes == mask && !memcmp(back, pass, sizeof pass) && !memcmp(px, rgb, sizeof rgb),
              "the passes and pixels come back to the bit");
    }
    free(px);
    px = NULL;
    buf[len - 3] ^= 1;
    CHECK(img_read_partial((unsigned char *)buf, len, &got, &px, &err) < 0 && strstr(err.msg, "hash"),
          "a damaged passes block is refused by its hash: %s", err.msg);
    free(px);
    free(buf);
    pass[7] = NAN;
    buf = NULL;
    f = open_memstream(&buf, &len);
    img_write_passes(f, &info, rgb, pass, &err);
    fclose(f);
    px = NULL;
    CHECK(img_read_partial((unsigned char *)buf, len, &got, &px, &err) < 0 && strstr(err.msg, "not finite"),
          "a NaN in the passes is refused: %s", err.msg);
    free(px);
    free(buf);
}

/* The shadow pass under a point light and a sphere over a floor: floor
 * points whose way to the light the sphere clearly blocks are 0, those it
 * clearly leaves free 1. */
static void check_shadow(void)
{
    static const char json[] =
        "{\"image\": {\"width\": 40, \"height\": 30, \"spp\": 4, \"max_depth\": 2},"
        " \"camera\": {\"position\": [0, 6, -8], \"target\": [0, 0, 0], \"fov\": 50},"
        " \"materials\": {\"floor\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]},"
        "  \"ball\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}},"
        " \"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"},"
        "  {\"type\": \"sphere\", \"center\": [0, 2, 0], \"radius\": 1, \"material\": \"ball\"}],"
        " \"lights\": [{\"type\": \"point\", \"position\": [0.5, 5, 0.5], \"intensity\": [20, 20, 20]}]}";
    fr_scene s;
    test_scene(json, &s);
    uint32_t mask = 1u << PASS_POSITION | 1u << PASS_MATERIAL_ID | 1u << PASS_SHADOW, nch = pass_channels(mask);
    size_t n = (size_t)W * H;
    float *rgb = malloc(n * 3 * sizeof *rgb), *pass = malloc(n * nch * sizeof *pass);
    pt_render_rows_passes(&s, PT_MIS, 0, H, rgb, mask, pass);
    vec3 light = v3(0.5f, 5.0f, 0.5f), centre = v3(0.0f, 2.0f, 0.0f);
    int dark = 0, dark_bad = 0, lit = 0, lit_bad = 0, range_bad = 0;
    for (size_t i = 0; i < n; i++) {
        const float *p = pass + i * nch; /* position, material_id, shadow */
        for (int c = 0; c < 3; c++)
            range_bad += !(p[4 + c] >= 0.0f && p[4 + c] <= 1.0f);
        /* The floor, away from the ball's outline (its samples are the floor's). */
        int x = (int)(i % W), y = (int)(i / W), floor = x > 0 && y > 0 && x < W - 1 && y < H - 1;
        for (int dy = -1; dy <= 1 && floor; dy++)
            for (int dx = -1; dx <= 1; dx++)
                floor &= pass[((size_t)(y + dy) * W + (size_t)(x + dx)) * nch + 3] == 1.0f;
        if (!floor)
            continue;
        vec3 at = v3(p[0], p[1], p[2]), seg = v3_sub(light, at);
        float t = v3_dot(v3_sub(centre, at), seg) / v3_dot(seg, seg);
        t = t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
        float d = v3_len(v3_sub(v3_add(at, v3_scale(seg, t)), centre));
        if (d < 0.8f) {
            dark++;
            dark_bad += p[4] != 0.0f || p[5] != 0.0f || p[6] != 0.0f;
        } else if (d > 1.3f) {
            lit++;
            lit_bad += p[4] != 1.0f || p[5] != 1.0f || p[6] != 1.0f;
        }
    }
    CHECK(range_bad == 0, "shadow: %d values outside [0, 1]", range_bad);
    CHECK(dark > 10 && dark_bad == 0, "shadow: %d of %d floor pixels behind the ball are not 0", dark_bad, dark);
    CHECK(lit > 100 && lit_bad == 0, "shadow: %d of %d floor pixels in the open are not 1", lit_bad, lit);
    free(rgb);
    free(pass);
    scn_free(&s);
}

static void check_names(void)
{
    uint32_t m = 0;
    fr_error err;
    CHECK(pass_parse("albedo,normal", &m, &err) == 0 && m == (1u << PASS_ALBEDO | 1u << PASS_NORMAL),
          "albedo,normal parses");
    CHECK(pass_parse("all", &m, &err) == 0 && m == PASS_ALL && pass_channels(m) == C_ALL, "all: every pass, %d channels", C_ALL);
    CHECK(pass_parse("none", &m, &err) == 0 && m == 0, "none parses to no pass");
    CHECK(pass_parse("albedo,nromal", &m, &err) < 0 && strstr(err.msg, "nromal"), "a misspelt pass is named: %s",
          err.msg);
    char text[400];
    pass_format(PASS_ALL, text, sizeof text);
    uint32_t back = 0;
    CHECK(pass_parse(text, &back, &err) == 0 && back == PASS_ALL, "pass_format reads back: %s", text);
}

int main(void)
{
    check_names();
    check_partial();
    check_cornell();
    /* Light each scene must put in: emission (bit 0), diffuse direct (1)
     * and indirect (2), glossy direct (3) and indirect (4), transmission
     * direct (5) and indirect (6). */
    check_scene("scenes/spheres.json", 0x7f & ~(1u << 5));
    check_scene("scenes/metals.json", 1u << 3 | 1u << 4);
    check_scene("scenes/fog-room.json", 1u << 1);
    check_groups();
    check_shadow();
    return check_done();
}
