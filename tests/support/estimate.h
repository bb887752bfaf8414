/* estimate.h -- the mean of a region of an image rendered by one path
 * tracing strategy, with its standard error, for unbiasedness tests. */
#ifndef FRANJA_TEST_ESTIMATE_H
#define FRANJA_TEST_ESTIMATE_H

#include <math.h>
#include <stdint.h>

#include "pathtrace.h"

typedef struct {
    double mean; /* mean of the pixel means (green channel) */
    double se;   /* its standard error */
} estimate;

/* Mean of the green channel over the pixels [x0, x1) x [y0, y1) rendered
 * with `spp` samples each by `strategy`, and its standard error: the sum of
 * the variances of the pixel means, each from its samples' spread (an
 * overestimate with stratified samples, so tests built on it are
 * conservative). */
static inline estimate est_region(const fr_scene *s, pt_strategy strategy, uint32_t spp, uint32_t x0, uint32_t x1,
                                  uint32_t y0, uint32_t y1)
{
    double sum = 0, var = 0;
    uint32_t n = (x1 - x0) * (y1 - y0);
    for (uint32_t y = y0; y < y1; y++)
        for (uint32_t x = x0; x < x1; x++) {
            double px = 0, px2 = 0;
            for (uint32_t i = 0; i < spp; i++) {
                double v = pt_sample(s, strategy, x, y, i).y;
                px += v;
                px2 += v * v;
            }
            double m = px / spp;
            sum += m;
            var += (px2 / spp - m * m) / spp;
        }
    estimate e = {sum / n, sqrt(var) / n};
    return e;
}

/* The same over the whole image. */
static inline estimate est_image(const fr_scene *s, pt_strategy strategy, uint32_t spp)
{
    return est_region(s, strategy, spp, 0, s->settings.width, 0, s->settings.height);
}

#endif
