/* unpack.c -- a compressed binary scene into the host's scene cache (see
 * unpack.h). */
#include "unpack.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "fbin.h"
#include "file.h"
#include "mip.h"
#include "texture.h"
#include "xform.h"

int unpack_texture_ranges(const fr_texture *t, uint64_t texels_at, uint64_t texels_size, uint64_t *l0,
                          uint64_t *l0_len, uint64_t *mip, uint64_t *mip_len, fr_error *err)
{
    if (t->kind != FR_TEX_IMAGE)
        return fr_fail(err, "not an image texture");
    if (t->width == 0 || t->height == 0 || t->width > FR_TEX_MAX_SIDE || t->height > FR_TEX_MAX_SIDE)
        return fr_fail(err, "an image of %ux%u texels", t->width, t->height);
    if ((t->channels != 1 && t->channels != 3) || t->format >= FR_TEXEL_FORMATS)
        return fr_fail(err, "%u channels of format %u", t->channels, t->format);
    uint32_t side = t->width > t->height ? t->width : t->height, chain = 1;
    while (side >> chain)
        chain++;
    if (t->levels < 1 || t->levels > chain)
        return fr_fail(err, "%u mip levels (1 to %u)", t->levels, chain);
    uint64_t word = t->first[0], bytes = tex_format_bytes(t->format);
    *mip_len = 0;
    for (uint32_t k = 0; k < t->levels; k++) {
        if (t->first[k] != word)
            return fr_fail(err, "mip level %u does not follow level %u", k, k - 1);
        uint32_t w, h;
        tex_level_size(t, k, &w, &h);
        uint64_t words = ((uint64_t)w * h * t->channels * bytes + 3) / 4;
        if (k == 0) {
            *l0 = texels_at + 4 * word;
            *l0_len = 4 * words;
            *mip = *l0 + *l0_len;
        } else {
            *mip_len += 4 * words;
        }
        word += words;
    }
    if (4 * word > texels_size)
        return fr_fail(err, "mip levels past the end of the texels");
    return 0;
}

#ifdef FRANJA_NO_ZSTD

int unpack_available(void) { return 0; }

int unpack_file(const char *in, const char *out, uint64_t *hash, fr_error *err)
{
    (void)out;
    *hash = 0;
    unlink(in);
    return fr_fail(err, "%s: this worker was built without libzstd and cannot unpack scenes", in);
}

#else

#include <zstd.h>

int unpack_available(void) { return 1; }

/* Streams the frame of fd_in into fd_out; err names `in`. */
static int decompress(const char *in, int fd_in, int fd_out, fr_error *err)
{
    ZSTD_DCtx *dc = ZSTD_createDCtx();
    size_t in_cap = ZSTD_DStreamInSize(), out_cap = ZSTD_DStreamOutSize();
    char *ibuf = malloc(in_cap), *obuf = malloc(out_cap);
    int rc = 0;
    size_t left = 1;           /* ZSTD_decompressStream's hint: 0 once a frame is complete */
    if (!dc || !ibuf || !obuf)
        rc = fr_fail(err, "%s: out of memory", in);
    while (rc == 0) {
        ssize_t got = read(fd_in, ibuf, in_cap);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            rc = fr_fail(err, "%s: read error: %s", in, strerror(errno));
            break;
        }
        if (got == 0)
            break;
        if (left == 0) {
            rc = fr_fail(err, "%s: bytes after the end of the compressed scene", in);
            break;
        }
        ZSTD_inBuffer ib = {ibuf, (size_t)got, 0};
        while (rc == 0 && ib.pos < ib.size) {
            ZSTD_outBuffer ob = {obuf, out_cap, 0};
            left = ZSTD_decompressStream(dc, &ob, &ib);
            if (ZSTD_isError(left))
                rc = fr_fail(err, "%s: damaged compressed scene (%s)", in, ZSTD_getErrorName(left));
            else if (file_write_all(fd_out, obuf, ob.pos) < 0)
                rc = fr_fail(err, "%s: write error: %s", in, strerror(errno));
            else if (left == 0 && ib.pos < ib.size)
                rc = fr_fail(err, "%s: bytes after the end of the compressed scene", in);
        }
    }
    /* The rest of a frame can sit in the context's buffers: flush it. */
    while (rc == 0 && left != 0) {
        ZSTD_inBuffer ib = {ibuf, 0, 0};
        ZSTD_outBuffer ob = {obuf, out_cap, 0};
        left = ZSTD_decompressStream(dc, &ob, &ib);
        if (ZSTD_isError(left))
            rc = fr_fail(err, "%s: damaged compressed scene (%s)", in, ZSTD_getErrorName(left));
        else if (file_write_all(fd_out, obuf, ob.pos) < 0)
            rc = fr_fail(err, "%s: write error: %s", in, strerror(errno));
        else if (ob.pos == 0 && left != 0)
            rc = fr_fail(err, "%s: the compressed scene is cut short", in);
    }
    free(ibuf);
    free(obuf);
    ZSTD_freeDCtx(dc);
    return rc;
}

