/* mip.c -- mip levels of image textures, and rounding to a texel format
 * (see mip.h). */
#include "mip.h"

#include <math.h>
#include <pthread.h>
#include <string.h>

#include "fmath.h"
#include "texture.h"

/* Binary16 bits nearest to v (round to nearest even; infinity past the
 * largest half, NaN kept a NaN). */
static uint16_t half_bits(double v)
{
    uint16_t sign = signbit(v) ? 0x8000u : 0;
    double a = fabs(v);
    if (isnan(v))
        return 0x7e00u;
    if (a >= 65520.0)                       /* halfway to 2^16 and beyond */
        return sign | 0x7c00u;
    if (a < 0x1p-14) {                      /* subnormal: multiples of 2^-24 */
        double q = nearbyint(a * 0x1p24);   /* exact scaling; ties to even */
        return sign | (uint16_t)q;          /* q = 1024 is the smallest normal */
    }
    int e;
    frexp(a, &e);                           /* a = f 2^e, f in [0.5, 1) */
    double q = nearbyint(ldexp(a, 11 - e)); /* 11 significant bits: [1024, 2048] */
    if (q == 2048.0) {
        q = 1024.0;
        e++;
    }
    if (e - 1 > 15)
        return sign | 0x7c00u;
    return sign | (uint16_t)((uint32_t)(e - 1 + 15) << 10 | ((uint32_t)q - 1024u));
}

/* The linear value of sRGB code k of `maxcode` + 1 codes, as lookups decode it. */
static double srgb_decoded(uint32_t k, uint32_t maxcode)
{
    return tex_srgb_to_linear((float)k / (float)maxcode);
}

/* The sRGB code nearest (in decoded value) to linear v; ties to the lower. */
static uint32_t srgb_nearest(double v, uint32_t maxcode)
{
    if (!(v > 0.0))
        return 0;
    if (v >= 1.0)
        return maxcode;
    float fv = (float)v;
    float e = fv <= 0.0031308f ? 12.92f * fv : 1.055f * fm_powf(fv, 1.0f / 2.4f) - 0.055f;
    double g = nearbyint((double)e * maxcode);
    long c0 = (long)g - 2, best = -1;
    double bd = 0.0;
    for (long c = c0 < 0 ? 0 : c0; c <= (long)g + 2 && c <= (long)maxcode; c++) {
        double d = fabs(srgb_decoded((uint32_t)c, maxcode) - v);
        if (best < 0 || d < bd) {
            best = c;
            bd = d;
        }
    }
    return (uint32_t)best;
}

/* Midpoints between the decoded values of consecutive 8-bit sRGB codes:
 * the nearest code to v is the number of midpoints below v (a tie, v on a
 * midpoint, goes to the lower code). */
static double srgb8_mid[255];
/* srgb8_below[b]: the number of midpoints below b / SRGB8_BUCKETS, where
 * the count for v in bucket b starts (a few steps at most). */
enum { SRGB8_BUCKETS = 4096 };
static uint8_t srgb8_below[SRGB8_BUCKETS];
/* The decoded value of each 8-bit sRGB code, as lookups decode it (the
 * same floats as texture.c's table: test_texture checks that one). */
static float srgb8_linear[256];
static pthread_once_t srgb8_once = PTHREAD_ONCE_INIT;

static void srgb8_init(void)
{
    for (uint32_t k = 0; k < 256; k++)
        srgb8_linear[k] = tex_srgb_to_linear((float)k / 255.0f);
    for (uint32_t k = 0; k < 255; k++)
        srgb8_mid[k] = 0.5 * (srgb_decoded(k, 255) + srgb_decoded(k + 1, 255));
    uint32_t k = 0;
    for (uint32_t b = 0; b < SRGB8_BUCKETS; b++) {
        while (k < 255 && srgb8_mid[k] < (double)b / SRGB8_BUCKETS)
            k++;
        srgb8_below[b] = (uint8_t)k;
    }
}

