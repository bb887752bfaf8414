/* test_mlt_short.c -- Veach's split of Metropolis renders: the short paths
 * by bidirectional path tracing, the longer ones by the chains.
 *
 * On the Cornell box (scenes/), a small image: bd_render_short's image
 * (paths of at most one bounce, its subpaths cut short) against the sum of
 * two bidirectional renders of depth 0 and depth 1 alone with full
 * subpaths, sample for sample (the same numbers: equal to float rounding);
 * the spp scaling of its splats (the image at another scene spp is the
 * same); the hybrid render's mean luminance against path tracing's (within
 * noise); mlt_boot_long leaving the chains the depths above; and the
 * hybrid rows rendered as one slab against two slabs (rows and splats
 * added): the same bits. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bdpt.h"
#include "check.h"
#include "scenes.h"
#include "compile/json_scene.h"
#include "mlt_path.h"
#include "pathtrace.h"
#include "splat.h"

#define W 20
#define H 20
#define N ((size_t)W * H * 3)

static double luma(const float *p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

static double mean_luma(const float *rgb)
{
    double sum = 0;
    for (size_t i = 0; i < (size_t)W * H; i++)
        sum += luma(rgb + i * 3);
    return sum / (W * H);
}

/* Splats of bd_sample into double sums per pixel. */
static void add_double(void *ctx, uint32_t x, uint32_t y, float r, float g, float b)
{
    double *p = (double *)ctx + ((size_t)y * W + x) * 3;
    p[0] += r;
    p[1] += g;
    p[2] += b;
}

/* The image of depths 0 and 1 by bd_sample, each depth alone (full
 * subpaths), at spp samples per pixel. */
static void depths_by_sample(const fr_scene *s, uint32_t spp, float *out)
{
    static double acc[N];
    memset(acc, 0, sizeof acc);
    bd_work *w = bd_work_new(s);
    for (int d = 0; d <= 1; d++) {
        const bd_strategy st = {-1, -1, d};
        for (uint32_t y = 0; y < H; y++)
            for (uint32_t x = 0; x < W; x++)
                for (uint32_t i = 0; i < spp; i++) {
                    vec3 c = bd_sample(s, w, &st, x, y, i, add_double, acc);
                    double *p = acc + ((size_t)y * W + x) * 3;
                    p[0] += c.x;
                    p[1] += c.y;
                    p[2] += c.z;
                }
    }
    bd_work_free(w);
    for (size_t i = 0; i < N; i++)
        out[i] = (float)(acc[i] / spp);
}

/* bd_render_short of the whole image, resolved with the scene's spp. */
static void short_image(const fr_scene *s, uint32_t spp, float *out)
{
    uint64_t *splat = calloc(N, sizeof *splat);
    fr_error err;
    CHECK(bd_render_short(s, 0, H, 2, spp, out, splat, &err) == 0, "bd_render_short: %s", err.msg);
    spl_resolve(out, splat, W, 0, H, s->settings.spp);
    free(splat);
}

int main(void)
{
    fr_scene s;
    fr_error err;
    test_scene_file("scenes/cornell.json", &s);
    s.settings.width = W;
    s.settings.height = H;
    s.settings.noise_threshold = 0.0f;
    static float a[N], b[N], pt[N], img[N], two[N];

    /* The short part is depths 0 and 1 of bidirectional path tracing. */
    s.settings.spp = 4;
    short_image(&s, 4, a);
    depths_by_sample(&s, 4, b);
    double worst = 0.0;
    for (size_t i = 0; i < N; i++) {
        double e = fabs(a[i] - b[i]) / (fabs(b[i]) + 1e-3);
        worst = e > worst ? e : worst;
    }
    CHECK(worst < 1e-4, "short paths differ from depths 0 and 1 of bd_sample by %g (relative)", worst);
    /* At scene spp 16 with 4 short samples: the same image (splats scaled). */
    s.settings.spp = 16;
    short_image(&s, 4, b);
    worst = 0.0;
    for (size_t i = 0; i < N; i++)
        worst = fmax(worst, fabs(a[i] - b[i]) / (fabs(a[i]) + 1e-3));
    CHECK(worst < 1e-5, "short paths at scene spp 16 differ from spp 4 by %g", worst);

    /* mlt_boot_long keeps b_d above the short depth only. */
    mlt_boot bt, lo;
    CHECK(mlt_bootstrap(&s, MLT_NORM_MIN, &bt, &err) == 0, "bootstrap: %s", err.msg);
    CHECK(mlt_boot_long(&bt, MLT_SHORT_DEPTH, &lo, &err) == 0, "mlt_boot_long: %s", err.msg);
    double sum = 0.0;
    for (uint32_t d = 0; d < bt.nd; d++) {
        CHECK(lo.bd[d] == ((int)d > MLT_SHORT_DEPTH ? bt.bd[d] : 0.0), "depth %u: b_d %g of %g", d, lo.bd[d], bt.bd[d]);
        sum += lo.bd[d];
    }
    CHECK(lo.b == sum && lo.b > 0.0 && lo.b < bt.b, "the long depths' b %g, the sum of theirs %g, all %g", lo.b, sum,
          bt.b);

    /* The hybrid's mean against path tracing's: the chains add exactly the
     * long depths' b, the short paths their mean (at 16 samples per pixel
     * within about 1 % of it on this box; at 4 they stray by 20 %), so
     * the noise is the normalisation's (1 %), the short paths' and path
     * tracing's. */
    s.settings.spp = 256;
    pt_render_rows(&s, PT_MIS, 0, H, pt);
    s.settings.spp = 16 * MLT_SHORT_DIV;
    uint64_t *splat = calloc(N, sizeof *splat), *parts = calloc(N, sizeof *parts);
    CHECK(mlt_render_rows(&s, &bt, 0, H, img, splat, &err) == 0, "mlt_render_rows: %s", err.msg);
    static float resolved[N];
    memcpy(resolved, img, sizeof resolved);
    spl_resolve(resolved, splat, W, 0, H, s.settings.spp);
    double m = mean_luma(resolved), r = mean_luma(pt);
    CHECK(fabs(m / r - 1.0) < 0.03, "the hybrid's mean luminance %g, path tracing's %g", m, r);
    double rows = mean_luma(img);
    CHECK(rows > 0.0 && rows < m, "the short paths' own radiance %g, of the image's %g", rows, m);

    /* Split invariance: rows [0, 7) and [7, H) as two slabs. */
    uint64_t *part = calloc(N, sizeof *part);
    CHECK(mlt_render_rows(&s, &bt, 7, H, two + (size_t)7 * W * 3, part, &err) == 0, "slab 7:%d: %s", H, err.msg);
    spl_sum(parts, part, N);
    memset(part, 0, N * sizeof *part);
    CHECK(mlt_render_rows(&s, &bt, 0, 7, two, part, &err) == 0, "slab 0:7: %s", err.msg);
    spl_sum(parts, part, N);
    CHECK(memcmp(two, img, sizeof img) == 0 && memcmp(parts, splat, N * sizeof *splat) == 0,
          "two slabs give other bits than one");
    mlt_boot_free(&lo);
    free(part);
    free(parts);
    free(splat);
    mlt_boot_free(&bt);
    scn_free(&s);
    return check_done();
}
