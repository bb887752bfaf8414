/* output.c -- tone mapping and the atomic write of the final image. */
#include "output.h"

#include "tonemap.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "file.h"
#include "image.h"
#include "imageio.h"
#include "protocol.h"

static const char *extension(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash : path, '.');
    return dot ? dot + 1 : "";
}

static int is_ext(const char *path, const char *ext) { return !strcasecmp(extension(path), ext); }

int out_has_ext(const char *path, const char *ext) { return is_ext(path, ext); }

/* PFM is written to a path ending in .pfm, and to a stream file_out
 * writes in place whose name has no extension (/dev/null, /dev/stdout, a
 * named pipe): it has no name to choose a format by, and PFM is the one
 * written without OpenImageIO. */
static int is_pfm(const char *path) { return is_ext(path, "pfm") || (!*extension(path) && file_out_in_place(path)); }

void out_meta_make(out_meta *m, const job_spec *spec, double seconds, const char *hosts)
{
    memset(m, 0, sizeof *m);
    snprintf(m->software, sizeof m->software, "Franja %s", FRANJA_VERSION);
    snprintf(m->scene, sizeof m->scene, "%016llx", (unsigned long long)spec->hash);
    snprintf(m->spp, sizeof m->spp, "%u", spec->spp);
    const char *integ = proto_integrator_name((int)spec->integrator);
    snprintf(m->integrator, sizeof m->integrator, "%s", integ ? integ : "unknown");
    if (seconds >= 0)
        snprintf(m->seconds, sizeof m->seconds, "%.2f", seconds);
    /* Whole names only: a list too long ends with ",...". */
    size_t n = 0, cap = sizeof m->hosts - 5;
    for (const char *h = hosts ? hosts : ""; *h;) {
        size_t k = strcspn(h, ",");
        if (k && n + (n > 0) + k > cap) {
            strcpy(m->hosts + n, n ? ",..." : "...");
            break;
        }
        if (k) {
            if (n)
                m->hosts[n++] = ',';
            memcpy(m->hosts + n, h, k);
            n += k;
            m->hosts[n] = 0;
        }
        h += k + (h[k] == ',');
    }
    int len = snprintf(m->desc, sizeof m->desc, "%s render; scene %s; %s spp; integrator %s", m->software, m->scene,
                       m->spp, m->integrator);
    if (m->seconds[0] && len >= 0 && (size_t)len < sizeof m->desc)
        len += snprintf(m->desc + len, sizeof m->desc - (size_t)len, "; render time %s s", m->seconds);
    if (m->hosts[0] && len >= 0 && (size_t)len < sizeof m->desc)
        snprintf(m->desc + len, sizeof m->desc - (size_t)len, "; hosts %s", m->hosts);
    const char **a = m->attrs;
    *a++ = "Software", *a++ = m->software;
    *a++ = "ImageDescription", *a++ = m->desc;
    *a++ = "franja:version", *a++ = FRANJA_VERSION;
    *a++ = "franja:scene", *a++ = m->scene;
    *a++ = "franja:spp", *a++ = m->spp;
    *a++ = "franja:integrator", *a++ = m->integrator;
    if (m->seconds[0])
        *a++ = "franja:render_time", *a++ = m->seconds;
    if (m->hosts[0])
        *a++ = "franja:hosts", *a++ = m->hosts;
    *a = NULL;
}

void out_meta_set_time(out_meta *m, long long epoch)
{
    if (epoch < 0 || epoch > 253402300799LL)
        epoch = 0;
    time_t t = (time_t)epoch;
    struct tm tm;
    gmtime_r(&t, &tm);
    strftime(m->datetime, sizeof m->datetime, "%Y:%m:%d %H:%M:%S", &tm);
    const char **a = m->attrs;
    while (*a)
        a++;
    *a++ = "DateTime", *a++ = m->datetime;
    *a = NULL;
}

int out_check_type(const char *path, fr_error *err)
{
    if (is_pfm(path))
        return 0;
    const char *why = iio_unavailable();
    if (why)
        return fr_fail(err, "%s: only .pfm can be written: %s", path, why);
    if (!(*extension(path) && iio_can_write(path)))
        return fr_fail(err, "%s: unknown image type '%s': expected .png, .exr, .tif, .jpg, .hdr, .ppm, .bmp, "
                       ".tga or .pfm", path, extension(path));
    return 0;
}

