/* test_bdpt.c -- bidirectional path tracing agrees with path tracing.
 *
 * Bidirectional path tracing estimates the same images as path tracing.
 *
 * - On the Cornell box and the spheres scene (mirror, glass), block by
 *   block, BDPT's means agree with path tracing's within their noise.
 * - Each strategy (s, t) alone, with weight 1, estimates the same image of
 *   the paths of its depth as all strategies combined with MIS.
 * - Rough materials (GGX conductor, rough glass, principled): all
 *   strategies, alone and with MIS, agree with path tracing.
 * - Light tracing carries importance: through refraction into glass and
 *   over bump-mapped shading normals (Veach's adjoint corrections), BDPT
 *   still agrees with path tracing.
 * - A white furnace gives Le / (1 - rho) everywhere.
 * - A glass ball focusing a point light onto a floor: a caustic only light
 *   tracing can render; its power and centroid against the test's own ray
 *   tracing of the ball in double precision.  Under a small round lamp,
 *   light tracing and the camera path hitting the lamp through the ball
 *   agree, MIS agrees with both and is about as good as light tracing.
 * - An unbounded plane under the sky and a sun: BDPT agrees with path
 *   tracing out to the horizon, beyond the disk that light paths start on.
 * - Scenes with media are refused, with a message.
 *
 * Standard errors come from each pixel's spread of sample values, and for
 * light tracing from each pixel sample's whole contribution (its own pixel
 * plus every splat it makes) to a block, so they cover splats too.  They
 * overestimate the error of stratified samples: the checks are
 * conservative. */
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "bdpt.h"
#include "bsdf.h"
#include "camera.h"
#include "check.h"
#include "pathtrace.h"
#include "scenes.h"
#include "splat.h"

#define MAXB 16
typedef struct {
    int k;                     /* k x k blocks */
    double mean[MAXB * MAXB][3], se[MAXB * MAXB][3];
} blocks;

static int block_of(const fr_scene *s, int k, uint32_t x, uint32_t y)
{
    return (int)(y * (uint32_t)k / s->settings.height) * k + (int)(x * (uint32_t)k / s->settings.width);
}

/* Accumulation of one pixel's samples into block sums. */
typedef struct {
    const fr_scene *s;
    int k;
    double x[MAXB * MAXB][3];  /* the current sample's contribution per block */
    double s1[MAXB * MAXB][3], s2[MAXB * MAXB][3];
    double sum[MAXB * MAXB][3], var[MAXB * MAXB][3];
} acc;

static void add_splat(void *ctx, uint32_t x, uint32_t y, float r, float g, float b)
{
    acc *a = ctx;
    int bl = block_of(a->s, a->k, x, y);
    a->x[bl][0] += r; a->x[bl][1] += g; a->x[bl][2] += b;
}

static void finish(const fr_scene *s, acc *a, uint32_t spp, blocks *out)
{
    int nb = a->k * a->k;
    double npix[MAXB * MAXB] = {0};
    for (uint32_t y = 0; y < s->settings.height; y++)
        for (uint32_t x = 0; x < s->settings.width; x++)
            npix[block_of(s, a->k, x, y)] += 1;
    out->k = a->k;
    for (int b = 0; b < nb; b++)
        for (int c = 0; c < 3; c++) {
            out->mean[b][c] = a->sum[b][c] / (spp * npix[b]);
            out->se[b][c] = sqrt(a->var[b][c]) / (spp * npix[b]);
        }
}

/* Per-block means and standard errors of path tracing or (pt == NULL) of
 * bidirectional path tracing with strategy st. */
static void render(const fr_scene *s, const bd_strategy *st, uint32_t spp, int k, blocks *out)
{
    acc *a = calloc(1, sizeof *a);
    a->s = s;
    a->k = k;
    int nb = k * k;
    bd_work *w = st ? bd_work_new(s) : NULL;
    for (uint32_t y = 0; y < s->settings.height; y++)
        for (uint32_t x = 0; x < s->settings.width; x++) {
            memset(a->s1, 0, sizeof a->s1);
            memset(a->s2, 0, sizeof a->s2);
            int own = block_of(s, k, x, y);
            for (uint32_t i = 0; i < spp; i++) {
                memset(a->x, 0, sizeof a->x);
                vec3 c = st ? bd_sample(s, w, st, x, y, i, add_splat, a) : pt_sample(s, PT_MIS, x, y, i);
                a->x[own][0] += c.x; a->x[own][1] += c.y; a->x[own][2] += c.z;
                for (int b = 0; b < nb; b++)
                    for (int ch = 0; ch < 3; ch++) {
                        a->s1[b][ch] += a->x[b][ch];
                        a->s2[b][ch] += a->x[b][ch] * a->x[b][ch];
                    }
            }
            for (int b = 0; b < nb; b++)
                for (int ch = 0; ch < 3; ch++) {
                    double m = a->s1[b][ch] / spp;
                    a->sum[b][ch] += a->s1[b][ch];
                    a->var[b][ch] += (a->s2[b][ch] / spp - m * m) * spp;
                }
        }
    finish(s, a, spp, out);
    bd_work_free(w);
    free(a);
}

/* Every block and channel of a and b within z_max standard errors of each
 * other; returns the largest z. */
