/* test_mipmap.c -- textures at their own precision and their mip levels: every texel format
 * looks up exactly the value its stored bits decode to at texel centres;
 * half floats go to and from their bits exactly; each mip level is the box
 * filter of the one above, by the rule scene.h and texstore.h give; the
 * level of detail follows the footprint; and a far textured plane rendered
 * with mip-maps at 4 spp is closer to a supersampled reference than with
 * level 0 only, while a close-up renders the same bits either way; an
 * image decoded straight into the texels stores what it would malloc'd. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "camera.h"
#include "check.h"
#include "pathtrace.h"
#include "texture.h"
#include "compile/freeze.h"
#include "compile/json_scene.h"
#include "compile/texstore.h"
#include "mip.h"
#include "sampler.h"

/* An integer hash, for test images that are the same on every run. */
static uint32_t mix(uint32_t x) { return smp_hash(x); }

/* A scene view of the builder's textures and texels, for lookups. */
static fr_scene view_of(const fr_builder *b)
{
    fr_scene s;
    memset(&s, 0, sizeof s);
    s.textures = b->textures.data;
    s.n_textures = b->textures.count;
    s.texels = b->texels.data;
    s.n_texels = b->texels.count;
    return s;
}

/* Store w x h x ch values of pixel type `type` (bytes in data) as a
 * texture of the builder; returns its index or FR_NONE (after a failed check). */
static uint32_t store(fr_builder *b, const void *data, uint32_t type, uint32_t w, uint32_t h, uint32_t ch,
                      int srgb)
{
    scene_image img;
    memset(&img, 0, sizeof img);
    img.data = (void *)data;
    img.type = type;
    img.width = w, img.height = h, img.channels = ch;
    fr_texture t;
    memset(&t, 0, sizeof t);
    t.kind = FR_TEX_IMAGE;
    t.scale = (vec2){1, 1};
    fr_error err;
    if (texstore_image(b, &img, srgb, &t, "test image", &err) < 0) {
        CHECK(0, "texstore_image: %s", err.msg);
        return FR_NONE;
    }
    return bld_push(&b->textures, &t);
}

/* The value at the centre of texel (x, y) of level 0, through tex_eval. */
static vec3 at_centre(const fr_scene *s, uint32_t t, uint32_t x, uint32_t y)
{
    const fr_texture *tx = &s->textures[t];
    vec2 uv = {((float)x + 0.5f) / (float)tx->width, 1.0f - ((float)y + 0.5f) / (float)tx->height};
    return tex_eval(s, t, uv);
}

/* ---- exact lookups at texel centres, per format ------------------------- */

