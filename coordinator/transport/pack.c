/* pack.c -- binary scenes compressed for the trip to a host (see pack.h). */
#include "transport/pack.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zstd.h>

#include "fbin.h"
#include "file.h"
#include "mip.h"
#include "texture.h"
#include "unpack.h"
#include "xform.h"

/* A zstd stream being written to a file. */
typedef struct {
    ZSTD_CCtx *cc;
    int fd;
    const char *in, *out;      /* names for messages */
    unsigned char *obuf;
    size_t cap;
    uint64_t size;             /* bytes written */
} stream;

/* Opens `out` (a new file) and a zstd context at `level` with checksums
 * for `pledged` bytes of content. */
static int stream_open(stream *z, const char *in, const char *out, int level, uint64_t pledged, fr_error *err)
{
    *z = (stream){.in = in, .out = out, .fd = -1, .cap = ZSTD_CStreamOutSize()};
    z->fd = open(out, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (z->fd < 0)
        return fr_fail(err, "%s: %s", out, strerror(errno));
    z->cc = ZSTD_createCCtx();
    z->obuf = malloc(z->cap);
    if (!z->cc || !z->obuf)
        return fr_fail(err, "%s: out of memory", in);
    if (ZSTD_isError(ZSTD_CCtx_setParameter(z->cc, ZSTD_c_compressionLevel, level)) ||
        ZSTD_isError(ZSTD_CCtx_setParameter(z->cc, ZSTD_c_checksumFlag, 1)) ||
        ZSTD_isError(ZSTD_CCtx_setPledgedSrcSize(z->cc, pledged)))
        return fr_fail(err, "%s: zstd refused level %d", in, level);
    return 0;
}

/* Compresses n bytes of data into the file; `end` ends the frame. */
static int stream_feed(stream *z, const void *data, size_t n, int end, fr_error *err)
{
    ZSTD_inBuffer ib = {data, n, 0};
    for (;;) {
        ZSTD_outBuffer ob = {z->obuf, z->cap, 0};
        size_t left = ZSTD_compressStream2(z->cc, &ob, &ib, end ? ZSTD_e_end : ZSTD_e_continue);
        if (ZSTD_isError(left))
            return fr_fail(err, "%s: zstd: %s (the file changed while it was read?)", z->in, ZSTD_getErrorName(left));
        if (file_write_all(z->fd, z->obuf, ob.pos) < 0)
            return fr_fail(err, "%s: write error: %s", z->out, strerror(errno));
        z->size += ob.pos;
        if (end ? left == 0 : ib.pos == ib.size)
            return 0;
    }
}

/* Closes the file (removed when rc < 0); returns rc, or -1 if closing fails. */
static int stream_close(stream *z, int rc, fr_error *err)
{
    free(z->obuf);
    ZSTD_freeCCtx(z->cc);
    if (z->fd >= 0 && close(z->fd) < 0 && rc == 0)
        rc = fr_fail(err, "%s: write error: %s", z->out, strerror(errno));
    if (rc < 0 && z->fd >= 0)
        unlink(z->out);
    return rc;
}

int pack_file(const char *in, const char *out, int level, uint64_t *size, fr_error *err)
{
    *size = 0;
    int fi;
    size_t len;
    if (file_open_regular(in, SIZE_MAX, &fi, &len, err) < 0)
        return -1;
    stream z;
    int rc = stream_open(&z, in, out, level, len, err);
    size_t in_cap = ZSTD_CStreamInSize();
    char *ibuf = malloc(in_cap);
    if (rc == 0 && !ibuf)
        rc = fr_fail(err, "%s: out of memory", in);
    uint64_t done = 0;
    for (int last = 0; rc == 0 && !last;) {
        ssize_t got = read(fi, ibuf, in_cap);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            rc = fr_fail(err, "%s: read error: %s", in, strerror(errno));
            break;
        }
        done += (uint64_t)got;
        last = got == 0 || done >= len;
        rc = stream_feed(&z, ibuf, (size_t)got, last, err);
    }
    free(ibuf);
    close(fi);
    *size = z.size;
    return stream_close(&z, rc, err);
}

/* ---- packed scenes (unpack.h; FORMAT.md, "Packed scenes") ---- */

typedef struct {
    uint32_t how, arg;         /* UNPACK_* transform, its texture */
    uint64_t off, len;         /* bytes of the scene */
} part;

/* The sections sent byte-shuffled (tests/bench/README.md, "Packed
 * scenes"): prims, triangles, normals. */
static const uint32_t shuffled[] = {4, 7, 9};

static int part_cmp(const void *a, const void *b)
{
    const part *x = a, *y = b;
    return x->off < y->off ? -1 : x->off > y->off;
}

/* 1 when mip_level rebuilds levels 1 on of texture t exactly as they are
 * stored (always, for a scene of this compiler). */
