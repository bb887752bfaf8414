/* passout.c -- the final image with its render passes: one multilayer
 * OpenEXR, or one file per pass beside the beauty (see passout.h). */
#include "passout.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "output.h"
#include "passes.h"

/* The file of pass `name` beside path (out.png: out.NAME.png) into
 * out[cap]. */
static void pass_file(const char *path, const char *name, char *out, size_t cap)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash : path, '.');
    size_t stem = dot ? (size_t)(dot - path) : strlen(path);
    snprintf(out, cap, "%.*s.%s%s", (int)stem, path, name, dot ? dot : "");
}

/* The number of light groups of the scene (at least the default one). */
static uint32_t group_count(const crypto_names *groups)
{
    return groups && groups->n ? (groups->n < PASS_LIGHT_GROUPS ? groups->n : PASS_LIGHT_GROUPS) : 1;
}

/* The name of light group g: the scene's, "default" for group 0 of a
 * scene that names none. */
static void group_name(const crypto_names *groups, uint32_t g, char *out)
{
    if (groups && g < groups->n)
        crypto_name(groups, g, out);
    else
        snprintf(out, 64, "default");
}

/* The EXR name of channel k of the light_groups pass into out[64], "" for
 * a group past the scene's. */
static void group_channel(const crypto_names *groups, uint32_t k, char *out)
{
    static const char rgb[] = "RGB";
    char name[64];
    if (k / 3 >= group_count(groups)) {
        out[0] = 0;
        return;
    }
    group_name(groups, k / 3, name);
    snprintf(out, 64, "ViewLayer.Combined_%.40s.%c", name, rgb[k % 3]);
}

/* Whether EXR channel `at` (the beauty's 4, then the passes') is written. */
static int channel_kept(uint32_t mask, const crypto_names *groups, uint32_t at)
{
    if (at < 4 || !(mask >> PASS_LIGHTGROUP & 1u))
        return 1;
    uint32_t before = 4 + pass_channels(mask & ((1u << PASS_LIGHTGROUP) - 1u));
    return at < before || at >= before + 3 * PASS_LIGHT_GROUPS || (at - before) / 3 < group_count(groups);
}

/* The multilayer OpenEXR: the beauty in RGBA, then the passes' channels,
 * interleaved in *passes itself (grown), so that the passes are not held
 * twice. */
