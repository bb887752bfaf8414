/* test_bdpt_norm.c -- bd_depth_means_mt gives the same bits on any number
 * of threads, and stops when asked.
 *
 * On the Cornell box (scenes/) at 24 x 24: sample counts below the pixel
 * count (one partial block), over it and not a multiple of the 4096-sample
 * block (the last block partial, more threads than blocks), each on 1, 2,
 * 3 and 7 threads against bd_depth_means (one thread), compared as bytes;
 * the means are finite, non-negative and not all zero; a stop callback
 * that says stop before the first block, or after it when there are more,
 * returns 1, one that never does changes nothing. */
#include <math.h>
#include <string.h>

#include "bdpt.h"
#include "check.h"
#include "scenes.h"
#include "compile/json_scene.h"

#define MAXD 64

/* A stop callback: stops once *ctx blocks have been asked about. */
static int stop_after(void *ctx)
{
    int *left = ctx;
    return __atomic_sub_fetch(left, 1, __ATOMIC_SEQ_CST) < 0;
}

static void same_bits(const fr_scene *s, uint32_t n)
{
    uint32_t nd = s->settings.max_depth + 1;
    double one[MAXD], many[MAXD], sum = 0.0;
    CHECK(bd_depth_means(s, n, one) == 0, "n %u: bd_depth_means failed", n);
    for (uint32_t d = 0; d < nd; d++) {
        CHECK(isfinite(one[d]) && one[d] >= 0.0, "n %u: depth %u: mean %g", n, d, one[d]);
        sum += one[d];
    }
    CHECK(sum > 0.0, "n %u: every depth's mean is 0", n);
    const int threads[] = {1, 2, 3, 7};
    for (size_t k = 0; k < sizeof threads / sizeof *threads; k++) {
        memset(many, 0xff, sizeof many);
        CHECK(bd_depth_means_mt(s, n, threads[k], NULL, NULL, many) == 0, "n %u, %d threads: failed", n, threads[k]);
        CHECK(memcmp(one, many, nd * sizeof *one) == 0, "n %u, %d threads: other bits than one thread (b_0 %.17g, %.17g)",
              n, threads[k], one[0], many[0]);
    }
    int left = 1 << 30;
    memset(many, 0xff, sizeof many);
    CHECK(bd_depth_means_mt(s, n, 2, stop_after, &left, many) == 0 && memcmp(one, many, nd * sizeof *one) == 0,
          "n %u: a stop callback that never stops changes the means", n);
    left = 0;
    CHECK(bd_depth_means_mt(s, n, 2, stop_after, &left, many) == 1, "n %u: stopped before the first block: not 1", n);
    left = 1;
    CHECK(bd_depth_means_mt(s, n, 1, stop_after, &left, many) == (n > 4096 ? 1 : 0),
          "n %u: stopped after the first block: not %d", n, n > 4096);
}

int main(void)
{
    fr_scene s;
    test_scene_file("scenes/cornell.json", &s);
    s.settings.width = 24;
    s.settings.height = 24;
    CHECK(s.settings.max_depth + 1 <= MAXD, "max_depth %u", s.settings.max_depth);
    if (s.settings.max_depth + 1 <= MAXD) {
        same_bits(&s, 300);    /* under the 576 pixels: one partial block */
        same_bits(&s, 10000);  /* 18 samples a pixel, 10368: two blocks and a part */
        same_bits(&s, 12288);  /* three whole blocks */
    }
    scn_free(&s);
    return check_done();
}
