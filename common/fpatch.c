/* fpatch.c -- scene patches: a binary scene as the sections it changes in
 * another (see fpatch.h). */
#include "fpatch.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fbin.h"
#include "file.h"
#include "le.h"

#define XXH_INLINE_ALL
#include <xxhash.h>

/* The binary scene's own layout (FORMAT.md): header, table, alignment. */
enum { SCN_HEADER = 64, SCN_ENTRY = 32, SCN_ALIGN = 64 };
_Static_assert(FPATCH_SECTIONS > 32, "the sections past the mask's first word are named from byte 52");
_Static_assert(FPATCH_SECTIONS <= 64, "a patch's mask has 64 bits: a new mask is a new patch version");
/* The header and table, then zeros to the first section's alignment. */
enum { SCN_HEAD = (SCN_HEADER + SCN_ENTRY * FPATCH_SECTIONS + SCN_ALIGN - 1) & ~(SCN_ALIGN - 1) };
static const unsigned char scn_magic[8] = {0x89, 'F', 'R', 'J', 'S', 'C', 'N', '\n'};


int fpatch_sections(const void *blob, size_t size, fpatch_sect s[FPATCH_SECTIONS + 1], fr_error *err)
{
    const unsigned char *p = blob;
    memset(s, 0, sizeof(fpatch_sect) * (FPATCH_SECTIONS + 1));
    if (size < SCN_HEAD || memcmp(p, scn_magic, 8))
        return fr_fail(err, "byte 0: not a binary scene");
    if (le_get32(p + 16) != SCN_HEADER || le_get32(p + 20) != FPATCH_SECTIONS)
        return fr_fail(err, "byte 16: header size %u / section count %u, expected %d / %d", le_get32(p + 16),
                       le_get32(p + 20), SCN_HEADER, FPATCH_SECTIONS);
    for (uint32_t k = 0; k < FPATCH_SECTIONS; k++) {
        const unsigned char *e = p + SCN_HEADER + (size_t)SCN_ENTRY * k;
        uint32_t elem = le_get32(e + 4);
        uint64_t off = le_get64(e + 8), count = le_get64(e + 16);
        if (le_get32(e) != k + 1 || elem == 0 || count > 0xffffffffu || off > size || count > (size - off) / elem)
            return fr_fail(err, "byte %zu: section %u out of bounds", (size_t)(e - p), k + 1);
        s[k + 1] = (fpatch_sect){p + off, elem, count};
    }
    return 0;
}

/* The size of a scene of sections s (0 past what size_t holds). */
static size_t laid_size(const fpatch_sect s[FPATCH_SECTIONS + 1], size_t off[FPATCH_SECTIONS + 1])
{
    size_t at = SCN_HEAD;
    for (int id = 1; id <= FPATCH_SECTIONS; id++) {
        uint64_t bytes = s[id].count * s[id].elem; /* count < 2^32, elem < 2^32 */
        if (s[id].count > 0xffffffffu || bytes > SIZE_MAX - at - SCN_ALIGN)
            return 0;
        off[id] = at;
        at = (at + (size_t)bytes + SCN_ALIGN - 1) & ~(size_t)(SCN_ALIGN - 1);
    }
    return at;
}

int fpatch_assemble(const fpatch_sect s[FPATCH_SECTIONS + 1], void **blob, size_t *size, uint64_t *hash,
                    fr_error *err)
{
    size_t off[FPATCH_SECTIONS + 1];
    size_t n = laid_size(s, off);
    if (!n)
        return fr_fail(err, "the scene's sections add up past the address space");
    unsigned char *p = calloc(1, n);
    if (!p)
        return fr_fail(err, "out of memory assembling a scene of %zu bytes", n);
    fbin_put_header(p, n);
    for (int id = 1; id <= FPATCH_SECTIONS; id++) {
        unsigned char *e = p + SCN_HEADER + (size_t)SCN_ENTRY * (id - 1);
        size_t bytes = (size_t)(s[id].count * s[id].elem);
        le_put32(e, (uint32_t)id);
        le_put32(e + 4, s[id].elem);
        le_put64(e + 8, off[id]);
        le_put64(e + 16, s[id].count);
        le_put64(e + 24, bytes);
        if (bytes)
            memcpy(p + off[id], s[id].data, bytes);
    }
    *hash = XXH3_64bits(p + SCN_HEADER, n - SCN_HEADER);
    le_put64(p + 32, *hash);
    *blob = p;
    *size = n;
    return 0;
}