static double agree(const char *what, const blocks *a, const blocks *b, double z_max)
{
    double worst = 0;
    int bad = 0;
    for (int bl = 0; bl < a->k * a->k; bl++)
        for (int c = 0; c < 3; c++) {
            double d = fabs(a->mean[bl][c] - b->mean[bl][c]);
            double se = sqrt(a->se[bl][c] * a->se[bl][c] + b->se[bl][c] * b->se[bl][c]);
            double z = se > 0 ? d / se : (d > 1e-9 ? INFINITY : 0);
            if (z > worst)
                worst = z;
            if (z >= z_max && bad++ < 4)
                printf("  %s: block %d channel %d: %.5f vs %.5f (%.1f standard errors)\n", what, bl, c,
                       a->mean[bl][c], b->mean[bl][c], z);
        }
    printf("%s: largest difference %.2f standard errors over %d blocks\n", what, worst, a->k * a->k);
    CHECK(!bad, "%s: %d block means differ by %.1f or more standard errors", what, bad, z_max);
    return worst;
}

/* The median over blocks of the relative standard error (green), so a
 * test can check that it can see a difference of a few percent. */
static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median_rel_se(const blocks *b)
{
    double r[MAXB * MAXB];
    int nb = b->k * b->k;
    for (int i = 0; i < nb; i++)
        r[i] = b->mean[i][1] > 0 ? b->se[i][1] / b->mean[i][1] : INFINITY;
    qsort(r, (size_t)nb, sizeof r[0], cmp_double);
    return r[nb / 2];
}

static void load_file(const char *path, uint32_t w, uint32_t h, fr_scene *s)
{
    fr_error err;
    if (json_scene_load(path, NULL, s, &err) < 0) {
        printf("FAIL %s\n", err.msg);
        exit(1);
    }
    s->settings.width = w;
    s->settings.height = h;
}

static const bd_strategy all = {-1, -1, -1};

/* BDPT and path tracing on the example scenes, 4x4 blocks. */
static void against_path_tracing(const char *path, uint32_t pt_spp, uint32_t bd_spp)
{
    fr_scene s;
    load_file(path, 16, 16, &s);
    blocks pt, bd;
    render(&s, NULL, pt_spp, 4, &pt);
    render(&s, &all, bd_spp, 4, &bd);
    agree(path, &bd, &pt, 4.5);
    CHECK(median_rel_se(&bd) < 0.015 && median_rel_se(&pt) < 0.015, "%s: too noisy to tell (%.3f, %.3f)", path,
          median_rel_se(&bd), median_rel_se(&pt));
    scn_free(&s);
}

/* An open scene without concave corners (where joining two subpath
 * vertices that are close has unbounded variance): a glossy floor, a
 * Lambert ball above it, a wall behind, a rectangle and a ball of light.
 * Every strategy reaches all of its light: pinhole, no delta lobe. */
static const char open_scene[] =
    "{\"image\": {\"width\": 12, \"height\": 10, \"spp\": 1, \"max_depth\": 8},"
    " \"camera\": {\"position\": [0, 1.5, -4], \"target\": [0, 0.6, 1], \"fov\": 40},"
    " \"materials\": {"
    "   \"floor\": {\"type\": \"phong\", \"diffuse\": [0.4, 0.35, 0.3], \"glossy\": [0.3, 0.3, 0.3], \"exponent\": 8},"
    "   \"ball\": {\"type\": \"lambert\", \"albedo\": [0.7, 0.6, 0.5]},"
    "   \"wall\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.6, 0.7]},"
    "   \"panel\": {\"type\": \"emitter\", \"emission\": [3, 3, 3]},"
    "   \"bulb\": {\"type\": \"emitter\", \"emission\": [20, 16, 12]}},"
    " \"shapes\": ["
    "   {\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"},"
    "   {\"type\": \"sphere\", \"center\": [0.3, 0.9, 0.5], \"radius\": 0.6, \"material\": \"ball\"},"
    "   {\"type\": \"rect\", \"origin\": [-3, 0.4, 3], \"edge_u\": [6, 0, 0], \"edge_v\": [0, 3, 0], \"material\": \"wall\"},"
    "   {\"type\": \"rect\", \"origin\": [-1.5, 3, -1], \"edge_u\": [1.5, 0, 0], \"edge_v\": [0, 0, 1], \"material\": \"panel\"},"
    "   {\"type\": \"sphere\", \"center\": [1.6, 1.8, -1], \"radius\": 0.15, \"material\": \"bulb\"}]}";

/* Each strategy of depth 1 and 2 alone against all of that depth. */
static void strategies(void)
{
    fr_scene s;
    test_scene(open_scene, &s);
    for (int depth = 1; depth <= 2; depth++) {
        bd_strategy mis = {-1, -1, depth};
        blocks ref;
        render(&s, &mis, 512, 2, &ref);
        for (int sv = 0; sv <= depth + 1; sv++) {
            int t = depth + 2 - sv;
            if (sv == 1 && t == 1)
                continue;
            bd_strategy one = {sv, t, -1};
            blocks b;
            /* Hitting the small lights by chance needs more samples. */
            render(&s, &one, sv == 0 ? 8192 : 1024, 2, &b);
            char name[64];
            snprintf(name, sizeof name, "strategy (%d,%d) alone vs MIS at depth %d", sv, t, depth);
            agree(name, &b, &ref, 4.5);
            CHECK(b.mean[0][1] + b.mean[3][1] > 1e-4, "%s: black", name);
        }
    }
    scn_free(&s);
}

/* Rough materials (microfacet models): the open scene with a rough gold
 * ball, a frosted glass ball (rough refraction is not symmetric: light
 * subpaths evaluate it as radiance flows) and a principled floor.  Every
 * strategy that can connect at a rough vertex does; each of depth 1 and 2
 * alone and all of them with MIS agree with path tracing's image. */