static int write_exr(const char *path, const float *rgb, float **passes, const job_spec *spec,
                     const iio_options *o, const crypto_names *cn, uint32_t n_materials, const crypto_names *on,
                     const crypto_names *groups, fr_error *err)
{
    uint32_t nch = pass_channels(spec->passes), all = 4 + nch;
    size_t npx = (size_t)spec->width * spec->height;
    float *px = realloc(*passes, npx * all * sizeof *px);
    char (*names)[64] = malloc(all * sizeof *names);
    const char **ptrs = malloc(all * sizeof *ptrs);
    if (px)
        *passes = px;
    if (!px || !names || !ptrs) {
        free(names);
        free(ptrs);
        return fr_fail(err, "%s: out of memory for %u channels of %ux%u pixels", path, all, spec->width,
                       spec->height);
    }
    /* From the last pixel back, each pixel's passes move up to their place
     * (never over a pixel not yet moved) and the beauty goes before them. */
    for (size_t i = npx; i-- > 0;) {
        float *d = px + i * all;
        memmove(d + 4, px + i * nch, nch * sizeof *d);
        d[0] = rgb[i * 3], d[1] = rgb[i * 3 + 1], d[2] = rgb[i * 3 + 2], d[3] = 1.0f;
    }
    static const char rgba[] = "RGBA";
    uint32_t c = 0;
    for (; c < 4; c++)
        snprintf(names[c], sizeof names[c], "ViewLayer.Combined.%c", rgba[c]);
    uint32_t crypto_at = 0, crypto_obj_at = 0;
    for (int i = 0; i < PASS_COUNT; i++) {
        if (!(spec->passes >> i & 1u))
            continue;
        const pass_info *p = pass_get(i);
        int crypto = i == PASS_CRYPTO_MATERIAL || i == PASS_CRYPTO_OBJECT;
        if (i == PASS_CRYPTO_MATERIAL)
            crypto_at = c;
        if (i == PASS_CRYPTO_OBJECT)
            crypto_obj_at = c;
        for (const char *ch = p->channels; *ch; ch++, c++)
            if (i == PASS_LIGHTGROUP) /* ViewLayer.Combined_NAME.R ..., "" past the scene's groups */
                group_channel(groups, (uint32_t)(ch - p->channels), names[c]);
            else if (crypto) /* Cryptomatte's ranks: ViewLayer.CryptoMaterial00.R ... 02.A */
                snprintf(names[c], sizeof names[c], "ViewLayer.%s%02u.%c", p->layer,
                         (unsigned)(ch - p->channels) / 4, *ch);
            else
                snprintf(names[c], sizeof names[c], "ViewLayer.%s.%c", p->layer, *ch);
    }
    if (spec->passes >> PASS_CRYPTO_MATERIAL & 1u)
        crypto_ids(px + crypto_at, npx, all, cn);
    if (spec->passes >> PASS_CRYPTO_OBJECT & 1u)
        crypto_ids(px + crypto_obj_at, npx, all, on);
    /* The light groups the scene lacks leave the file. */
    uint32_t kept = 0;
    for (c = 0; c < all; c++)
        if (names[c][0])
            memmove(names[kept++], names[c], sizeof names[c]);
    if (kept < all) {
        uint32_t from_of[4 + PASS_MAX_CHANNELS];
        for (uint32_t from = 0, to = 0; from < all; from++)
            if (channel_kept(spec->passes, groups, from))
                from_of[to++] = from;
        for (size_t i = 0; i < npx; i++)
            for (uint32_t to = 0; to < kept; to++)
                px[i * kept + to] = px[i * all + from_of[to]];
        all = kept;
    }
    for (c = 0; c < all; c++)
        ptrs[c] = names[c];
    /* The caller's attributes and franja:passes. */
    char list[400];
    pass_format(spec->passes, list, sizeof list);
    const char *attrs[64];
    size_t k = 0;
    for (const char *const *a = o ? o->attrs : NULL; a && a[0] && a[1] && k + 24 < 64; a += 2)
        attrs[k++] = a[0], attrs[k++] = a[1];
    attrs[k++] = "franja:passes", attrs[k++] = list;
    char *table = NULL, *crypto = NULL, *otable = NULL, *ocrypto = NULL;
    int rc = 0;
    if (spec->passes & (1u << PASS_MATERIAL_ID | 1u << PASS_CRYPTO_MATERIAL)) {
        rc = crypto_name_table(cn, n_materials, &table, err);
        if (rc == 0)
            attrs[k++] = "franja:materials", attrs[k++] = table;
    }
    if (rc == 0 && (spec->passes & (1u << PASS_OBJECT_ID | 1u << PASS_CRYPTO_OBJECT))) {
        rc = crypto_name_table(on, on->n, &otable, err);
        if (rc == 0)
            attrs[k++] = "franja:objects", attrs[k++] = otable;
    }
    if (rc == 0 && (spec->passes >> PASS_CRYPTO_MATERIAL & 1u)) {
        rc = crypto_metadata("ViewLayer.CryptoMaterial", cn, n_materials, attrs + k, &crypto, err);
        k += 8;
    }
    if (rc == 0 && (spec->passes >> PASS_CRYPTO_OBJECT & 1u)) {
        rc = crypto_metadata("ViewLayer.CryptoObject", on, on->n, attrs + k, &ocrypto, err);
        k += 8;
    }
    attrs[k] = NULL;
    iio_options with = o ? *o : (iio_options){0};
    with.attrs = attrs;
    with.channels = all;
    with.channel_names = ptrs;
    if (rc == 0)
        rc = out_write_with(path, px, spec, NULL, &with, err);
    free(table);
    free(crypto);
    free(otable);
    free(ocrypto);
    free(names);
    free(ptrs);
    return rc;
}

