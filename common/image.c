/* image.c -- partial images of the PPM family: written by workers, read back
 * strictly (see image.h). */

#include "image.h"

#include <errno.h>
#include <float.h>
#include <inttypes.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define XXH_INLINE_ALL
#include <xxhash.h>

#include "fmath.h"
#include "passes.h"
#include "proto_limits.h"
#include "splat.h"

float img_srgb_encode(float v)
{
    if (!(v > 0.0f))
        return 0.0f;
    if (v >= 1.0f)
        return 1.0f;
    return v <= 0.0031308f ? 12.92f * v : 1.055f * fm_powf(v, 1.0f / 2.4f) - 0.055f;
}

int img_format_parse(const char *name, img_format *fmt)
{
    if (!strcmp(name, "pf")) *fmt = IMG_PF;
    else if (!strcmp(name, "ppm16")) *fmt = IMG_PPM16;
    else if (!strcmp(name, "ppm8")) *fmt = IMG_PPM8;
    else return -1;
    return 0;
}

/* The splat block as bytes: n sums, little-endian, a chunk at a time into
 * tmp[SPLAT_CHUNK * 8], each chunk passed to fn. */
#define SPLAT_CHUNK 4096
static int splat_bytes(const uint64_t *splat, size_t n, unsigned char *tmp,
                       int (*fn)(const unsigned char *bytes, size_t len, void *ctx), void *ctx)
{
    for (size_t at = 0; at < n; at += SPLAT_CHUNK) {
        size_t k = n - at < SPLAT_CHUNK ? n - at : SPLAT_CHUNK;
        for (size_t i = 0; i < k; i++)
            for (int b = 0; b < 8; b++)
                tmp[i * 8 + b] = (unsigned char)(splat[at + i] >> (8 * b));
        if (fn(tmp, k * 8, ctx) < 0)
            return -1;
    }
    return 0;
}

static int hash_chunk(const unsigned char *bytes, size_t len, void *ctx)
{
    return XXH3_64bits_update(ctx, bytes, len) == XXH_OK ? 0 : -1;
}

static int write_chunk(const unsigned char *bytes, size_t len, void *ctx)
{
    return fwrite(bytes, 1, len, ctx) == len ? 0 : -1;
}

/* The pass block's bytes (width*rows*pass_channels floats, little-endian)
 * into a malloc'd *out, and the header's tail naming the passes and the
 * block's hash. */
static int pass_bytes(const img_partial_info *info, const float *pass, unsigned char **out, size_t *len,
                      char *tail, size_t cap)
{
    size_t n = (size_t)info->width * (info->y1 - info->y0) * pass_channels(info->passes);
    unsigned char *b = malloc(n ? n * 4 : 1);
    if (!b)
        return -1;
    for (size_t i = 0; i < n; i++) {
        uint32_t bits;
        memcpy(&bits, &pass[i], 4);
        for (int k = 0; k < 4; k++)
            b[i * 4 + k] = (unsigned char)(bits >> (8 * k));
    }
    char names[400];
    pass_format(info->passes, names, sizeof names);
    snprintf(tail, cap, " passes=%s:%016" PRIx64, names, (uint64_t)XXH3_64bits(b, n * 4));
    *out = b;
    *len = n * 4;
    return 0;
}

/* The image, then (PF only) a block of nsplat 64-bit values after the
 * pixels: the splats (sums == 0) or the sample sums (sums != 0); or the
 * render passes' block (pass not NULL, info->passes not 0). */