static const char rough_scene[] =
    "{\"image\": {\"width\": 12, \"height\": 10, \"spp\": 1, \"max_depth\": 8},"
    " \"camera\": {\"position\": [0, 1.5, -4], \"target\": [0, 0.6, 1], \"fov\": 40},"
    " \"materials\": {"
    "   \"floor\": {\"type\": \"principled\", \"base_color\": [0.6, 0.5, 0.4], \"metallic\": 0, \"roughness\": 0.5},"
    "   \"gold\": {\"type\": \"conductor\", \"roughness\": 0.35, \"reflectance\": [1.0, 0.78, 0.34]},"
    "   \"frosted\": {\"type\": \"glass\", \"roughness\": 0.4, \"ior\": 1.5},"
    "   \"wall\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.6, 0.7]},"
    "   \"panel\": {\"type\": \"emitter\", \"emission\": [3, 3, 3]},"
    "   \"bulb\": {\"type\": \"emitter\", \"emission\": [20, 16, 12]}},"
    " \"shapes\": ["
    "   {\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"},"
    "   {\"type\": \"sphere\", \"center\": [-0.7, 0.6, 0.5], \"radius\": 0.6, \"material\": \"gold\"},"
    "   {\"type\": \"sphere\", \"center\": [0.8, 0.6, 0.3], \"radius\": 0.6, \"material\": \"frosted\"},"
    "   {\"type\": \"rect\", \"origin\": [-3, 0.4, 3], \"edge_u\": [6, 0, 0], \"edge_v\": [0, 3, 0], \"material\": \"wall\"},"
    "   {\"type\": \"rect\", \"origin\": [-1.5, 3, -1], \"edge_u\": [1.5, 0, 0], \"edge_v\": [0, 0, 1], \"material\": \"panel\"},"
    "   {\"type\": \"sphere\", \"center\": [1.6, 1.8, -1], \"radius\": 0.15, \"material\": \"bulb\"}]}";

static void rough(void)
{
    fr_scene s;
    test_scene(rough_scene, &s);
    int micro = 0;
    for (uint32_t i = 0; i < s.n_materials; i++)
        micro += s.materials[i].model != FR_MAT_LOBES && bsdf_has_smooth(&s.materials[i]);
    CHECK(micro == 3, "rough: %d microfacet materials that connections may end on, expected 3", micro);
    blocks pt, bd;
    render(&s, NULL, 4096, 2, &pt);
    render(&s, &all, 1024, 2, &bd);
    agree("rough materials: BDPT vs path tracing", &bd, &pt, 4.5);
    CHECK(bd.mean[0][1] + bd.mean[3][1] > 1e-3, "rough: black");
    for (int depth = 1; depth <= 2; depth++) {
        bd_strategy mis = {-1, -1, depth};
        blocks ref;
        render(&s, &mis, 512, 2, &ref);
        for (int sv = 0; sv <= depth + 1; sv++) {
            int t = depth + 2 - sv;
            if (sv == 1 && t == 1)
                continue;
            bd_strategy one = {sv, t, -1};
            blocks b;
            /* Joining a light point to a camera path through the frosted
             * ball, (1,3) alone has a heavy tail: at 1024 samples its block
             * means fell 5 standard errors short with some seeds, and came
             * within 2 at 8192. */
            render(&s, &one, sv == 0 || (sv == 1 && depth == 2) ? 8192 : 1024, 2, &b);
            char name[80];
            snprintf(name, sizeof name, "rough: strategy (%d,%d) alone vs MIS at depth %d", sv, t, depth);
            agree(name, &b, &ref, 4.5);
        }
    }
    scn_free(&s);
}

/* Glass: the camera inside a box of glass (normals out), looking down at
 * a Lambert floor laid inside it; a lamp outside above.  The only paths
 * of depth 2 are camera - floor - glass (refraction) - lamp: the camera
 * path hits the lamp through the glass (0,4), or a light path refracts
 * into the glass, reaches the floor and is joined to the lens (3,1).
 * Radiance inside glass is n^2 times the lamp's, importance is not scaled
 * (Veach's adjoint for refraction): each alone must agree, and with all
 * the other strategies BDPT must agree with path tracing. */
static const char glass_box[] =
    "{\"image\": {\"width\": 12, \"height\": 12, \"spp\": 1, \"max_depth\": 6},"
    " \"camera\": {\"position\": [0, 1.0, -0.3], \"target\": [0, 0.05, 0.1], \"fov\": 40},"
    " \"materials\": {"
    "   \"glass\": {\"type\": \"glass\", \"ior\": 1.5},"
    "   \"white\": {\"type\": \"lambert\", \"albedo\": [0.7, 0.7, 0.7]},"
    "   \"lamp\": {\"type\": \"emitter\", \"emission\": [1, 1, 1]}},"
    " \"shapes\": ["
    "   {\"type\": \"rect\", \"origin\": [-1, 0, -1], \"edge_u\": [2, 0, 0], \"edge_v\": [0, 0, 2], \"material\": \"glass\"},"
    "   {\"type\": \"rect\", \"origin\": [-1, 1.4, -1], \"edge_u\": [0, 0, 2], \"edge_v\": [2, 0, 0], \"material\": \"glass\"},"
    "   {\"type\": \"rect\", \"origin\": [-1, 0, -1], \"edge_u\": [0, 1.4, 0], \"edge_v\": [2, 0, 0], \"material\": \"glass\"},"
    "   {\"type\": \"rect\", \"origin\": [-1, 0, 1], \"edge_u\": [2, 0, 0], \"edge_v\": [0, 1.4, 0], \"material\": \"glass\"},"
    "   {\"type\": \"rect\", \"origin\": [-1, 0, -1], \"edge_u\": [0, 0, 2], \"edge_v\": [0, 1.4, 0], \"material\": \"glass\"},"
    "   {\"type\": \"rect\", \"origin\": [1, 0, -1], \"edge_u\": [0, 1.4, 0], \"edge_v\": [0, 0, 2], \"material\": \"glass\"},"
    "   {\"type\": \"rect\", \"origin\": [-0.95, 0.05, -0.95], \"edge_u\": [0, 0, 1.9], \"edge_v\": [1.9, 0, 0], \"material\": \"white\"},"
    "   {\"type\": \"rect\", \"origin\": [-3, 3, -3], \"edge_u\": [6, 0, 0], \"edge_v\": [0, 0, 6], \"material\": \"lamp\"}]}";

