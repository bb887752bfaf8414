/* file.c -- whole files into memory (see file.h). */
#include "file.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int file_read(const char *path, char **text, size_t *len, fr_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        *text = NULL;
        return fr_fail(err, "%s: %s", path, strerror(errno));
    }
    return file_read_stream(f, path, text, len, err);
}

int file_read_stream(FILE *f, const char *path, char **text, size_t *len, fr_error *err)
{
    *text = NULL;
    *len = 0;
    /* A regular file's size is known: room for it, its NUL, and one byte
     * more so that the read that finds the end needs no bigger buffer.  A
     * pipe or a /proc file (size 0) grows as it is read. */
    struct stat st;
    size_t cap = 4096;
    if (fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode) && (size_t)st.st_size + 2 > cap)
        cap = (size_t)st.st_size + 2;
    size_t n = 0;
    char *buf = malloc(cap);
    while (buf) {
        size_t got = fread(buf + n, 1, cap - n - 1, f);
        n += got;
        if (got == 0)
            break;
        if (n + 1 == cap) {
            char *bigger = realloc(buf, cap * 2);
            if (!bigger)
                free(buf);
            buf = bigger;
            cap *= 2;
        }
    }
    int bad = ferror(f), why = errno;
    fclose(f);
    if (!buf)
        return fr_fail(err, "%s: out of memory", path);
    if (bad) {
        free(buf);
        return fr_fail(err, "%s: read error: %s", path, strerror(why));
    }
    buf[n] = 0;
    *text = buf;
    *len = n;
    return 0;
}

void file_dir(const char *path, char *dir, size_t cap)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(dir, cap, ".");
    else
        snprintf(dir, cap, "%.*s", (int)(slash - path), path);
}