static void formats(void)
{
    fr_builder b;
    bld_init(&b);
    enum { W = 16, H = 16 };
    /* Every byte value, RGB 16x16 (value 3i + c mod 256), as sRGB and linear. */
    static uint8_t u8[W * H * 3];
    for (int i = 0; i < W * H * 3; i++)
        u8[i] = (uint8_t)(mix((uint32_t)i) >> 7);
    for (int i = 0; i < 256; i++)
        u8[i] = (uint8_t)i;                 /* every code somewhere */
    static uint16_t u16[W * H], f16[W * H];
    for (int i = 0; i < W * H; i++) {
        u16[i] = (uint16_t)mix((uint32_t)i + 1000u);
        /* Finite halves of every kind: subnormal, normal, negative. */
        uint16_t h = (uint16_t)mix((uint32_t)i + 7u);
        if ((h & 0x7c00u) == 0x7c00u)
            h &= 0xbfffu;
        f16[i] = h;
    }
    f16[0] = 0x0001, f16[1] = 0x03ff, f16[2] = 0x3c00, f16[3] = 0x7bff, f16[4] = 0x8000;
    static float f32[W * H], big[W * H];
    for (int i = 0; i < W * H; i++) {
        f32[i] = (float)(mix((uint32_t)i + 99u) % 100000u) / 1000.0f;   /* [0, 100): halves */
        big[i] = f32[i];
    }
    big[5] = 1e5f;                          /* past half's range: floats */
    uint32_t ts = store(&b, u8, SCENE_PIX_U8, W, H, 3, 1), tl = store(&b, u8, SCENE_PIX_U8, W, H, 3, 0);
    uint32_t t16 = store(&b, u16, SCENE_PIX_U16, W, H, 1, 0), t16s = store(&b, u16, SCENE_PIX_U16, W, H, 1, 1);
    uint32_t th = store(&b, f16, SCENE_PIX_F16, W, H, 1, 0);
    uint32_t tf = store(&b, f32, SCENE_PIX_F32, W, H, 1, 0), tb = store(&b, big, SCENE_PIX_F32, W, H, 1, 0);
    if (ts == FR_NONE || tl == FR_NONE || t16 == FR_NONE || t16s == FR_NONE || th == FR_NONE || tf == FR_NONE ||
        tb == FR_NONE) {
        bld_free(&b);
        return;
    }
    fr_scene s = view_of(&b);
    const fr_texture *T = s.textures;
    CHECK(T[ts].format == FR_TEXEL_U8_SRGB && T[tl].format == FR_TEXEL_U8 && T[t16].format == FR_TEXEL_U16 &&
          T[t16s].format == FR_TEXEL_U16_SRGB && T[th].format == FR_TEXEL_F16 && T[tf].format == FR_TEXEL_F16 &&
          T[tb].format == FR_TEXEL_F32, "formats %u %u %u %u %u %u %u", T[ts].format, T[tl].format, T[t16].format,
          T[t16s].format, T[th].format, T[tf].format, T[tb].format);
    CHECK(T[ts].levels == 5 && T[ts].channels == 3, "16x16 RGB: %u levels, %u channels", T[ts].levels,
          T[ts].channels);
    /* 8-bit RGB: 768 bytes of level 0 in 192 words. */
    CHECK(T[ts].first[1] - T[ts].first[0] == W * H * 3 / 4, "8-bit level 0 takes %u words",
          T[ts].first[1] - T[ts].first[0]);
    int bad = 0;
    for (uint32_t y = 0; y < H; y++)
        for (uint32_t x = 0; x < W; x++) {
            uint32_t i = y * W + x;
            vec3 a = at_centre(&s, ts, x, y), l = at_centre(&s, tl, x, y);
            for (int c = 0; c < 3; c++) {
                uint8_t k = u8[3 * i + c];
                bad += v3_get(a, c) != tex_srgb_to_linear((float)k / 255.0f);
                bad += v3_get(l, c) != (float)k / 255.0f;
            }
            bad += at_centre(&s, t16, x, y).x != (float)u16[i] / 65535.0f;
            bad += at_centre(&s, t16s, x, y).y != tex_srgb_to_linear((float)u16[i] / 65535.0f);
            bad += at_centre(&s, th, x, y).x != tex_half_to_float(f16[i]);
            float hf = tex_half_to_float((uint16_t)mip_encode(FR_TEXEL_F16, f32[i]));
            bad += at_centre(&s, tf, x, y).x != hf;
            bad += fabsf(hf - f32[i]) > f32[i] * 0x1p-11f;   /* half's rounding */
            bad += at_centre(&s, tb, x, y).x != big[i];
        }
    CHECK(bad == 0, "%d lookups at texel centres differ from the decoded stored values", bad);
    CHECK(tex_half_to_float(0x0001) == 0x1p-24f && tex_half_to_float(0x3c00) == 1.0f &&
          tex_half_to_float(0x7bff) == 65504.0f && tex_half_to_float(0xc000) == -2.0f &&
          tex_half_to_float(0x3555) == 0.333251953125f, "half decoding of known values");
    bld_free(&b);
}

/* Every finite half goes to its float and back to the same bits; floats
 * between two halves go to the nearer (ties to the even one). */
