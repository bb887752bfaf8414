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
#include "protocol.h"
#include "scene.h"
#include "splat.h"

int job_check_partial(const unsigned char *buf, size_t len, const job_spec *spec, uint32_t y0,
                      uint32_t y1, fr_error *err)
{
    img_partial_info info;
    float *rgb = NULL;
    if (img_read_partial(buf, len, &info, &rgb, err))
        return -1;
    free(rgb);
    if (info.scene != spec->hash)
        return fr_fail(err, "scene hash %016llx, expected %016llx", (unsigned long long)info.scene,
                       (unsigned long long)spec->hash);
    if (info.width != spec->width || info.height != spec->height)
        return fr_fail(err, "image size %ux%u, expected %ux%u", info.width, info.height, spec->width,
                       spec->height);
    if (info.y0 != y0 || info.y1 != y1)
        return fr_fail(err, "rows %u:%u, expected %u:%u", info.y0, info.y1, y0, y1);
    if (info.spp != spec->spp)
        return fr_fail(err, "%u samples per pixel, expected %u", info.spp, spec->spp);
    uint64_t paths = spec->integrator == FR_INTEGRATOR_BDPT ? (uint64_t)spec->width * (y1 - y0) * spec->spp : 0;
    if (info.splat_paths != paths)
        return paths ? fr_fail(err, "%llu light subpaths splatted, expected %llu (one per pixel sample of its rows)",
                               (unsigned long long)info.splat_paths, (unsigned long long)paths)
                     : fr_fail(err, "light-tracing splats in a path-traced render");
    return 0;
}

size_t job_max_partial(const job_spec *spec, uint32_t y0, uint32_t y1)
{
    size_t n = 4096 + (size_t)spec->width * (y1 - y0) * 12;
    if (spec->integrator == FR_INTEGRATOR_BDPT)
        n += (size_t)spec->width * spec->height * 24;
    return n;
}

static void spec_text(const job_spec *s, char *out, size_t cap)
{
    char noise[48] = "";
    if (s->noise_threshold > 0.0f) /* nine significant digits give back the same float */
        snprintf(noise, sizeof noise, "noise_threshold=%.9g\n", (double)s->noise_threshold);
    snprintf(out, cap, "franja job\nscene=%016llx\nsize=%ux%u\nspp=%u\n%s%s", (unsigned long long)s->hash,
             s->width, s->height, s->spp, s->integrator == FR_INTEGRATOR_BDPT ? "integrator=bdpt\n" : "", noise);
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

int job_open(const char *dir, const job_spec *spec, int resume, fr_error *err)
{
    char want[256], path[4200];
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
            int same = len == strlen(want) && !memcmp(have, want, len);
            free(have);
            if (!same)
                return fr_fail(err, "%s: this job directory belongs to another render (different scene, "
                               "size, samples, integrator or noise threshold); remove it or render without --resume", dir);
            return 0;
        }
    } else {
        fr_error ignore;
        each_slab(dir, remove_one, NULL, &ignore);
    }
    return file_write_atomic(path, want, strlen(want), err);
}

typedef struct {
    const job_spec *spec;
    unsigned char *have;
    float *rgb;                /* job_stitch and job_gather only */
    int rows;
    const note_sink *notes;
    int keep;                  /* job_gather: skip bad slabs, silently, and keep them */
    int skipped;
} scan_ctx;

