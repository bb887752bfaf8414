/** @file image.h
 * Partial images of the PPM family, written by workers and
 * read back (strictly) by the coordinator and the tests.
 *
 * Formats: PF (standard PFM: linear float32 RGB, little-endian, rows
 * bottom-to-top), P6 with maxval 65535 (16-bit big-endian) or 255, both
 * sRGB-encoded and clamped.  Every header carries one comment line
 *     # franja scene=<16 hex> rows=<y0>:<y1> spp=<n> size=<W>x<H>
 * naming what the pixels are, so a partial can be checked against what was
 * asked for.
 *
 * A bidirectional render's PF partial also carries the light its slab's
 * light subpaths splatted onto the whole image (splat.h): the comment
 * line ends with " splat=<paths>:<16 hex>", the number of light subpaths
 * traced and the XXH3-64 hash of the splat block, and the block follows
 * the pixels: W*H*3 unsigned 64-bit little-endian fixed-point sums (2^-32
 * units), top row first, whole pixels of R, G, B (common/FORMAT.md).
 *
 * A path-traced PF partial may instead carry its sample sums, what an exact
 * continuation with more samples needs (franja-worker --sums, --continue):
 * the comment line ends with " sums=<16 hex>", the XXH3-64 hash of the
 * block that follows the pixels: W*(y1-y0)*3 IEEE 754 doubles,
 * little-endian, top row first, each the sum of the pixel channel's spp
 * samples in sample order; each pixel value is (float)(sum / spp), which
 * the reader checks to the bit.
 *
 * A path-traced PF partial may instead carry render passes (passes.h;
 * franja-worker --passes): the comment line ends with
 * " passes=<names>:<16 hex>", the passes' names comma-separated in their
 * fixed order and the XXH3-64 hash of the block that follows the pixels:
 * W*(y1-y0)*C IEEE 754 floats, little-endian, top row first (unlike the
 * PFM pixels), each pixel's C channels (pass_channels) in pass order.
 * The reader checks the hash and that every value is finite (normals and
 * positions may be negative).
 *
 * A bidirectional PF partial may carry both: the comment line ends with
 * " splat=<paths>:<16 hex> passes=<names>:<16 hex>", and the splat block
 * follows the pixels, the passes block the splat block (the passes
 * bidirectional path tracing fills, bdpt.h BD_PASSES).
 */
#ifndef FRANJA_IMAGE_H
#define FRANJA_IMAGE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "error.h"

/** Partial-image formats: PF (linear float PFM), P6 16-bit and 8-bit sRGB. */
typedef enum { IMG_PF = 0, IMG_PPM16, IMG_PPM8 } img_format;

/** What a partial image's header comment says about it. */
typedef struct {
    uint64_t scene;            /**< scene content hash */
    uint32_t y0, y1;           /**< rows of the full image */
    uint32_t spp;
    uint32_t width, height;    /**< size of the full image */
    uint64_t splat_paths;      /**< light subpaths whose splats follow the pixels; 0: no splat block */
    uint64_t splat_hash;       /**< img_read_partial: XXH3-64 of the splat block */
    size_t splat_offset;       /**< img_read_partial: where the splat block starts in the buffer */
    size_t sums_offset;        /**< img_read_partial: where the sums block starts; 0: none */
    uint32_t passes;           /**< render passes (passes.h mask) whose block follows the pixels; 0: none */
    size_t passes_offset;      /**< img_read_partial: where the passes block starts */
} img_partial_info;

/** Write rows (3 floats per pixel, top row first, width*(y1-y0) pixels) in
 * the given format, and when splat is not NULL (PF only) the splat block:
 * width*height*3 sums, top row first, for info->splat_paths light
 * subpaths (> 0).  Returns -1 with err set if writing fails or a P6 image
 * is given splats. */
int img_write(FILE *f, img_format fmt, const img_partial_info *info, const float *rgb, const uint64_t *splat,
              fr_error *err);

/** Write a PF partial with its sample sums (width*(y1-y0)*3 doubles, top
 * row first) after the pixels.  Returns -1 with err set if writing fails. */
int img_write_sums(FILE *f, const img_partial_info *info, const float *rgb, const double *sums, fr_error *err);

/** Write a PF partial with the render passes info->passes (not 0) after
 * the pixels: passes holds width*(y1-y0)*pass_channels(info->passes)
 * floats, top row first.  Returns -1 with err set if writing fails. */
int img_write_passes(FILE *f, const img_partial_info *info, const float *rgb, const float *passes, fr_error *err);

/** Write a bidirectional PF partial with its splat block (as img_write)
 * and then the render passes info->passes (as img_write_passes).
 * Returns -1 with err set if writing fails. */
int img_write_splat_passes(FILE *f, const img_partial_info *info, const float *rgb, const uint64_t *splat,
                           const float *passes, fr_error *err);

/** Copies the passes block of a partial that img_read_partial accepted with
 * passes != 0 into out (width*(y1-y0)*pass_channels(passes) floats, the
 * caller's), top row first. */
void img_passes_get(const unsigned char *buf, const img_partial_info *info, float *out);

/** Copies the sums block of a partial that img_read_partial accepted with
 * sums_offset != 0 into sums (width*(y1-y0)*3 doubles, the caller's). */
void img_sums_get(const unsigned char *buf, const img_partial_info *info, double *sums);

/** Parse a PF partial image held in buf[0..len).  Checks the magic, the
 * header comment, that the pixel rows match rows and width, that the
 * data length is exact (with the splat block, if the header announces one,
 * whose hash must match, or the sums block, whose hash must match and
 * whose every sum must be finite, >= 0 and give its pixel), and that every float is finite and >= 0 (a NaN,
 * infinity or negative value is refused, naming the pixel).  On success *rgb is a malloc'd array (caller
 * frees) of width*(y1-y0)*3 floats, top row first.  Errors give the byte
 * offset. */
int img_read_partial(const unsigned char *buf, size_t len, img_partial_info *info, float **rgb, fr_error *err);

/** Add the splat block of a partial that img_read_partial accepted (buf
 * and its info, splat_paths > 0) to acc (width*height*3 sums, top row
 * first), saturating as spl_add does. */
void img_splat_add(const unsigned char *buf, const img_partial_info *info, uint64_t *acc);

/** sRGB transfer curve of a linear value, clamped to [0,1]. */
float img_srgb_encode(float linear);

/** Parse "<name>" as pf|ppm16|ppm8; -1 if unknown. */
int img_format_parse(const char *name, img_format *fmt);

#endif