int fpatch_same(const fpatch_sect *a, const fpatch_sect *b)
{
    return a->elem == b->elem && a->count == b->count && !memcmp(a->data, b->data, (size_t)(a->count * a->elem));
}

int fpatch_make(const void *base, size_t bsize, const void *res, size_t rsize, void **patch, size_t *psize,
                uint64_t *changed, fr_error *err)
{
    fpatch_sect b[FPATCH_SECTIONS + 1], r[FPATCH_SECTIONS + 1];
    fr_error e;
    if (fpatch_sections(base, bsize, b, &e) < 0 || fpatch_sections(res, rsize, r, &e) < 0)
        return fr_fail(err, "patch: %s", e.msg);
    if (le_get32((const unsigned char *)base + 8) != le_get32((const unsigned char *)res + 8))
        return fr_fail(err, "patch: scenes of two format versions");
    uint64_t mask = 0;
    size_t n = FPATCH_HEADER;
    for (int id = 1; id <= FPATCH_SECTIONS; id++)
        if (!fpatch_same(&b[id], &r[id])) {
            mask |= 1ull << (id - 1);
            n += FPATCH_ENTRY + (size_t)(r[id].count * r[id].elem);
        }
    unsigned char *p = calloc(1, n);
    if (!p)
        return fr_fail(err, "out of memory making a patch of %zu bytes", n);
    memcpy(p, FPATCH_MAGIC, 8);
    le_put32(p + 8, FPATCH_VERSION);
    le_put32(p + 12, (uint32_t)mask);
    le_put32(p + 52, (uint32_t)(mask >> 32));
    le_put64(p + 16, le_get64((const unsigned char *)base + 32));
    le_put64(p + 24, bsize);
    le_put64(p + 32, le_get64((const unsigned char *)res + 32));
    le_put64(p + 40, rsize);
    le_put32(p + 48, le_get32((const unsigned char *)res + 8));
    size_t at = FPATCH_HEADER;
    for (int id = 1; id <= FPATCH_SECTIONS; id++)
        if (mask >> (id - 1) & 1) {
            size_t bytes = (size_t)(r[id].count * r[id].elem);
            le_put32(p + at, (uint32_t)id);
            le_put32(p + at + 4, r[id].elem);
            le_put64(p + at + 8, r[id].count);
            memcpy(p + at + FPATCH_ENTRY, r[id].data, bytes);
            at += FPATCH_ENTRY + bytes;
        }
    *patch = p;
    *psize = n;
    *changed = mask;
    return 0;
}

int fpatch_base(const void *patch, size_t psize, uint64_t *base, fr_error *err)
{
    const unsigned char *p = patch;
    if (psize < FPATCH_HEADER || memcmp(p, FPATCH_MAGIC, 8))
        return fr_fail(err, "byte 0: not a scene patch (bad magic or shorter than its %d-byte header)",
                       FPATCH_HEADER);
    *base = le_get64(p + 16);
    return 0;
}

