/* packbench.c -- times packing and unpacking a binary scene in both forms.
 *
 *   bin/bench/packbench SCENE.fbin [REPS]
 *   bin/bench/packbench SCENE.fbin -o OUT     (the packed scene)
 *   bin/bench/packbench SCENE.fbin -O OUT     (its header and frame content)
 *
 * Packs SCENE as one zstd frame (pack_file, what older workers get) and as
 * a packed scene (pack_scene_file), at PACK_LEVEL, REPS times each
 * (default 3), unpacks each copy as a worker does (unpack_file) and checks
 * that it is SCENE byte for byte.  Prints per form the packed size, its
 * ratio to the .fbin, and the median pack and unpack wall times.  Scratch
 * files go beside SCENE.  Exit status 1 if a copy does not unpack to the
 * scene.  With -o, writes the packed scene to OUT instead; with -O, its
 * header followed by the content of its zstd frame, uncompressed (the
 * seeds of tests/fuzz/fuzz_unpack.c).  Results: tests/bench/README.md,
 * "A production-like scene". */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <zstd.h>

#include "file.h"
#include "transport/pack.h"
#include "unpack.h"

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* 1 when files a and b hold the same bytes (read in 1 MiB blocks). */
static int same(const char *a, const char *b)
{
    FILE *x = fopen(a, "rb"), *y = fopen(b, "rb");
    int eq = x && y;
    static char p[1 << 20], q[1 << 20];
    while (eq) {
        size_t m = fread(p, 1, sizeof p, x), n = fread(q, 1, sizeof q, y);
        eq = m == n && !memcmp(p, q, m);
        if (m == 0)
            break;
    }
    if (x)
        fclose(x);
    if (y)
        fclose(y);
    return eq;
}

/* Writes the packed scene of `scene` to out, with its frame decompressed
 * when `open`. */
static int write_packed(const char *scene, const char *out, int open)
{
    fr_error err;
    uint64_t size;
    unlink(out);
    if (pack_scene_file(scene, out, PACK_LEVEL, &size, &err) < 0) {
        fprintf(stderr, "packbench: %s\n", err.msg);
        return 1;
    }
    if (!open)
        return 0;
    char *f;
    size_t n;
    if (file_read(out, &f, &n, &err) < 0) {
        fprintf(stderr, "packbench: %s\n", err.msg);
        return 1;
    }
    unsigned long long c = ZSTD_getFrameContentSize(f + UNPACK_HEADER, n - UNPACK_HEADER);
    char *o = c < ((size_t)1 << 32) ? malloc(UNPACK_HEADER + c) : NULL;
    int rc = !o || ZSTD_decompress(o + UNPACK_HEADER, c, f + UNPACK_HEADER, n - UNPACK_HEADER) != c;
    if (!rc) {
        memcpy(o, f, UNPACK_HEADER);
        rc = file_write_atomic(out, o, UNPACK_HEADER + c, &err) < 0;
    }
    if (rc)
        fprintf(stderr, "packbench: %s: cannot write the frame's content\n", out);
    free(o);
    free(f);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc == 4 && (!strcmp(argv[2], "-o") || !strcmp(argv[2], "-O")))
        return write_packed(argv[1], argv[3], argv[2][1] == 'O');
    if (argc < 2) {
        fprintf(stderr, "usage: packbench SCENE.fbin [REPS]\n");
        return 2;
    }
    const char *scene = argv[1];
    int reps = argc > 2 ? atoi(argv[2]) : 3;
    if (reps < 1 || reps > 99)
        reps = 3;
    struct stat st;
    if (stat(scene, &st) < 0) {
        perror(scene);
        return 1;
    }
    char pk[4200], un[4200];
    snprintf(pk, sizeof pk, "%s.packbench-%ld", scene, (long)getpid());
    snprintf(un, sizeof un, "%s.unpacked-%ld", scene, (long)getpid());
    const char *names[2] = {"zstd frame", "packed scene"};
    int rc = 0;
    for (int form = 0; form < 2; form++) {
        double tp[99], tu[99];
        uint64_t size = 0, hash;
        for (int r = 0; r < reps; r++) {
            fr_error err;
            unlink(pk);
            double t = now();
            if ((form ? pack_scene_file(scene, pk, PACK_LEVEL, &size, &err)
                      : pack_file(scene, pk, PACK_LEVEL, &size, &err)) < 0) {
                fprintf(stderr, "packbench: %s\n", err.msg);
                return 1;
            }
            tp[r] = now() - t;
            t = now();
            if (unpack_file(pk, un, &hash, &err) < 0) {
                fprintf(stderr, "packbench: %s\n", err.msg);
                return 1;
            }
            tu[r] = now() - t;
            if (r == 0 && !same(scene, un)) {
                fprintf(stderr, "packbench: the %s does not unpack to the scene\n", names[form]);
                rc = 1;
            }
            unlink(un);
        }
        qsort(tp, (size_t)reps, sizeof tp[0], cmp_double);
        qsort(tu, (size_t)reps, sizeof tu[0], cmp_double);
        printf("%s: %.1f MiB (%.3f x the .fbin's %.1f MiB), pack %.2f s, unpack %.2f s (medians of %d)\n",
               names[form], (double)size / 1048576, (double)size / (double)st.st_size,
               (double)st.st_size / 1048576, tp[reps / 2], tu[reps / 2], reps);
    }
    return rc;
}