/* ---- packed scenes (FORMAT.md, "Packed scenes") ---- */

/* Ids of the sections a part may name (FORMAT.md, "Sections"), and the end
 * of the section table's entries up to theirs: bytes every scene has,
 * whatever its number of sections. */
enum { SEC_TEXTURES = 15, SEC_TEXELS = 16, TABLE_END = 64 + 32 * SEC_TEXELS };

/* The zstd frame of a packed scene, read as it is needed. */
typedef struct {
    const char *path;
    int fd;
    ZSTD_DCtx *dc;
    unsigned char *buf;
    size_t cap;
    ZSTD_inBuffer ib;
    uint64_t read_total;       /* bytes of the file read so far */
    uint64_t out_at;           /* bytes of the frame's content taken so far */
    size_t left;               /* ZSTD_decompressStream's hint: 0 once the frame is complete */
} reader;

/* The file's byte the reader has got to. */
static unsigned long long rd_at(const reader *r)
{
    return (unsigned long long)(r->read_total - (r->ib.size - r->ib.pos));
}

/* More of the file into the input buffer: its bytes, 0 at the end, -1 on
 * an error (err set). */
static ssize_t rd_fill(reader *r, fr_error *err)
{
    for (;;) {
        ssize_t got = read(r->fd, r->buf, r->cap);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0)
            fr_fail(err, "%s: read error: %s", r->path, strerror(errno));
        else {
            r->ib = (ZSTD_inBuffer){r->buf, (size_t)got, 0};
            r->read_total += (uint64_t)got;
        }
        return got;
    }
}

/* The next n bytes of the frame's content into dst. */
static int rd_need(reader *r, void *dst, size_t n, fr_error *err)
{
    ZSTD_outBuffer ob = {dst, n, 0};
    while (ob.pos < ob.size) {
        if (r->left == 0)
            return fr_fail(err, "%s: byte %llu: the compressed stream ends after %llu bytes, before its parts do",
                           r->path, rd_at(r), (unsigned long long)(r->out_at + ob.pos));
        size_t before = ob.pos;
        r->left = ZSTD_decompressStream(r->dc, &ob, &r->ib);
        if (ZSTD_isError(r->left))
            return fr_fail(err, "%s: byte %llu: damaged packed scene (%s)", r->path, rd_at(r),
                           ZSTD_getErrorName(r->left));
        if (ob.pos == before && r->ib.pos == r->ib.size) {
            ssize_t got = rd_fill(r, err);
            if (got < 0)
                return -1;
            if (got == 0)
                return fr_fail(err, "%s: byte %llu: the packed scene is cut short", r->path, rd_at(r));
        }
    }
    r->out_at += n;
    return 0;
}

/* The frame ends where its parts do, and the file with it. */
static int rd_finish(reader *r, fr_error *err)
{
    unsigned char one;
    while (r->left != 0) {
        ZSTD_outBuffer ob = {&one, 1, 0};
        r->left = ZSTD_decompressStream(r->dc, &ob, &r->ib);
        if (ZSTD_isError(r->left))
            return fr_fail(err, "%s: byte %llu: damaged packed scene (%s)", r->path, rd_at(r),
                           ZSTD_getErrorName(r->left));
        if (ob.pos)
            return fr_fail(err, "%s: byte %llu: more data than the parts hold", r->path, rd_at(r));
        if (r->left != 0 && r->ib.pos == r->ib.size) {
            ssize_t got = rd_fill(r, err);
            if (got < 0)
                return -1;
            if (got == 0)
                return fr_fail(err, "%s: byte %llu: the packed scene is cut short", r->path, rd_at(r));
        }
    }
    if (r->ib.pos < r->ib.size || rd_fill(r, err) != 0)
        return fr_fail(err, "%s: byte %llu: bytes after the end of the packed scene", r->path, rd_at(r));
    return 0;
}

static uint32_t u32_at(const unsigned char *p)
{
    uint32_t v;
    memcpy(&v, p, 4);
    return v;
}