/* The glass box, smooth (as above) or rough: each strategy that can
 * make the depth-2 paths (with rough glass, light sampling and joins at the
 * glass too) alone against the camera path hitting the lamp. */
static void glass_box_with(const char *json, const char *name, int rough)
{
    fr_scene s;
    test_scene(json, &s);
    blocks pt, bd, hit, mis;
    const bd_strategy camera_path = {0, 4, -1}, depth2 = {-1, -1, 2};
    render(&s, &camera_path, 4096, 2, &hit);
    char what[96];
    for (int sv = 1; sv <= 3; sv++) {
        if (!rough && sv != 3)
            continue;  /* smooth glass: only light tracing besides (0,4) */
        bd_strategy one = {sv, 4 - sv, -1};
        blocks b;
        render(&s, &one, 1024, 2, &b);
        snprintf(what, sizeof what, "%s: strategy (%d,%d) vs hitting the lamp (0,4)", name, sv, 4 - sv);
        agree(what, &b, &hit, 4.5);
    }
    render(&s, &depth2, 1024, 2, &mis);
    snprintf(what, sizeof what, "%s: MIS at depth 2 vs hitting the lamp (0,4)", name);
    agree(what, &mis, &hit, 4.5);
    CHECK(hit.mean[0][1] > 0.05, "%s: the floor is dark (%g)", name, hit.mean[0][1]);
    render(&s, NULL, 4096, 2, &pt);
    render(&s, &all, 1024, 2, &bd);
    snprintf(what, sizeof what, "%s: BDPT vs path tracing", name);
    agree(what, &bd, &pt, 4.5);
    scn_free(&s);
}

static void through_glass(void)
{
    glass_box_with(glass_box, "glass box", 0);
    /* Frosted: a rough dielectric (roughness 0.3). */
    static char frosted[sizeof glass_box + 64];
    const char *smooth = "\"type\": \"glass\", \"ior\": 1.5}";
    const char *at = strstr(glass_box, smooth);
    CHECK(at != NULL, "glass box: no glass material to roughen");
    if (!at)
        return;
    snprintf(frosted, sizeof frosted, "%.*s\"type\": \"glass\", \"ior\": 1.5, \"roughness\": 0.3}%s",
             (int)(at - glass_box), glass_box, at + strlen(smooth));
    glass_box_with(frosted, "frosted glass box", 1);
}

/* Shading normals: a bump-mapped floor (a synthetic egg-crate height map)
 * lit by a panel; light tracing's splats need the adjoint correction. */
static int bumps(const char *path, const void *data, size_t len, scene_image *img, fr_error *err)
{
    (void)data;
    (void)len;
    (void)path;
    (void)err;
    img->width = img->height = 32;
    img->channels = 1;
    img->pixels = malloc(sizeof(float) * 32 * 32);
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++) {
            /* Pyramids: |x| + |y| tent within each 8x8 cell. */
            int u = x % 8, v = y % 8;
            img->pixels[y * 32 + x] = (float)(abs(u - 4) + abs(v - 4)) / 8.0f;
        }
    return 0;
}

static const char bumpy_floor[] =
    "{\"image\": {\"width\": 12, \"height\": 12, \"spp\": 1, \"max_depth\": 4},"
    " \"camera\": {\"position\": [0, 2, -3], \"target\": [0, 0, 0.5], \"fov\": 40},"
    " \"textures\": {\"h\": {\"type\": \"image\", \"file\": \"bumps.png\", \"scale\": [3, 3], \"colorspace\": \"linear\"}},"
    " \"materials\": {"
    "   \"floor\": {\"type\": \"phong\", \"diffuse\": [0.5, 0.5, 0.5], \"glossy\": [0.3, 0.3, 0.3], \"exponent\": 20,"
    "              \"bump\": {\"texture\": \"h\", \"strength\": 0.2}},"
    "   \"wall\": {\"type\": \"lambert\", \"albedo\": [0.6, 0.6, 0.6]},"
    "   \"lamp\": {\"type\": \"emitter\", \"emission\": [5, 5, 5]}},"
    " \"shapes\": ["
    "   {\"type\": \"rect\", \"origin\": [-2, 0, -2], \"edge_u\": [0, 0, 4], \"edge_v\": [4, 0, 0], \"material\": \"floor\"},"
    "   {\"type\": \"rect\", \"origin\": [-2, 0.3, 2], \"edge_u\": [4, 0, 0], \"edge_v\": [0, 2, 0], \"material\": \"wall\"},"
    "   {\"type\": \"rect\", \"origin\": [-1.5, 2.5, -0.5], \"edge_u\": [1, 0, 0], \"edge_v\": [0, 0, 1], \"material\": \"lamp\"}]}";