static void half_bits(void)
{
    int bad = 0;
    for (uint32_t h = 0; h < 65536; h++) {
        if ((h & 0x7c00u) == 0x7c00u)
            continue;
        float f = tex_half_to_float((uint16_t)h);
        bad += mip_encode(FR_TEXEL_F16, f) != h;
    }
    CHECK(bad == 0, "%d halves do not come back to their bits", bad);
    /* 1 + 2^-11 is halfway between 1 and 1 + 2^-10: to the even, 1. */
    CHECK(mip_encode(FR_TEXEL_F16, 1.0 + 0x1p-11) == 0x3c00 &&
          mip_encode(FR_TEXEL_F16, 1.0 + 3 * 0x1p-11) == 0x3c02 &&
          mip_encode(FR_TEXEL_F16, 65519.0) == 0x7bff && mip_encode(FR_TEXEL_F16, 65520.0) == 0x7c00,
          "half rounding ties and overflow");
    /* The sRGB table: every code decodes as the curve does. */
    int off = 0;
    for (uint32_t k = 0; k < 256; k++)
        off += mip_encode(FR_TEXEL_U8_SRGB, tex_srgb_to_linear((float)k / 255.0f)) != k;
    CHECK(off == 0, "%d sRGB codes do not encode back to themselves", off);
}

/* ---- mip levels: each the box filter of the level above ----------------- */

/* The nearest code of the 8-bit sRGB format to v, by trying all 256. */
static uint32_t nearest_srgb8(double v)
{
    uint32_t best = 0;
    double bd = INFINITY;
    for (uint32_t k = 0; k < 256; k++) {
        double d = fabs((double)tex_srgb_to_linear((float)k / 255.0f) - v);
        if (d < bd)
            best = k, bd = d;
    }
    return best;
}

/* The nearest code of the 16-bit sRGB format to v, by trying a window of
 * codes around the curve's inverse (wide enough for any rounding). */
static uint32_t nearest_srgb16(double v)
{
    double e = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
    long g = lround(e * 65535.0);
    uint32_t best = 0;
    double bd = INFINITY;
    for (long k = g - 8; k <= g + 8; k++) {
        if (k < 0 || k > 65535)
            continue;
        double d = fabs((double)tex_srgb_to_linear((float)k / 65535.0f) - v);
        if (d < bd)
            best = (uint32_t)k, bd = d;
    }
    return best;
}

/* Checks every level of texture t against the rule, recomputed here. */
static void check_levels(const fr_scene *s, uint32_t t, const char *what)
{
    const fr_texture *tx = &s->textures[t];
    uint32_t side = tx->width > tx->height ? tx->width : tx->height, chain = 1;
    while (side >> chain)
        chain++;
    CHECK(tx->levels == chain, "%s: %u levels, expected %u", what, tx->levels, chain);
    int bad = 0;
    uint32_t bytes = tex_format_bytes(tx->format);
    for (uint32_t k = 1; k < tx->levels; k++) {
        uint32_t w, h, pw, ph;
        tex_level_size(tx, k, &w, &h);
        tex_level_size(tx, k - 1, &pw, &ph);
        CHECK(w == (pw / 2 ? pw / 2 : 1) && h == (ph / 2 ? ph / 2 : 1), "%s: level %u is %ux%u", what, k, w, h);
        const unsigned char *prev = (const unsigned char *)(s->texels + tx->first[k - 1]);
        for (uint32_t y = 0; y < h; y++)
            for (uint32_t x = 0; x < w; x++) {
                /* The texels of level k - 1 this one covers. */
                uint32_t x0 = pw == 1 ? 0 : 2 * x, x1 = pw == 1 ? 1 : (x == w - 1 ? pw : 2 * x + 2);
                uint32_t y0 = ph == 1 ? 0 : 2 * y, y1 = ph == 1 ? 1 : (y == h - 1 ? ph : 2 * y + 2);
                uint32_t n = (x1 - x0) * (y1 - y0);
                float got[3];
                tex_texel(s->texels, tx, k, x, y, got);
                for (uint32_t c = 0; c < tx->channels; c++) {
                    double sum = 0.0;
                    uint64_t isum = 0;
                    for (uint32_t yy = y0; yy < y1; yy++)
                        for (uint32_t xx = x0; xx < x1; xx++) {
                            float v[3];
                            tex_texel(s->texels, tx, k - 1, xx, yy, v);
                            sum += v[c];
                            size_t at = ((size_t)yy * pw + xx) * tx->channels + c;
                            isum += bytes == 1 ? prev[at] : (uint64_t)((const uint16_t *)prev)[at];
                        }
                    double mean = sum / n;
                    float want;
                    switch (tx->format) {
                    case FR_TEXEL_U8:
                        want = (float)((2 * isum + n) / (2 * n)) / 255.0f;
                        break;
                    case FR_TEXEL_U16:
                        want = (float)((2 * isum + n) / (2 * n)) / 65535.0f;
                        break;
                    case FR_TEXEL_U8_SRGB:
                        want = tex_srgb_to_linear((float)nearest_srgb8(mean) / 255.0f);
                        break;
                    case FR_TEXEL_U16_SRGB:
                        want = tex_srgb_to_linear((float)nearest_srgb16(mean) / 65535.0f);
                        break;
                    case FR_TEXEL_F32:
                        want = (float)mean;
                        break;
                    default: {
                        /* Halves: the stored one, and no neighbour nearer the mean. */
                        uint16_t hb = (uint16_t)mip_encode(FR_TEXEL_F16, mean);
                        double d = fabs(tex_half_to_float(hb) - mean);
                        bad += fabs(tex_half_to_float((uint16_t)(hb + 1)) - mean) < d;
                        bad += hb > 0 && fabs(tex_half_to_float((uint16_t)(hb - 1)) - mean) < d;
                        want = tex_half_to_float(hb);
                    }
                    }
                    bad += got[c] != want;
                }
            }
    }
    CHECK(bad == 0, "%s: %d mip texels are not the box filter of the level above", what, bad);
}

