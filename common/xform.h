/** @file xform.h
 * Reversible byte transforms that make a scene's arrays compress better
 * on their trip to a host (unpack.h, "Packed scenes" in FORMAT.md): a
 * byte shuffle of 32-bit words and a predictor for 8- and 16-bit image
 * planes.  Both are exact integer operations, undone bit for bit.
 */
#ifndef FRANJA_XFORM_H
#define FRANJA_XFORM_H

#include <stddef.h>
#include <stdint.h>

/** The most bytes one shuffled block holds: a part is shuffled block by
 * block, each XFORM_BLOCK bytes but the last. */
#define XFORM_BLOCK ((size_t)1 << 20)

/** Byte shuffle of the n bytes at `in` (n a multiple of 4, at most
 * XFORM_BLOCK) into `out`: byte 0 of every word, then byte 1 of every
 * word, then 2, then 3.  With `undo`, the inverse (`in` shuffled). */
void xform_shuffle(const unsigned char *in, size_t n, unsigned char *out, int undo);

/** Residuals of values from..to - 1 of an image whose rows are w texels
 * of n values of `bytes` bytes (1 or 2, little-endian), counting values
 * from the image's first: each value less its prediction, modulo 2^8
 * (2^16), the prediction being (a + b + c + d + 2) / 4 (integer) of its
 * left, up, up-left and up-right neighbours in the same channel (at the
 * left edge a = b, c = b; at the right edge d = b; on the first row
 * b = c = d = a, and a = 0 for the first texel).  The residuals go to
 * res (`bytes` each).  With `undo`, the values are rebuilt into img from
 * res instead: the values before `from` must be there already. */
void xform_predict(unsigned char *img, uint32_t w, uint32_t n, uint32_t bytes, size_t from, size_t to,
                   unsigned char *res, int undo);

#endif