static void shading_normals(void)
{
    /* The reader wants the texture file to exist; the hook makes its texels. */
    char dir[] = "/tmp/franja-bdpt-XXXXXX", file[64], scene[64];
    if (!mkdtemp(dir)) {
        CHECK(0, "cannot make a temporary directory");
        return;
    }
    snprintf(file, sizeof file, "%s/bumps.png", dir);
    snprintf(scene, sizeof scene, "%s/scene.json", dir);
    int fd = open(file, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW, 0600);
    if (fd >= 0)
        close(fd);
    const scene_hooks hooks = {.texture = bumps};
    fr_builder b;
    fr_error err;
    fr_scene s;
    bld_init(&b);
    int rc = json_scene_parse(bumpy_floor, scene, &hooks, &b, &err);
    if (rc == 0)
        rc = frz_scene(&b, &s, &err);
    bld_free(&b);
    remove(file);
    rmdir(dir);
    if (rc < 0) {
        CHECK(0, "bumpy floor scene: %s", err.msg);
        return;
    }
    /* Depth 1: light sampled from the floor (1,2), and light paths from
     * the lamp to the floor joined to the lens (2,1), whose throughput
     * needs the correction. */
    blocks nee, traced, pt, bd;
    const bd_strategy light_sample = {1, 2, -1}, light_path = {2, 1, -1};
    render(&s, &light_sample, 1024, 2, &nee);
    render(&s, &light_path, 4096, 2, &traced);
    agree("bump-mapped floor: light tracing (2,1) vs light sampling (1,2)", &traced, &nee, 4.5);
    render(&s, NULL, 4096, 3, &pt);
    render(&s, &all, 1024, 3, &bd);
    agree("bump-mapped floor: BDPT vs path tracing", &bd, &pt, 4.5);
    scn_free(&s);
}

/* Inside a two-sided emitting sphere of albedo rho, radiance is
 * Le / (1 - rho) everywhere: the whole image's mean, splats included. */
static void furnace(void)
{
    const float rho = 0.5f, le = 1.0f;
    char json[1024];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 4, \"height\": 4, \"spp\": 1, \"max_depth\": 4096},"
             " \"camera\": {\"position\": [0.1, 0.2, 0], \"target\": [1, 0, 0], \"fov\": 90},"
             " \"materials\": {\"wall\": {\"type\": \"lambert\", \"albedo\": [%g, %g, %g],"
             "   \"emission\": [%g, %g, %g], \"two_sided\": true}},"
             " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 3, \"material\": \"wall\"}]}",
             rho, rho, rho, le, le, le);
    fr_scene s;
    test_scene(json, &s);
    blocks b;
    render(&s, &all, 4096, 1, &b);
    double expect = le / (1.0 - rho);
    printf("furnace: %.5f +- %.5f, expected %.5f\n", b.mean[0][0], b.se[0][0], expect);
    CHECK(fabs(b.mean[0][0] - expect) / expect < 0.005, "furnace: %g, expected %g", b.mean[0][0], expect);
    scn_free(&s);
}

/* A caustic: a glass ball (ior 1.5) focuses a point light onto a floor
 * that lies wholly in the ball's shadow, so with at most 3 bounces the
 * only light on it went through the ball (refracted in and out).  No
 * camera path can find a point light through glass: only light tracing
 * renders this.  The reference is the test's own ray tracing of the ball
 * in double precision: rays from the light on a fine grid over the cone
 * toward the ball, each carrying its share of the light's power times
 * both Fresnel transmittances, deposited where they land as the radiance
 * (rho/pi) E their power makes, seen through the pixel grid. */
#define CW 48
#define CH 36
static const double ball_c[3] = {0, 1.2, 0}, ball_r = 1.0, lamp_p[3] = {-3, 5, 0}, lamp_i = 50.0, ior = 1.5;
static const double floor_rho = 0.8;

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Nearest t > eps of the ray o + t d (d unit) with the ball, 0 if none. */
static double ball_hit(const double *o, const double *d, int from_inside)
{
    double oc[3] = {o[0] - ball_c[0], o[1] - ball_c[1], o[2] - ball_c[2]};
    double b = dot3(oc, d), c = dot3(oc, oc) - ball_r * ball_r, disc = b * b - c;
    if (disc < 0)
        return 0;
    double t = from_inside ? -b + sqrt(disc) : -b - sqrt(disc);
    return t > 1e-9 ? t : 0;
}

/* Refract d (unit) at normal n (unit, against d) from index n1 to n2:
 * returns the Fresnel transmittance (0 on total internal reflection). */
static double refract(double *d, const double *n, double n1, double n2)
{
    double eta = n1 / n2, ci = -dot3(d, n), s2 = eta * eta * (1 - ci * ci);
    if (s2 >= 1)
        return 0;
    double ct = sqrt(1 - s2);
    double rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct), rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
    for (int k = 0; k < 3; k++)
        d[k] = eta * d[k] + (eta * ci - ct) * n[k];
    return 1 - 0.5 * (rs * rs + rp * rp);
}

