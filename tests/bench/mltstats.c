/* mltstats.c -- what a Metropolis render's mutations do, by path length:
 * chains, small and large steps proposed and the share of each accepted.
 *
 *   bin/bench/mltstats SCENE.json [--size WxH] [--spp N]
 *
 * The chains of a whole image as franja-worker runs them (row y is chain
 * y, of width x spp mutations, over the paths longer than MLT_SHORT_DEPTH
 * bounces), normalised as franja render does (mlt_norm_samples bidirectional
 * samples), counted by mlt_chains_counted.  Prints one line per path
 * length that has chains. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compile/json_scene.h"
#include "mlt_path.h"

static double share(uint64_t a, uint64_t n) { return n ? 100.0 * (double)a / (double)n : 0.0; }

int main(int argc, char **argv)
{
    if (argc < 2 || argc % 2) {
        fprintf(stderr, "usage: mltstats SCENE.json [--size WxH] [--spp N]\n");
        return 2;
    }
    unsigned w = 0, h = 0, spp = 0;
    for (int i = 2; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--size") && sscanf(argv[i + 1], "%ux%u", &w, &h) == 2 && w && h && w <= 8192 && h <= 8192)
            continue;
        if (!strcmp(argv[i], "--spp") && (spp = (unsigned)strtoul(argv[i + 1], NULL, 10)) > 0 && spp <= 65536)
            continue;
        fprintf(stderr, "mltstats: bad argument %s %s (--size WxH up to 8192, --spp 1..65536)\n", argv[i], argv[i + 1]);
        return 2;
    }
    fr_scene s;
    fr_error err;
    if (json_scene_load(argv[1], NULL, &s, &err) < 0) {
        fprintf(stderr, "mltstats: %s\n", err.msg);
        return 1;
    }
    if (w) {
        s.settings.width = w;
        s.settings.height = h;
    }
    if (spp)
        s.settings.spp = spp;
    w = s.settings.width;
    h = s.settings.height;
    mlt_boot bt, lo;
    mlt_counts *counts = calloc(s.settings.max_depth + 1, sizeof *counts);
    uint64_t *splat = calloc((size_t)w * h * 3, sizeof *splat);
    int rc = !counts || !splat || mlt_supported(&s, &err) < 0 ||
             mlt_bootstrap(&s, mlt_norm_samples(&s), &bt, &err) < 0;
    if (!rc) {
        rc = mlt_boot_long(&bt, MLT_SHORT_DEPTH, &lo, &err) < 0 ||
             mlt_chains_counted(&s, &lo, 0, h, h, (uint64_t)w * s.settings.spp, splat, counts, &err) < 0;
        if (!rc)
            mlt_boot_free(&lo);
        mlt_boot_free(&bt);
    }
    if (rc) {
        fprintf(stderr, "mltstats: %s\n", counts && splat ? err.msg : "out of memory");
    } else {
        printf("%s %ux%u, %u mutations/pixel, %u chains of %llu mutations (the paths of more than %d bounce%s)\n", argv[1],
               w, h, s.settings.spp, h, (unsigned long long)w * s.settings.spp, MLT_SHORT_DEPTH, MLT_SHORT_DEPTH == 1 ? "" : "s");
        for (uint32_t d = 0; d <= s.settings.max_depth; d++) {
            const mlt_counts *c = &counts[d];
            if (c->proposed[0] + c->proposed[1] == 0)
                continue;
            printf("path length %2u: %10llu small steps, %6.2f %% accepted; %9llu large steps, %7.3f %% accepted\n", d,
                   (unsigned long long)c->proposed[0], share(c->accepted[0], c->proposed[0]),
                   (unsigned long long)c->proposed[1], share(c->accepted[1], c->proposed[1]));
        }
    }
    free(counts);
    free(splat);
    scn_free(&s);
    return rc;
}
