/* jobdir.c -- finished slabs on disk (see jobdir.h). */
#include "jobdir.h"

#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "file.h"
#include "passes.h"
#include "protocol.h"
#include "scene.h"
#include "splat.h"

int job_sums(const job_spec *spec)
{
    return spec->integrator == FR_INTEGRATOR_PATH && !(spec->noise_threshold > 0.0f) && !spec->passes;
}

/* A partial checked against the render (scene, size, rows, splats for its
 * own sample count) whatever its sample count; *out says what it holds. */
static int check_slab(const unsigned char *buf, size_t len, const job_spec *spec, uint32_t y0, uint32_t y1,
                      img_partial_info *out, float **pixels, fr_error *err)
{
    img_partial_info info;
    float *rgb = NULL;
    if (img_read_partial(buf, len, &info, &rgb, err))
        return -1;
    if (pixels)
        *pixels = rgb;
    else
        free(rgb);
    rgb = NULL;
    if (info.scene != spec->hash)
        return fr_fail(err, "scene hash %016llx, expected %016llx", (unsigned long long)info.scene,
                       (unsigned long long)spec->hash);
    if (info.width != spec->width || info.height != spec->height)
        return fr_fail(err, "image size %ux%u, expected %ux%u", info.width, info.height, spec->width,
                       spec->height);
    if (info.y0 != y0 || info.y1 != y1)
        return fr_fail(err, "rows %u:%u, expected %u:%u", info.y0, info.y1, y0, y1);
    uint64_t paths = fr_integrator_splats(spec->integrator) ? (uint64_t)spec->width * (y1 - y0) * info.spp : 0;
    if (info.splat_paths != paths)
        return paths ? fr_fail(err, "%llu light subpaths splatted, expected %llu (one per pixel sample of its rows)",
                               (unsigned long long)info.splat_paths, (unsigned long long)paths)
                     : fr_fail(err, "light-tracing splats in a path-traced render");
    if (info.passes != spec->passes) {
        char got[400], want[400];
        pass_format(info.passes, got, sizeof got);
        pass_format(spec->passes, want, sizeof want);
        return fr_fail(err, "render passes %s, expected %s", got, want);
    }
    *out = info;
    return 0;
}

/* check_slab that frees the pixels it hands back when the slab fails. */
static int read_slab(const unsigned char *buf, size_t len, const job_spec *spec, uint32_t y0, uint32_t y1,
                     img_partial_info *out, float **pixels, fr_error *err)
{
    *pixels = NULL;
    if (check_slab(buf, len, spec, y0, y1, out, pixels, err)) {
        free(*pixels);
        *pixels = NULL;
        return -1;
    }
    return 0;
}

int job_check_partial(const unsigned char *buf, size_t len, const job_spec *spec, uint32_t y0,
                      uint32_t y1, int sums, fr_error *err)
{
    img_partial_info info;
    if (check_slab(buf, len, spec, y0, y1, &info, NULL, err))
        return -1;
    if (info.spp != spec->spp)
        return fr_fail(err, "%u samples per pixel, expected %u", info.spp, spec->spp);
    if (sums && !info.sums_offset)
        return fr_fail(err, "no sample sums (a path-traced slab keeps them, for adding samples later)");
    return 0;
}

size_t job_max_partial(const job_spec *spec, uint32_t y0, uint32_t y1)
{
    size_t n = 4096 + (size_t)spec->width * (y1 - y0) * 12;
    if (job_sums(spec))
        n += (size_t)spec->width * (y1 - y0) * 24;
    if (fr_integrator_splats(spec->integrator))
        n += (size_t)spec->width * spec->height * 24;
    n += (size_t)spec->width * (y1 - y0) * pass_channels(spec->passes) * 4 + 512;
    return n;
}