static uint64_t u64_at(const unsigned char *p)
{
    uint64_t v;
    memcpy(&v, p, 8);
    return v;
}

/* Texture `index` of the scene written so far (map, up to byte `done`):
 * its record in *t, the texels section's offset in *texels_at and the
 * ranges of its levels (unpack_texture_ranges). */
static int texture_at(const unsigned char *map, uint64_t size, uint64_t done, uint32_t index, fr_texture *t,
                      uint64_t *texels_at, uint64_t r[4], fr_error *err)
{
    const unsigned char *tx = map + 64 + 32 * (SEC_TEXTURES - 1), *tl = map + 64 + 32 * (SEC_TEXELS - 1);
    uint64_t at = u64_at(tx + 8), count = u64_at(tx + 16), bytes = u64_at(tx + 24);
    *texels_at = u64_at(tl + 8);
    uint64_t texels_size = u64_at(tl + 24);
    if (u32_at(tx + 4) != sizeof(fr_texture) || at < TABLE_END || bytes != count * sizeof(fr_texture) || at > done ||
        bytes > done - at)
        return fr_fail(err, "the textures section is not before the part");
    if (index >= count)
        return fr_fail(err, "texture %u of %llu", index, (unsigned long long)count);
    if (*texels_at % 4 || *texels_at > size || texels_size > size - *texels_at)
        return fr_fail(err, "the texels section is outside the scene");
    memcpy(t, map + at + (uint64_t)index * sizeof(fr_texture), sizeof *t);
    fr_error e;
    if (unpack_texture_ranges(t, *texels_at, texels_size, &r[0], &r[1], &r[2], &r[3], &e))
        return fr_fail(err, "texture %u: %s", index, e.msg);
    return 0;
}

/* The scene being written: the file (its offset at the next part's
 * start, for parts written with write(): pages filled whole, which the
 * kernel need not zero first) and a shared mapping of it (for the parts
 * that read what is written: predicted texels and the levels above). */
typedef struct {
    int fd;
    const char *tmp;
    unsigned char *map;
} sink;

static int put(const sink *o, const void *p, size_t n, fr_error *err)
{
    if (file_write_all(o->fd, p, n) < 0)
        return fr_fail(err, "%s: write error: %s", o->tmp, strerror(errno));
    return 0;
}

/* Part i of the table (at `entry`) into the scene. */
static int part(reader *r, const sink *o, uint64_t size, const unsigned char *entry, uint32_t i,
                unsigned char *scratch, fr_error *err)
{
    uint32_t how = u32_at(entry), arg = u32_at(entry + 4);
    uint64_t off = u64_at(entry + 8), len = u64_at(entry + 16);
    unsigned char *map = o->map;
    if (how == UNPACK_COPY || how == UNPACK_SHUFFLE) {
        unsigned char *sh = scratch + XFORM_BLOCK;
        for (uint64_t done = 0; done < len; done += XFORM_BLOCK) {
            size_t n = len - done < XFORM_BLOCK ? len - done : XFORM_BLOCK;
            if (rd_need(r, scratch, n, err))
                return -1;
            if (how == UNPACK_SHUFFLE)
                xform_shuffle(scratch, n, sh, 1);
            if (put(o, how == UNPACK_SHUFFLE ? sh : scratch, n, err))
                return -1;
        }
        return 0;
    }
    fr_texture t;
    uint64_t texels_at, rg[4];
    fr_error e;
    if (texture_at(map, size, off, arg, &t, &texels_at, rg, &e))
        return fr_fail(err, "%s: part %u: %s", r->path, i, e.msg);
    uint32_t bytes = tex_format_bytes(t.format);
    if (how == UNPACK_PREDICT) {
        if (t.format == FR_TEXEL_F32 || t.format == FR_TEXEL_F16 || off != rg[0] || len != rg[1])
            return fr_fail(err, "%s: part %u: not the integer level 0 of texture %u", r->path, i, arg);
        size_t values = (size_t)t.width * t.height * t.channels, step = XFORM_BLOCK / bytes;
        for (size_t v = 0; v < values; v += step) {
            size_t n = values - v < step ? values - v : step;
            if (rd_need(r, scratch, n * bytes, err))
                return -1;
            xform_predict(map + off, t.width, t.channels, bytes, v, v + n, scratch, 1);
        }
        if (rd_need(r, map + off + values * bytes, len - values * bytes, err))
            return -1;
        if (lseek(o->fd, (off_t)(off + len), SEEK_SET) < 0)
            return fr_fail(err, "%s: %s", o->tmp, strerror(errno));
        return 0;
    }
    if (len == 0 || off != rg[2] || len != rg[3])
        return fr_fail(err, "%s: part %u: not the mip levels of texture %u", r->path, i, arg);
    /* Level by level, in strips of rows: level k - 1 read back through the map. */
    const uint32_t *texels = (const uint32_t *)(map + texels_at);
    static const unsigned char zero[4];
    for (uint32_t k = 1; k < t.levels; k++) {
        uint32_t w, h;
        tex_level_size(&t, k, &w, &h);
        size_t row = (size_t)w * t.channels * bytes, used = row * h;
        uint32_t rows = row >= XFORM_BLOCK ? 1 : (uint32_t)(XFORM_BLOCK / row);
        for (uint32_t y = 0; y < h; y += rows) {
            uint32_t y1 = h - y < rows ? h : y + rows;
            mip_level(texels, &t, k, y, y1, scratch);
            if (put(o, scratch, (y1 - y) * row, err))
                return -1;
        }
        if (put(o, zero, (4 - used % 4) % 4, err))
            return -1;
    }
    return 0;
}

