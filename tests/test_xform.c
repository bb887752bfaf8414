/* test_xform.c -- the byte transforms of packed scenes (common/xform.h):
 * the shuffle and the texel predictor are undone bit for bit, whatever
 * the image's width (1 texel too), channels (1, 3) and value size (1, 2
 * bytes) and however the values are cut into runs; the predictor's
 * residuals of a smooth image are small and those of a flat one zero
 * after the first texel; the shuffle puts byte k of each word in plane k. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "xform.h"

static uint32_t rnd(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

int main(void)
{
    uint32_t seed = 7;
    /* Shuffle: planes, and back. */
    unsigned char w[16], sh[16], back[16];
    for (int i = 0; i < 16; i++)
        w[i] = (unsigned char)(16 * (i % 4) + i / 4);   /* byte k of word j: 16k + j */
    xform_shuffle(w, 16, sh, 0);
    int planes = 1;
    for (int i = 0; i < 16; i++)
        planes &= sh[i] == 16 * (i / 4) + i % 4;     /* plane k, word j at 4k + j */
    CHECK(planes, "byte k of each word in plane k");
    xform_shuffle(sh, 16, back, 1);
    CHECK(!memcmp(back, w, 16), "shuffled back");

    const uint32_t widths[] = {1, 2, 5, 64}, chans[] = {1, 3};
    for (size_t wi = 0; wi < 4; wi++)
        for (size_t ci = 0; ci < 2; ci++)
            for (uint32_t bytes = 1; bytes <= 2; bytes++) {
                uint32_t wd = widths[wi], n = chans[ci], h = 9;
                size_t values = (size_t)wd * h * n, len = values * bytes;
                unsigned char *img = malloc(len), *res = malloc(len), *got = calloc(len, 1);
                for (size_t i = 0; i < len; i++)
                    img[i] = (unsigned char)rnd(&seed);
                xform_predict(img, wd, n, bytes, 0, values, res, 0);
                /* Undone in runs of 1 to 7 values. */
                for (size_t v = 0, step = 1; v < values; v += step, step = step % 7 + 1) {
                    size_t end = v + step < values ? v + step : values;
                    xform_predict(got, wd, n, bytes, v, end, res + v * bytes, 1);
                }
                CHECK(!memcmp(img, got, len), "width %u, %u channels, %u bytes: undone exactly", wd, n, bytes);
                /* Residuals made in runs are those made at once. */
                unsigned char *res2 = malloc(len);
                for (size_t v = 0; v < values; v += 5)
                    xform_predict(img, wd, n, bytes, v, v + 5 < values ? v + 5 : values, res2 + v * bytes, 0);
                CHECK(!memcmp(res, res2, len), "width %u, %u channels, %u bytes: residuals in runs", wd, n, bytes);
                free(img);
                free(res);
                free(res2);
                free(got);
            }

    /* A flat image: zero residuals after the first texel; a ramp: small. */
    enum { W = 32, H = 8 };
    unsigned char flat[W * H * 3], ramp[W * H], r1[W * H * 3];
    memset(flat, 200, sizeof flat);
    xform_predict(flat, W, 3, 1, 0, W * H * 3, r1, 0);
    int zero = r1[0] == 200 && r1[1] == 200 && r1[2] == 200;
    for (int i = 3; i < W * H * 3; i++)
        zero &= r1[i] == 0;
    CHECK(zero, "a flat image: its first texel, then zeros");
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            ramp[y * W + x] = (unsigned char)(3 * x + 2 * y);
    xform_predict(ramp, W, 1, 1, 0, W * H, r1, 0);
    int small = 1;
    for (int y = 1; y < H; y++)
        for (int x = 1; x < W - 1; x++) {
            int8_t e = (int8_t)r1[y * W + x];
            small &= e >= -3 && e <= 3;
        }
    CHECK(small, "a ramp: residuals within 3 inside the image");
    return check_done();
}