static void mip_levels(void)
{
    fr_builder b;
    bld_init(&b);
    /* Odd sizes (the odd column and row folded in), a power of two, and
     * a thin strip. */
    enum { N = 64 * 64 * 3 };
    static uint8_t u8[N];
    static uint16_t u16[N], f16[N];
    for (int i = 0; i < N; i++) {
        u8[i] = (uint8_t)(mix((uint32_t)i) >> 5);
        u16[i] = (uint16_t)mix((uint32_t)i + 5u);
        f16[i] = (uint16_t)(mix((uint32_t)i + 11u) % 0x7800u);   /* positive finite halves */
    }
    uint32_t a = store(&b, u8, SCENE_PIX_U8, 13, 7, 3, 1);
    uint32_t c = store(&b, u8, SCENE_PIX_U8, 64, 64, 1, 0);
    uint32_t d = store(&b, u16, SCENE_PIX_U16, 37, 20, 3, 0);
    uint32_t e = store(&b, f16, SCENE_PIX_F16, 31, 1, 3, 0);
    uint32_t g = store(&b, u16, SCENE_PIX_U16, 9, 6, 3, 1);
    static float fl[11 * 5];
    for (int i = 0; i < 11 * 5; i++)
        fl[i] = (float)(mix((uint32_t)i + 3u) % 1000u) * 100.0f;   /* up to 99900: floats */
    uint32_t h = store(&b, fl, SCENE_PIX_F32, 11, 5, 1, 0);
    if (a == FR_NONE || c == FR_NONE || d == FR_NONE || e == FR_NONE || g == FR_NONE || h == FR_NONE) {
        bld_free(&b);
        return;
    }
    fr_scene s = view_of(&b);
    check_levels(&s, a, "13x7 RGB sRGB bytes");
    check_levels(&s, c, "64x64 grey bytes");
    check_levels(&s, d, "37x20 RGB 16-bit");
    check_levels(&s, e, "31x1 RGB halves");
    CHECK(s.textures[g].format == FR_TEXEL_U16_SRGB && s.textures[h].format == FR_TEXEL_F32,
          "16-bit sRGB and float formats: %u %u", s.textures[g].format, s.textures[h].format);
    check_levels(&s, g, "9x6 RGB 16-bit sRGB");
    check_levels(&s, h, "11x5 grey floats");
    /* A constant image stays exactly constant all the way down. */
    static uint8_t flat[40 * 24];
    memset(flat, 200, sizeof flat);
    uint32_t f = store(&b, flat, SCENE_PIX_U8, 40, 24, 1, 1);
    s = view_of(&b);
    int off = 0;
    for (uint32_t k = 0; f != FR_NONE && k < s.textures[f].levels; k++) {
        float v[3];
        tex_texel(s.texels, &s.textures[f], k, 0, 0, v);
        off += v[0] != tex_srgb_to_linear(200.0f / 255.0f);
    }
    CHECK(off == 0, "a constant sRGB image changes in %d levels", off);
    bld_free(&b);
}

