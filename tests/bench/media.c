/* media.c -- what equiangular sampling brings: one scene with a point light
 * in fog rendered at the same samples per pixel with distance sampling
 * alone and with equiangular + distance sampling combined by MIS; each
 * against a reference of many more samples (other seed).  Prints RMSE,
 * seconds (one thread) and their ratios.
 *
 *   bin/bench/media SCENE.json [--size N] [--spp N] [--ref-spp N]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "pathtrace.h"
#include "compile/json_scene.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double render(fr_scene *s, pt_strategy st, uint32_t spp, uint32_t seed, float *rgb)
{
    s->settings.spp = spp;
    s->settings.seed = seed;
    double t0 = now();
    pt_render_rows(s, st, 0, s->settings.height, rgb);
    return now() - t0;
}

static double rmse(const float *a, const float *b, size_t n)
{
    double sum = 0;
    for (size_t i = 0; i < n; i++)
        sum += (double)(a[i] - b[i]) * (a[i] - b[i]);
    return sqrt(sum / n);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: media SCENE.json [--size N] [--spp N] [--ref-spp N]\n");
        return 2;
    }
    uint32_t size = 64, spp = 32, ref_spp = 1024;
    for (int i = 2; i + 1 < argc; i += 2) {
        uint32_t v = (uint32_t)strtoul(argv[i + 1], NULL, 10);
        if (!strcmp(argv[i], "--size")) size = v;
        else if (!strcmp(argv[i], "--spp")) spp = v;
        else if (!strcmp(argv[i], "--ref-spp")) ref_spp = v;
    }
    fr_scene s;
    fr_error err;
    if (json_scene_load(argv[1], NULL, &s, &err) < 0) {
        fprintf(stderr, "media: %s\n", err.msg);
        return 1;
    }
    s.settings.width = s.settings.height = size;
    size_t n = (size_t)size * size * 3;
    float *ref = malloc(n * sizeof *ref), *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
    double tref = render(&s, PT_MIS, ref_spp, 12345, ref);
    double tdist = render(&s, PT_MIS_DISTANCE, spp, 0, a);
    double tmis = render(&s, PT_MIS, spp, 0, b);
    double ed = rmse(a, ref, n), em = rmse(b, ref, n);
    printf("scene %s, %ux%u, %u spp, reference %u spp (%.1f s)\n", argv[1], size, size, spp, ref_spp, tref);
    printf("distance sampling only:  RMSE %.5f  %.2f s\n", ed, tdist);
    printf("equiangular + MIS:       RMSE %.5f  %.2f s\n", em, tmis);
    printf("variance ratio (distance / equiangular+MIS) at equal spp: %.2f\n", (ed * ed) / (em * em));
    printf("efficiency ratio (1 / (variance * time)): %.2f\n", (ed * ed * tdist) / (em * em * tmis));
    free(ref), free(a), free(b);
    scn_free(&s);
    return 0;
}
