/* texstore.c -- images stored at their own precision, with their mip levels
 * (see texstore.h). */
#include "compile/texstore.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mip.h"
#include "texture.h"

/* The most words of texels a scene may hold (8 GiB): the builder's arrays
 * stop below 2^31 elements. */
#define MAX_WORDS (1u << 31)

/* Decoded value of channel c of pixel i of the hook's image (before any
 * sRGB decoding), as a double. */
static double image_value(const scene_image *img, size_t i, uint32_t c)
{
    size_t k = i * img->channels + c;
    switch (img->type) {
    case SCENE_PIX_U8: return ((const uint8_t *)img->data)[k] / 255.0;
    case SCENE_PIX_U16: return ((const uint16_t *)img->data)[k] / 65535.0;
    case SCENE_PIX_F16: return tex_half_to_float(((const uint16_t *)img->data)[k]);
    default: return img->pixels[k];
    }
}

/* The format an image is stored in (texstore.h). */
static uint32_t choose_format(const scene_image *img, int from_srgb, uint32_t keep)
{
    if (img->type == SCENE_PIX_U8)
        return from_srgb ? FR_TEXEL_U8_SRGB : FR_TEXEL_U8;
    if (img->type == SCENE_PIX_U16)
        return from_srgb ? FR_TEXEL_U16_SRGB : FR_TEXEL_U16;
    if (img->type == SCENE_PIX_F16)
        return from_srgb ? FR_TEXEL_F32 : FR_TEXEL_F16;
    /* Floats: halves when every value fits, unless they are sRGB-decoded
     * (a float image read as sRGB keeps its decoded floats exactly). */
    if (from_srgb)
        return FR_TEXEL_F32;
    size_t n = (size_t)img->width * img->height;
    for (size_t i = 0; i < n; i++)
        for (uint32_t c = 0; c < keep; c++)
            if (!(fabs(image_value(img, i, c)) <= 65504.0))
                return FR_TEXEL_F32;
    return FR_TEXEL_F16;
}

/* The image fields of tex (width, height, channels, format set) that
 * depend on its size: levels; words[k], the words of level k; returns
 * their sum. */
static uint64_t plan(fr_texture *tex, uint64_t words[FR_TEX_MAX_LEVELS])
{
    uint32_t side = tex->width > tex->height ? tex->width : tex->height, levels = 1;
    while (side >> levels)
        levels++;
    tex->levels = levels;
    uint32_t bytes = tex_format_bytes(tex->format);
    uint64_t total = 0;
    for (uint32_t k = 0; k < levels; k++) {
        uint32_t w, h;
        tex_level_size(tex, k, &w, &h);
        words[k] = ((uint64_t)w * h * tex->channels * bytes + 3) / 4;
        total += words[k];
    }
    return total;
}

/* Room for `total` more words of texels, all at once (no doubling);
 * 0, or -1 past MAX_WORDS or out of memory (*oom set then). */
static int reserve(fr_builder *b, uint64_t total, int *oom)
{
    *oom = 0;
    if (total >= MAX_WORDS || b->texels.count >= MAX_WORDS - total)
        return -1;
    uint32_t need = b->texels.count + (uint32_t)total;
    if (need > b->texels.cap) {
        void *p = realloc(b->texels.data, (size_t)need * sizeof(uint32_t));
        if (!p) {
            *oom = 1;
            return -1;
        }
        b->texels.data = p;
        b->texels.cap = need;
    }
    return 0;
}

static void *target_at(const scene_image_dest *d, uint32_t width, uint32_t height, uint32_t channels,
                       uint32_t type, uint32_t *keep)
{
    const texstore_target *t = (const texstore_target *)d;
    if (width == 0 || height == 0 || channels == 0 || channels > 4 || width > FR_TEX_MAX_SIDE ||
        height > FR_TEX_MAX_SIDE || !(type == SCENE_PIX_U8 || type == SCENE_PIX_U16 ||
                                      (type == SCENE_PIX_F16 && !t->from_srgb)))
        return NULL;
    scene_image img = {.width = width, .height = height, .channels = channels, .type = type};
    fr_texture tex;
    memset(&tex, 0, sizeof tex);
    tex.width = width;
    tex.height = height;
    tex.channels = channels >= 3 ? 3 : 1;
    tex.format = choose_format(&img, t->from_srgb, tex.channels);
    uint64_t words[FR_TEX_MAX_LEVELS];
    int oom;
    if (reserve(t->b, plan(&tex, words), &oom) < 0)
        return NULL;
    *keep = tex.channels;
    return (uint32_t *)t->b->texels.data + t->b->texels.count;
}