/* ---- decoded straight into the texels ------------------------------------ */

/* An image decoded where texstore_target says (a hook keeping the first
 * channels it is told) stores the same texels, words and fields as the
 * same image malloc'd whole; float images, and halves to be sRGB-decoded,
 * are not taken in place. */
static void in_place(void)
{
    enum { W = 23, H = 9 };
    static uint16_t src[W * H * 4];
    for (int i = 0; i < W * H * 4; i++)
        src[i] = (uint16_t)(mix((uint32_t)i + 7u) % 0x7800u);
    static const uint32_t types[] = {SCENE_PIX_U8, SCENE_PIX_U16, SCENE_PIX_F16};
    int bad = 0, cases = 0;
    for (int ti = 0; ti < 3; ti++)
        for (uint32_t ch = 1; ch <= 4; ch++)
            for (int srgb = 0; srgb < 2; srgb++) {
                uint32_t type = types[ti], size = type == SCENE_PIX_U8 ? 1 : 2;
                fr_builder whole, placed;
                bld_init(&whole);
                bld_init(&placed);
                /* Something before it, so the place is not the array's start. */
                uint32_t before = store(&whole, src, SCENE_PIX_U8, 3, 5, 3, 0);
                store(&placed, src, SCENE_PIX_U8, 3, 5, 3, 0);
                uint32_t a = store(&whole, src, type, W, H, ch, srgb);
                texstore_target into;
                texstore_target_init(&into, &placed, srgb);
                uint32_t keep = 0;
                unsigned char *at = into.dest.at(&into.dest, W, H, ch, type, &keep);
                if (type == SCENE_PIX_F16 && srgb) {
                    bad += at != NULL;
                } else if (!at || keep != (ch >= 3 ? 3u : 1u)) {
                    bad++;
                } else {
                    for (uint32_t i = 0; i < W * H; i++)
                        memcpy(at + (size_t)i * keep * size, (const unsigned char *)src + (size_t)i * ch * size,
                               (size_t)keep * size);
                    scene_image img;
                    memset(&img, 0, sizeof img);
                    img.data = at;
                    img.type = type;
                    img.width = W, img.height = H, img.channels = keep;
                    img.borrowed = 1;
                    fr_texture t;
                    memset(&t, 0, sizeof t);
                    t.kind = FR_TEX_IMAGE;
                    t.scale = (vec2){1, 1};
                    fr_error err;
                    uint32_t words = placed.texels.count;
                    if (a == FR_NONE || before == FR_NONE ||
                        texstore_image(&placed, &img, srgb, &t, "in place", &err) < 0 ||
                        placed.texels.count != whole.texels.count ||
                        memcmp(&t, (fr_texture *)whole.textures.data + a, sizeof t) ||
                        memcmp(placed.texels.data, whole.texels.data, (size_t)whole.texels.count * 4) ||
                        words == placed.texels.count)
                        bad++;
                    cases++;
                }
                bld_free(&whole);
                bld_free(&placed);
            }
    CHECK(bad == 0 && cases == 20, "decoded in place: %d of %d cases differ from the image malloc'd whole", bad,
          cases);
    texstore_target into;
    fr_builder b;
    bld_init(&b);
    texstore_target_init(&into, &b, 0);
    uint32_t keep = 0;
    CHECK(into.dest.at(&into.dest, W, H, 3, SCENE_PIX_F32, &keep) == NULL &&
          into.dest.at(&into.dest, FR_TEX_MAX_SIDE + 1, 1, 3, SCENE_PIX_U8, &keep) == NULL,
          "float and oversized images are not decoded in place");
    bld_free(&b);
}

/* ---- the level of detail follows the footprint --------------------------- */

