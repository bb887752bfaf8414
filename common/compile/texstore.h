/** @file texstore.h
 * Storing a decoded image as an image texture (compile time): the texel
 * format that keeps the file's precision, and its mip levels.
 *
 * Formats (scene.h, FR_TEXEL_*): an 8-bit image is stored as bytes (sRGB-
 * encoded when it is decoded as sRGB, so the lookup's table decodes it),
 * a 16-bit one as 16-bit integers, a half-float one as halves; a float
 * image as halves when every value lies within half's range (|v| <=
 * 65504: rounded to nearest even, a relative error of at most 2^-11, or
 * 2^-25 absolute below 2^-14), else as floats.  A float or half image
 * that must be sRGB-decoded (rare: a "colorspace" asked for it) is
 * decoded and stored as floats.  Three or
 * four channels keep three (RGB; alpha is not used), one or two keep one.
 *
 * Mip levels: mip.h builds them (level k down to 1 x 1, each the box
 * filter of the one above, rounded by mip_encode).
 */
#ifndef FRANJA_TEXSTORE_H
#define FRANJA_TEXSTORE_H

#include "compile/builder.h"
#include "compile/scene_hooks.h"

/** Append image `img` with its mip levels to b->texels and fill tex's
 * image fields (width, height, channels, format, levels, first);
 * `from_srgb` decodes the sRGB curve (at lookup, for integer images).
 * An image decoded through texstore_target is already level 0 and is
 * not copied.
 * Fails (naming `where`) on an empty or oversized image, a non-finite
 * value, or when the scene's texels would pass 2^31 words (8 GiB). */
int texstore_image(fr_builder *b, const scene_image *img, int from_srgb, fr_texture *tex, const char *where,
                   fr_error *err);

/** A scene_image_dest (scene_hooks.h) that has an image decoded straight
 * into b->texels, where texstore_image then takes it as level 0, so the
 * decoded image is not held beside its texels: for 8- and 16-bit images
 * and half-float ones not sRGB-decoded, whose level 0 is the values as
 * decoded (the first 3 channels of 3 or 4, the first of 1 or 2); for
 * other images `at` returns NULL (the hook mallocs them).  It only
 * reserves room: texstore_image must follow, with the same builder and
 * from_srgb, before anything else appends texels. */
typedef struct {
    scene_image_dest dest;     /**< first, so that hooks are given &t.dest */
    fr_builder *b;
    int from_srgb;
} texstore_target;

/** Set *t up for builder b and from_srgb (as texstore_image's). */
void texstore_target_init(texstore_target *t, fr_builder *b, int from_srgb);

#endif