static uint32_t srgb8_nearest(double v)
{
    pthread_once(&srgb8_once, srgb8_init);
    if (!(v > srgb8_mid[0]))
        return 0;
    if (v > srgb8_mid[254])
        return 255;
    /* 0 < v < 1: b / SRGB8_BUCKETS <= v (the scaling is exact). */
    uint32_t k = srgb8_below[(uint32_t)(v * SRGB8_BUCKETS)];
    while (srgb8_mid[k] < v)   /* k < 255: srgb8_mid[254] >= v */
        k++;
    return k;
}

uint32_t mip_encode(uint32_t format, double v)
{
    switch (format) {
    case FR_TEXEL_U8_SRGB:
        return v != v ? 0 : srgb8_nearest(v);
    case FR_TEXEL_U16_SRGB:
        return srgb_nearest(v, 65535);
    case FR_TEXEL_U8:
    case FR_TEXEL_U16: {
        double m = format == FR_TEXEL_U8 ? 255.0 : 65535.0;
        return !(v > 0.0) ? 0 : v >= 1.0 ? (uint32_t)m : (uint32_t)floor(v * m + 0.5);
    }
    case FR_TEXEL_F16:
        return half_bits(v);
    default: {
        float f = (float)v;
        uint32_t b;
        memcpy(&b, &f, sizeof b);
        return b;
    }
    }
}

void mip_put(unsigned char *p, size_t i, uint32_t bytes, uint32_t code)
{
    if (bytes == 1) {
        p[i] = (unsigned char)code;
    } else if (bytes == 2) {
        uint16_t h = (uint16_t)code;
        memcpy(p + 2 * i, &h, 2);
    } else {
        memcpy(p + 4 * i, &code, 4);
    }
}

/* The raw integer of value i of a level (8- or 16-bit formats). */
static uint32_t get_int(const unsigned char *p, size_t i, uint32_t bytes)
{
    if (bytes == 1)
        return p[i];
    uint16_t h;
    memcpy(&h, p + 2 * i, 2);
    return h;
}

void mip_level(const uint32_t *texels, const fr_texture *t, uint32_t k, uint32_t y0r, uint32_t y1r, unsigned char *out)
{
    uint32_t w, h, pw, ph, n = t->channels, bytes = tex_format_bytes(t->format);
    tex_level_size(t, k, &w, &h);
    tex_level_size(t, k - 1, &pw, &ph);
    int integer = t->format == FR_TEXEL_U8 || t->format == FR_TEXEL_U16, srgb8 = t->format == FR_TEXEL_U8_SRGB;
    if (srgb8)
        pthread_once(&srgb8_once, srgb8_init);
    const unsigned char *prev = (const unsigned char *)(texels + t->first[k - 1]);
    for (uint32_t y = y0r; y < y1r; y++) {
        uint32_t y0 = ph == 1 ? 0 : 2 * y, y1 = ph == 1 ? 1 : y + 1 == h ? ph : 2 * y + 2;
        for (uint32_t x = 0; x < w; x++) {
            uint32_t x0 = pw == 1 ? 0 : 2 * x, x1 = pw == 1 ? 1 : x + 1 == w ? pw : 2 * x + 2;
            uint32_t count = (y1 - y0) * (x1 - x0);
            double sum[3] = {0, 0, 0};
            uint64_t isum[3] = {0, 0, 0};
            for (uint32_t yy = y0; yy < y1; yy++)
                for (uint32_t xx = x0; xx < x1; xx++) {
                    if (integer) {
                        for (uint32_t c = 0; c < n; c++)
                            isum[c] += get_int(prev, ((size_t)yy * pw + xx) * n + c, bytes);
                    } else if (srgb8) {    /* tex_texel's values, without its calls */
                        for (uint32_t c = 0; c < n; c++)
                            sum[c] += srgb8_linear[prev[((size_t)yy * pw + xx) * n + c]];
                    } else {
                        float v[3];
                        tex_texel(texels, t, k - 1, xx, yy, v);
                        for (uint32_t c = 0; c < n; c++)
                            sum[c] += v[c];
                    }
                }
            for (uint32_t c = 0; c < n; c++) {
                uint32_t code = integer ? (uint32_t)((2 * isum[c] + count) / (2 * (uint64_t)count))
                                        : mip_encode(t->format, sum[c] / count);
                mip_put(out, ((size_t)(y - y0r) * w + x) * n + c, bytes, code);
            }
        }
    }
}

