/* pfmmap.h -- environment maps for tests: written as PFM files by the test
 * and decoded by a texture hook that reads exactly what pfm_write writes
 * (test programs do not link OpenImageIO). */
#ifndef FRANJA_TEST_PFMMAP_H
#define FRANJA_TEST_PFMMAP_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compile/scene_hooks.h"

/* Write w x h RGB floats, given top row first, as a little-endian PFM
 * (which stores the bottom row first).  Returns 0 or -1. */
static inline int pfm_write(const char *path, uint32_t w, uint32_t h, const float *rgb)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    fprintf(f, "PF\n%u %u\n-1.0\n", w, h);
    for (uint32_t r = h; r-- > 0;)
        fwrite(rgb + (size_t)r * w * 3, sizeof(float), (size_t)w * 3, f);
    return fclose(f) == 0 ? 0 : -1;
}

/* A texture hook for the files pfm_write makes (the reader hands over
 * their bytes). */
static inline int pfm_hook(const char *path, const void *data, size_t len, scene_image *img, fr_error *err)
{
    FILE *f = len ? fmemopen((void *)data, len, "rb") : NULL;
    unsigned w, h;
    float scale;
    if (!f)
        return fr_fail(err, "%s: cannot open", path);
    if (fscanf(f, "PF %u %u %f", &w, &h, &scale) != 3 || fgetc(f) != '\n' || w == 0 || h == 0 || w > 4096 ||
        h > 4096) {
        fclose(f);
        return fr_fail(err, "%s: not a PFM of pfm_write", path);
    }
    img->pixels = malloc((size_t)w * h * 3 * sizeof(float));
    img->width = w;
    img->height = h;
    img->channels = 3;
    int ok = img->pixels != NULL;
    for (uint32_t r = h; ok && r-- > 0;)
        ok = fread(img->pixels + (size_t)r * w * 3, sizeof(float), (size_t)w * 3, f) == (size_t)w * 3;
    fclose(f);
    return ok ? 0 : fr_fail(err, "%s: short PFM", path);
}

static const scene_hooks pfm_hooks = {.texture = pfm_hook};

#endif