static void lod(void)
{
    fr_builder b;
    bld_init(&b);
    static uint8_t px[256 * 256];
    uint32_t t = store(&b, px, SCENE_PIX_U8, 256, 256, 1, 0);
    if (t == FR_NONE) {
        bld_free(&b);
        return;
    }
    fr_scene s = view_of(&b);
    fr_surface sf;
    memset(&sf, 0, sizeof sf);
    sf.dpdu = v3(2, 0, 0);        /* the texture spans 2 x 2 scene units */
    sf.dpdv = v3(0, 2, 0);
    CHECK(tex_lod(&s, t, &sf) == 0.0f, "no footprint: level 0");
    sf.footprint = 1.0f / 256.0f;  /* half a texel */
    CHECK(tex_lod(&s, t, &sf) == 0.0f, "half a texel: level 0");
    float prev = 0.0f;
    int mono = 1;
    for (int k = 1; k <= 8; k++) {
        sf.footprint = 2.0f * (float)(1 << k) / 256.0f;   /* 2^k texels */
        float l = tex_lod(&s, t, &sf);
        CHECK(fabsf(l - (float)k) < 1e-5f, "a footprint of 2^%d texels: level %g", k, l);
        mono &= l > prev;
        prev = l;
    }
    CHECK(mono, "the level grows with the footprint");
    /* Twice the texture scale: twice the texels under the same footprint. */
    ((fr_texture *)b.textures.data)[t].scale = (vec2){2, 2};
    sf.footprint = 2.0f * 4.0f / 256.0f;
    CHECK(fabsf(tex_lod(&s, t, &sf) - 3.0f) < 1e-5f, "scale 2: level %g, expected 3", tex_lod(&s, t, &sf));
    /* The camera's cone: a pixel's angle times max(1/8, 1/sqrt(spp)). */
    fr_scene cs;
    memset(&cs, 0, sizeof cs);
    cs.camera.tan_half = 0.5f;
    cs.settings.height = 100;
    cs.settings.spp = 1;
    CHECK(cam_pixel_spread(&cs) == 0.01f, "1 spp: the pixel's angle, %g", cam_pixel_spread(&cs));
    cs.settings.spp = 16;
    CHECK(cam_pixel_spread(&cs) == 0.0025f, "16 spp: a quarter of it, %g", cam_pixel_spread(&cs));
    cs.settings.spp = 4096;
    CHECK(cam_pixel_spread(&cs) == 0.00125f, "4096 spp: an eighth, %g", cam_pixel_spread(&cs));
    /* Head-on, a cone 2 units wide; at 60 degrees, as wide as a disk of
     * its elliptical section's area. */
    CHECK(cam_footprint(2.0f, v3(0, 0, 1), v3(0, 0, -1)) == 2.0f, "head-on footprint");
    CHECK(fabsf(cam_footprint(2.0f, v3(0, 0, 1), v3(0, 0.8660254f, -0.5f)) - 2.0f / sqrtf(0.5f)) < 1e-6f,
          "footprint at 60 degrees");
    bld_free(&b);
}

/* ---- a far textured plane ----------------------------------------------- */

static char dir[64];

/* The image behind "checks.png": 512x512 grey bytes, 0 and 255 in one-texel
 * checks (linear, a data texture). */
static int checks(const char *path, const void *data, size_t len, scene_image *img, fr_error *err)
{
    (void)path;
    (void)data;
    (void)len;
    (void)err;
    img->width = img->height = 512;
    img->channels = 1;
    img->type = SCENE_PIX_U8;
    uint8_t *p = malloc(512 * 512);
    for (int y = 0; y < 512; y++)
        for (int x = 0; x < 512; x++)
            p[y * 512 + x] = (x + y) % 2 ? 255 : 0;
    img->data = p;
    return 0;
}

static const scene_hooks hooks = {.texture = checks};

/* The plane, a 2 x 2 rect at distance `dist`, lit head-on by a sun,
 * rendered at 32x32 with `spp` samples; its texture's levels cut to one
 * when level0.  rgb receives the image. */