static void spec_text(const job_spec *s, char *out, size_t cap)
{
    char noise[48] = "", passes[420] = "";
    if (s->noise_threshold > 0.0f) /* nine significant digits give back the same float */
        snprintf(noise, sizeof noise, "noise_threshold=%.9g\n", (double)s->noise_threshold);
    if (s->passes) {
        char names[400];
        pass_format(s->passes, names, sizeof names);
        snprintf(passes, sizeof passes, "passes=%s\n", names);
    }
    snprintf(out, cap, "franja job\nscene=%016llx\nsize=%ux%u\nspp=%u\n%s%s%s", (unsigned long long)s->hash,
             s->width, s->height, s->spp, s->integrator == FR_INTEGRATOR_BDPT  ? "integrator=bdpt\n"
             : s->integrator == FR_INTEGRATOR_MLT ? "integrator=mlt\n"
                                                  : "", noise,
             passes);
}

/* Calls fn for every slab file name in dir ("rows-Y0-Y1.pf"). */
static int each_slab(const char *dir, int (*fn)(const char *dir, const char *name, uint32_t y0,
                                                uint32_t y1, void *ctx),
                     void *ctx, fr_error *err)
{
    DIR *d = opendir(dir);
    if (!d)
        return fr_fail(err, "%s: %s", dir, strerror(errno));
    struct dirent *e;
    int rc = 0;
    while (rc == 0 && (e = readdir(d))) {
        unsigned y0, y1;
        char tail;
        if (sscanf(e->d_name, "rows-%u-%u.p%c", &y0, &y1, &tail) == 3 && tail == 'f' &&
            strlen(e->d_name) > 4 && !strcmp(e->d_name + strlen(e->d_name) - 3, ".pf"))
            rc = fn(dir, e->d_name, y0, y1, ctx);
    }
    closedir(d);
    return rc;
}

/* A file half-written when a coordinator died (file_out_open's
 * ".NAME.tmp-..."): never used, removed. */
static void remove_temporaries(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *e;
    char path[4200];
    while ((e = readdir(d)))
        if (e->d_name[0] == '.' && strstr(e->d_name, ".tmp-")) {
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            unlink(path);
        }
    closedir(d);
}

static int remove_one(const char *dir, const char *name, uint32_t y0, uint32_t y1, void *ctx)
{
    (void)y0, (void)y1, (void)ctx;
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    unlink(path);
    return 0;
}

/* The samples per pixel a slab file's header names (its second line), 0
 * when the header cannot be read; nothing else is checked. */
static uint32_t header_spp(const char *path)
{
    char head[512];
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    size_t n = fread(head, 1, sizeof head - 1, f);
    fclose(f);
    head[n] = 0;
    const char *line = strchr(head, '\n');
    unsigned long long scene;
    unsigned y0, y1, spp = 0;
    if (!line || sscanf(line + 1, "# franja scene=%16llx rows=%u:%u spp=%u", &scene, &y0, &y1, &spp) != 4)
        return 0;
    return spp;
}

/* The most samples per pixel of the slab files in a directory (by their
 * headers). */
static int max_spp_one(const char *dir, const char *name, uint32_t y0, uint32_t y1, void *ctx)
{
    (void)y0, (void)y1;
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    uint32_t spp = header_spp(path), *max = ctx;
    if (spp > *max)
        *max = spp;
    return 0;
}

