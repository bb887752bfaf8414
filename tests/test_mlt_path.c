/* test_mlt_path.c -- Metropolis light transport over bidirectional paths
 * renders path tracing's image, normalised by its bootstrap, the same bits
 * for any grouping of chains.
 *
 * On the Cornell box and the glass-and-mirror spheres (scenes/), small
 * images: the normalisation's b (the integral of the target, the image's mean
 * luminance) against path tracing's mean luminance; the MLT image's mean
 * against b (the chains distribute exactly b over the image); the image's
 * quadrants against path tracing's (within MLT's noise at this budget); and chains [0, K) rendered as one
 * group against three groups added in another order (fixed-point sums).
 * The normalisation's sample count follows the render's mutations within
 * its bounds, and one handed over as floats (mlt_boot_set) renders the
 * bits of the one computed. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "compile/json_scene.h"
#include "mlt_path.h"
#include "pathtrace.h"
#include "splat.h"

#define W 24
#define H 24
#define K (4 * H)

static double luma(const float *p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

/* Mean luminance of quadrant q (0..3; 4: the whole image) of a W x H image. */
static double quadrant(const float *rgb, int q)
{
    double sum = 0;
    int n = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            if (q == 4 || (x >= W / 2) + 2 * (y >= H / 2) == q) {
                sum += luma(rgb + ((size_t)y * W + x) * 3);
                n++;
            }
    return sum / n;
}

/* quad_tol: the relative difference allowed in a quadrant (MLT's noise:
 * on the Cornell box over five seeds the darkest quadrant strayed up to
 * 8.4 %, its standard deviation about 4 %; the spheres' caustics make it
 * several times that, their worst quadrant over six seeds 16 %). */