/* The header's and the part table's rules (FORMAT.md). */
static int check_table(const char *in, const unsigned char *table, uint32_t n, uint64_t size, fr_error *err)
{
    uint64_t end = 0;
    for (uint32_t i = 0; i < n; i++) {
        const unsigned char *e = table + (size_t)i * UNPACK_ENTRY;
        uint32_t how = u32_at(e), arg = u32_at(e + 4);
        uint64_t off = u64_at(e + 8), len = u64_at(e + 16);
        unsigned long long at = (unsigned long long)i * UNPACK_ENTRY;
        if (how >= UNPACK_TRANSFORMS)
            return fr_fail(err, "%s: part %u (byte %llu of the frame's content): unknown transform %u", in, i, at, how);
        if (off != end || len == 0 || len > size - off)
            return fr_fail(err, "%s: part %u (byte %llu of the frame's content): bytes %llu to %llu do not follow the last "
                           "part (which ended at %llu) inside the scene's %llu", in, i, at, (unsigned long long)off,
                           (unsigned long long)(off + len), (unsigned long long)end, (unsigned long long)size);
        if ((how == UNPACK_COPY || how == UNPACK_SHUFFLE) && arg != 0)
            return fr_fail(err, "%s: part %u (byte %llu of the frame's content): argument %u (0 expected)", in, i, at, arg);
        if (how == UNPACK_SHUFFLE && len % 4)
            return fr_fail(err, "%s: part %u (byte %llu of the frame's content): %llu bytes of words", in, i, at,
                           (unsigned long long)len);
        end = off + len;
    }
    if (end != size)
        return fr_fail(err, "%s: the parts end at byte %llu of the scene's %llu", in, (unsigned long long)end,
                       (unsigned long long)size);
    return 0;
}

/* Unpacks the packed scene open as fd (its header read, in hd) into the
 * new file fd_out; *want gets the hash the header announces. */
