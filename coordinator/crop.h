/** @file crop.h
 * `franja render --crop X0:Y0:X1:Y1`: a window of the image, in pixels of
 * the full image (x to the right, y down from the top row), X1 and Y1
 * excluded.  The render runs only the window's rows (full rows, so its
 * slabs are those of any render of the same image and a job directory
 * serves both); the pixels outside the window are then made black, or
 * (`--crop-output`) the window alone is written.
 */
#ifndef FRANJA_CROP_H
#define FRANJA_CROP_H

#include <stdint.h>

#include "error.h"

/** A window [x0, x1) x [y0, y1) of the image. */
typedef struct {
    uint32_t x0, y0, x1, y1;
} crop_window;

/** Parses "X0:Y0:X1:Y1" (decimal integers, X0 < X1, Y0 < Y1).  Fails
 * saying what was expected. */
int crop_parse(const char *text, crop_window *c, fr_error *err);

/** Fails, naming the image size, unless the window lies inside a
 * width x height image. */
int crop_check(const crop_window *c, uint32_t width, uint32_t height, fr_error *err);

/** Sets every pixel of rgb (width*height*3 floats, top row first) outside
 * the window to black. */
void crop_black(const crop_window *c, float *rgb, uint32_t width, uint32_t height);

/** crop_black for pixels of `channels` floats (render passes). */
void crop_black_n(const crop_window *c, float *px, uint32_t width, uint32_t height, uint32_t channels);

/** crop_extract for pixels of `channels` floats (render passes). */
void crop_extract_n(const crop_window *c, const float *px, uint32_t width, uint32_t channels, float *out);

/** Copies the window's pixels of rgb (width pixels a row) into out
 * ((x1-x0)*(y1-y0)*3 floats, the caller's), top row first. */
void crop_extract(const crop_window *c, const float *rgb, uint32_t width, float *out);

#endif