int fpatch_apply(const void *patch, size_t psize, const void *base, size_t bsize, void **out, size_t *osize,
                 fr_error *err)
{
    const unsigned char *p = patch, *b = base;
    uint64_t want_base = 0;
    if (fpatch_base(patch, psize, &want_base, err) < 0)
        return -1;
    if (le_get32(p + 8) != FPATCH_VERSION)
        return fr_fail(err, "byte 8: patch version %u, this program reads version %u", le_get32(p + 8), FPATCH_VERSION);
    if (le_get32(p + 48) != FBIN_VERSION)
        return fr_fail(err, "byte 48: a patch of scene format version %u, this program reads version %d",
                       le_get32(p + 48), FBIN_VERSION);
    for (int k = 56; k < FPATCH_HEADER; k++)
        if (p[k])
            return fr_fail(err, "byte %d: reserved header byte is not zero", k);
    fpatch_sect s[FPATCH_SECTIONS + 1];
    fr_error e;
    if (fpatch_sections(base, bsize, s, &e) < 0)
        return fr_fail(err, "the base scene: %s", e.msg);
    if (want_base != le_get64(b + 32) || le_get64(p + 24) != bsize)
        return fr_fail(err, "byte 16: the patch is of base scene %016llx (%llu bytes), not of %016llx (%zu bytes)",
                       (unsigned long long)want_base, (unsigned long long)le_get64(p + 24),
                       (unsigned long long)le_get64(b + 32), bsize);
    uint64_t mask = le_get32(p + 12) | (uint64_t)le_get32(p + 52) << 32;
    if (mask >> FPATCH_SECTIONS)
        return fr_fail(err, "byte 52: the mask names a section past %d", FPATCH_SECTIONS);
    size_t at = FPATCH_HEADER;
    for (uint32_t id = 1; id <= FPATCH_SECTIONS; id++) {
        if (!(mask >> (id - 1) & 1))
            continue;
        if (psize - at < FPATCH_ENTRY)
            return fr_fail(err, "byte %zu: section %u's entry runs past the end of the patch", at, id);
        uint32_t got = le_get32(p + at), elem = le_get32(p + at + 4);
        uint64_t count = le_get64(p + at + 8);
        if (got != id)
            return fr_fail(err, "byte %zu: section %u where the mask says %u comes next", at, got, id);
        if (elem != s[id].elem)
            return fr_fail(err, "byte %zu: section %u: element size %u, expected %u", at + 4, id, elem, s[id].elem);
        if (count > 0xffffffffu || count > (psize - at - FPATCH_ENTRY) / elem)
            return fr_fail(err, "byte %zu: section %u: %llu elements run past the end of the patch", at + 8, id,
                           (unsigned long long)count);
        s[id] = (fpatch_sect){p + at + FPATCH_ENTRY, elem, count};
        at += FPATCH_ENTRY + (size_t)(count * elem);
    }
    if (at != psize)
        return fr_fail(err, "byte %zu: %zu bytes after the last section", at, psize - at);
    size_t off[FPATCH_SECTIONS + 1];
    size_t n = laid_size(s, off);
    uint64_t want = le_get64(p + 40);
    if (!n || n != want)
        return fr_fail(err, "byte 40: the patch announces a scene of %llu bytes, its sections make %zu",
                       (unsigned long long)want, n);
    uint64_t hash;
    if (fpatch_assemble(s, out, osize, &hash, err) < 0)
        return -1;
    if (hash != le_get64(p + 32)) {
        free(*out);
        *out = NULL;
        return fr_fail(err, "byte 32: the rebuilt scene has hash %016llx, the patch announces %016llx",
                       (unsigned long long)hash, (unsigned long long)le_get64(p + 32));
    }
    return 0;
}

int fpatch_is(const char *path)
{
    char head[8];
    FILE *f = fopen(path, "rb");
    int is = f && fread(head, 1, 8, f) == 8 && !memcmp(head, FPATCH_MAGIC, 8);
    if (f)
        fclose(f);
    return is;
}

int fpatch_file(const char *in, const char *out, uint64_t *hash, fr_error *err)
{
    *hash = 0;
    char *data = NULL, dir[4096], base_path[4200], part[4200];
    size_t len = 0;
    fr_error e;
    fr_scene base = {0}, res = {0};
    void *blob = NULL;
    size_t size = 0;
    uint64_t want = 0;
    /* A patch is small: the sections it replaces (at most the scene). */
    int rc = file_read_max(in, (size_t)1 << 36, &data, &len, &e);
    unlink(in);
    if (rc < 0)
        return fr_fail(err, "%s", e.msg);
    if (fpatch_base(data, len, &want, &e) < 0) {
        free(data);
        return fr_fail(err, "%s: %s", in, e.msg);
    }
    char hex[17];
    fbin_hash_hex(want, hex);
    file_dir(out, dir, sizeof dir);
    snprintf(base_path, sizeof base_path, "%s/%s.fbin", dir, hex);
    snprintf(part, sizeof part, "%s.part-%ld", out, (long)getpid());
    if (fbin_load(base_path, &base, &e) < 0)
        rc = fr_fail(err, "%s: its base scene: %s", in, e.msg);
    else if (base.hash != want)
        rc = fr_fail(err, "%s: its base scene %s has hash %016llx", in, base_path, (unsigned long long)base.hash);
    else if (fpatch_apply(data, len, base.blob, base.blob_size, &blob, &size, &e) < 0)
        rc = fr_fail(err, "%s: %s", in, e.msg);
    else if (file_write_atomic(part, blob, size, &e) < 0)
        rc = fr_fail(err, "%s", e.msg);
    else if (fbin_load(part, &res, &e) < 0)
        rc = fr_fail(err, "%s: the rebuilt scene: %s", in, e.msg);
    else if (rename(part, out) < 0)
        rc = fr_fail(err, "%s: %s", out, strerror(errno));
    else
        *hash = res.hash;
    if (rc < 0)
        unlink(part);
    scn_free(&res);
    scn_free(&base);
    free(blob);
    free(data);
    return rc;
}
