/* fuzz_jobdir.c -- libFuzzer target for what `franja render --resume` and
 * `franja stitch` read from a job directory (coordinator/jobdir.h): the
 * job file and the slab files, which a crash, a full disk or another
 * program may have left in any state.
 *
 * The input is a job directory: its sections, separated by the line
 * "--8<--", are DIR/job and then slab files, each named rows-Y0-Y1.pf
 * after the rows its header names (rows-K-K+1.pf for the K-th section when
 * the header does not parse).  The directory, made once, is emptied and
 * filled for every input; then, as the commands do: job_read_spec,
 * job_gather, job_rows_present, job_rows_at, job_kept_note, job_scan (which
 * removes the slabs that do not check out), job_cont_build for the rows
 * the scan found sums for, job_stitch, job_missing_rows, job_prune and
 * job_open --resume.  Images above 2^20 pixels are left out (stitching
 * one allocates its pixels, as franja does).  Seeds: job directories of
 * franja renders, made by tests/fuzz/run.sh, and
 * tests/fuzz/corpus/jobdir. */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "jobdir.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char dir[64];

/* Removes every file of the directory. */
static void empty(void)
{
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *e;
    char path[512];
    while ((e = readdir(d)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            unlink(path);
        }
    closedir(d);
}

static void cleanup(void)
{
    empty();
    rmdir(dir);
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    snprintf(dir, sizeof dir, "/tmp/franja-fuzz-jobdir-XXXXXX");
    if (!mkdtemp(dir)) {
        fprintf(stderr, "fuzz_jobdir: cannot create a directory\n");
        exit(1);
    }
    atexit(cleanup);
    return 0;
}

static void put(const char *name, const uint8_t *data, size_t len)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f)
        return;
    fwrite(data, 1, len, f);
    fclose(f);
}

/* The name of a slab file for section k (data[0..len)). */
static void slab_name(const uint8_t *data, size_t len, int k, char *name, size_t cap)
{
    char head[300];
    size_t n = len < sizeof head - 1 ? len : sizeof head - 1;
    memcpy(head, data, n);
    head[n] = 0;
    const char *line = strchr(head, '\n');
    unsigned long long scene;
    unsigned y0, y1;
    if (line && sscanf(line + 1, "# franja scene=%16llx rows=%u:%u", &scene, &y0, &y1) == 3)
        snprintf(name, cap, "rows-%05u-%05u.pf", y0, y1);
    else
        snprintf(name, cap, "rows-%d-%d.pf", k, k + 1);
}

static const char SEP[] = "\n--8<--\n";

static void use(void)
{
    job_spec spec;
    fr_error err;
    (void)job_rows_present(dir);
    (void)job_rows_at(dir, 1);
    char note[600];
    job_kept_note(dir, note, sizeof note);
    if (job_read_spec(dir, &spec, &err))
        return;
    if (spec.width == 0 || spec.height == 0 || spec.spp == 0)
        abort();
    if ((uint64_t)spec.width * spec.height > (1u << 20))
        return;
    size_t px = (size_t)spec.width * spec.height;
    float *rgb = malloc(px * 3 * sizeof *rgb);
    unsigned char *have = malloc(spec.height);
    uint32_t *base = malloc(spec.height * sizeof *base);
    if (!rgb || !have || !base)
        goto out;
    int skipped = 0;
    int rows = job_gather(dir, &spec, rgb, have, &skipped, &err);
    if (rows > (int)spec.height)
        abort();
    (void)job_rows_at(dir, spec.spp);
    rows = job_scan(dir, &spec, have, base, NULL, &err);
    if (rows > (int)spec.height)
        abort();
    /* The first run of rows with kept sums, continued as a worker would be. */
    for (uint32_t y = 0; y < spec.height; y++) {
        if (have[y] || !base[y])
            continue;
        uint32_t y1 = y + 1;
        while (y1 < spec.height && !have[y1] && base[y1] == base[y])
            y1++;
        char path[4200];
        if (job_cont_build(dir, &spec, y, y1, base[y], path, sizeof path, &err) == 0)
            unlink(path);
        break;
    }
    if (job_stitch(dir, &spec, rgb, NULL, &err) == 0)
        for (size_t i = 0; i < px * 3; i++)
            if (!(rgb[i] >= 0.0f))
                abort();
    char missing[300];
    job_missing_rows(have, spec.height, missing, sizeof missing);
    job_prune(dir, &spec);
    (void)job_open(dir, &spec, 1, &err);
out:
    free(rgb);
    free(have);
    free(base);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    empty();
    const uint8_t *p = data, *end = data + size;
    for (int k = 0; p <= end && k < 16; k++) {
        const uint8_t *s = memmem(p, (size_t)(end - p), SEP, sizeof SEP - 1);
        size_t len = s ? (size_t)(s - p) : (size_t)(end - p);
        char name[64];
        if (k == 0)
            snprintf(name, sizeof name, "job");
        else
            slab_name(p, len, k, name, sizeof name);
        put(name, p, len);
        if (!s)
            break;
        p = s + sizeof SEP - 1;
    }
    use();
    return 0;
}