static void caustic(void)
{
    char json[2048];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d, \"spp\": 1, \"max_depth\": 3},"
             " \"camera\": {\"position\": [4, 4, 0.5], \"target\": [1.0, 0, 0], \"fov\": 22},"
             " \"materials\": {\"glass\": {\"type\": \"glass\", \"ior\": %g},"
             "   \"floor\": {\"type\": \"lambert\", \"albedo\": [%g, %g, %g]}},"
             " \"shapes\": [{\"type\": \"sphere\", \"center\": [%g, %g, %g], \"radius\": %g, \"material\": \"glass\"},"
             "   {\"type\": \"rect\", \"origin\": [0.3, 0, -0.6], \"edge_u\": [0, 0, 1.2], \"edge_v\": [1.2, 0, 0],"
             "    \"material\": \"floor\"}],"
             " \"lights\": [{\"type\": \"point\", \"position\": [%g, %g, %g], \"intensity\": [%g, %g, %g]}]}",
             CW, CH, ior, floor_rho, floor_rho, floor_rho, ball_c[0], ball_c[1], ball_c[2], ball_r, lamp_p[0],
             lamp_p[1], lamp_p[2], lamp_i, lamp_i, lamp_i);
    fr_scene s;
    test_scene(json, &s);
    const fr_camera *cam = &s.camera;
    double pix_area = 4.0 * cam->tan_half * cam->tan_half / ((double)CH * CH);

    /* The reference: power landing on the floor rect, as pixel values. */
    static double ref[CH][CW];
    memset(ref, 0, sizeof ref);
    double axis[3] = {ball_c[0] - lamp_p[0], ball_c[1] - lamp_p[1], ball_c[2] - lamp_p[2]};
    double dist = sqrt(dot3(axis, axis));
    for (int k = 0; k < 3; k++)
        axis[k] /= dist;
    double cos_max = sqrt(1 - ball_r * ball_r / (dist * dist)), omega = 2 * M_PI * (1 - cos_max);
    double u[3], v[3];  /* a basis around the axis */
    double helper[3] = {0, 0, 1};
    u[0] = axis[1] * helper[2] - axis[2] * helper[1];
    u[1] = axis[2] * helper[0] - axis[0] * helper[2];
    u[2] = axis[0] * helper[1] - axis[1] * helper[0];
    double ul = sqrt(dot3(u, u));
    for (int k = 0; k < 3; k++)
        u[k] /= ul;
    v[0] = axis[1] * u[2] - axis[2] * u[1];
    v[1] = axis[2] * u[0] - axis[0] * u[2];
    v[2] = axis[0] * u[1] - axis[1] * u[0];
    const int n = 1000;
    double ray_power = lamp_i * omega / ((double)n * n), landed = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double ct = 1 - (1 - cos_max) * (i + 0.5) / n, st = sqrt(1 - ct * ct), ph = 2 * M_PI * (j + 0.5) / n;
            double d[3], o[3], p[3], nrm[3];
            for (int k = 0; k < 3; k++) {
                d[k] = ct * axis[k] + st * (cos(ph) * u[k] + sin(ph) * v[k]);
                o[k] = lamp_p[k];
            }
            double t = ball_hit(o, d, 0);
            if (t == 0)
                continue;
            for (int k = 0; k < 3; k++) {
                p[k] = o[k] + t * d[k];
                nrm[k] = (p[k] - ball_c[k]) / ball_r;
            }
            double w = refract(d, nrm, 1.0, ior);
            t = ball_hit(p, d, 1);
            for (int k = 0; k < 3; k++) {
                p[k] = p[k] + t * d[k];
                nrm[k] = -(p[k] - ball_c[k]) / ball_r;
            }
            w *= refract(d, nrm, ior, 1.0);
            if (w == 0 || d[1] >= 0)
                continue;
            double tf = -p[1] / d[1], q[3] = {p[0] + tf * d[0], 0, p[2] + tf * d[2]};
            if (q[0] < 0.3 || q[0] > 1.5 || q[2] < -0.6 || q[2] > 0.6)
                continue;
            /* Seen from the camera: where, and how much radiance per unit power. */
            vec3 to = v3((float)(q[0] - cam->position.x), (float)(q[1] - cam->position.y), (float)(q[2] - cam->position.z));
            double d2 = v3_len2(to), dl = sqrt(d2);
            float rx, ry;
            if (!cam_raster(&s, cam->position, v3_norm(to), &rx, &ry))
                continue;
            double cos_floor = -to.y / dl, cos_cam = v3_dot(v3_norm(to), cam->forward);
            ref[(int)ry][(int)rx] += floor_rho / M_PI * ray_power * w * cos_floor / (d2 * cos_cam * cos_cam * cos_cam * pix_area);
            landed += ray_power * w;
        }

    /* BDPT: the whole image (splats included). */
    static double img[CH][CW];
    memset(img, 0, sizeof img);
    uint32_t spp = 1024;
    s.settings.spp = spp;
    float *rgb = malloc(sizeof(float) * CW * CH * 3);
    uint64_t *splat = calloc((size_t)CW * CH * 3, sizeof *splat);
    fr_error err;
    CHECK(bd_render_rows(&s, 0, CH, rgb, splat, &err) == 0, "caustic: %s", err.msg);
    spl_resolve(rgb, splat, CW, 0, CH, spp);
    for (int y = 0; y < CH; y++)
        for (int x = 0; x < CW; x++)
            img[y][x] = rgb[(y * CW + x) * 3 + 1];
    free(rgb);
    free(splat);

    /* Compare the total and the centroid over the pixels that see the
     * floor without the ball in the way (the spot is among them). */
    double tot[2] = {0, 0}, cx[2] = {0, 0}, cy[2] = {0, 0};
    for (int y = 0; y < CH; y++)
        for (int x = 0; x < CW; x++) {
            fr_ray r = pt_camera_ray(&s, (uint32_t)x, (uint32_t)y, 0.5f, 0.5f, 0.5f, 0.5f);
            fr_hit h;
            if (!trace_closest(&s, &r, INFINITY, &h) || s.prims[h.prim].kind != FR_PRIM_RECT)
                continue;
            double val[2] = {img[y][x], ref[y][x]};
            for (int k = 0; k < 2; k++) {
                tot[k] += val[k];
                cx[k] += val[k] * (x + 0.5);
                cy[k] += val[k] * (y + 0.5);
            }
        }
    for (int k = 0; k < 2; k++) {
        cx[k] /= tot[k];
        cy[k] /= tot[k];
    }
    printf("caustic: %.1f%% of the light's cone landed; total %.4f (reference %.4f), centroid (%.2f, %.2f) "
           "(reference (%.2f, %.2f))\n", 100 * landed / (lamp_i * omega), tot[0], tot[1], cx[0], cy[0], cx[1], cy[1]);
    CHECK(landed > 0.5 * lamp_i * omega, "caustic: the spot misses the floor (the test is set up wrong)");
    CHECK(fabs(tot[0] / tot[1] - 1) < 0.02, "caustic: total %.4f, reference %.4f", tot[0], tot[1]);
    CHECK(fabs(cx[0] - cx[1]) < 0.2 && fabs(cy[0] - cy[1]) < 0.2, "caustic: centroid (%.2f, %.2f), reference (%.2f, %.2f)",
          cx[0], cy[0], cx[1], cy[1]);
    scn_free(&s);
}

