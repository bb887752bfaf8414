/* cmd_frames.c -- `franja render PATTERN --frames LIST`: one render per
 * frame, outputs that exist skipped. */
#include "cmd_frames.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "clock.h"
#include "frames.h"

/* argv with every string that holds (points into) one of the patterns
 * rewritten for frame f; NULL when out of memory or a name is too long.
 * Free with free_args. */
static char **frame_args(int argc, char **argv, const char *const *pats, int npat, uint32_t f)
{
    char **v = calloc((size_t)argc + 1, sizeof *v);
    if (!v)
        return NULL;
    for (int i = 0; i < argc; i++) {
        const char *s = argv[i];
        size_t len = strlen(s);
        const char *at = NULL;
        for (int k = 0; k < npat; k++)
            if (pats[k] && pats[k] >= s && pats[k] <= s + len)
                at = pats[k];
        char buf[4096];
        size_t pre = at ? (size_t)(at - s) : 0;
        if (at && (pre >= sizeof buf || frames_subst(at, f, buf + pre, sizeof buf - pre)))
            goto fail;
        if (at)
            memcpy(buf, s, pre);
        v[i] = strdup(at ? buf : s);
        if (!v[i])
            goto fail;
    }
    return v;
fail:
    for (int i = 0; i < argc; i++)
        free(v[i]);
    free(v);
    return NULL;
}

/* Creates the missing directories above the file at path (like mkdir -p of
 * its directory, mode 0777 less the umask).  Returns 0, or -1 with errno. */
static int make_parents(const char *path)
{
    char d[4096];
    if (snprintf(d, sizeof d, "%s", path) >= (int)sizeof d) {
        errno = ENAMETOOLONG;
        return -1;
    }
    char *slash = strrchr(d, '/');
    if (!slash || slash == d)
        return 0;
    *slash = '\0';
    for (char *p = d + 1; ; p++) {
        if (*p == '/' || !*p) {
            char c = *p;
            *p = '\0';
            if (mkdir(d, 0777) && errno != EEXIST)
                return -1;
            *p = c;
            if (!c)
                return 0;
        }
    }
}

static void free_args(int argc, char **v)
{
    for (int i = 0; i < argc; i++)
        free(v[i]);
    free(v);
}

int frames_check_plain(const char *scene)
{
    struct stat st;
    if (frames_is_pattern(scene) && stat(scene, &st)) {
        fprintf(stderr, "franja render: %s: no such file; a scene name with # is a frame pattern: give "
                "--frames LIST (e.g. --frames 1-240)\n", scene);
        return 2;
    }
    return 0;
}

int frames_run(int argc, char **argv, const frames_job *job, frames_render_fn fn)
{
    fr_error err;
    frame_list fl;
    if (frames_parse(job->list, &fl, &err)) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        return 2;
    }
    const char *what = NULL, *name = NULL;
    if (!frames_is_pattern(job->scene))
        what = "the scene", name = job->scene;
    else if (!frames_is_pattern(job->out))
        what = "the output (-o, else named after the scene)", name = job->out;
    else if (job->jobdir && !frames_is_pattern(job->jobdir))
        what = "--job", name = job->jobdir;
    if (what) {
        fprintf(stderr, "franja render: --frames: %s '%s' has no # for the frame number (e.g. "
                "shots/f.####.json -o out/f.####.exr: each frame its own file)\n", what, name);
        frames_free(&fl);
        return 2;
    }
    const char *pats[] = {job->scene, job->out, job->jobdir, job->preview};
    double t0 = clk_now();
    size_t rendered = 0, skipped = 0;
    int rc = 0;
    for (size_t i = 0; i < fl.n && !rc; i++) {
        uint32_t f = fl.v[i];
        char scene[4096], out[4096];
        char **v = frame_args(argc, argv, pats, 4, f);
        if (!v || frames_subst(job->scene, f, scene, sizeof scene) || frames_subst(job->out, f, out, sizeof out)) {
            fprintf(stderr, "franja render: frame %u: out of memory or a file name too long\n", f);
            if (v)
                free_args(argc, v);
            rc = 1;
            break;
        }
        struct stat st;
        if (!job->overwrite && !stat(out, &st)) {
            fprintf(stderr, "franja: frame %u (%zu of %zu): %s exists, skipped (--overwrite renders it again)\n",
                    f, i + 1, fl.n, out);
            skipped++;
            free_args(argc, v);
            continue;
        }
        fprintf(stderr, "franja: frame %u (%zu of %zu): %s -> %s\n", f, i + 1, fl.n, scene, out);
        if (make_parents(out)) {
            fprintf(stderr, "franja render: frame %u: cannot make the directory of %s: %s\n", f, out, strerror(errno));
            free_args(argc, v);
            rc = 1;
            break;
        }
        rc = fn(argc, v);
        free_args(argc, v);
        if (!rc) {
            rendered++;
            continue;
        }
        if (rc == 130)
            fprintf(stderr, "franja: interrupted at frame %u (%s): %zu of %zu frames done; rerun with --resume "
                    "to go on\n", f, out, rendered + skipped, fl.n);
        else
            fprintf(stderr, "franja render: frame %u (%s -> %s) failed; %zu of %zu frames done\n", f, scene, out,
                    rendered + skipped, fl.n);
    }
    if (!rc)
        fprintf(stderr, "franja: frames: %zu of %zu done (%zu rendered, %zu skipped: output exists) in %.2f s\n",
                rendered + skipped, fl.n, rendered, skipped, clk_now() - t0);
    frames_free(&fl);
    return rc;
}