int out_check(const char *path, fr_error *err)
{
    if (out_check_type(path, err))
        return -1;
    /* Before any rendering: the output is not a directory the rename could
     * not replace, and a file can be made beside it (the directory exists
     * and is writable); the trial file is removed at once. */
    struct stat st;
    if (lstat(path, &st) == 0 && S_ISDIR(st.st_mode))
        return fr_fail(err, "%s: is a directory", path);
    /* A device or named pipe is written in place at the end: opened now,
     * a pipe's reader would see its end before the image. */
    if (file_out_in_place(path)) {
        if (access(path, W_OK))
            return fr_fail(err, "%s: cannot write: %s", path, strerror(errno));
        return 0;
    }
    file_out o;
    if (file_out_open(path, &o, err))
        return -1;
    file_out_abort(&o);
    return 0;
}

/* The PFM file in memory: the header a one-process worker render has. */
static int encode_pfm(const char *path, const float *rgb, const job_spec *spec, unsigned char **data, size_t *len,
                      fr_error *err)
{
    char *buf = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&buf, &n);
    if (!f)
        return fr_fail(err, "%s: out of memory for the encoded image", path);
    img_partial_info info = {.scene = spec->hash, .y1 = spec->height, .spp = spec->spp, .width = spec->width,
                             .height = spec->height};
    int rc = img_write(f, IMG_PF, &info, rgb, NULL, err);
    if (fclose(f) && rc == 0)
        rc = fr_fail(err, "%s: out of memory for the encoded image", path);
    if (rc) {
        free(buf);
        return -1;
    }
    *data = (unsigned char *)buf;
    *len = n;
    return 0;
}

/* out_encode with the writer's options o (imageio.h; NULL: none). */
static int out_encode_with(const char *path, const float *rgb, const job_spec *spec, const fr_tonemap *tm,
                           const iio_options *o, unsigned char **data, size_t *len, fr_error *err)
{
    /* Encoded in memory: OpenImageIO's writers do not all report a failed
     * write, and libjpeg's exits. */
    size_t n = (size_t)spec->width * spec->height * 3;
    *data = NULL;
    *len = 0;
    if (is_pfm(path))
        return encode_pfm(path, rgb, spec, data, len, err);
    if (is_ext(path, "exr") || is_ext(path, "hdr"))
        return iio_encode_with(path, rgb, IIO_F32, spec->width, spec->height, o, data, len, err);
    int wide = is_ext(path, "tif") || is_ext(path, "tiff");
    void *px = malloc(n * (wide ? 2 : 1));
    if (!px)
        return fr_fail(err, "%s: out of memory for the final image", path);
    for (size_t i = 0; i < n; i++) {
        float v = tm_display(tm, rgb[i]);
        if (wide)
            ((uint16_t *)px)[i] = (uint16_t)(v * 65535.0f + 0.5f);
        else
            ((uint8_t *)px)[i] = (uint8_t)(v * 255.0f + 0.5f);
    }
    int rc = iio_encode_with(path, px, wide ? IIO_U16 : IIO_U8, spec->width, spec->height, o, data, len, err);
    free(px);
    return rc;
}

int out_encode(const char *path, const float *rgb, const job_spec *spec, const fr_tonemap *tm, unsigned char **data,
               size_t *len, fr_error *err)
{
    return out_encode_with(path, rgb, spec, tm, NULL, data, len, err);
}

int out_write(const char *path, const float *rgb, const job_spec *spec, const fr_tonemap *tm, fr_error *err)
{
    return out_write_with(path, rgb, spec, tm, NULL, err);
}

int out_write_with(const char *path, const float *rgb, const job_spec *spec, const fr_tonemap *tm,
                   const iio_options *o, fr_error *err)
{
    /* file_write_atomic checks every write, the fsync and the close before
     * the rename. */
    unsigned char *data = NULL;
    size_t len = 0;
    int rc = out_encode_with(path, rgb, spec, tm, o, &data, &len, err);
    if (rc == 0) {
        fr_error e;
        if (file_write_atomic(path, data, len, &e))
            rc = fr_fail(err, "%s: not written (%zu bytes): %s", path, len, e.msg);
    }
    free(data);
    return rc;
}
