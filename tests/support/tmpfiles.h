/* tmpfiles.h -- for tests that work in their own temporary folder: a
 * scene compiled there, how many entries a folder has, whether two files
 * hold the same bytes. */
#ifndef FRANJA_TMPFILES_H
#define FRANJA_TMPFILES_H

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "file.h"

/* Compiles the JSON scene `json` into the binary scene `out` with
 * bin/franja (run from the repository's root), quietly: 0 on success. */
static inline int tmpfiles_compile(const char *json, const char *out)
{
    char cmd[1200];
    if (snprintf(cmd, sizeof cmd, "bin/franja compile '%s' -o '%s' >/dev/null 2>&1", json, out) >= (int)sizeof cmd)
        return -1;
    return system(cmd);
}

/* Entries of folder dir other than . and .. (0 if it cannot be read). */
static inline int tmpfiles_entries(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
    if (d)
        closedir(d);
    return n;
}

/* 1 when files a and b can be read and hold the same bytes. */
static inline int tmpfiles_same(const char *a, const char *b)
{
    char *x, *y;
    size_t nx, ny;
    fr_error err;
    if (file_read(a, &x, &nx, &err))
        return 0;
    if (file_read(b, &y, &ny, &err)) {
        free(x);
        return 0;
    }
    int same = nx == ny && !memcmp(x, y, nx);
    free(x);
    free(y);
    return same;
}

#endif