static int write_image(FILE *f, img_format fmt, const img_partial_info *info, const float *rgb,
                       const uint64_t *splat, size_t nsplat, int sums, const float *pass, fr_error *err)
{
    uint32_t w = info->width, rows = info->y1 - info->y0;
    char tail[512] = "", ptail[460] = "";
    unsigned char *tmp = NULL, *pb = NULL;
    size_t pblen = 0;
    if (pass && fmt != IMG_PF)
        return fr_fail(err, "render passes need the PF format");
    if (pass && pass_bytes(info, pass, &pb, &pblen, ptail, sizeof ptail) < 0)
        return fr_fail(err, "out of memory writing the image");
    if (splat) {
        if (fmt != IMG_PF) {
            free(pb);
            return fr_fail(err, "%s need the PF format", sums ? "sample sums" : "light-tracing splats");
        }
        tmp = malloc(SPLAT_CHUNK * 8);
        XXH3_state_t *st = XXH3_createState();
        if (!tmp || !st || XXH3_64bits_reset(st) != XXH_OK || splat_bytes(splat, nsplat, tmp, hash_chunk, st) < 0) {
            free(tmp);
            free(pb);
            XXH3_freeState(st);
            return fr_fail(err, "out of memory writing the image");
        }
        if (sums)
            snprintf(tail, sizeof tail, " sums=%016" PRIx64, (uint64_t)XXH3_64bits_digest(st));
        else
            snprintf(tail, sizeof tail, " splat=%" PRIu64 ":%016" PRIx64, info->splat_paths,
                     (uint64_t)XXH3_64bits_digest(st));
        XXH3_freeState(st);
    }
    /* Splats and passes (bidirectional): the splat block, then the passes'. */
    fprintf(f, "%s\n# franja scene=%016" PRIx64 " rows=%u:%u spp=%u size=%ux%u%s%s\n%u %u\n%s\n",
            fmt == IMG_PF ? "PF" : "P6", info->scene, info->y0, info->y1, info->spp, info->width,
            info->height, tail, ptail, w, rows, fmt == IMG_PF ? "-1.0" : fmt == IMG_PPM16 ? "65535" : "255");
    size_t rowbytes = (size_t)w * 3 * (fmt == IMG_PF ? 4 : fmt == IMG_PPM16 ? 2 : 1);
    unsigned char *line = malloc(rowbytes ? rowbytes : 1);
    if (!line) {
        free(tmp);
        free(pb);
        return fr_fail(err, "out of memory writing the image");
    }
    for (uint32_t r = 0; r < rows; r++) {
        /* PFM stores the bottom row first. */
        const float *src = rgb + (size_t)(fmt == IMG_PF ? rows - 1 - r : r) * w * 3;
        for (size_t i = 0; i < (size_t)w * 3; i++) {
            if (fmt == IMG_PF) {
                uint32_t bits;
                memcpy(&bits, &src[i], 4);
                for (int k = 0; k < 4; k++)
                    line[i * 4 + k] = (unsigned char)(bits >> (8 * k));
            } else if (fmt == IMG_PPM16) {
                unsigned v = (unsigned)(img_srgb_encode(src[i]) * 65535.0f + 0.5f);
                line[i * 2] = (unsigned char)(v >> 8);
                line[i * 2 + 1] = (unsigned char)v;
            } else {
                line[i] = (unsigned char)(img_srgb_encode(src[i]) * 255.0f + 0.5f);
            }
        }
        if (fwrite(line, 1, rowbytes, f) != rowbytes) {
            free(line);
            free(tmp);
            free(pb);
            return fr_fail(err, "write failed: %s", strerror(errno));
        }
    }
    free(line);
    int bad = splat && splat_bytes(splat, nsplat, tmp, write_chunk, f) < 0;
    bad |= pb && fwrite(pb, 1, pblen, f) != pblen;
    free(tmp);
    free(pb);
    if (bad || fflush(f) != 0)
        return fr_fail(err, "write failed: %s", strerror(errno));
    return 0;
}

int img_write(FILE *f, img_format fmt, const img_partial_info *info, const float *rgb, const uint64_t *splat,
              fr_error *err)
{
    return write_image(f, fmt, info, rgb, splat, (size_t)info->width * info->height * 3, 0, NULL, err);
}

int img_write_passes(FILE *f, const img_partial_info *info, const float *rgb, const float *passes, fr_error *err)
{
    return write_image(f, IMG_PF, info, rgb, NULL, 0, 0, info->passes ? passes : NULL, err);
}

int img_write_splat_passes(FILE *f, const img_partial_info *info, const float *rgb, const uint64_t *splat,
                           const float *passes, fr_error *err)
{
    return write_image(f, IMG_PF, info, rgb, splat, (size_t)info->width * info->height * 3, 0,
                       info->passes ? passes : NULL, err);
}

/* " passes=<names>:<16 hex>" at rest (to its end) into *passes and *hash;
 * at: the header's byte offset, for the message. */
static int parse_passes(const char *rest, size_t at, uint32_t *passes, unsigned long long *hash, fr_error *err)
{
    char names[400];
    const char *colon = strrchr(rest, ':');
    size_t k = colon ? (size_t)(colon - (rest + 8)) : 0;
    fr_error e2;
    if (!colon || k == 0 || k >= sizeof names || strlen(colon + 1) != 16 ||
        strspn(colon + 1, "0123456789abcdef") != 16)
        return fr_fail(err, "byte %zu: malformed franja header comment (expected passes=<names>:<16 hex digits>)",
                       at);
    memcpy(names, rest + 8, k);
    names[k] = 0;
    *passes = 0;
    if (pass_parse(names, passes, &e2) < 0 || !*passes)
        return fr_fail(err, "byte %zu: franja header comment: passes=: %s", at, *passes ? e2.msg : "no pass");
    *hash = strtoull(colon + 1, NULL, 16);
    return 0;
}