static void scene_against_path(const char *path, uint32_t pt_spp, uint32_t mlt_spp, double quad_tol)
{
    fr_scene s;
    fr_error err;
    if (json_scene_load(path, NULL, &s, &err) < 0) {
        CHECK(0, "%s", err.msg);
        return;
    }
    s.settings.width = W;
    s.settings.height = H;
    s.settings.noise_threshold = 0.0f;
    static float ref[W * H * 3], img[W * H * 3];
    s.settings.spp = pt_spp;
    pt_render_rows(&s, PT_MIS, 0, H, ref);

    mlt_boot bt;
    CHECK(mlt_bootstrap(&s, MLT_NORM_MIN, &bt, &err) == 0, "%s: bootstrap: %s", path, err.msg);
    double pt_mean = quadrant(ref, 4);
    CHECK(fabs(bt.b / pt_mean - 1.0) < 0.02, "%s: b %g, path tracing's mean luminance %g", path, bt.b, pt_mean);

    /* The whole image in K = 4H chains of W * spp / 4 mutations (franja-worker
     * runs H chains of W * spp: more, shorter chains here for less noise in
     * the quadrants). */
    s.settings.spp = mlt_spp;
    uint64_t *one = calloc((size_t)W * H * 3, sizeof *one), *parts = calloc((size_t)W * H * 3, sizeof *parts),
             *part = calloc((size_t)W * H * 3, sizeof *part);
    CHECK(mlt_chains(&s, &bt, 0, K, K, (uint64_t)W * mlt_spp / 4, one, &err) == 0, "%s: chains: %s", path, err.msg);
    memset(img, 0, sizeof img);
    spl_resolve(img, one, W, 0, H, mlt_spp);
    double mlt_mean = quadrant(img, 4);
    CHECK(fabs(mlt_mean / bt.b - 1.0) < 1e-4, "%s: MLT image's mean luminance %g, b %g", path, mlt_mean, bt.b);
    for (int q = 0; q < 4; q++) {
        double a = quadrant(img, q), r = quadrant(ref, q);
        CHECK(fabs(a / r - 1.0) < quad_tol, "%s: quadrant %d: MLT %g, path tracing %g", path, q, a, r);
    }

    /* The normalisation handed over as floats, as a worker gets it from
     * the coordinator: the same chains, the same bits. */
    float bf[64];
    for (uint32_t d = 0; d < bt.nd && d < 64; d++)
        bf[d] = (float)bt.bd[d];
    mlt_boot given;
    CHECK(bt.nd <= 64 && mlt_boot_set(&given, bf, bt.nd, &err) == 0, "%s: mlt_boot_set", path);
    memset(part, 0, (size_t)W * H * 3 * sizeof *part);
    mlt_chains(&s, &given, 0, K, K, (uint64_t)W * mlt_spp / 4, part, &err);
    CHECK(given.b == bt.b && memcmp(one, part, (size_t)W * H * 3 * sizeof *one) == 0,
          "%s: the normalisation handed over as floats renders other bits", path);
    mlt_boot_free(&given);

    /* Counted: the same bits, every mutation counted once under its path
     * length, with large steps about MLT_P_LARGE of them. */
    static mlt_counts counts[64];
    memset(counts, 0, sizeof counts);
    memset(part, 0, (size_t)W * H * 3 * sizeof *part);
    mlt_chains_counted(&s, &bt, 0, K, K, (uint64_t)W * mlt_spp / 4, part, counts, &err);
    CHECK(memcmp(one, part, (size_t)W * H * 3 * sizeof *one) == 0, "%s: counted chains render other bits", path);
    uint64_t proposed = 0, large = 0, accepted = 0;
    for (uint32_t d = 0; d < bt.nd && d < 64; d++) {
        proposed += counts[d].proposed[0] + counts[d].proposed[1];
        large += counts[d].proposed[1];
        accepted += counts[d].accepted[0] + counts[d].accepted[1];
        CHECK(counts[d].accepted[0] <= counts[d].proposed[0] && counts[d].accepted[1] <= counts[d].proposed[1],
              "%s: depth %u: more accepted than proposed", path, d);
    }
    CHECK(proposed == (uint64_t)K * W * mlt_spp / 4, "%s: %llu mutations counted of %llu", path,
          (unsigned long long)proposed, (unsigned long long)K * W * mlt_spp / 4);
    CHECK(fabs((double)large / (double)proposed - MLT_P_LARGE) < 0.01 && accepted > 0 && accepted < proposed,
          "%s: large steps %g of the mutations, %llu accepted", path, (double)large / (double)proposed,
          (unsigned long long)accepted);

    /* Groups [67, 96), [0, 5), [5, 67), added in that order. */
    const uint32_t cut[][2] = {{67, K}, {0, 5}, {5, 67}};
    for (int g = 0; g < 3; g++) {
        memset(part, 0, (size_t)W * H * 3 * sizeof *part);
        mlt_chains(&s, &bt, cut[g][0], cut[g][1], K, (uint64_t)W * mlt_spp / 4, part, &err);
        spl_sum(parts, part, (size_t)W * H * 3);
    }
    CHECK(memcmp(one, parts, (size_t)W * H * 3 * sizeof *one) == 0, "%s: chains in three groups differ from one",
          path);
    free(one);
    free(parts);
    free(part);
    mlt_boot_free(&bt);
    scn_free(&s);
}

/* mlt_norm_samples: a sixteenth of the mutations, within its bounds. */
static void norm_samples(void)
{
    fr_scene s;
    memset(&s, 0, sizeof s);
    const struct { uint32_t w, h, spp, want; } cases[] = {
        {64, 64, 16, MLT_NORM_MIN},                      /* 4096 */
        {128, 96, 128, 128 * 96 * 128 / MLT_NORM_SHARE},   /* 98304 */
        {640, 480, 64, 640 * 480 * 64 / MLT_NORM_SHARE},
        {1920, 1080, 4096, MLT_NORM_MAX},
        {65536, 65536, 1u << 20, MLT_NORM_MAX},            /* no overflow */
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        s.settings.width = cases[k].w;
        s.settings.height = cases[k].h;
        s.settings.spp = cases[k].spp;
        uint32_t n = mlt_norm_samples(&s);
        CHECK(n == cases[k].want, "%ux%u at %u spp: %u normalisation samples, expected %u", cases[k].w, cases[k].h,
              cases[k].spp, n, cases[k].want);
    }
}

int main(void)
{
    norm_samples();
    scene_against_path("scenes/cornell.json", 1024, 512, 0.12);
    scene_against_path("scenes/spheres.json", 1024, 512, 0.25);
    return check_done();
}
