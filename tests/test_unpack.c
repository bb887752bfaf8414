/* test_unpack.c -- packed scenes (FORMAT.md, "Packed scenes";
 * coordinator/transport/pack.h: pack_scene_file, common/unpack.h): a
 * textured scene travels as shuffled, predicted and copied parts with its
 * mip levels left out, and unpacks to its bytes, with images of every
 * texel format and odd sizes added; a scene whose mip levels are not the
 * filter's keeps them; every rule of the header and the part
 * table is enforced with an error naming the file, and nothing is left of
 * a refused transfer. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zstd.h>

#include "check.h"
#include "tmpfiles.h"
#include "compile/texstore.h"
#include "fbin.h"
#include "file.h"
#include "transport/pack.h"
#include "unpack.h"

static char dir[64], scene[128], pak[128], out[128];

static int entries(void) { return tmpfiles_entries(dir); }

/* The little-endian number of `bytes` bytes (4 or 8) at p. */
static uint64_t get(const unsigned char *p, int bytes)
{
    uint64_t v = 0;
    for (int i = bytes - 1; i >= 0; i--)
        v = v << 8 | p[i];
    return v;
}
#define get32(p) ((uint32_t)get((p), 4))
#define get64(p) get((p), 8)

/* The packed scene at pak: its header in hd, its frame's content (malloc'd). */
static unsigned char *content(unsigned char hd[UNPACK_HEADER], size_t *len)
{
    char *f;
    size_t n;
    fr_error err;
    if (file_read(pak, &f, &n, &err) || n < UNPACK_HEADER)
        return NULL;
    memcpy(hd, f, UNPACK_HEADER);
    unsigned long long c = ZSTD_getFrameContentSize(f + UNPACK_HEADER, n - UNPACK_HEADER);
    unsigned char *body = c < ((size_t)1 << 30) ? malloc(c + 1) : NULL;
    if (body && ZSTD_decompress(body, c, f + UNPACK_HEADER, n - UNPACK_HEADER) != c) {
        free(body);
        body = NULL;
    }
    free(f);
    *len = c;
    return body;
}

/* Writes hd and body (compressed) as the file pak, `extra` bytes of junk after. */
static void repack(const unsigned char *hd, const unsigned char *body, size_t len, size_t extra)
{
    size_t cap = ZSTD_compressBound(len);
    char *z = malloc(UNPACK_HEADER + cap + extra);
    memcpy(z, hd, UNPACK_HEADER);
    ZSTD_CCtx *cc = ZSTD_createCCtx();
    ZSTD_CCtx_setParameter(cc, ZSTD_c_checksumFlag, 1);
    size_t n = ZSTD_compress2(cc, z + UNPACK_HEADER, cap, body, len);
    ZSTD_freeCCtx(cc);
    memset(z + UNPACK_HEADER + n, 'J', extra);
    fr_error err;
    if (file_write_atomic(pak, z, UNPACK_HEADER + n + extra, &err))
        printf("cannot write %s: %s\n", pak, err.msg);
    free(z);
}

/* Unpacks pak, which must fail with `what` in the message, leaving only the scene. */
static void refused(const char *why, const char *what)
{
    uint64_t hash;
    fr_error err = {0};
    int rc = unpack_file(pak, out, &hash, &err);
    CHECK(rc < 0 && strstr(err.msg, what) && strstr(err.msg, pak), "%s: want \"%s\", got %d \"%s\"", why, what, rc,
          err.msg);
    CHECK(entries() == 1, "%s: only the scene is left (%d entries)", why, entries());
}

/* The first part with transform `how` (its index), or -1. */
static int find(const unsigned char *body, uint32_t n, uint32_t how)
{
    for (uint32_t i = 0; i < n; i++)
        if (get32(body + (size_t)i * UNPACK_ENTRY) == how)
            return (int)i;
    return -1;
}

/* Scene s with seven images of odd sizes added, one of each texel format
 * and of 1 and 3 channels (unused by its materials), written to path;
 * *added gets their number. */