int job_open(const char *dir, const job_spec *spec, int resume, fr_error *err)
{
    char want[768], path[4200];
    spec_text(spec, want, sizeof want);
    snprintf(path, sizeof path, "%s/job", dir);
    if (mkdir(dir, 0755) && errno != EEXIST)
        return fr_fail(err, "%s: cannot create job directory: %s", dir, strerror(errno));
    remove_temporaries(dir);
    if (resume) {
        char *have;
        size_t len;
        fr_error e2;
        if (file_read(path, &have, &len, &e2) == 0) {
            /* The same render, maybe with another sample count. */
            job_spec old;
            int known = job_read_spec(dir, &old, &e2) == 0;
            job_spec same = *spec;
            if (known)
                same.spp = old.spp;
            char was[768];
            spec_text(&same, was, sizeof was);
            int ok = known && len == strlen(was) && !memcmp(have, was, len);
            free(have);
            if (!ok) {
                fr_fail(err, "%s: this job directory belongs to another render (different scene, "
                        "size, integrator, noise threshold or render passes); remove it or render without --resume", dir);
                return JOB_REFUSED;
            }
            if (old.spp != spec->spp && !job_sums(spec)) {
                fr_fail(err, "%s: holds a render with %u samples per pixel; %s cannot be continued to %u "
                        "exactly (only path tracing without --noise-threshold or render passes keeps each "
                        "pixel's sample sums): render with --fresh, or with --spp %u", dir, old.spp,
                        spec->integrator == FR_INTEGRATOR_BDPT  ? "a bidirectional render"
                        : spec->integrator == FR_INTEGRATOR_MLT ? "a Metropolis render"
                        : spec->passes                          ? "a render with passes"
                                                                : "an adaptive render",
                        spec->spp, old.spp);
                return JOB_REFUSED;
            }
            uint32_t max = 0;
            fr_error ignore;
            each_slab(dir, max_spp_one, &max, &ignore);
            if (max > spec->spp) {
                fr_fail(err, "%s holds rows rendered with %u samples per pixel, more than the %u asked for; "
                        "samples cannot be taken away: render with --spp %u or more, or with --fresh to "
                        "discard them", dir, max, spec->spp, max);
                return JOB_REFUSED;
            }
            if (old.spp == spec->spp)
                return 0;
        }
    } else {
        fr_error ignore;
        each_slab(dir, remove_one, NULL, &ignore);
    }
    return file_write_atomic(path, want, strlen(want), err);
}

/* The slab files of a directory, for the bidirectional stitch. */
typedef struct {
    uint32_t y0, y1;
    char name[64];
} slab_file;

typedef struct {
    slab_file *v;
    size_t n, cap;
} slab_list;

static int list_one(const char *dir, const char *name, uint32_t y0, uint32_t y1, void *vctx)
{
    (void)dir;
    slab_list *l = vctx;
    if (y0 >= y1 || strlen(name) >= sizeof l->v->name)
        return 0;
    if (l->n == l->cap) {
        size_t cap = l->cap ? l->cap * 2 : 64;
        slab_file *v = realloc(l->v, cap * sizeof *v);
        if (!v)
            return -1;
        l->v = v;
        l->cap = cap;
    }
    l->v[l->n].y0 = y0;
    l->v[l->n].y1 = y1;
    snprintf(l->v[l->n].name, sizeof l->v[l->n].name, "%s", name);
    l->n++;
    return 0;
}

/* What a pass over the slab files does with each (scan_ctx.mode). */
enum {
    SCAN,                      /* job_scan: rows at the render's samples; lower counts with sums as bases */
    STITCH,                    /* job_stitch: the rows at the render's samples into rgb */
    GATHER                     /* job_gather: each row from the slab with the most samples, up to the render's */
};

typedef struct {
    const job_spec *spec;
    unsigned char *have;
    uint32_t *best;            /* per row: SCAN, the most samples below spec->spp with sums (NULL: not
                                  wanted); GATHER, the samples of the row in rgb */
    float *rgb;                /* STITCH and GATHER */
    float *passes;             /* STITCH and GATHER: the render passes, or NULL */
    int rows;
    const note_sink *notes;
    int mode;
    int skipped;               /* GATHER: slab files that did not check out, kept */
    slab_list *slabs;          /* STITCH: receives the slab files at the render's samples, or NULL */
    int no_memory;             /* set when slabs could not grow */
} scan_ctx;

