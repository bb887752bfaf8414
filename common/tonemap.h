/** @file tonemap.h
 * From linear radiance to display values, once, after the
 * slabs are stitched: exposure (2^stops), an optional filmic curve, then
 * the sRGB transfer curve.  HDR outputs skip all of this and keep linear
 * radiance.  Same bits everywhere (fmath.h only).
 */
#ifndef FRANJA_TONEMAP_H
#define FRANJA_TONEMAP_H

#include "scene.h"

/** Display value in [0, 1] (sRGB-encoded) of one linear channel value. */
float tm_display(const fr_tonemap *t, float linear);

/** The filmic curve alone (Hable 2010, normalized so that linear 11.2 maps
 * to 1): a toe that deepens shadows slightly and a shoulder that rolls
 * highlights off instead of clipping them; 0 maps to 0, increasing. */
float tm_filmic(float x);

/** Parse "none" or "filmic" into *curve (FR_CURVE_*); -1 if neither. */
int tm_curve_parse(const char *name, uint32_t *curve);

#endif
