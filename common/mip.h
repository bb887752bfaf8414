/** @file mip.h
 * Mip levels of an image texture and the rounding of a linear value to a
 * texel format: the filter the compiler builds a texture's levels with
 * (compile/texstore.h) and the one a host rebuilds them with when a scene
 * travels without them (unpack.h), so both give the same bytes.  Only
 * + - * / of doubles, the exact rounding functions and integer
 * arithmetic: the same bits on every architecture.
 *
 * Level k (max(1, w >> k) x max(1, h >> k)) down to 1 x 1: its texel
 * (x, y) averages the texels 2x..2x+1 by 2y..2y+1 of level k - 1, the last
 * column (row) also the odd one left over, so every texel of level k - 1
 * counts once.  The mean is taken of the linear values (in double) and
 * stored as mip_encode rounds it, except for linear 8- and 16-bit
 * integers, whose mean is that of the integers rounded half up (the same
 * value, as they are proportional to the linear ones).
 */
#ifndef FRANJA_MIP_H
#define FRANJA_MIP_H

#include <stddef.h>
#include <stdint.h>

#include "scene.h"

/** The stored value (the bits of a byte, 16-bit integer, half or float)
 * of texel format `format` nearest to linear value v: for the sRGB
 * formats the code whose decoded value is nearest (ties to the lower
 * code), for the linear integers round(v x 255) or round(v x 65535)
 * clamped to their range, for half and float IEEE rounding to nearest
 * even (half: infinity past 65519.99). */
uint32_t mip_encode(uint32_t format, double v);

/** Stores `code` as value i (counting values, not bytes) of a level whose
 * values are `bytes` (1, 2 or 4) bytes long. */
void mip_put(unsigned char *p, size_t i, uint32_t bytes, uint32_t code);

/** Rows y0 to y1 - 1 of level k (>= 1) of image texture t from its level
 * k - 1, read in `texels` (the scene's texel words, t->first[k - 1] on):
 * written to out (row y0 first, rows packed, no padding).  t must be a
 * valid image (width, height, channels, format, first as fbin checks). */
void mip_level(const uint32_t *texels, const fr_texture *t, uint32_t k, uint32_t y0, uint32_t y1, unsigned char *out);

#endif
