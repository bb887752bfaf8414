/* test_split.c -- any split of the rows into slabs renders the same bytes.
 *
 * Split invariance: the full image and its concatenation from uneven
 * slabs (2, 3 and 7 of them) are byte-identical, on a scene with every
 * material kind, point and area lights, and on one lit by an environment
 * map, a sun disk and a spot, with a medium inside a box.  Bidirectional
 * renders too: each slab's light tracing splats onto the whole image, and
 * the slabs' fixed-point splat sums, added in any order, are the full
 * render's to the bit. */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bdpt.h"
#include "check.h"
#include "pathtrace.h"
#include "splat.h"
#include "pfmmap.h"
#include "scenes.h"

static const char scene[] =
    "{\"image\": {\"width\": 23, \"height\": 19, \"spp\": 3, \"max_depth\": 8, \"seed\": 5},"
    " \"camera\": {\"position\": [0, 1, -5], \"target\": [0, 0.8, 0], \"fov\": 50, \"aperture\": 0.05},"
    " \"materials\": {"
    "   \"floor\": {\"type\": \"phong\", \"diffuse\": [0.4, 0.3, 0.3], \"glossy\": [0.3, 0.3, 0.3], \"exponent\": 40},"
    "   \"mirror\": {\"type\": \"mirror\"}, \"glass\": {\"type\": \"glass\", \"ior\": 1.5},"
    "   \"mix\": {\"type\": \"mix\", \"diffuse\": [0.3, 0.1, 0.1], \"specular\": [0.2, 0.2, 0.2], \"transmit\": [0.3, 0.3, 0.3]},"
    "   \"lamp\": {\"type\": \"emitter\", \"emission\": [8, 7, 6]}},"
    " \"lights\": [{\"type\": \"point\", \"position\": [2, 3, -2], \"intensity\": [20, 20, 20]}],"
    " \"shapes\": ["
    "   {\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"},"
    "   {\"type\": \"sphere\", \"center\": [-1, 0.7, 0], \"radius\": 0.7, \"material\": \"mirror\"},"
    "   {\"type\": \"sphere\", \"center\": [0.8, 0.6, -0.5], \"radius\": 0.6, \"material\": \"glass\"},"
    "   {\"type\": \"triangle\", \"vertices\": [[-2, 0, 2], [2, 0, 2], [0, 2.5, 2]], \"material\": \"mix\"},"
    "   {\"type\": \"rect\", \"origin\": [-1, 3, -1], \"edge_u\": [2, 0, 0], \"edge_v\": [0, 0, 1], \"material\": \"lamp\"}]}";

static const char sky_scene[] =
    "{\"image\": {\"width\": 21, \"height\": 17, \"spp\": 3, \"max_depth\": 6, \"seed\": 2},"
    " \"camera\": {\"position\": [0, 1, -5], \"target\": [0, 0.8, 0], \"fov\": 50},"
    " \"textures\": {\"sky\": {\"type\": \"image\", \"file\": \"sky.pfm\"}},"
    " \"environment\": {\"color\": \"sky\", \"rotation\": 20},"
    " \"media\": {\"smoke\": {\"sigma_s\": 0.8, \"sigma_a\": 0.1}},"
    " \"materials\": {"
    "   \"floor\": {\"type\": \"phong\", \"diffuse\": [0.4, 0.3, 0.3], \"glossy\": [0.3, 0.3, 0.3], \"exponent\": 40},"
    "   \"glass\": {\"type\": \"glass\", \"ior\": 1.5}, \"smoke\": {\"type\": \"interface\", \"medium\": \"smoke\"}},"
    " \"lights\": [{\"type\": \"sun\", \"direction\": [1, -2, 1], \"irradiance\": [3, 3, 2], \"angle\": 3},"
    "   {\"type\": \"spot\", \"position\": [0, 3, 0], \"target\": [0, 0, 0], \"intensity\": [9, 9, 9]}],"
    " \"shapes\": ["
    "   {\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"},"
    "   {\"type\": \"sphere\", \"center\": [0.8, 0.6, -0.5], \"radius\": 0.6, \"material\": \"glass\"},"
    "   {\"type\": \"box\", \"min\": [-2, 0.01, 0], \"max\": [-0.5, 1.5, 1.5], \"material\": \"smoke\"}]}";

static void check_split(const fr_scene *s, const float *full, const uint32_t *cuts, int n)
{
    uint32_t w = s->settings.width, h = s->settings.height;
    float *img = malloc((size_t)w * h * 3 * sizeof *img);
    for (int i = 0; i + 1 < n; i++)
        pt_render_rows(s, PT_MIS, cuts[i], cuts[i + 1], img + (size_t)cuts[i] * w * 3);
    CHECK(memcmp(img, full, (size_t)w * h * 3 * sizeof *img) == 0, "%d slabs differ from the full image", n - 1);
    free(img);
}

static void split_all(const fr_scene *s);
static void split_bdpt(const fr_scene *s);