static int scan_one(const char *dir, const char *name, uint32_t y0, uint32_t y1, void *vctx)
{
    scan_ctx *c = vctx;
    char path[4200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    char *text;
    size_t len;
    fr_error e;
    int bad = file_read(path, &text, &len, &e);
    if (!bad) {
        const unsigned char *buf = (const unsigned char *)text;
        bad = job_check_partial(buf, len, c->spec, y0, y1, &e);
        if (!bad && c->rgb) {
            img_partial_info info;
            float *rows;
            if ((bad = img_read_partial(buf, len, &info, &rows, &e)) == 0) {
                memcpy(c->rgb + (size_t)y0 * c->spec->width * 3, rows,
                       (size_t)(y1 - y0) * c->spec->width * 3 * sizeof(float));
                free(rows);
            }
        }
        free(text);
    }
    if (bad && c->keep) {
        c->skipped++;
        return 0;
    }
    if (bad) {
        note_say(c->notes, "%s: discarded (%s)", path, e.msg);
        unlink(path);
        return 0;
    }
    for (uint32_t y = y0; y < y1; y++) {
        c->rows += !c->have[y];
        c->have[y] = 1;
    }
    return 0;
}

int job_scan(const char *dir, const job_spec *spec, unsigned char *have, const note_sink *notes, fr_error *err)
{
    scan_ctx c = {spec, have, NULL, 0, notes, 0, 0};
    memset(have, 0, spec->height);
    if (each_slab(dir, scan_one, &c, err))
        return -1;
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

static int by_rows(const void *a, const void *b)
{
    const slab_file *x = a, *y = b;
    if (x->y0 != y->y0)
        return x->y0 < y->y0 ? -1 : 1;
    return x->y1 < y->y1 ? -1 : x->y1 > y->y1;
}

/* Bidirectional: rows from a chain of slabs that splits [0, height) into
 * non-overlapping pieces, and every chosen slab's splats summed. */
static int stitch_splats(const char *dir, const job_spec *spec, float *rgb, fr_error *err)
{
    slab_list l = {NULL, 0, 0};
    int32_t *from = malloc(sizeof *from * ((size_t)spec->height + 1));
    uint64_t *sum = calloc((size_t)spec->width * spec->height * 3, sizeof *sum);
    int rc = -1;
    if (!from || !sum) {
        fr_fail(err, "out of memory for the splats of a %ux%u image", spec->width, spec->height);
        goto out;
    }
    if (each_slab(dir, list_one, &l, err))
        goto out;
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
        if (file_read(path, &text, &len, err))
            goto out;
        const unsigned char *buf = (const unsigned char *)text;
        if (job_check_partial(buf, len, spec, sf->y0, sf->y1, err) ||
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
    free(l.v);
    free(from);
    free(sum);
    return rc;
}

int job_stitch(const char *dir, const job_spec *spec, float *rgb, const note_sink *notes, fr_error *err)
{
    unsigned char *have = calloc(spec->height, 1);
    if (!have)
        return fr_fail(err, "out of memory");
    scan_ctx c = {spec, have, spec->integrator == FR_INTEGRATOR_BDPT ? NULL : rgb, 0, notes, 0, 0};
    int rc = each_slab(dir, scan_one, &c, err);
    if (rc == 0 && (uint32_t)c.rows != spec->height) {
        char missing[300];
        job_missing_rows(have, spec->height, missing, sizeof missing);
        rc = fr_fail(err, "rows %s are missing from %s; the image was not written", missing, dir);
    }
    free(have);
    if (rc == 0 && spec->integrator == FR_INTEGRATOR_BDPT)
        rc = stitch_splats(dir, spec, rgb, err);
    return rc;
}

int job_gather(const char *dir, const job_spec *spec, float *rgb, unsigned char *have, int *skipped,
               fr_error *err)
{
    scan_ctx c = {spec, have, rgb, 0, NULL, 1, 0};
    memset(have, 0, spec->height);
    int rc = each_slab(dir, scan_one, &c, err);
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
    int ok = len < 200 && memchr(text, 0, len) == NULL;
    if (ok) {
        char copy[200];
        memcpy(copy, text, len);
        copy[len] = 0;
        ok = sscanf(copy, "franja job\nscene=%16llx\nsize=%ux%u\nspp=%u\n%n", &hash, &w, &h, &spp, &n) == 4 && n > 0;
        if (ok && !strncmp(copy + n, "integrator=bdpt\n", 16)) {
            bdpt = 1;
            n += 16;
        }
        if (ok && n < (int)len) {
            int m = -1;
            ok = sscanf(copy + n, "noise_threshold=%g\n%n", &noise, &m) == 1 && m > 0 && n + m == (int)len &&
                 noise > 0.0f && noise <= 1.0f && !bdpt;
        }
    }
    free(text);
    if (!ok || w == 0 || h == 0 || w > PROTO_MAX_SIZE || h > PROTO_MAX_SIZE || spp == 0 || spp > PROTO_MAX_SPP)
        return fr_fail(err, "%s: not a job file of franja (expected scene=, size=WxH and spp= lines, maybe integrator=bdpt "
                       "or noise_threshold=E in (0, 1], sizes in 1..%u)", path, PROTO_MAX_SIZE);
    spec->hash = hash;
    spec->width = w;
    spec->height = h;
    spec->spp = spp;
    spec->integrator = bdpt ? FR_INTEGRATOR_BDPT : FR_INTEGRATOR_PATH;
    spec->noise_threshold = noise;
    return 0;
}

void job_remove(const char *dir)
{
    fr_error ignore;
    char path[4200];
    each_slab(dir, remove_one, NULL, &ignore);
    remove_temporaries(dir);
    const char *names[] = {"job", "scene.fbin"};
    for (size_t i = 0; i < 2; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        unlink(path);
    }
    rmdir(dir);
}