static int scan_one(const char *dir, const char *name, uint32_t y0, uint32_t y1, void *vctx)
{
    scan_ctx *c = vctx;
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    char *text;
    size_t len;
    fr_error e;
    img_partial_info info;
    float *rows = NULL, *prows = NULL;
    size_t nch = pass_channels(c->spec->passes);
    /* A slab with every render pass can pass FILE_READ_MAX: its job bounds it. */
    int bad = file_read_max(path, job_max_partial(c->spec, y0, y1), &text, &len, &e);
    if (!bad) {
        bad = read_slab((const unsigned char *)text, len, c->spec, y0, y1, &info, &rows, &e);
        if (!c->rgb) {
            free(rows);
            rows = NULL;
        }
        if (!bad && c->passes && nch) {
            prows = malloc((size_t)c->spec->width * (y1 - y0) * nch * sizeof *prows);
            if (!prows) {
                bad = 1;
                snprintf(e.msg, sizeof e.msg, "out of memory for its render passes");
            } else {
                img_passes_get((const unsigned char *)text, &info, prows);
            }
        }
        free(text);
    }
    if (!bad && info.spp != c->spec->spp) {
        /* Another sample count: more is never this render's (the slab is
         * left alone); fewer is a base to add samples to, when it has its
         * sums, or a row of the image so far.  A render that keeps no sums
         * (render passes' --time-limit) leaves fewer alone too. */
        int use = 0;
        if (info.spp < c->spec->spp && c->mode == GATHER) {
            use = 1;
        } else if (info.spp < c->spec->spp && c->mode == SCAN && !info.sums_offset && job_sums(c->spec)) {
            bad = 1;
            snprintf(e.msg, sizeof e.msg, "%u samples per pixel, expected %u, and no sample sums to add to",
                     info.spp, c->spec->spp);
        } else if (info.spp < c->spec->spp && c->mode == SCAN && c->best) {
            for (uint32_t y = y0; y < y1; y++)
                if (c->best[y] < info.spp)
                    c->best[y] = info.spp;
        } else if (c->mode == GATHER) {
            c->skipped++;
        }
        if (!use && !bad) {
            free(rows);
            free(prows);
            return 0;
        }
    }
    if (bad && c->mode == GATHER) {
        c->skipped++;
        free(rows);
        free(prows);
        return 0;
    }
    if (bad) {
        note_say(c->notes, "%s: discarded (%s)", path, e.msg);
        unlink(path);
        free(rows);
        free(prows);
        return 0;
    }
    size_t row = (size_t)c->spec->width * 3;
    for (uint32_t y = y0; y < y1; y++) {
        if (c->mode == GATHER) {
            if (c->have[y] && c->best[y] >= info.spp)
                continue;
            c->best[y] = info.spp;
        }
        if (rows)
            memcpy(c->rgb + y * row, rows + (y - y0) * row, row * sizeof(float));
        if (prows) {
            size_t prow = (size_t)c->spec->width * nch;
            memcpy(c->passes + y * prow, prows + (y - y0) * prow, prow * sizeof(float));
        }
        c->rows += !c->have[y];
        c->have[y] = 1;
    }
    free(rows);
    free(prows);
    if (c->mode == STITCH && c->slabs && list_one(dir, name, y0, y1, c->slabs))
        return c->no_memory = -1;
    return 0;
}

int job_scan(const char *dir, const job_spec *spec, unsigned char *have, uint32_t *base, const note_sink *notes,
             fr_error *err)
{
    scan_ctx c = {spec, have, base, NULL, NULL, 0, notes, SCAN, 0, NULL, 0};
    memset(have, 0, spec->height);
    if (base)
        memset(base, 0, spec->height * sizeof *base);
    if (each_slab(dir, scan_one, &c, err))
        return -1;
    if (base)
        for (uint32_t y = 0; y < spec->height; y++)
            if (have[y])
                base[y] = 0;
    return c.rows;
}

int job_save(const char *dir, uint32_t y0, uint32_t y1, const unsigned char *buf, size_t len, fr_error *err)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/rows-%05u-%05u.pf", dir, y0, y1);
    return file_write_atomic(path, buf, len, err);
}

static int mark_rows(const char *dir, const char *name, uint32_t y0, uint32_t y1, void *ctx)
{
    (void)dir, (void)name;
    unsigned char *seen = ctx;
    for (uint32_t y = y0; y < y1 && y < PROTO_MAX_SIZE; y++)
        seen[y] = 1;
    return 0;
}