static int unpack_parts(const char *in, int fd, const unsigned char *hd, int fd_out, const char *tmp,
                        uint64_t *want, fr_error *err)
{
    uint32_t version = u32_at(hd + 8), n = u32_at(hd + 32);
    uint64_t size = u64_at(hd + 16);
    *want = u64_at(hd + 24);
    if (version != UNPACK_VERSION)
        return fr_fail(err, "%s: byte 8: packed scene version %u (this worker reads %u)", in, version, UNPACK_VERSION);
    if (u32_at(hd + 12) != UNPACK_HEADER || u32_at(hd + 36) != 0 || u64_at(hd + 40) != 0)
        return fr_fail(err, "%s: byte 12: not a packed scene header of %d bytes with its reserved fields zero", in,
                       UNPACK_HEADER);
    if (size < TABLE_END || size > UNPACK_MAX_SCENE || size > SIZE_MAX)
        return fr_fail(err, "%s: byte 16: a scene of %llu bytes", in, (unsigned long long)size);
    if (n == 0 || n > UNPACK_MAX_PARTS)
        return fr_fail(err, "%s: byte 32: %u parts (1 to %d)", in, n, UNPACK_MAX_PARTS);
    int e = posix_fallocate(fd_out, 0, (off_t)size);
    if (e)
        return fr_fail(err, "%s: no room for %llu bytes: %s", tmp, (unsigned long long)size, strerror(e));
    unsigned char *map = mmap(NULL, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd_out, 0);
    if (map == MAP_FAILED)
        return fr_fail(err, "%s: %s", tmp, strerror(errno));
    reader r = {.path = in, .fd = fd, .dc = ZSTD_createDCtx(), .cap = ZSTD_DStreamInSize(),
                .read_total = UNPACK_HEADER, .left = 1};
    r.buf = malloc(r.cap);
    unsigned char *table = malloc((size_t)n * UNPACK_ENTRY), *scratch = malloc(2 * XFORM_BLOCK);
    int rc = 0;
    if (!r.dc || !r.buf || !table || !scratch)
        rc = fr_fail(err, "%s: out of memory", in);
    else if (ZSTD_isError(ZSTD_DCtx_setParameter(r.dc, ZSTD_d_windowLogMax, 27)))
        rc = fr_fail(err, "%s: zstd refused a window limit", in);
    /* The frame's header (RFC 8878): the magic, then a descriptor whose bit
     * 2 says that the frame ends with its checksum. */
    if (rc == 0 && rd_fill(&r, err) < 0)
        rc = -1;
    else if (rc == 0 && (r.ib.size < 5 || memcmp(r.buf, "\x28\xb5\x2f\xfd", 4) || !(r.buf[4] & 4)))
        rc = fr_fail(err, "%s: byte %d: not a zstd frame with its checksum", in, UNPACK_HEADER);
    if (rc == 0)
        rc = rd_need(&r, table, (size_t)n * UNPACK_ENTRY, err);
    if (rc == 0)
        rc = check_table(in, table, n, size, err);
    sink o = {fd_out, tmp, map};
    for (uint32_t i = 0; rc == 0 && i < n; i++)
        rc = part(&r, &o, size, table + (size_t)i * UNPACK_ENTRY, i, scratch, err);
    if (rc == 0)
        rc = rd_finish(&r, err);
    if (munmap(map, size) < 0 && rc == 0)
        rc = fr_fail(err, "%s: write error: %s", tmp, strerror(errno));
    free(table);
    free(scratch);
    free(r.buf);
    ZSTD_freeDCtx(r.dc);
    return rc;
}

int unpack_file(const char *in, const char *out, uint64_t *hash, fr_error *err)
{
    *hash = 0;
    int fd_in;
    size_t size;
    if (file_open_regular(in, SIZE_MAX, &fd_in, &size, err) < 0) {
        unlink(in);
        return -1;
    }
    char tmp[4200];
    if (snprintf(tmp, sizeof tmp, "%s.part-%ld", out, (long)getpid()) >= (int)sizeof tmp) {
        close(fd_in);
        unlink(in);
        return fr_fail(err, "%s: path too long", out);
    }
    int fd_out = open(tmp, O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd_out < 0) {
        int e = errno;
        close(fd_in);
        unlink(in);
        return fr_fail(err, "%s: %s", tmp, strerror(e));
    }
    /* A packed scene starts with its header, a zstd frame with zstd's magic. */
    unsigned char hd[UNPACK_HEADER];
    int packed = size >= UNPACK_HEADER && pread(fd_in, hd, sizeof hd, 0) == (ssize_t)sizeof hd &&
                 !memcmp(hd, UNPACK_MAGIC, 8);
    uint64_t want = 0;
    int rc;
    if (packed && lseek(fd_in, UNPACK_HEADER, SEEK_SET) != UNPACK_HEADER)
        rc = fr_fail(err, "%s: %s", in, strerror(errno));
    else
        rc = packed ? unpack_parts(in, fd_in, hd, fd_out, tmp, &want, err) : decompress(in, fd_in, fd_out, err);
    close(fd_in);
    unlink(in);
    if (close(fd_out) < 0 && rc == 0)
        rc = fr_fail(err, "%s: write error: %s", tmp, strerror(errno));
    fr_scene s;
    fr_error e;
    if (rc == 0 && fbin_load(tmp, &s, &e) < 0) {
        rc = fr_fail(err, "%s: the unpacked scene does not check out (%s)", in, e.msg);
    } else if (rc == 0) {
        *hash = s.hash;
        scn_free(&s);
        if (packed && *hash != want) {
            char a[17], b[17];
            fbin_hash_hex(*hash, a);
            fbin_hash_hex(want, b);
            rc = fr_fail(err, "%s: the unpacked scene's hash %s is not the %s its header announced", in, a, b);
        }
    }
    if (rc == 0 && rename(tmp, out) < 0)
        rc = fr_fail(err, "%s: %s", out, strerror(errno));
    if (rc < 0)
        unlink(tmp);
    return rc;
}

#endif