/* Pass i of the passes as an RGB image for a file of its own: one-channel
 * passes grey; for LDR files the normal as 0.5 + 0.5 n and the depth and
 * material_id and object_id over their largest value (a depth of nothing hit as 1). */
static void pass_image(const float *passes, uint32_t nch, uint32_t at, int i, size_t npx, int ldr, float *out)
{
    const pass_info *p = pass_get(i);
    int k = (int)strlen(p->channels);
    float top = 0.0f;
    for (size_t j = 0; j < npx; j++) {
        float v = passes[j * nch + at];
        if (v < PASS_DEPTH_NONE && v > top)
            top = v;
    }
    for (size_t j = 0; j < npx; j++)
        for (int c = 0; c < 3; c++) {
            float v = passes[j * nch + at + (k == 3 ? (uint32_t)c : 0)];
            if (ldr && i == PASS_NORMAL)
                v = 0.5f + 0.5f * v;
            else if (ldr && (i == PASS_DEPTH || i == PASS_MATERIAL_ID || i == PASS_OBJECT_ID))
                v = v >= PASS_DEPTH_NONE ? 1.0f : top > 0.0f ? v / top : 0.0f;
            out[j * 3 + c] = v;
        }
}

int passout_write(const char *path, const float *rgb, float **pass_buf, const job_spec *spec,
                  const fr_tonemap *tm, const iio_options *o, const crypto_names *names, uint32_t n_materials,
                  const crypto_names *objects, const crypto_names *groups, fr_error *err)
{
    const float *passes = pass_buf ? *pass_buf : NULL;
    if (!passes || !spec->passes)
        return out_write_with(path, rgb, spec, tm, o, err);
    if (out_has_ext(path, "exr"))
        return write_exr(path, rgb, pass_buf, spec, o, names, n_materials, objects, groups, err);
    if (out_write_with(path, rgb, spec, tm, o, err))
        return -1;
    size_t npx = (size_t)spec->width * spec->height;
    uint32_t nch = pass_channels(spec->passes), at = 0;
    float *img = malloc(npx * 3 * sizeof *img);
    if (!img)
        return fr_fail(err, "%s: out of memory for its render passes", path);
    int ldr = !(out_has_ext(path, "hdr") || out_has_ext(path, "pfm"));
    /* LDR data passes are not tone-mapped beyond the sRGB curve. */
    fr_tonemap plain = {0};
    int rc = 0;
    for (int i = 0; i < PASS_COUNT && rc == 0; i++) {
        if (!(spec->passes >> i & 1u))
            continue;
        const pass_info *p = pass_get(i);
        if (i == PASS_CRYPTO_MATERIAL || i == PASS_CRYPTO_OBJECT) { /* OpenEXR only (frame.c says so) */
            at += (uint32_t)strlen(p->channels);
            continue;
        }
        char file[4200];
        if (i == PASS_LIGHTGROUP) { /* one file a group: OUT.Combined_NAME.png */
            for (uint32_t g = 0; g < group_count(groups) && rc == 0; g++) {
                char name[64], what[80];
                group_name(groups, g, name);
                snprintf(what, sizeof what, "Combined_%.64s", name);
                pass_file(path, what, file, sizeof file);
                for (size_t j = 0; j < npx; j++)
                    for (int c = 0; c < 3; c++)
                        img[j * 3 + c] = passes[j * nch + at + 3 * g + (uint32_t)c];
                rc = out_write_with(file, img, spec, tm, o, err);
            }
            at += (uint32_t)strlen(p->channels);
            continue;
        }
        pass_file(path, p->name, file, sizeof file);
        pass_image(passes, nch, at, i, npx, ldr, img);
        int light = i >= PASS_EMISSION && i <= PASS_TRANSMISSION_INDIRECT;
        rc = out_write_with(file, img, spec, light ? tm : &plain, o, err);
        at += (uint32_t)strlen(p->channels);
    }
    free(img);
    return rc;
}
