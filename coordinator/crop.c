/* crop.c -- a window of the image (see crop.h). */
#include "crop.h"

#include <string.h>

/* One decimal number of at most 9 digits at *p, then the separator sep
 * ('\0': the end). */
static int number(const char **p, char sep, uint32_t *out)
{
    const char *s = *p;
    uint32_t v = 0;
    int n = 0;
    while (*s >= '0' && *s <= '9' && n < 9) {
        v = v * 10 + (uint32_t)(*s++ - '0');
        n++;
    }
    if (n == 0 || *s != sep)
        return -1;
    *out = v;
    *p = sep ? s + 1 : s;
    return 0;
}

int crop_parse(const char *text, crop_window *c, fr_error *err)
{
    const char *p = text;
    if (number(&p, ':', &c->x0) || number(&p, ':', &c->y0) || number(&p, ':', &c->x1) || number(&p, '\0', &c->y1))
        return fr_fail(err, "'%s' is not X0:Y0:X1:Y1 (pixels, the window [X0,X1) x [Y0,Y1), y down from the top)",
                       text);
    if (c->x0 >= c->x1 || c->y0 >= c->y1)
        return fr_fail(err, "'%s': the window is empty (X0 < X1 and Y0 < Y1 are needed)", text);
    return 0;
}

int crop_check(const crop_window *c, uint32_t width, uint32_t height, fr_error *err)
{
    if (c->x1 > width || c->y1 > height)
        return fr_fail(err, "%u:%u:%u:%u does not fit in the %ux%u image (X1 <= %u, Y1 <= %u)", c->x0, c->y0, c->x1,
                       c->y1, width, height, width, height);
    return 0;
}

void crop_black(const crop_window *c, float *rgb, uint32_t width, uint32_t height)
{
    crop_black_n(c, rgb, width, height, 3);
}

void crop_black_n(const crop_window *c, float *px, uint32_t width, uint32_t height, uint32_t channels)
{
    for (uint32_t y = 0; y < height; y++) {
        float *row = px + (size_t)y * width * channels;
        if (y < c->y0 || y >= c->y1) {
            memset(row, 0, (size_t)width * channels * sizeof *row);
            continue;
        }
        memset(row, 0, (size_t)c->x0 * channels * sizeof *row);
        memset(row + (size_t)c->x1 * channels, 0, (size_t)(width - c->x1) * channels * sizeof *row);
    }
}

void crop_extract(const crop_window *c, const float *rgb, uint32_t width, float *out)
{
    crop_extract_n(c, rgb, width, 3, out);
}

void crop_extract_n(const crop_window *c, const float *px, uint32_t width, uint32_t channels, float *out)
{
    size_t w = c->x1 - c->x0;
    for (uint32_t y = c->y0; y < c->y1; y++)
        memcpy(out + (size_t)(y - c->y0) * w * channels, px + ((size_t)y * width + c->x0) * channels,
               w * channels * sizeof *out);
}
