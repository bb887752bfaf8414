/* cont.c -- the sums of an earlier render of a slab (see cont.h). */
#include "cont.h"

#include <stdlib.h>

#include "file.h"
#include "image.h"

int cont_load(const char *path, const fr_scene *sc, uint32_t y0, uint32_t y1, double *sums, uint32_t *first,
              fr_error *err)
{
    char *buf;
    size_t len;
    if (file_read(path, &buf, &len, err) < 0)
        return -1;
    img_partial_info info;
    float *rgb = NULL;
    fr_error e;
    int rc = 0;
    if (img_read_partial((const unsigned char *)buf, len, &info, &rgb, &e) < 0)
        rc = fr_fail(err, "--continue %s: %s", path, e.msg);
    else if (info.scene != sc->hash)
        rc = fr_fail(err, "--continue %s: another scene (%016llx, not %016llx)", path, (unsigned long long)info.scene,
                     (unsigned long long)sc->hash);
    else if (info.width != sc->settings.width || info.height != sc->settings.height || info.y0 != y0 ||
             info.y1 != y1)
        rc = fr_fail(err, "--continue %s: rows %u:%u of a %ux%u image, not rows %u:%u of %ux%u", path, info.y0,
                     info.y1, info.width, info.height, y0, y1, sc->settings.width, sc->settings.height);
    else if (!info.sums_offset)
        rc = fr_fail(err, "--continue %s: has no sample sums (render it with --sums)", path);
    else if (info.spp > sc->settings.spp)
        rc = fr_fail(err, "--continue %s: has %u samples per pixel, more than the %u asked for", path, info.spp,
                     sc->settings.spp);
    if (rc == 0) {
        img_sums_get((const unsigned char *)buf, &info, sums);
        *first = info.spp;
    }
    free(rgb);
    free(buf);
    return rc;
}