/* The same ball and floor under a small round lamp, seen from beside the
 * ball (which no camera ray hits).  Every path of depth 3 that reaches
 * the camera is lamp - glass - glass - floor - camera: made by light
 * tracing (4,1) and by the camera path that hits the lamp through the ball
 * (0,5), nothing else.  Each alone and both with MIS agree (the weights of
 * the two sum to 1 across the chain of delta vertices); and MIS is nearly
 * as good as light tracing alone: the camera path's chance to hit the
 * small lamp through the ball is tiny, so the power heuristic must give it
 * almost no weight.  Weighing the chain by its first segment alone gave the
 * camera path most of the weight near the ball's foot, and MIS several
 * times light tracing's noise. */
static void caustic_weights(void)
{
    char json[2048];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 12, \"height\": 9, \"spp\": 1, \"max_depth\": 3},"
             " \"camera\": {\"position\": [2.6, 0.7, 0.2], \"target\": [0.9, 0, 0], \"fov\": 20},"
             " \"materials\": {\"glass\": {\"type\": \"glass\", \"ior\": %g},"
             "   \"floor\": {\"type\": \"lambert\", \"albedo\": [%g, %g, %g]},"
             "   \"lamp\": {\"type\": \"emitter\", \"emission\": [400, 400, 400]}},"
             " \"shapes\": [{\"type\": \"sphere\", \"center\": [%g, %g, %g], \"radius\": %g, \"material\": \"glass\"},"
             "   {\"type\": \"rect\", \"origin\": [0.3, 0, -0.6], \"edge_u\": [0, 0, 1.2], \"edge_v\": [1.2, 0, 0],"
             "    \"material\": \"floor\"},"
             "   {\"type\": \"sphere\", \"center\": [%g, %g, %g], \"radius\": 0.1, \"material\": \"lamp\"}]}",
             ior, floor_rho, floor_rho, floor_rho, ball_c[0], ball_c[1], ball_c[2], ball_r, lamp_p[0], lamp_p[1],
             lamp_p[2]);
    fr_scene s;
    test_scene(json, &s);
    int seen = 0;
    for (uint32_t y = 0; y < s.settings.height; y++)
        for (uint32_t x = 0; x < s.settings.width; x++)
            for (int c = 0; c < 4; c++) {
                fr_ray r = pt_camera_ray(&s, x, y, (float)(c & 1), (float)(c >> 1), 0.5f, 0.5f);
                fr_hit h;
                seen += trace_closest(&s, &r, INFINITY, &h) && s.prims[h.prim].kind != FR_PRIM_RECT;
            }
    CHECK(seen == 0, "caustic weights: the camera sees the ball (the test is set up wrong)");
    const bd_strategy lt = {4, 1, -1}, hit = {0, 5, -1}, mis3 = {-1, -1, 3};
    blocks b_lt, b_hit, b_mis;
    render(&s, &lt, 256, 2, &b_lt);
    render(&s, &hit, 4096, 2, &b_hit);
    render(&s, &mis3, 256, 2, &b_mis);
    agree("caustic weights: light tracing (4,1) vs hitting the lamp (0,5)", &b_lt, &b_hit, 4.5);
    agree("caustic weights: MIS at depth 3 vs light tracing (4,1)", &b_mis, &b_lt, 4.5);
    double lit = 0, worst = 0;
    for (int b = 0; b < 4; b++) {
        lit += b_lt.mean[b][1];
        if (b_lt.se[b][1] > 0)
            worst = fmax(worst, b_mis.se[b][1] / b_lt.se[b][1]);
    }
    printf("caustic weights: MIS's standard error at most %.2f times light tracing's (same samples)\n", worst);
    CHECK(lit > 0.05, "caustic weights: no caustic on the floor (%g)", lit);
    CHECK(worst < 1.3, "caustic weights: MIS %.2f times as noisy as light tracing alone", worst);
    scn_free(&s);
}

/* Distant and delta lights: an environment, a sun with a disk and a spot
 * over a floor, a ball and a wall.  Camera paths that leave the scene end
 * on the distant lights; light paths start on a disk facing the scene. */
static const char sky_scene[] =
    "{\"image\": {\"width\": 12, \"height\": 10, \"spp\": 1, \"max_depth\": 6},"
    " \"camera\": {\"position\": [0, 1.5, -4], \"target\": [0, 0.5, 1], \"fov\": 45},"
    " \"environment\": {\"color\": [0.3, 0.35, 0.5]},"
    " \"materials\": {"
    "   \"floor\": {\"type\": \"phong\", \"diffuse\": [0.5, 0.45, 0.4], \"glossy\": [0.2, 0.2, 0.2], \"exponent\": 10},"
    "   \"ball\": {\"type\": \"lambert\", \"albedo\": [0.7, 0.6, 0.5]},"
    "   \"wall\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.6, 0.7]}},"
    " \"shapes\": ["
    "   {\"type\": \"rect\", \"origin\": [-3, 0, -3], \"edge_u\": [0, 0, 6], \"edge_v\": [6, 0, 0], \"material\": \"floor\"},"
    "   {\"type\": \"sphere\", \"center\": [0.3, 0.7, 0.5], \"radius\": 0.6, \"material\": \"ball\"},"
    "   {\"type\": \"rect\", \"origin\": [-3, 0.2, 2], \"edge_u\": [6, 0, 0], \"edge_v\": [0, 2, 0], \"material\": \"wall\"}],"
    " \"lights\": [%s]}";

