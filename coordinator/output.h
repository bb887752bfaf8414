/** @file output.h
 * The final image: tone mapping (once, after stitching) and an atomic write
 * in the format the file name's extension names (PFM for a character device
 * or named pipe whose name has none, such as /dev/null or /dev/stdout).
 *
 * HDR outputs (.exr, .hdr, .pfm) keep linear radiance and ignore the tone
 * mapping; LDR outputs (.png, .jpg, .bmp, .ppm 8-bit; .tif 16-bit) are
 * tone-mapped by common/tonemap.h: scaled by 2^exposure, optionally
 * through the filmic curve, then sRGB-encoded and clamped.  A .pfm is written
 * by Franja itself (OpenImageIO has no PFM writer) with the same header a
 * one-process worker render of the whole image has, so the two files can
 * be compared byte for byte.
 */
#ifndef FRANJA_OUTPUT_H
#define FRANJA_OUTPUT_H

#include "error.h"
#include "imageio.h"
#include "jobdir.h"
#include "scene.h"

/** What a final image says about itself in its header (out_meta_make). */
typedef struct {
    char software[64];         /**< "Franja VERSION" */
    char scene[24], spp[16], integrator[16], seconds[32];
    char hosts[1024];          /**< host names, comma-separated */
    char desc[1400];           /**< the figures above in one line, ImageDescription */
    char datetime[24];         /**< DateTime "YYYY:MM:DD HH:MM:SS", UTC; "" = the time of the write */
    const char *attrs[19];     /**< name, value pairs, NULL-terminated: iio_options.attrs */
} out_meta;

/** Fills m with the metadata of a final image of spec: Software "Franja
 * VERSION"; ImageDescription "Franja VERSION render; scene HASH; N spp;
 * integrator NAME; render time S s; hosts A,B" (the time left out when
 * seconds < 0, the hosts when hosts is NULL or empty); and the same
 * figures as OpenEXR string attributes franja:version, franja:scene,
 * franja:spp, franja:integrator, franja:render_time (seconds) and
 * franja:hosts.  m->attrs points into m: pass m->attrs as
 * iio_options.attrs while m lives.  Long host lists are cut at a name
 * boundary with ",...". */
void out_meta_make(out_meta *m, const job_spec *spec, double seconds, const char *hosts);

/** Gives m a fixed DateTime (TIFF and OpenEXR headers, which otherwise
 * get the time of the write): `epoch` seconds since 1970, UTC; a value
 * out of the years 1970..9999 gives 1970:01:01 00:00:00. */
void out_meta_set_time(out_meta *m, long long epoch);

/** Whether path's extension is ext (without the dot, any case). */
int out_has_ext(const char *path, const char *ext);

/** Fails if no writer handles the path's extension. */
int out_check_type(const char *path, fr_error *err);

/** Fails, before any rendering, if no writer handles the path's extension,
 * if path is a directory, or if no file can be created beside it (the trial
 * file is removed at once). */
int out_check(const char *path, fr_error *err);

/** Encodes rgb (width*height*3 linear floats, top row first) in memory as
 * the file path would hold it (by its extension; LDR types tone-mapped by
 * tm): *data (malloc'd, the caller frees) receives *len bytes.  Nothing is
 * written.  Fails, naming path, for lack of memory or with the encoder's
 * message; *data is then NULL. */
int out_encode(const char *path, const float *rgb, const job_spec *spec, const fr_tonemap *tm, unsigned char **data,
               size_t *len, fr_error *err);

/** out_write with the writer's options o (imageio.h; NULL: none). */
int out_write_with(const char *path, const float *rgb, const job_spec *spec, const fr_tonemap *tm,
                   const iio_options *o, fr_error *err);

/** Writes rgb (width*height*3 linear floats, top row first) to path via a
 * temporary file in the same directory and a rename, so path is either the
 * old file or the complete new one. */
int out_write(const char *path, const float *rgb, const job_spec *spec, const fr_tonemap *tm, fr_error *err);

#endif