int img_write_sums(FILE *f, const img_partial_info *info, const float *rgb, const double *sums, fr_error *err)
{
    size_t n = (size_t)info->width * (info->y1 - info->y0) * 3;
    uint64_t *bits = malloc((n ? n : 1) * sizeof *bits);
    if (!bits)
        return fr_fail(err, "out of memory writing the image");
    memcpy(bits, sums, n * sizeof *bits);
    int rc = write_image(f, IMG_PF, info, rgb, bits, n, 1, NULL, err);
    free(bits);
    return rc;
}

/* Read one header line (without the newline) starting at *pos. */
static int header_line(const unsigned char *buf, size_t len, size_t *pos, char *out, size_t cap)
{
    size_t i = 0;
    while (*pos < len && buf[*pos] != '\n') {
        if (i + 1 >= cap)
            return -1;
        out[i++] = (char)buf[(*pos)++];
    }
    if (*pos >= len)
        return -1;
    (*pos)++;
    out[i] = 0;
    return 0;
}

/* A little-endian IEEE double at p. */
static double get_double(const unsigned char *p)
{
    uint64_t bits = 0;
    for (int b = 7; b >= 0; b--)
        bits = bits << 8 | p[b];
    double d;
    memcpy(&d, &bits, 8);
    return d;
}

void img_passes_get(const unsigned char *buf, const img_partial_info *info, float *out)
{
    size_t n = (size_t)info->width * (info->y1 - info->y0) * pass_channels(info->passes);
    const unsigned char *p = buf + info->passes_offset;
    for (size_t i = 0; i < n; i++, p += 4) {
        uint32_t bits = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
        memcpy(&out[i], &bits, 4);
    }
}

void img_sums_get(const unsigned char *buf, const img_partial_info *info, double *sums)
{
    size_t n = (size_t)info->width * (info->y1 - info->y0) * 3;
    for (size_t k = 0; k < n; k++)
        sums[k] = get_double(buf + info->sums_offset + k * 8);
}