int job_rows_present(const char *dir)
{
    unsigned char *seen = calloc(PROTO_MAX_SIZE, 1);
    if (!seen)
        return 0;
    fr_error ignore;
    int rows = 0;
    if (each_slab(dir, mark_rows, seen, &ignore) == 0)
        for (uint32_t y = 0; y < PROTO_MAX_SIZE; y++)
            rows += seen[y];
    free(seen);
    return rows;
}

/* Rows of slab files by their headers' sample counts (job_rows_at,
 * job_prune). */
typedef struct {
    uint32_t spp;              /* the count looked for */
    unsigned char *seen;       /* rows of files with at least spp (job_rows_at), exactly spp (job_prune) */
    int exact;
} rows_at_ctx;

static int rows_at_one(const char *dir, const char *name, uint32_t y0, uint32_t y1, void *vctx)
{
    rows_at_ctx *c = vctx;
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    uint32_t spp = header_spp(path);
    if (c->exact ? spp == c->spp : spp >= c->spp)
        for (uint32_t y = y0; y < y1 && y < PROTO_MAX_SIZE; y++)
            c->seen[y] = 1;
    return 0;
}

int job_rows_at(const char *dir, uint32_t spp)
{
    rows_at_ctx c = {spp, calloc(PROTO_MAX_SIZE, 1), 0};
    if (!c.seen)
        return 0;
    fr_error ignore;
    int rows = 0;
    if (each_slab(dir, rows_at_one, &c, &ignore) == 0)
        for (uint32_t y = 0; y < PROTO_MAX_SIZE; y++)
            rows += c.seen[y];
    free(c.seen);
    return rows;
}

static int prune_one(const char *dir, const char *name, uint32_t y0, uint32_t y1, void *vctx)
{
    rows_at_ctx *c = vctx;
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    uint32_t spp = header_spp(path);
    if (spp == 0 || spp >= c->spp)
        return 0;
    for (uint32_t y = y0; y < y1; y++)
        if (y >= PROTO_MAX_SIZE || !c->seen[y])
            return 0;
    unlink(path);
    return 0;
}

void job_prune(const char *dir, const job_spec *spec)
{
    rows_at_ctx c = {spec->spp, calloc(PROTO_MAX_SIZE, 1), 1};
    if (!c.seen)
        return;
    fr_error ignore;
    if (each_slab(dir, rows_at_one, &c, &ignore) == 0)
        each_slab(dir, prune_one, &c, &ignore);
    free(c.seen);
}

/* The sums of rows [y0, y1) at spp samples, gathered from slab files. */
typedef struct {
    const job_spec *spec;
    uint32_t y0, y1, spp;
    unsigned char *got;        /* y1 - y0 rows */
    float *rgb;
    double *sums;
} cont_ctx;

static int cont_one(const char *dir, const char *name, uint32_t y0, uint32_t y1, void *vctx)
{
    cont_ctx *c = vctx;
    uint32_t a = y0 > c->y0 ? y0 : c->y0, b = y1 < c->y1 ? y1 : c->y1;
    int needed = 0;
    for (uint32_t y = a; y < b; y++)
        needed |= !c->got[y - c->y0];
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    if (!needed || header_spp(path) != c->spp)
        return 0;
    char *text;
    size_t len;
    fr_error e;
    if (file_read_max(path, job_max_partial(c->spec, y0, y1), &text, &len, &e))
        return 0;
    const unsigned char *buf = (const unsigned char *)text;
    img_partial_info info;
    float *rows = NULL;
    if (read_slab(buf, len, c->spec, y0, y1, &info, &rows, &e) == 0 && info.spp == c->spp && info.sums_offset) {
        size_t row = (size_t)c->spec->width * 3;
        double *sums = malloc((y1 - y0) * row * sizeof *sums);
        if (sums) {
            img_sums_get(buf, &info, sums);
            for (uint32_t y = a; y < b; y++) {
                memcpy(c->rgb + (y - c->y0) * row, rows + (y - y0) * row, row * sizeof *rows);
                memcpy(c->sums + (y - c->y0) * row, sums + (y - y0) * row, row * sizeof *sums);
                c->got[y - c->y0] = 1;
            }
            free(sums);
        }
    }
    free(rows);
    free(text);
    return 0;
}