void texstore_target_init(texstore_target *t, fr_builder *b, int from_srgb)
{
    t->dest.at = target_at;
    t->b = b;
    t->from_srgb = from_srgb;
}

int texstore_image(fr_builder *b, const scene_image *img, int from_srgb, fr_texture *tex, const char *where,
                   fr_error *err)
{
    if (img->width == 0 || img->height == 0 || img->channels == 0 || img->channels > 4)
        return fr_fail(err, "%s: the image has %ux%u pixels and %u channels (expected 1 to 4)", where, img->width,
                       img->height, img->channels);
    if (img->width > FR_TEX_MAX_SIDE || img->height > FR_TEX_MAX_SIDE)
        return fr_fail(err, "%s: the image has %ux%u pixels (at most %u per side)", where, img->width, img->height,
                       FR_TEX_MAX_SIDE);
    if (img->type > SCENE_PIX_F16)
        return fr_fail(err, "%s: unknown pixel type %u", where, img->type);
    uint32_t keep = img->channels >= 3 ? 3 : 1;
    size_t n = (size_t)img->width * img->height;
    /* Every value finite (halves: exponent not all ones). */
    if (img->type == SCENE_PIX_F32 || img->type == SCENE_PIX_F16)
        for (size_t i = 0; i < n; i++)
            for (uint32_t c = 0; c < keep; c++)
                if (!isfinite(image_value(img, i, c)))
                    return fr_fail(err, "%s: pixel %zu is not a finite number", where, i);
    tex->width = img->width;
    tex->height = img->height;
    tex->channels = keep;
    tex->format = choose_format(img, from_srgb, keep);
    uint64_t words[FR_TEX_MAX_LEVELS];
    uint64_t total = plan(tex, words);
    int oom;
    if (reserve(b, total, &oom) < 0)
        return oom ? fr_fail(err, "%s: out of memory for texels (%llu bytes)", where, (unsigned long long)total * 4)
                   : fr_fail(err, "%s: the scene's textures exceed %u MiB of texels", where, (MAX_WORDS >> 20) * 4);
    uint32_t base = b->texels.count, bytes = tex_format_bytes(tex->format);
    uint32_t *texels = b->texels.data;
    /* Decoded in place (texstore_target): level 0 is there already. */
    int in_place = img->data == (void *)(texels + base);
    if (in_place && (img->channels != keep || (img->type != SCENE_PIX_U8 && img->type != SCENE_PIX_U16 &&
                                               img->type != SCENE_PIX_F16) || tex->format == FR_TEXEL_F32))
        return fr_fail(err, "%s: an image decoded in place must be stored as it is", where);
    memset(tex->first, 0, sizeof tex->first);
    for (uint32_t k = 0, at = base; k < tex->levels; at += (uint32_t)words[k], k++) {
        /* The padding after the level's values, zeroed. */
        uint32_t w, h;
        tex_level_size(tex, k, &w, &h);
        size_t used = (size_t)w * h * keep * bytes;
        memset((unsigned char *)(texels + at) + used, 0, (size_t)words[k] * 4 - used);
        tex->first[k] = at;
    }
    b->texels.count = base + (uint32_t)total;
    /* Level 0: integers and halves as they are, floats rounded. */
    unsigned char *l0 = (unsigned char *)(texels + base);
    for (size_t i = 0; i < n && !in_place; i++)
        for (uint32_t c = 0; c < keep; c++) {
            size_t src = i * img->channels + c, dst = i * keep + c;
            uint32_t code;
            if (img->type == SCENE_PIX_U8)
                code = ((const uint8_t *)img->data)[src];
            else if (img->type == SCENE_PIX_U16 || (img->type == SCENE_PIX_F16 && tex->format == FR_TEXEL_F16 &&
                                                    !from_srgb))
                code = ((const uint16_t *)img->data)[src];
            else {
                double v = image_value(img, i, c);
                if (from_srgb)
                    v = tex_srgb_to_linear((float)v);
                code = mip_encode(tex->format, v);
            }
            mip_put(l0, dst, bytes, code);
        }
    for (uint32_t k = 1; k < tex->levels; k++)
    {
        uint32_t w, h;
        tex_level_size(tex, k, &w, &h);
        mip_level(texels, tex, k, 0, h, (unsigned char *)(texels + tex->first[k]));
    }
    return 0;
}