static int mip_rebuilds(const fr_scene *s, const fr_texture *t, unsigned char *scratch)
{
    uint32_t bytes = tex_format_bytes(t->format);
    for (uint32_t k = 1; k < t->levels; k++) {
        uint32_t w, h;
        tex_level_size(t, k, &w, &h);
        size_t row = (size_t)w * t->channels * bytes, used = row * h;
        uint32_t rows = row >= XFORM_BLOCK ? 1 : (uint32_t)(XFORM_BLOCK / row);
        const unsigned char *lv = (const unsigned char *)(s->texels + t->first[k]);
        for (uint32_t y = 0; y < h; y += rows) {
            uint32_t y1 = h - y < rows ? h : y + rows;
            mip_level(s->texels, t, k, y, y1, scratch);
            if (memcmp(scratch, lv + y * row, (y1 - y) * row))
                return 0;
        }
        for (size_t i = used; i % 4; i++)
            if (lv[i])
                return 0;
    }
    return 1;
}

/* The parts of scene s in order (*parts malloc'd, *n of them). */
static int plan(const fr_scene *s, part **parts, uint32_t *n, unsigned char *scratch, fr_error *err)
{
    const unsigned char *b = s->blob;
    uint64_t size = s->blob_size, cap = 2 * (uint64_t)s->n_textures + 8;
    part *sp = malloc(cap * sizeof *sp), *all = malloc((2 * cap + 1) * sizeof *all);
    if (!sp || !all) {
        free(sp);
        free(all);
        return fr_fail(err, "out of memory");
    }
    uint32_t ns = 0;
    for (size_t i = 0; i < sizeof shuffled / sizeof shuffled[0]; i++) {
        uint64_t off, len;
        memcpy(&off, b + 64 + 32 * (shuffled[i] - 1) + 8, 8);
        memcpy(&len, b + 64 + 32 * (shuffled[i] - 1) + 24, 8);
        if (len)
            sp[ns++] = (part){UNPACK_SHUFFLE, 0, off, len};
    }
    uint64_t texels_at = s->n_texels ? (uint64_t)((const unsigned char *)s->texels - b) : 0;
    for (uint32_t t = 0; t < s->n_textures && s->n_texels && ns + 2 < UNPACK_MAX_PARTS / 2; t++) {
        const fr_texture *x = &s->textures[t];
        uint64_t r[4];
        fr_error e;
        if (unpack_texture_ranges(x, texels_at, (uint64_t)s->n_texels * 4, &r[0], &r[1], &r[2], &r[3], &e))
            continue;
        if (x->format != FR_TEXEL_F32 && x->format != FR_TEXEL_F16)
            sp[ns++] = (part){UNPACK_PREDICT, t, r[0], r[1]};
        if (r[3] && mip_rebuilds(s, x, scratch))
            sp[ns++] = (part){UNPACK_MIP, t, r[2], r[3]};
    }
    qsort(sp, ns, sizeof *sp, part_cmp);
    uint64_t at = 0;
    uint32_t na = 0;
    for (uint32_t i = 0; i < ns; i++) {
        if (sp[i].off < at)
            continue;          /* overlapping ranges: the first one only */
        if (sp[i].off > at)
            all[na++] = (part){UNPACK_COPY, 0, at, sp[i].off - at};
        all[na++] = sp[i];
        at = sp[i].off + sp[i].len;
    }
    if (at < size)
        all[na++] = (part){UNPACK_COPY, 0, at, size - at};
    free(sp);
    *parts = all;
    *n = na;
    return 0;
}

/* Compresses part p of scene s (its bytes after their transform). */
static int pack_part(stream *z, const fr_scene *s, const part *p, unsigned char *scratch, fr_error *err)
{
    unsigned char *src = (unsigned char *)s->blob + p->off;
    if (p->how == UNPACK_COPY)
        return stream_feed(z, src, p->len, 0, err);
    if (p->how == UNPACK_SHUFFLE) {
        for (uint64_t done = 0; done < p->len; done += XFORM_BLOCK) {
            size_t k = p->len - done < XFORM_BLOCK ? p->len - done : XFORM_BLOCK;
            xform_shuffle(src + done, k, scratch, 0);
            if (stream_feed(z, scratch, k, 0, err))
                return -1;
        }
        return 0;
    }
    if (p->how == UNPACK_PREDICT) {
        const fr_texture *t = &s->textures[p->arg];
        uint32_t bytes = tex_format_bytes(t->format);
        size_t values = (size_t)t->width * t->height * t->channels, step = XFORM_BLOCK / bytes;
        for (size_t v = 0; v < values; v += step) {
            size_t k = values - v < step ? values - v : step;
            xform_predict(src, t->width, t->channels, bytes, v, v + k, scratch, 0);
            if (stream_feed(z, scratch, k * bytes, 0, err))
                return -1;
        }
        return stream_feed(z, src + values * bytes, p->len - values * bytes, 0, err);
    }
    return 0;                  /* UNPACK_MIP: rebuilt by the host */
}

static void put32(unsigned char *p, uint32_t v) { memcpy(p, &v, 4); }
static void put64(unsigned char *p, uint64_t v) { memcpy(p, &v, 8); }

