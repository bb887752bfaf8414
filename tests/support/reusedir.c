/* reusedir.c -- a scratch folder of a scene for the reuse tests (see reusedir.h). */
#include "reusedir.h"

#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "compile/compile_child.h"
#include "file.h"

void reusedir_put(const char *dir, const char *name, const char *text)
{
    char path[256];
    fr_error err;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    if (file_write_atomic(path, text, strlen(text), &err) < 0) {
        printf("FAIL write %s: %s\n", path, err.msg);
        exit(1);
    }
}

int reusedir_same_as_full(const char *dir, const char *path, const compile_opts *co, double f)
{
    char scene[256], ref[256];
    snprintf(scene, sizeof scene, "%s/scene.json", dir);
    snprintf(ref, sizeof ref, "%s/ref.fbin", dir);
    compile_opts o = *co;
    o.frame = f;
    fr_error err;
    char *a = NULL, *b = NULL;
    size_t na = 0, nb = 0;
    int same = compile_child(scene, &o, ref, NULL, NULL, &err) == 0 && file_read(path, &a, &na, &err) == 0 &&
               file_read(ref, &b, &nb, &err) == 0 && na == nb && !memcmp(a, b, na);
    free(a);
    free(b);
    unlink(ref);
    return same;
}

void reusedir_rewrite(const char *dir, const char *name, const char *text)
{
    reusedir_put(dir, name, text);
    char path[256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    struct timespec t[2] = {{1000000000, 0}, {1000000000, 0}};
    utimensat(AT_FDCWD, path, t, 0);
}

void reusedir_opts(compile_opts *co)
{
    memset(co, 0, sizeof *co);
    co->timed = 1;
    co->fps = 24.0;
}

int reusedir_clean(const char *dir, const char *const *names, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        char path[256];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        unlink(path);
    }
    return rmdir(dir);
}

int reusedir_frame(const char *dir, reuse_state *st, compile_opts *co, int f, char *out, size_t n,
                   reuse_result *r, fr_error *err)
{
    char scene[256], patch[256];
    snprintf(scene, sizeof scene, "%s/scene.json", dir);
    snprintf(patch, sizeof patch, "%s/scene.patch", dir);
    snprintf(out, n, "%s/f%d.fbin", dir, f);
    co->frame = f;
    return reuse_compile(st, scene, co, out, patch, NULL, r, err);
}