int job_cont_build(const char *dir, const job_spec *spec, uint32_t y0, uint32_t y1, uint32_t spp, char *path,
                   size_t cap, fr_error *err)
{
    size_t n = (size_t)spec->width * (y1 - y0) * 3;
    cont_ctx c = {spec, y0, y1, spp, calloc(y1 - y0, 1), malloc(n * sizeof(float)), malloc(n * sizeof(double))};
    char *buf = NULL;
    size_t len = 0;
    int rc = 0;
    if (!c.got || !c.rgb || !c.sums) {
        rc = fr_fail(err, "out of memory for the sums of rows %u:%u", y0, y1);
        goto out;
    }
    if (each_slab(dir, cont_one, &c, err)) {
        rc = -1;
        goto out;
    }
    for (uint32_t y = y0; y < y1; y++)
        if (!c.got[y - y0]) {
            rc = fr_fail(err, "%s: row %u with %u samples per pixel and their sums is no longer there", dir, y, spp);
            goto out;
        }
    img_partial_info info = {spec->hash, y0, y1, spp, spec->width, spec->height, 0, 0, 0, 0, 0, 0};
    FILE *f = open_memstream(&buf, &len);
    if (!f) {
        rc = fr_fail(err, "out of memory for the sums of rows %u:%u", y0, y1);
        goto out;
    }
    rc = img_write_sums(f, &info, c.rgb, c.sums, err);
    if (fclose(f) && rc == 0)
        rc = fr_fail(err, "out of memory for the sums of rows %u:%u", y0, y1);
    if (rc == 0 && snprintf(path, cap, "%s/.cont-%05u-%05u-%u.tmp-sums", dir, y0, y1, spp) >= (int)cap)
        rc = fr_fail(err, "%s: path too long", dir);
    if (rc == 0)
        rc = file_write_atomic(path, buf, len, err);
out:
    free(buf);
    free(c.got);
    free(c.rgb);
    free(c.sums);
    return rc;
}

void job_kept_note(const char *dir, char *out, size_t cap)
{
    struct stat st;
    if (lstat(dir, &st) || !S_ISDIR(st.st_mode)) {
        snprintf(out, cap, "the job directory %s was removed by another process; nothing was kept", dir);
        return;
    }
    int rows = job_rows_present(dir);
    if (rows == 0)
        snprintf(out, cap, "no finished slab is in %s, so nothing was kept", dir);
    else
        snprintf(out, cap, "%d finished rows are kept in %s; rerun with --resume", rows, dir);
}

void job_missing_rows(const unsigned char *have, uint32_t height, char *out, size_t cap)
{
    size_t n = 0;
    out[0] = 0;
    for (uint32_t y = 0; y < height;) {
        if (have[y]) {
            y++;
            continue;
        }
        uint32_t a = y;
        while (y < height && !have[y])
            y++;
        int k = snprintf(out + n, cap - n, "%s%u:%u", n ? ", " : "", a, y);
        if (k < 0 || (size_t)k >= cap - n) {
            if (cap > 4)
                strcpy(out + cap - 4, "...");
            return;
        }
        n += (size_t)k;
    }
}

static int by_rows(const void *a, const void *b)
{
    const slab_file *x = a, *y = b;
    if (x->y0 != y->y0)
        return x->y0 < y->y0 ? -1 : 1;
    return x->y1 < y->y1 ? -1 : x->y1 > y->y1;
}

/* Bidirectional: rows from a chain of the slabs l (those at the render's
 * samples: a --time-limit job holds other passes' too) that splits
 * [0, height) into non-overlapping pieces, and every chosen slab's splats
 * summed. */