int pack_scene_file(const char *in, const char *out, int level, uint64_t *size, fr_error *err)
{
    *size = 0;
    fr_scene s;
    if (fbin_load(in, &s, err))
        return -1;
    part *parts = NULL;
    uint32_t n = 0;
    unsigned char *scratch = malloc(XFORM_BLOCK), *table = NULL;
    int rc = scratch ? plan(&s, &parts, &n, scratch, err) : fr_fail(err, "%s: out of memory", in);
    uint64_t content = (uint64_t)n * UNPACK_ENTRY;
    if (rc == 0 && !(table = malloc(content)))
        rc = fr_fail(err, "%s: out of memory", in);
    for (uint32_t i = 0; rc == 0 && i < n; i++) {
        unsigned char *e = table + (size_t)i * UNPACK_ENTRY;
        put32(e, parts[i].how);
        put32(e + 4, parts[i].arg);
        put64(e + 8, parts[i].off);
        put64(e + 16, parts[i].len);
        content += parts[i].how == UNPACK_MIP ? 0 : parts[i].len;
    }
    unsigned char hd[UNPACK_HEADER] = {0};
    memcpy(hd, UNPACK_MAGIC, 8);
    put32(hd + 8, UNPACK_VERSION);
    put32(hd + 12, UNPACK_HEADER);
    put64(hd + 16, s.blob_size);
    put64(hd + 24, s.hash);
    put32(hd + 32, n);
    stream z = {.fd = -1};
    if (rc == 0)
        rc = stream_open(&z, in, out, level, content, err);
    if (rc == 0 && file_write_all(z.fd, hd, sizeof hd) < 0)
        rc = fr_fail(err, "%s: write error: %s", out, strerror(errno));
    z.size = sizeof hd;
    if (rc == 0)
        rc = stream_feed(&z, table, (size_t)n * UNPACK_ENTRY, 0, err);
    for (uint32_t i = 0; rc == 0 && i < n; i++)
        rc = pack_part(&z, &s, &parts[i], scratch, err);
    if (rc == 0)
        rc = stream_feed(&z, NULL, 0, 1, err);
    *size = z.size;
    free(parts);
    free(table);
    free(scratch);
    scn_free(&s);
    return stream_close(&z, rc, err);
}

/* The copies in use: few at once (one per scene being staged). */
enum { SLOTS = 16 };
static struct {
    uint64_t hash;
    int form;                  /* PACK_* */
    int users;                 /* 0: free */
    int ready;                 /* made (users wait on `made` until then) */
    char path[4200];
    uint64_t size;
} slot[SLOTS];
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t made = PTHREAD_COND_INITIALIZER;

int pack_acquire(const char *scene, uint64_t hash, int form, char *path, size_t cap, uint64_t *size,
                 fr_error *err)
{
    pthread_mutex_lock(&lock);
    int i, free_i = -1;
    for (;;) {
        for (i = 0; i < SLOTS; i++)
            if (slot[i].users && slot[i].hash == hash && slot[i].form == form)
                break;
        if (i == SLOTS || slot[i].ready)
            break;
        pthread_cond_wait(&made, &lock);
    }
    if (i < SLOTS) {
        slot[i].users++;
        snprintf(path, cap, "%s", slot[i].path);
        *size = slot[i].size;
        pthread_mutex_unlock(&lock);
        return 0;
    }
    for (i = 0; i < SLOTS && free_i < 0; i++)
        if (!slot[i].users)
            free_i = i;
    if (free_i < 0) {
        pthread_mutex_unlock(&lock);
        return fr_fail(err, "more than %d scenes being compressed at once", SLOTS);
    }
    i = free_i;
    const char *tmp = getenv("TMPDIR");
    char hex[17];
    fbin_hash_hex(hash, hex);
    snprintf(slot[i].path, sizeof slot[i].path, "%s/franja-%s-%ld-%d.fbin.%s", tmp && tmp[0] ? tmp : "/tmp", hex,
             (long)getpid(), i, form == PACK_PARTS ? "fpak" : "zst");
    slot[i].hash = hash;
    slot[i].form = form;
    slot[i].users = 1;
    slot[i].ready = 0;
    pthread_mutex_unlock(&lock);

    /* Compressed outside the lock: hosts of other scenes go on. */
    uint64_t n;
    unlink(slot[i].path);
    int rc = form == PACK_PARTS ? pack_scene_file(scene, slot[i].path, PACK_LEVEL, &n, err)
                                : pack_file(scene, slot[i].path, PACK_LEVEL, &n, err);

    pthread_mutex_lock(&lock);
    if (rc == 0) {
        slot[i].size = n;
        slot[i].ready = 1;
        snprintf(path, cap, "%s", slot[i].path);
        *size = n;
    } else {
        slot[i].users = 0;     /* waiting threads try again themselves */
    }
    pthread_cond_broadcast(&made);
    pthread_mutex_unlock(&lock);
    return rc;
}

void pack_release(uint64_t hash, int form)
{
    pthread_mutex_lock(&lock);
    for (int i = 0; i < SLOTS; i++)
        if (slot[i].users && slot[i].ready && slot[i].hash == hash && slot[i].form == form) {
            if (--slot[i].users == 0)
                unlink(slot[i].path);
            break;
        }
    pthread_mutex_unlock(&lock);
}
