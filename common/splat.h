/** @file splat.h
 * Light-tracing splats in 64-bit fixed point, so that sums do not
 * depend on their order.
 *
 * A bidirectional render's light subpaths add light to pixels anywhere in
 * the image, not only in the rows whose samples traced them.  Each slab
 * accumulates its splats over the whole image; the coordinator adds the
 * slabs' buffers.  Floating-point sums would depend on the grouping (which
 * slabs, which order); integer sums do not.  So a splat is rounded once, to
 * a multiple of 2^-32 (SPL_FRAC_BITS fraction bits), and everything after
 * is unsigned integer addition, saturating at UINT64_MAX (for non-negative
 * terms, min(sum, max) is also independent of the grouping).  Values below
 * 2^-33 are lost; a pixel saturates above 2^32 (sums over all samples).
 */
#ifndef FRANJA_SPLAT_H
#define FRANJA_SPLAT_H

#include <stddef.h>
#include <stdint.h>

#define SPL_FRAC_BITS 32

/** The fixed-point value of a splat v, rounded to nearest (0 for negative
 * or NaN, UINT64_MAX from 2^32 on). */
uint64_t spl_fixed(float v);

/** *acc += add, saturating. */
static inline void spl_add(uint64_t *acc, uint64_t add)
{
    uint64_t r = *acc + add;
    *acc = r < add ? UINT64_MAX : r;
}

/** acc[i] += add[i] for n entries, saturating. */
void spl_sum(uint64_t *acc, const uint64_t *add, size_t n);

/** What a sum of splats over `spp` samples per pixel adds to the pixel's
 * mean: sum * 2^-32 / spp, as a float (the same bits everywhere). */
float spl_value(uint64_t sum, uint32_t spp);

/** Add the splats of rows [y0, y1) of a width-pixel image (splat: 3 sums
 * per pixel, the whole image, top row first) to rgb (3 floats per pixel,
 * row y0 first): the finished pixels of a bidirectional render. */
void spl_resolve(float *rgb, const uint64_t *splat, uint32_t width, uint32_t y0, uint32_t y1, uint32_t spp);

#endif