/* Distant lights and a spot for the bidirectional split (no medium). */
static const char lit_scene[] =
    "{\"image\": {\"width\": 19, \"height\": 15, \"spp\": 2, \"max_depth\": 5, \"seed\": 3},"
    " \"camera\": {\"position\": [0, 1, -5], \"target\": [0, 0.8, 0], \"fov\": 50},"
    " \"environment\": {\"color\": [0.2, 0.25, 0.3]},"
    " \"materials\": {\"floor\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]},"
    "   \"glass\": {\"type\": \"glass\", \"ior\": 1.5}},"
    " \"lights\": [{\"type\": \"sun\", \"direction\": [1, -2, 1], \"irradiance\": [3, 3, 2], \"angle\": 3},"
    "   {\"type\": \"spot\", \"position\": [0, 3, 0], \"target\": [0, 0, 0], \"intensity\": [9, 9, 9]}],"
    " \"shapes\": ["
    "   {\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"},"
    "   {\"type\": \"sphere\", \"center\": [0.8, 0.6, -0.5], \"radius\": 0.6, \"material\": \"glass\"}]}";

int main(void)
{
    fr_scene s;
    test_scene(scene, &s);
    split_all(&s);
    split_bdpt(&s);
    /* A different seed gives a different image: the seed is really used. */
    uint32_t w = s.settings.width, h = s.settings.height;
    float *full = malloc((size_t)w * h * 3 * sizeof *full), *other = malloc((size_t)w * h * 3 * sizeof *other);
    pt_render_rows(&s, PT_MIS, 0, h, full);
    fr_scene s2 = s;
    s2.settings.seed = 6;
    pt_render_rows(&s2, PT_MIS, 0, h, other);
    CHECK(memcmp(other, full, (size_t)w * h * 3 * sizeof *other) != 0, "seed does not change the image");
    free(other);
    free(full);
    scn_free(&s);
    char dir[] = "/tmp/franja-splitXXXXXX", path[256], file[256];
    CHECK(mkdtemp(dir) != NULL, "mkdtemp");
    snprintf(path, sizeof path, "%s/sky.pfm", dir);
    snprintf(file, sizeof file, "%s/sky.json", dir);
    float map[16 * 8 * 3];
    for (int i = 0; i < 16 * 8 * 3; i++)
        map[i] = 0.2f + (float)((i * 7) % 11) * 0.1f;
    CHECK(pfm_write(path, 16, 8, map) == 0, "write %s", path);
    test_scene_with(sky_scene, file, &pfm_hooks, &s);
    unlink(path);
    rmdir(dir);
    split_all(&s);
    scn_free(&s);
    test_scene(lit_scene, &s);
    split_bdpt(&s);
    scn_free(&s);
    return check_done();
}

/* The full image of s against its slabs. */
static void split_all(const fr_scene *s)
{
    uint32_t w = s->settings.width, h = s->settings.height;
    float *full = malloc((size_t)w * h * 3 * sizeof *full);
    pt_render_rows(s, PT_MIS, 0, h, full);
    /* The image is not black (the test would be empty otherwise). */
    double sum = 0;
    for (size_t i = 0; i < (size_t)w * h * 3; i++)
        sum += full[i];
    CHECK(sum > 1.0, "the test image is black");
    const uint32_t two[] = {0, 11, h};
    const uint32_t three[] = {0, 1, 13, h};
    const uint32_t seven[] = {0, 2, 3, 7, 8, 12, h - 1, h};
    check_split(s, full, two, 3);
    check_split(s, full, three, 4);
    check_split(s, full, seven, 8);
    free(full);
}

/* Bidirectional: rows and splats of each split against the full render;
 * the slabs are rendered and their splats added last slab first. */
static void split_bdpt(const fr_scene *s)
{
    uint32_t w = s->settings.width, h = s->settings.height;
    size_t n = (size_t)w * h * 3;
    float *full = malloc(n * sizeof *full), *img = malloc(n * sizeof *img);
    uint64_t *full_splat = calloc(n, sizeof *full_splat), *sum = malloc(n * sizeof *sum),
             *part = malloc(n * sizeof *part);
    fr_error err;
    CHECK(bd_render_rows(s, 0, h, full, full_splat, &err) == 0, "bidirectional render: %s", err.msg);
    const uint32_t two[] = {0, 7, h}, three[] = {0, 1, 9, h}, seven[] = {0, 2, 3, 6, 8, 11, h - 1, h};
    const uint32_t *cuts[] = {two, three, seven};
    const int slabs[] = {2, 3, 7};
    int outside = 0;
    for (int k = 0; k < 3; k++) {
        memset(sum, 0, n * sizeof *sum);
        for (int i = slabs[k] - 1; i >= 0; i--) {
            uint32_t y0 = cuts[k][i], y1 = cuts[k][i + 1];
            memset(part, 0, n * sizeof *part);
            bd_render_rows(s, y0, y1, img + (size_t)y0 * w * 3, part, &err);
            for (size_t j = 0; j < n; j++)
                if (part[j] && (j / (3 * (size_t)w) < y0 || j / (3 * (size_t)w) >= y1))
                    outside = 1;
            spl_sum(sum, part, n);
        }
        CHECK(memcmp(img, full, n * sizeof *img) == 0, "bidirectional: %d slabs' rows differ", slabs[k]);
        CHECK(memcmp(sum, full_splat, n * sizeof *sum) == 0, "bidirectional: %d slabs' splats differ", slabs[k]);
    }
    CHECK(outside, "no slab's light tracing reached another slab's rows (the test would be empty)");
    spl_resolve(full, full_splat, w, 0, h, s->settings.spp);
    double total = 0;
    for (size_t j = 0; j < n; j++)
        total += full[j];
    CHECK(total > 1.0, "the bidirectional test image is black");
    free(full);
    free(img);
    free(full_splat);
    free(sum);
    free(part);
}