static void distant_lights(void)
{
    char json[4096];
    fr_scene s;
    /* The environment alone: every strategy reaches it (no delta light). */
    snprintf(json, sizeof json, sky_scene, "");
    test_scene(json, &s);
    blocks mis, one;
    for (int depth = 1; depth <= 2; depth++) {
        bd_strategy md = {-1, -1, depth};
        render(&s, &md, 512, 2, &mis);
        for (int sv = 0; sv <= depth + 1; sv++) {
            int t = depth + 2 - sv;
            if (sv == 1 && t == 1)
                continue;
            bd_strategy st = {sv, t, -1};
            render(&s, &st, 1024, 2, &one);
            char name[96];
            snprintf(name, sizeof name, "environment: strategy (%d,%d) alone vs MIS at depth %d", sv, t, depth);
            agree(name, &one, &mis, 4.5);
        }
    }
    scn_free(&s);
    /* With a sun disk and a spot light as well, against path tracing. */
    snprintf(json, sizeof json, sky_scene,
             "{\"type\": \"sun\", \"direction\": [0.4, -1, 0.3], \"irradiance\": [2, 1.8, 1.5], \"angle\": 3},"
             "{\"type\": \"spot\", \"position\": [-1.5, 2.5, -1], \"direction\": [0.5, -1, 0.4],"
             " \"intensity\": [6, 6, 6], \"inner_angle\": 20, \"outer_angle\": 30}");
    test_scene(json, &s);
    blocks pt, bd;
    render(&s, NULL, 4096, 3, &pt);
    render(&s, &all, 1024, 3, &bd);
    agree("sun, spot and environment: BDPT vs path tracing", &bd, &pt, 4.5);
    CHECK(median_rel_se(&bd) < 0.015, "sun, spot and environment: too noisy to tell (%.3f)", median_rel_se(&bd));
    scn_free(&s);
}

/* An unbounded plane under the sky and a sun: light paths from distant
 * lights start on a disk the size of the world's bounds, so the far
 * ground is reached only by camera paths (and light sampling from them).
 * The strategies that would need a light path there must not count, or
 * the ground toward the horizon comes out too dark. */
static void unbounded_plane(void)
{
    fr_scene s;
    test_scene("{\"image\": {\"width\": 12, \"height\": 9, \"spp\": 1, \"max_depth\": 6},"
               " \"camera\": {\"position\": [-6.5, 1.6, 1.2], \"target\": [0, 0.55, 0.2], \"fov\": 40},"
               " \"environment\": {\"color\": [0.4, 0.45, 0.6]},"
               " \"materials\": {\"ground\": {\"type\": \"lambert\", \"albedo\": [0.6, 0.6, 0.55]},"
               "   \"glass\": {\"type\": \"glass\", \"ior\": 1.5},"
               "   \"white\": {\"type\": \"lambert\", \"albedo\": [0.8, 0.8, 0.8]}},"
               " \"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"ground\"},"
               "   {\"type\": \"sphere\", \"center\": [0.2, 0.6, 0.2], \"radius\": 0.6, \"material\": \"glass\"},"
               "   {\"type\": \"sphere\", \"center\": [-1.6, 0.3, 0.9], \"radius\": 0.3, \"material\": \"white\"}],"
               " \"lights\": [{\"type\": \"sun\", \"direction\": [0.5, -1, 0.3], \"irradiance\": [3, 2.8, 2.5],"
               " \"angle\": 2}]}",
               &s);
    blocks pt, bd;
    render(&s, NULL, 4096, 3, &pt);
    render(&s, &all, 512, 3, &bd);
    agree("unbounded plane under the sky and a sun: BDPT vs path tracing", &bd, &pt, 4.5);
    scn_free(&s);
}

/* Media are refused with a message, never rendered wrong. */
static void media_refused(void)
{
    fr_scene s;
    test_scene("{\"image\": {\"width\": 4, \"height\": 4, \"spp\": 1},"
               " \"camera\": {\"position\": [0, 0, -3], \"target\": [0, 0, 0], \"fov\": 40},"
               " \"media\": {\"fog\": {\"sigma_a\": [0.1, 0.1, 0.1], \"sigma_s\": [0.1, 0.1, 0.1]}},"
               " \"medium\": \"fog\","
               " \"materials\": {\"w\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}},"
               " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"w\"}],"
               " \"lights\": [{\"type\": \"point\", \"position\": [0, 3, 0], \"intensity\": [5, 5, 5]}]}",
               &s);
    fr_error err;
    err.msg[0] = 0;
    CHECK(bd_supported(&s, &err) < 0 && strstr(err.msg, "media"), "a scene with fog is not refused (%s)", err.msg);
    float rgb[4 * 3];
    uint64_t splat[16 * 3] = {0};
    CHECK(bd_render_rows(&s, 0, 1, rgb, splat, &err) < 0, "bd_render_rows renders a scene with fog");
    scn_free(&s);
}

static void cornell(void) { against_path_tracing("scenes/cornell.json", 2048, 512); }
static void spheres(void) { against_path_tracing("scenes/spheres.json", 8192, 1024); }

int main(void)
{
    /* BDPT_ONLY=name runs one part. */
    const char *only = getenv("BDPT_ONLY");
#define RUN(f) if (!only || !strcmp(only, #f)) { clock_t c0 = clock(); f(); printf("[%s %.1fs]\n", #f, (double)(clock() - c0) / CLOCKS_PER_SEC); }
    RUN(strategies);
    RUN(through_glass);
    RUN(rough);
    RUN(shading_normals);
    RUN(furnace);
    RUN(media_refused);
    RUN(caustic);
    RUN(caustic_weights);
    RUN(distant_lights);
    RUN(unbounded_plane);
    RUN(cornell);
    RUN(spheres);
    return check_done();
}