static int render_plane(float dist, float fov, uint32_t spp, int level0, float *rgb)
{
    char json[1536], file[128];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 32, \"height\": 32, \"spp\": %u, \"max_depth\": 1, \"integrator\": \"path\"},"
             " \"camera\": {\"position\": [0, 0, %g], \"target\": [0, 0, 0], \"fov\": %g},"
             " \"textures\": {\"c\": {\"type\": \"image\", \"file\": \"checks.png\", \"colorspace\": \"linear\"}},"
             " \"materials\": {\"m\": {\"type\": \"lambert\", \"albedo\": \"c\"}},"
             " \"lights\": [{\"type\": \"sun\", \"direction\": [0, 0, -1], \"irradiance\": [3.14159265, 3.14159265, 3.14159265]}],"
             " \"shapes\": [{\"type\": \"rect\", \"origin\": [-1, -1, 0], \"edge_u\": [2, 0, 0], \"edge_v\": [0, 2, 0],"
             "   \"material\": \"m\"}]}",
             spp, dist, fov);
    snprintf(file, sizeof file, "%s/scene.json", dir);
    fr_builder b;
    bld_init(&b);
    fr_error err;
    fr_scene s;
    int rc = json_scene_parse(json, file, &hooks, &b, &err);
    if (rc == 0 && level0) {
        fr_texture *t = b.textures.data;
        t->levels = 1;
        memset(t->first + 1, 0, sizeof t->first - sizeof t->first[0]);
    }
    if (rc == 0)
        rc = frz_scene(&b, &s, &err);
    bld_free(&b);
    if (rc < 0) {
        CHECK(0, "plane scene: %s", err.msg);
        return -1;
    }
    pt_render_rows(&s, PT_MIS, 0, 32, rgb);
    scn_free(&s);
    return 0;
}

static double rmse(const float *a, const float *b, int n)
{
    double e = 0.0;
    for (int i = 0; i < n; i++)
        e += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    return sqrt(e / n);
}

static double mean(const float *a, int n)
{
    double m = 0.0;
    for (int i = 0; i < n; i++)
        m += a[i];
    return m / n;
}

static void far_plane(void)
{
    snprintf(dir, sizeof dir, "/tmp/franja-mip-XXXXXX");
    char cmd[160];
    if (!mkdtemp(dir) || (snprintf(cmd, sizeof cmd, "touch %s/checks.png", dir), system(cmd) != 0)) {
        CHECK(0, "cannot create %s", dir);
        return;
    }
    enum { NPX = 32 * 32 * 3 };
    static float ref[NPX], mip[NPX], l0[NPX], near_mip[NPX], near_l0[NPX];
    /* The plane fills the frame (fov 2 atan(1/d)): each pixel covers 16x16
     * texels of one-texel checks, whose mean is 1/2. */
    float d = 8.0f, fov = (float)(2.0 * atan(1.0 / 8.0) * 180.0 / M_PI);
    if (render_plane(d, fov, 1024, 1, ref) < 0 || render_plane(d, fov, 4, 0, mip) < 0 ||
        render_plane(d, fov, 4, 1, l0) < 0)
        goto out;
    double e_mip = rmse(mip, ref, NPX), e_l0 = rmse(l0, ref, NPX);
    double m_ref = mean(ref, NPX), m_mip = mean(mip, NPX);
    printf("far plane at 4 spp: RMSE %.4f with mip-maps, %.4f with level 0 only (reference mean %.4f, "
           "mip-mapped mean %.4f)\n", e_mip, e_l0, m_ref, m_mip);
    CHECK(e_mip < 0.25 * e_l0, "mip-maps do not cut the error of a far plane: RMSE %g against level 0's %g", e_mip,
          e_l0);
    CHECK(fabs(m_mip - m_ref) < 0.01 * m_ref, "the mip-mapped far plane's mean %g is not the reference's %g", m_mip,
          m_ref);
    /* Close up (a pixel spans under a texel), mip-maps change no bit. */
    float fn = (float)(2.0 * atan(1.0 / 256.0) * 180.0 / M_PI);   /* half a texel a pixel */
    if (render_plane(8.0f, fn, 4, 0, near_mip) < 0 || render_plane(8.0f, fn, 4, 1, near_l0) < 0)
        goto out;
    CHECK(!memcmp(near_mip, near_l0, sizeof near_mip), "a close-up changes with mip-maps");
out:
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0)
        printf("note: could not remove %s\n", dir);
}

int main(void)
{
    formats();
    half_bits();
    mip_levels();
    in_place();
    lod();
    far_plane();
    return check_done();
}
