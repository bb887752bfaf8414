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
#include <unistd.h>

#include "file.h"
#include "image.h"
#include "imageio.h"

static const char *extension(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash : path, '.');
    return dot ? dot + 1 : "";
}

static int is_ext(const char *path, const char *ext) { return !strcasecmp(extension(path), ext); }

int out_check(const char *path, fr_error *err)
{
    if (is_ext(path, "pfm") || (*extension(path) && iio_can_write(path)))
        return 0;
    return fr_fail(err, "%s: unknown image type '%s': expected .png, .exr, .tif, .jpg, .hdr, .ppm, .bmp "
                   "or .pfm", path, extension(path));
}

static int write_pfm(file_out *o, const float *rgb, const job_spec *spec, fr_error *err)
{
    int fd = dup(o->fd);
    FILE *f = fd >= 0 ? fdopen(fd, "wb") : NULL;
    if (!f) {
        if (fd >= 0)
            close(fd);
        return fr_fail(err, "%s: %s", o->tmp, strerror(errno));
    }
    img_partial_info info = {.scene = spec->hash, .y1 = spec->height, .spp = spec->spp, .width = spec->width,
                             .height = spec->height};
    int rc = img_write(f, IMG_PF, &info, rgb, NULL, err);
    if (fclose(f) && rc == 0)
        rc = fr_fail(err, "%s: %s", o->tmp, strerror(errno));
    return rc;
}

int out_write(const char *path, const float *rgb, const job_spec *spec, const fr_tonemap *tm, fr_error *err)
{
    /* OpenImageIO writes by name: into the temporary file file_out_open
     * made (same extension, so the same format), which the commit renames. */
    file_out o;
    if (file_out_open(path, &o, err))
        return -1;
    const char *tmp = o.tmp;
    size_t n = (size_t)spec->width * spec->height * 3;
    int rc;
    if (is_ext(path, "pfm")) {
        rc = write_pfm(&o, rgb, spec, err);
    } else if (is_ext(path, "exr") || is_ext(path, "hdr")) {
        rc = iio_write(tmp, rgb, IIO_F32, spec->width, spec->height, err);
    } else {
        int wide = is_ext(path, "tif") || is_ext(path, "tiff");
        void *px = malloc(n * (wide ? 2 : 1));
        if (!px) {
            file_out_abort(&o);
            return fr_fail(err, "out of memory for the final image");
        }
        for (size_t i = 0; i < n; i++) {
            float v = tm_display(tm, rgb[i]);
            if (wide)
                ((uint16_t *)px)[i] = (uint16_t)(v * 65535.0f + 0.5f);
            else
                ((uint8_t *)px)[i] = (uint8_t)(v * 255.0f + 0.5f);
        }
        rc = iio_write(tmp, px, wide ? IIO_U16 : IIO_U8, spec->width, spec->height, err);
        free(px);
    }
    if (rc) {
        file_out_abort(&o);
        return rc;
    }
    return file_out_commit(&o, path, err);
}
