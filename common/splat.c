/* splat.c -- light-tracing splats as 64-bit fixed point, summed in any order
 * (see splat.h). */

#include "splat.h"

uint64_t spl_fixed(float v)
{
    if (!(v > 0.0f))
        return 0;
    /* v * 2^32 is exact in double; + 0.5 and the truncation round it. */
    double x = (double)v * 4294967296.0;
    if (!(x < 18446744073709549568.0))
        return UINT64_MAX;
    return (uint64_t)(x + 0.5);
}

void spl_sum(uint64_t *acc, const uint64_t *add, size_t n)
{
    for (size_t i = 0; i < n; i++)
        spl_add(&acc[i], add[i]);
}

float spl_value(uint64_t sum, uint32_t spp)
{
    return (float)((double)sum * (1.0 / 4294967296.0) / (double)spp);
}

void spl_resolve(float *rgb, const uint64_t *splat, uint32_t width, uint32_t y0, uint32_t y1, uint32_t spp)
{
    size_t n = (size_t)width * (y1 - y0) * 3;
    const uint64_t *src = splat + (size_t)y0 * width * 3;
    for (size_t i = 0; i < n; i++)
        rgb[i] += spl_value(src[i], spp);
}