int img_read_partial(const unsigned char *buf, size_t len, img_partial_info *info, float **rgb, fr_error *err)
{
    char line[512];
    size_t pos = 0, at;
    if (header_line(buf, len, &pos, line, sizeof line) < 0 || strcmp(line, "PF") != 0)
        return fr_fail(err, "byte 0: not a PF (float RGB) partial image");
    at = pos;
    unsigned long long scene, paths = 0, hash = 0, shash = 0, phash = 0;
    uint32_t passes = 0;
    int sums = 0;
    unsigned y0, y1, spp, fw, fh;
    char tail;
    if (header_line(buf, len, &pos, line, sizeof line) < 0)
        return fr_fail(err, "byte %zu: missing or malformed franja header comment", at);
    int end = -1;
    if (sscanf(line, "# franja scene=%16llx rows=%u:%u spp=%u size=%ux%u%n", &scene, &y0, &y1, &spp, &fw, &fh,
               &end) != 6 || end < 0)
        return fr_fail(err, "byte %zu: missing or malformed franja header comment", at);
    const char *rest = line + end;
    if (!strncmp(rest, " sums=", 6)) {
        /* " sums=<16 hex>": the sample sums follow the pixels. */
        int e2 = -1;
        if (strspn(rest + 6, "0123456789abcdef") != 16 || sscanf(rest, " sums=%16llx%n", &shash, &e2) != 1 ||
            e2 != 22 || rest[e2] != 0)
            return fr_fail(err, "byte %zu: malformed franja header comment (expected sums=<16 hex digits>)", at);
        sums = 1;
    } else if (!strncmp(rest, " passes=", 8)) {
        /* " passes=<names>:<16 hex>": the render passes follow the pixels. */
        if (parse_passes(rest, at, &passes, &phash, err))
            return -1;
    } else if (*rest) {
        /* " splat=<paths>:<16 hex>": a positive count, a whole hash; then
         * maybe the passes, whose block follows the splats'. */
        int e2 = -1;
        const char *colon = strchr(rest, ':');
        if (strncmp(rest, " splat=", 7) != 0 || rest[7] < '1' || rest[7] > '9' || !colon ||
            sscanf(rest, " splat=%llu:%16llx%n", &paths, &hash, &e2) != 2 || e2 < 0 ||
            (rest[e2] != 0 && strncmp(rest + e2, " passes=", 8) != 0) || rest + e2 - (colon + 1) != 16)
            return fr_fail(err, "byte %zu: malformed franja header comment (after size=: expected nothing, "
                                "sums=<16 hex digits>, splat=<paths>:<16 hex digits> or passes=<names>:<16 hex digits>)", at);
        if (rest[e2] && parse_passes(rest + e2, at, &passes, &phash, err))
            return -1;
    }
    at = pos;
    unsigned w, h;
    if (header_line(buf, len, &pos, line, sizeof line) < 0 || sscanf(line, "%u %u%c", &w, &h, &tail) != 2)
        return fr_fail(err, "byte %zu: expected '<width> <height>'", at);
    at = pos;
    if (header_line(buf, len, &pos, line, sizeof line) < 0 || strcmp(line, "-1.0") != 0)
        return fr_fail(err, "byte %zu: expected scale -1.0 (little-endian)", at);
    if (y0 >= y1 || y1 > fh || w != fw || h != y1 - y0 || w == 0 || fw > PROTO_MAX_SIZE || fh > PROTO_MAX_SIZE)
        return fr_fail(err, "byte %zu: size %ux%u does not match rows %u:%u of a %ux%u image", at, w, h, y0, y1,
                       fw, fh);
    size_t n = (size_t)w * h * 3, nsplat = paths ? (size_t)fw * fh * 3 : sums ? n : 0;
    size_t npass = (size_t)w * h * pass_channels(passes);
    if (len - pos != n * 4 + nsplat * 8 + npass * 4)
        return fr_fail(err, "byte %zu: %zu bytes of pixels%s, expected %zu", pos, len - pos,
                       paths ? " and splats" : sums ? " and sums" : passes ? " and passes" : "",
                       n * 4 + nsplat * 8 + npass * 4);
    size_t poff = pos + n * 4 + nsplat * 8;
    if (passes && XXH3_64bits(buf + poff, npass * 4) != phash)
        return fr_fail(err, "byte %zu: the passes block does not match its hash %016llx", poff, phash);
    for (size_t i = 0; i < npass; i++) {
        const unsigned char *p = buf + poff + i * 4;
        uint32_t bits = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
        float v;
        memcpy(&v, &bits, 4);
        if (!isfinite(v))
            return fr_fail(err, "byte %zu: a render pass value is not finite", poff + i * 4);
    }
    if (paths && XXH3_64bits(buf + pos + n * 4, nsplat * 8) != hash)
        return fr_fail(err, "byte %zu: the splat block does not match its hash %016llx", pos + n * 4, hash);
    if (sums && XXH3_64bits(buf + pos + n * 4, nsplat * 8) != shash)
        return fr_fail(err, "byte %zu: the sums block does not match its hash %016llx", pos + n * 4, shash);
    float *out = malloc(n * sizeof *out);
    if (!out)
        return fr_fail(err, "out of memory reading a partial image");
    for (size_t r = 0; r < h; r++) {
        const unsigned char *src = buf + pos + (h - 1 - r) * (size_t)w * 12;
        for (size_t i = 0; i < (size_t)w * 3; i++) {
            uint32_t bits = (uint32_t)src[i * 4] | (uint32_t)src[i * 4 + 1] << 8 | (uint32_t)src[i * 4 + 2] << 16 |
                            (uint32_t)src[i * 4 + 3] << 24;
            float v;
            memcpy(&v, &bits, 4);
            /* Radiance is finite and not negative: anything else is a
             * broken or hostile worker, never stitched. */
            if (!(v >= 0.0f && v <= FLT_MAX)) {
                free(out);
                return fr_fail(err, "byte %zu: pixel (%zu, %zu) is %s (%g)", (size_t)(src - buf) + i * 4,
                               i / 3, y0 + r, v < 0.0f ? "negative" : "not finite",
                               (double)v);
            }
            out[r * w * 3 + i] = v;
            if (sums) {
                /* The pixel is its sum over spp samples, to the bit. */
                size_t k = r * w * 3 + i, o = pos + n * 4 + k * 8;
                double sum = get_double(buf + o);
                if (!(sum >= 0.0 && sum <= DBL_MAX) || (float)(sum / spp) != v) {
                    free(out);
                    return fr_fail(err, "byte %zu: the sum of pixel (%zu, %zu) is %g, not %u samples of %g", o,
                                   i / 3, y0 + r, sum, spp, (double)v);
                }
            }
        }
    }
    info->scene = scene;
    info->y0 = y0; info->y1 = y1; info->spp = spp; info->width = fw; info->height = fh;
    info->splat_paths = paths;
    info->splat_hash = hash;
    info->splat_offset = paths ? pos + n * 4 : 0;
    info->sums_offset = sums ? pos + n * 4 : 0;
    info->passes = passes;
    info->passes_offset = passes ? poff : 0;
    *rgb = out;
    return 0;
}

void img_splat_add(const unsigned char *buf, const img_partial_info *info, uint64_t *acc)
{
    const unsigned char *p = buf + info->splat_offset;
    size_t n = (size_t)info->width * info->height * 3;
    for (size_t i = 0; i < n; i++, p += 8) {
        uint64_t v = 0;
        for (int b = 7; b >= 0; b--)
            v = v << 8 | p[b];
        spl_add(&acc[i], v);
    }
}