static int stitch_splats(const char *dir, const job_spec *spec, slab_list l, float *rgb, fr_error *err)
{
    int32_t *from = malloc(sizeof *from * ((size_t)spec->height + 1));
    uint64_t *sum = calloc((size_t)spec->width * spec->height * 3, sizeof *sum);
    int rc = -1;
    if (!from || !sum) {
        fr_fail(err, "out of memory for the splats of a %ux%u image", spec->width, spec->height);
        goto out;
    }
    /* Slabs in row order; from[y] is the slab that ends a chain from row 0
     * at row y (-1: none yet, -2: row 0 itself). */
    qsort(l.v, l.n, sizeof *l.v, by_rows);
    for (uint32_t y = 0; y <= spec->height; y++)
        from[y] = -1;
    from[0] = -2;
    for (size_t i = 0; i < l.n; i++)
        if (l.v[i].y1 <= spec->height && from[l.v[i].y0] != -1 && from[l.v[i].y1] == -1)
            from[l.v[i].y1] = (int32_t)i;
    if (from[spec->height] == -1) {
        fr_fail(err, "the slabs in %s do not split the image into non-overlapping rows (a bidirectional render "
                     "counts each slab's light paths once); the image was not written", dir);
        goto out;
    }
    for (uint32_t y = spec->height; y > 0;) {
        const slab_file *sf = &l.v[from[y]];
        char path[4200];
        snprintf(path, sizeof path, "%s/%s", dir, sf->name);
        char *text;
        size_t len;
        img_partial_info info;
        float *rows;
        if (file_read_max(path, job_max_partial(spec, sf->y0, sf->y1), &text, &len, err))
            goto out;
        const unsigned char *buf = (const unsigned char *)text;
        if (job_check_partial(buf, len, spec, sf->y0, sf->y1, 0, err) ||
            img_read_partial(buf, len, &info, &rows, err)) {
            fr_error e2 = *err;
            fr_fail(err, "%s: %s", path, e2.msg);
            free(text);
            goto out;
        }
        memcpy(rgb + (size_t)sf->y0 * spec->width * 3, rows, (size_t)(sf->y1 - sf->y0) * spec->width * 3 * sizeof(float));
        img_splat_add(buf, &info, sum);
        free(rows);
        free(text);
        y = sf->y0;
    }
    spl_resolve(rgb, sum, spec->width, 0, spec->height, spec->spp);
    rc = 0;
out:
    free(from);
    free(sum);
    return rc;
}

int job_stitch(const char *dir, const job_spec *spec, float *rgb, const note_sink *notes, fr_error *err)
{
    return job_stitch_passes(dir, spec, rgb, NULL, notes, err);
}

int job_stitch_passes(const char *dir, const job_spec *spec, float *rgb, float *passes, const note_sink *notes,
                      fr_error *err)
{
    unsigned char *have = calloc(spec->height, 1);
    if (!have)
        return fr_fail(err, "out of memory");
    int splats = fr_integrator_splats(spec->integrator);
    slab_list l = {NULL, 0, 0};
    scan_ctx c = {spec, have, NULL, splats ? NULL : rgb, passes, 0, notes, STITCH, 0, splats ? &l : NULL, 0};
    int rc = each_slab(dir, scan_one, &c, err);
    if (rc && c.no_memory)
        rc = fr_fail(err, "%s: out of memory for the list of its slabs", dir);
    if (rc == 0 && (uint32_t)c.rows != spec->height) {
        char missing[300];
        job_missing_rows(have, spec->height, missing, sizeof missing);
        rc = fr_fail(err, "rows %s are missing from %s; the image was not written", missing, dir);
    }
    free(have);
    if (rc == 0 && splats)
        rc = stitch_splats(dir, spec, l, rgb, err);
    free(l.v);
    return rc;
}

