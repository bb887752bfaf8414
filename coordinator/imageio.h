/** @file imageio.h
 * The coordinator's bridge to OpenImageIO (imageio.cpp, the one C++ file):
 * encodes a finished image in the format its file name's extension names,
 * and reads images (textures).
 *
 * imageio.cpp is built as the plug-in franja-imageio.so, which franja
 * loads on the first call of a function below (imageio_load.c), so that a
 * run that needs no image library does not load OpenImageIO's 250 shared
 * libraries.  Where the plug-in is missing or does not load, every
 * function fails (iio_can_write returns 0) and iio_unavailable says why.
 */
#ifndef FRANJA_IMAGEIO_H
#define FRANJA_IMAGEIO_H

#include <stddef.h>
#include <stdint.h>

#include "error.h"

/** Pixel types: iio_encode_with accepts the first three, iio_read gives
 * any (IIO_F16: IEEE 754 binary16 bits in uint16_t). */
typedef enum { IIO_U8 = 0, IIO_U16, IIO_F32, IIO_F16 } iio_type;

/** How iio_encode_with stores an image, where the format allows. */
typedef struct {
    int half;                  /**< float pixels stored as half floats (OpenEXR) */
    const char *compression;   /**< OpenImageIO's "compression" name (OpenEXR: none, rle, zips, zip, piz,
                                    pxr24, b44, b44a, dwaa, dwab); NULL: the writer's default */
    int quality;               /**< JPEG quality 1..100; 0: the writer's default */
    const char *const *attrs;  /**< string attributes to store: name, value, name, value ..., NULL; or NULL.
                                    "Software" and "ImageDescription" reach every format that has them
                                    (PNG text chunks, TIFF tags, EXR, JPEG); other names (say
                                    "franja:spp") only formats with free-form attributes (OpenEXR) */
    uint32_t channels;         /**< channels per pixel of float pixels (OpenEXR); 0: 3 (RGB) */
    const char *const *channel_names; /**< with channels: their names, as OpenEXR stores them */
} iio_options;

/** Encodes width x height RGB pixels (top row first, 3 values of `type`
 * per pixel, or o->channels floats named o->channel_names) in the format the extension of `name` names (png, exr, tif,
 * jpg, hdr, bmp, tga, ppm ...), into memory: *data (malloc'd, the caller
 * frees) receives the *len bytes of the file, which the caller writes.
 * Nothing is written to disk, so a full file system cannot truncate the
 * image or end the process (libjpeg exits on a failed write).  Options
 * (o; NULL: none) a format does not have are ignored by its writer.
 * Fails, naming `name`, with OpenImageIO's message or for lack of memory;
 * *data is then NULL. */
int iio_encode_with(const char *name, const void *pixels, iio_type type, uint32_t width, uint32_t height,
                    const iio_options *o, unsigned char **data, size_t *len, fr_error *err);

/** Where iio_read may decode an image instead of malloc'ing it. */
typedef struct iio_dest {
    /** Called once the image's size, channels and type are known: where
     * to decode it, keeping the first *keep (1 to channels) channels of
     * each pixel, or NULL: malloc it whole. */
    void *(*at)(const struct iio_dest *d, uint32_t width, uint32_t height, uint32_t channels, iio_type type,
                uint32_t *keep);
} iio_dest;

/** Decodes the first image of the file `name`, whose `len` bytes the
 * caller has read into `data` (OpenImageIO opens no file: the reader is
 * chosen by name's extension), at its own precision: *pixels holds
 * width*height*channels values of *type, top row first, as stored (no
 * colour conversion): 8-bit files as IIO_U8, 16-bit ones as IIO_U16,
 * half-float ones as IIO_F16, every other type (float, 32-bit integers
 * ...) as IIO_F32 (integers scaled to [0, 1]).  *pixels is where `dest`
 * said (dest NULL, or its `at` NULL: malloc'd, the caller frees), and
 * *channels then the channels kept; on failure *pixels is NULL.  Fails
 * for an unknown extension, undecodable bytes (without quoting them) and
 * images over 2^29 values. */
int iio_read(const char *name, const void *data, size_t len, const iio_dest *dest, void **pixels, iio_type *type,
             uint32_t *width, uint32_t *height, uint32_t *channels, fr_error *err);

/** Reads an image held in memory (`len` bytes of a PNG or JPEG file, told
 * apart by their signatures, else by `mime`) as iio_read does a file.
 * Fails for other formats and for undecodable bytes. */
int iio_read_mem(const void *data, size_t len, const char *mime, const iio_dest *dest, void **pixels,
                 iio_type *type, uint32_t *width, uint32_t *height, uint32_t *channels, fr_error *err);

/** Returns 1 if OpenImageIO has a writer for the file name's extension. */
int iio_can_write(const char *path);

/** NULL when the plug-in is loaded (loading it if need be), else a
 * sentence saying why it cannot be (not installed, not loadable). */
const char *iio_unavailable(void);

#endif
