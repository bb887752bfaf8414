/* normbench.c -- the Metropolis normalisation (bd_depth_means_mt) on 1 and
 * more threads: seconds of each, median of REPS runs, and whether every
 * run gave the bits of the first.
 *
 *   bin/bench/normbench SCENE.json [--size WxH] [--samples N] [--threads T] [--reps R]
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bdpt.h"
#include "compile/json_scene.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: normbench SCENE.json [--size WxH] [--samples N] [--threads T] [--reps R]\n");
        return 2;
    }
    unsigned w = 160, h = 120, n = 1u << 20, threads = 2, reps = 3;
    for (int i = 2; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--size"))
            sscanf(argv[i + 1], "%ux%u", &w, &h);
        else if (!strcmp(argv[i], "--samples"))
            n = (unsigned)strtoul(argv[i + 1], NULL, 10);
        else if (!strcmp(argv[i], "--threads"))
            threads = (unsigned)strtoul(argv[i + 1], NULL, 10);
        else if (!strcmp(argv[i], "--reps"))
            reps = (unsigned)strtoul(argv[i + 1], NULL, 10);
    }
    if (reps < 1 || reps > 64 || threads < 1 || threads > 256) {
        fprintf(stderr, "normbench: --reps 1..64, --threads 1..256\n");
        return 2;
    }
    fr_scene s;
    fr_error err;
    if (json_scene_load(argv[1], NULL, &s, &err) < 0) {
        fprintf(stderr, "normbench: %s\n", err.msg);
        return 1;
    }
    s.settings.width = w;
    s.settings.height = h;
    uint32_t nd = s.settings.max_depth + 1;
    double *first = calloc(nd, sizeof *first), *bd = calloc(nd, sizeof *bd), secs[2][64];
    int same = first && bd;
    for (unsigned t = 0; same && t < 2; t++)
        for (unsigned r = 0; r < reps; r++) {
            double t0 = now();
            if (bd_depth_means_mt(&s, n, t ? (int)threads : 1, NULL, NULL, t + r ? bd : first)) {
                fprintf(stderr, "normbench: out of memory\n");
                return 1;
            }
            secs[t][r] = now() - t0;
            same = same && (t + r == 0 || memcmp(first, bd, nd * sizeof *bd) == 0);
        }
    qsort(secs[0], reps, sizeof **secs, by_value);
    qsort(secs[1], reps, sizeof **secs, by_value);
    double b = 0.0;
    for (uint32_t d = 0; d < nd; d++)
        b += first[d];
    printf("%s %ux%u, %u samples: 1 thread %.2f s, %u threads %.2f s (medians of %u), speed-up %.2f, b %.6g, %s\n",
           argv[1], w, h, n, secs[0][reps / 2], threads, secs[1][reps / 2], reps, secs[0][reps / 2] / secs[1][reps / 2],
           b, same ? "the same bits every run" : "OTHER BITS");
    free(first);
    free(bd);
    scn_free(&s);
    return same ? 0 : 1;
}