int job_gather(const char *dir, const job_spec *spec, float *rgb, unsigned char *have, int *skipped,
               fr_error *err)
{
    return job_gather_passes(dir, spec, rgb, NULL, have, skipped, err);
}

int job_gather_passes(const char *dir, const job_spec *spec, float *rgb, float *passes, unsigned char *have,
                      int *skipped, fr_error *err)
{
    uint32_t *best = calloc(spec->height, sizeof *best);
    if (!best)
        return fr_fail(err, "out of memory");
    scan_ctx c = {spec, have, best, rgb, passes, 0, NULL, GATHER, 0, NULL, 0};
    memset(have, 0, spec->height);
    int rc = each_slab(dir, scan_one, &c, err);
    free(best);
    if (skipped)
        *skipped = c.skipped;
    return rc ? -1 : c.rows;
}

int job_read_spec(const char *dir, job_spec *spec, fr_error *err)
{
    char path[4200], *text;
    size_t len;
    snprintf(path, sizeof path, "%s/job", dir);
    if (file_read(path, &text, &len, err))
        return fr_fail(err, "%s: not a job directory (no readable job file: %s)", dir, err->msg);
    unsigned long long hash = 0;
    unsigned w = 0, h = 0, spp = 0;
    int n = -1, bdpt = 0;
    float noise = 0.0f;
    /* Exactly what spec_text writes, and nothing after it. */
    uint32_t passes = 0;
    int ok = len < 700 && memchr(text, 0, len) == NULL;
    if (ok) {
        char copy[700];
        memcpy(copy, text, len);
        copy[len] = 0;
        ok = sscanf(copy, "franja job\nscene=%16llx\nsize=%ux%u\nspp=%u\n%n", &hash, &w, &h, &spp, &n) == 4 && n > 0;
        if (ok && !strncmp(copy + n, "integrator=bdpt\n", 16)) {
            bdpt = 1;
            n += 16;
        } else if (ok && !strncmp(copy + n, "integrator=mlt\n", 15)) {
            bdpt = 2;
            n += 15;
        }
        if (ok && n < (int)len && !strncmp(copy + n, "noise_threshold=", 16)) {
            int m = -1;
            ok = sscanf(copy + n, "noise_threshold=%g\n%n", &noise, &m) == 1 && m > 0 && noise > 0.0f &&
                 noise <= 1.0f && !bdpt;
            n += ok ? m : 0;
        }
        if (ok && n < (int)len) {
            /* "passes=<names>\n", the last line. */
            char *nl = strchr(copy + n, '\n');
            fr_error e2;
            ok = !strncmp(copy + n, "passes=", 7) && nl && nl + 1 == copy + len && bdpt != 2;
            if (ok) {
                *nl = 0;
                ok = pass_parse(copy + n + 7, &passes, &e2) == 0 && passes;
            }
        }
    }
    free(text);
    if (!ok || w == 0 || h == 0 || w > PROTO_MAX_SIZE || h > PROTO_MAX_SIZE || spp == 0 || spp > PROTO_MAX_SPP)
        return fr_fail(err, "%s: not a job file of franja (expected scene=, size=WxH and spp= lines, maybe integrator=bdpt "
                       "or mlt, noise_threshold=E in (0, 1] and passes=NAMES, sizes in 1..%u)", path, PROTO_MAX_SIZE);
    spec->hash = hash;
    spec->width = w;
    spec->height = h;
    spec->spp = spp;
    spec->integrator = bdpt == 2 ? FR_INTEGRATOR_MLT : bdpt ? FR_INTEGRATOR_BDPT : FR_INTEGRATOR_PATH;
    spec->noise_threshold = noise;
    spec->passes = passes;
    return 0;
}

void job_remove(const char *dir)
{
    fr_error ignore;
    char path[4200];
    each_slab(dir, remove_one, NULL, &ignore);
    remove_temporaries(dir);
    const char *names[] = {"job", "scene.fbin", "scene.patch"};
    for (size_t i = 0; i < 3; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        unlink(path);
    }
    rmdir(dir);
}
