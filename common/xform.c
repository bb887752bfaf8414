/* xform.c -- reversible byte transforms of arrays before compression (see
 * xform.h). */
#include "xform.h"

#include <string.h>

void xform_shuffle(const unsigned char *in, size_t n, unsigned char *out, int undo)
{
    size_t words = n / 4;
    for (size_t i = 0; i < words; i++)
        for (size_t b = 0; b < 4; b++) {
            if (undo)
                out[4 * i + b] = in[b * words + i];
            else
                out[b * words + i] = in[4 * i + b];
        }
}

/* Value i of img (`bytes` bytes, little-endian). */
static inline uint32_t value(const unsigned char *img, size_t i, uint32_t bytes)
{
    return bytes == 1 ? img[i] : (uint32_t)img[2 * i] | (uint32_t)img[2 * i + 1] << 8;
}

static inline void store(unsigned char *p, size_t i, uint32_t bytes, uint32_t v)
{
    if (bytes == 1) {
        p[i] = (unsigned char)v;
    } else {
        p[2 * i] = (unsigned char)v;
        p[2 * i + 1] = (unsigned char)(v >> 8);
    }
}

/* xform_predict for one value size (inlined with a constant `bytes`, so
 * that each size gets its own loop). */
static inline __attribute__((always_inline)) void predict(unsigned char *img, uint32_t w, uint32_t n,
                                                          uint32_t bytes, size_t from, size_t to,
                                                          unsigned char *res, int undo)
{
    size_t row = (size_t)w * n;
    uint32_t mask = bytes == 1 ? 0xffu : 0xffffu;
    size_t y = from / row;
    uint32_t x = (uint32_t)(from % row / n), c = (uint32_t)(from % n);
    for (size_t i = from; i < to; i++) {
        uint32_t a, b, cc, d;
        if (y == 0) {
            a = x ? value(img, i - n, bytes) : 0;
            b = cc = d = a;
        } else {
            b = value(img, i - row, bytes);
            a = x ? value(img, i - n, bytes) : b;
            cc = x ? value(img, i - row - n, bytes) : b;
            d = x + 1 < w ? value(img, i - row + n, bytes) : b;
        }
        uint32_t p = (a + b + cc + d + 2) >> 2;
        if (undo)
            store(img, i, bytes, (value(res, i - from, bytes) + p) & mask);
        else
            store(res, i - from, bytes, (value(img, i, bytes) - p) & mask);
        if (++c == n) {
            c = 0;
            if (++x == w) {
                x = 0;
                y++;
            }
        }
    }
}

void xform_predict(unsigned char *img, uint32_t w, uint32_t n, uint32_t bytes, size_t from, size_t to,
                   unsigned char *res, int undo)
{
    if (bytes == 1)
        predict(img, w, n, 1, from, to, res, undo);
    else
        predict(img, w, n, 2, from, to, res, undo);
}