static int every_format(const fr_scene *s, const char *path, uint32_t *added)
{
    enum { W = 37, H = 23 };
    static uint8_t u8[W * H * 3];
    static uint16_t u16[W * H * 3], f16[W * H * 3];
    static float f32[W * H], big[W * H];
    uint32_t r = 12345;
    for (int i = 0; i < W * H * 3; i++) {
        r = r * 1103515245u + 12345u;
        u8[i] = (uint8_t)(i / 3 + (r >> 28));            /* a gradient with grain */
        u16[i] = (uint16_t)(i * 40 + (r >> 20));
        f16[i] = (uint16_t)(0x3000 + (i & 0xfff) + (r >> 29)); /* finite halves */
        if (i < W * H)
            f32[i] = big[i] = (float)(r >> 16) / 1000.0f;
    }
    big[3] = 1e6f;                                      /* past half's range: floats */
    struct { const void *data; uint32_t type, ch; int srgb; } img[] = {
        {u8, SCENE_PIX_U8, 3, 1},   {u8, SCENE_PIX_U8, 1, 0},   {u16, SCENE_PIX_U16, 3, 0},
        {u16, SCENE_PIX_U16, 1, 1}, {f16, SCENE_PIX_F16, 3, 0}, {f32, SCENE_PIX_F32, 1, 0},
        {big, SCENE_PIX_F32, 1, 0},
    };
    uint32_t n = sizeof img / sizeof img[0];
    fr_builder b;
    bld_init(&b);
    fr_texture *tex = malloc((s->n_textures + n) * sizeof *tex);
    memcpy(tex, s->textures, s->n_textures * sizeof *tex);
    /* The scene's texels first, then the new images'. */
    uint32_t *room = malloc((size_t)s->n_texels * 4);
    memcpy(room, s->texels, (size_t)s->n_texels * 4);
    b.texels.data = room;
    b.texels.count = b.texels.cap = s->n_texels;
    int rc = 0;
    for (uint32_t i = 0; i < n && rc == 0; i++) {
        scene_image im = {.data = (void *)img[i].data, .type = img[i].type, .width = W, .height = H,
                          .channels = img[i].ch};
        fr_texture *t = &tex[s->n_textures + i];
        memset(t, 0, sizeof *t);
        t->kind = FR_TEX_IMAGE;
        t->scale = (vec2){1, 1};
        fr_error err;
        rc = texstore_image(&b, &im, img[i].srgb, t, "test image", &err);
        CHECK(rc == 0, "%s", err.msg);
    }
    fr_scene view = *s;
    view.textures = tex;
    view.n_textures = s->n_textures + n;
    view.texels = b.texels.data;
    view.n_texels = b.texels.count;
    uint64_t h;
    size_t size;
    fr_error err;
    if (rc == 0 && fbin_write_view(&view, path, &h, &size, &err) < 0)
        rc = fr_fail(&err, "%s", err.msg);
    CHECK(rc == 0, "every format: %s", err.msg);
    free(tex);
    bld_free(&b);
    *added = n;
    return rc;
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/franja-test-unpack-XXXXXX");
    CHECK(mkdtemp(dir) != NULL, "mkdtemp");
    snprintf(scene, sizeof scene, "%s/s.fbin", dir);
    CHECK(tmpfiles_compile("scenes/cornell-textured.json", scene) == 0, "compile");
    fr_scene s;
    fr_error err;
    CHECK(fbin_load(scene, &s, &err) == 0, "%s", err.msg);
    snprintf(pak, sizeof pak, "%s/s.fpak", dir);
    snprintf(out, sizeof out, "%s/cache.fbin", dir);
    char cmd[300];
    uint64_t want = s.hash, fbin = s.blob_size;
    uint32_t textures = s.n_textures;

    /* Packed: smaller than one zstd frame of the file; unpacked: the same bytes. */
    uint64_t size, zsize, hash;
    CHECK(pack_file(scene, pak, PACK_LEVEL, &zsize, &err) == 0, "%s", err.msg);
    unlink(pak);
    CHECK(pack_scene_file(scene, pak, PACK_LEVEL, &size, &err) == 0, "%s", err.msg);
    CHECK(size < zsize && size * 2 < fbin, "packed %llu bytes, zstd alone %llu, the scene %llu",
          (unsigned long long)size, (unsigned long long)zsize, (unsigned long long)fbin);
    unsigned char hd[UNPACK_HEADER];
    size_t len;
    unsigned char *body = content(hd, &len);
    CHECK(body != NULL, "the packed scene is one zstd frame with its size");
    if (!body)
        return check_done();
    uint32_t n = get32(hd + 32);
    CHECK(!memcmp(hd, UNPACK_MAGIC, 8) && get32(hd + 8) == UNPACK_VERSION && get64(hd + 16) == fbin &&
          get64(hd + 24) == want && n > 3 && len > (size_t)n * UNPACK_ENTRY, "the header: %u parts", n);
    int sh = find(body, n, UNPACK_SHUFFLE), pr = find(body, n, UNPACK_PREDICT), mp = find(body, n, UNPACK_MIP);
    CHECK(sh >= 0 && pr >= 0 && mp >= 0, "shuffled (%d), predicted (%d) and mip (%d) parts", sh, pr, mp);
    CHECK(unpack_file(pak, out, &hash, &err) == 0, "%s", err.msg);
    CHECK(hash == want && tmpfiles_same(out, scene), "the unpacked scene is the scene");
    CHECK(access(pak, F_OK) < 0, "the packed file is removed");
    unlink(out);

    /* Images of every format added: each level 0 of 8 or 16 bits
     * predicted, every texture's mip levels rebuilt, the same bytes. */
    char all[128];
    uint32_t added = 0, mips_before = 0, mips = 0, preds = 0;
    snprintf(all, sizeof all, "%s/all.fbin", dir);
    for (uint32_t i = 0; i < n; i++)
        mips_before += get32(body + (size_t)i * UNPACK_ENTRY) == UNPACK_MIP;
    if (every_format(&s, all, &added) == 0) {
        uint64_t psz;
        CHECK(pack_scene_file(all, pak, PACK_LEVEL, &psz, &err) == 0, "%s", err.msg);
        size_t alen;
        unsigned char ahd[UNPACK_HEADER], *abody = content(ahd, &alen);
        for (uint32_t i = 0; abody && i < get32(ahd + 32); i++) {
            uint32_t how = get32(abody + (size_t)i * UNPACK_ENTRY), arg = get32(abody + (size_t)i * UNPACK_ENTRY + 4);
            mips += how == UNPACK_MIP && arg >= s.n_textures;
            preds += how == UNPACK_PREDICT && arg >= s.n_textures;
        }
        free(abody);
        CHECK(mips == added && preds == 4, "every format: %u of %u mip parts, %u predicted (4 expected)", mips,
              added, preds);
        CHECK(unpack_file(pak, out, &hash, &err) == 0 && tmpfiles_same(out, all), "every format: %s", err.msg);
        unlink(out);
        unlink(all);
    }
    CHECK(mips_before > 0, "the scene's own textures have mip parts");

    /* Mip levels that are not the filter's (another compiler's): kept. */
    const fr_texture *t = NULL;
    for (uint32_t i = 0; i < s.n_textures && !t; i++)
        if (s.textures[i].kind == FR_TEX_IMAGE && s.textures[i].levels > 1)
            t = &s.textures[i];
    CHECK(t != NULL, "a texture with mip levels");
    char odd[128];
    snprintf(odd, sizeof odd, "%s/odd.fbin", dir);
    if (t) {
        uint32_t *copy = malloc((size_t)s.n_texels * 4);
        memcpy(copy, s.texels, (size_t)s.n_texels * 4);
        copy[t->first[1]] ^= 0x01010101u;
        fr_scene view = s;
        view.texels = copy;
        uint64_t oh;
        size_t osz;
        CHECK(fbin_write_view(&view, odd, &oh, &osz, &err) == 0, "%s", err.msg);
        free(copy);
        uint64_t psz;
        CHECK(pack_scene_file(odd, pak, PACK_LEVEL, &psz, &err) == 0, "%s", err.msg);
        CHECK(unpack_file(pak, out, &hash, &err) == 0 && hash == oh && tmpfiles_same(out, odd), "odd levels: %s",
              err.msg);
        unlink(out);
        unlink(odd);
    }
    scn_free(&s);

    /* The header's rules. */
    unsigned char h2[UNPACK_HEADER];
    const struct { size_t at; uint32_t v; const char *what; } fields[] = {
        {8, 2, "version 2"}, {12, 40, "header"}, {32, 0, "parts"}, {32, UNPACK_MAX_PARTS + 1, "parts"},
        {36, 7, "reserved"}, {16, 100, "a scene of"},
    };
    for (size_t k = 0; k < sizeof fields / sizeof fields[0]; k++) {
        memcpy(h2, hd, sizeof h2);
        memcpy(h2 + fields[k].at, &fields[k].v, 4);
        repack(h2, body, len, 0);
        refused(fields[k].what, fields[k].what);
    }
    memcpy(h2, hd, sizeof h2);
    h2[24] ^= 1;
    repack(h2, body, len, 0);
    refused("another hash", "announced");

    /* The part table's rules. */
    unsigned char *b2 = malloc(len);
    struct { int part; size_t at; int64_t add; const char *what; } edits[] = {
        {0, 0, 9, "unknown transform"},         {1, 8, 1, "do not follow"},
        {(int)n - 1, 16, -4, "parts end at"},   {pr, 4, 999, "texture 999 of"},
        {mp, 4, 1, "not the mip levels"},       {sh, 4, 1, "argument"},
        {pr, 0, UNPACK_MIP - UNPACK_PREDICT, "not the mip levels"},
    };
    for (size_t k = 0; k < sizeof edits / sizeof edits[0]; k++) {
        memcpy(b2, body, len);
        unsigned char *e = b2 + (size_t)edits[k].part * UNPACK_ENTRY + edits[k].at;
        if (edits[k].at == 0 || edits[k].at == 4) {
            uint32_t v = edits[k].add == 999 ? 999 : get32(e) + (uint32_t)edits[k].add;
            if (k == 4)        /* another texture */
                v %= textures;
            memcpy(e, &v, 4);
        } else {
            uint64_t v = get64(e) + (uint64_t)edits[k].add;
            memcpy(e, &v, 8);
        }
        repack(hd, b2, len, 0);
        refused(edits[k].what, edits[k].what);
    }
    /* A shuffled part of an odd length (the next part starting there). */
    memcpy(b2, body, len);
    unsigned char *e = b2 + (size_t)sh * UNPACK_ENTRY;
    uint64_t l = get64(e + 16) - 1, o = get64(e + 24 + 8) - 1, l1 = get64(e + 24 + 16) + 1;
    memcpy(e + 16, &l, 8);
    memcpy(e + 24 + 8, &o, 8);
    memcpy(e + 24 + 16, &l1, 8);
    repack(hd, b2, len, 0);
    refused("odd shuffle", "bytes of words");
    free(b2);

    /* The frame: cut, longer than its parts, junk after it, damaged bytes. */
    repack(hd, body, len - 100, 0);
    refused("short content", "ends after");
    unsigned char *b3 = malloc(len + 5);
    memcpy(b3, body, len);
    memcpy(b3 + len, "extra", 5);
    repack(hd, b3, len + 5, 0);
    refused("long content", "more data than the parts");
    free(b3);
    /* A frame without its checksum. */
    char *f = NULL;
    size_t fl = 0;
    repack(hd, body, len, 0);
    if (file_read(pak, &f, &fl, &err) || fl < UNPACK_HEADER + 5)
        return check_done();
    f[UNPACK_HEADER + 4] &= ~4;
    CHECK(file_write_atomic(pak, f, fl, &err) == 0, "write");
    free(f);
    refused("no checksum", "checksum");
    repack(hd, body, len, 3);
    refused("junk after", "bytes after the end");
    body[len - 1000] ^= 0x40;
    repack(hd, body, len, 0);
    refused("a changed byte", "does not check out");
    body[len - 1000] ^= 0x40;
    repack(hd, body, len, 0);
    CHECK(truncate(pak, 5000) == 0, "truncate");
    refused("a cut file", "cut short");
    repack(hd, body, len, 0);
    snprintf(cmd, sizeof cmd, "printf XXXX | dd of=%s bs=1 seek=3000 conv=notrunc 2>/dev/null", pak);
    CHECK(system(cmd) == 0, "damage");
    refused("damaged", "damaged packed scene");
    free(body);

    unlink(scene);
    rmdir(dir);
    return check_done();
}
