/* framewalk.c -- `franja render PATTERN --frames LIST`: the walk over
 * the frames (outputs that exist skipped). */
#include "framewalk.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "clock.h"
#include "compile/compile.h"
#include "compile/json_keys.h"
#include "file.h"

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
        if (at && (pre >= sizeof buf || framelist_subst(at, f, buf + pre, sizeof buf - pre)))
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

int framewalk_one_scene(const char *scene)
{
    size_t n = strlen(scene);
    if (framelist_is_pattern(scene))
        return 0;
    if (compile_is_gltf(scene))
        return 1;
    if (n <= 5 || strcmp(scene + n - 5, ".json") != 0)
        return 0;
    /* A JSON scene with keyed values or a gltf shape (whose file may be
     * animated); one that cannot be read counts too, so that its compile
     * says what is wrong with it. */
    char *text;
    size_t len;
    fr_error err;
    if (file_read(scene, &text, &len, &err))
        return 1;
    cJSON *root = cJSON_ParseWithLength(text, len);
    free(text);
    if (!root)
        return 1;
    const cJSON *shapes = cJSON_GetObjectItemCaseSensitive(root, "shapes");
    int keyed = json_keys_in(cJSON_GetObjectItemCaseSensitive(root, "camera"));
    for (const cJSON *s = cJSON_IsArray(shapes) ? shapes->child : NULL; s && !keyed; s = s->next) {
        const cJSON *t = cJSON_GetObjectItemCaseSensitive(s, "type");
        keyed = json_keys_in(s) || (cJSON_IsString(t) && !strcmp(t->valuestring, "gltf"));
    }
    cJSON_Delete(root);
    return keyed;
}

int framewalk_check_plain(const char *scene)
{
    struct stat st;
    if (framelist_is_pattern(scene) && stat(scene, &st)) {
        fprintf(stderr, "franja render: %s: no such file; a scene name with # is a frame pattern: give "
                "--frames LIST (e.g. --frames 1-240)\n", scene);
        return 2;
    }
    return 0;
}

int framewalk_begin(framewalk_iter *it, int argc, char **argv, const framewalk_job *job)
{
    memset(it, 0, sizeof *it);
    fr_error err;
    if (framelist_parse(job->list, &it->fl, &err)) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        return 2;
    }
    const char *what = NULL, *name = NULL;
    if (!framelist_is_pattern(job->scene) && !job->one_scene)
        what = "the scene", name = job->scene;
    else if (!framelist_is_pattern(job->out))
        what = "the output (-o, else named after the scene)", name = job->out;
    else if (job->jobdir && !framelist_is_pattern(job->jobdir))
        what = "--job", name = job->jobdir;
    if (what) {
        fprintf(stderr, "franja render: --frames: %s '%s' has no # for the frame number (e.g. "
                "shots/f.####.json -o out/f.####.exr: each frame its own file; an animated\n"
                "glTF file, or a JSON scene with keyed values, is one scene for every frame)\n", what, name);
        framelist_free(&it->fl);
        return 2;
    }
    it->job = *job;
    it->argc = argc;
    it->argv = argv;
    it->t0 = clock_now();
    return 0;
}

int framewalk_next(framewalk_iter *it, framewalk_one *one)
{
    const char *pats[] = {it->job.scene, it->job.out, it->job.jobdir, it->job.preview};
    memset(one, 0, sizeof *one);
    for (; it->i < it->fl.n; it->i++) {
        uint32_t f = it->fl.v[it->i];
        size_t k = it->i + 1;
        if (framelist_subst(it->job.scene, f, one->scene, sizeof one->scene) ||
            framelist_subst(it->job.out, f, one->out, sizeof one->out) ||
            !(one->argv = frame_args(it->argc, it->argv, pats, 4, f))) {
            fprintf(stderr, "franja render: frame %u: out of memory or a file name too long\n", f);
            return 2;
        }
        one->argc = it->argc;
        one->number = f;
        one->index = k;
        struct stat st;
        if (!it->job.overwrite && !stat(one->out, &st)) {
            fprintf(stderr, "franja: frame %u (%zu of %zu): %s exists, skipped (--overwrite renders it again)\n",
                    f, k, it->fl.n, one->out);
            it->skipped++;
            if (it->on_skip)
                it->on_skip(it->skip_ctx, it->i, f, one->out);
            framewalk_put(one);
            continue;
        }
        fprintf(stderr, "franja: frame %u (%zu of %zu): %s -> %s\n", f, k, it->fl.n, one->scene, one->out);
        if (make_parents(one->out)) {
            fprintf(stderr, "franja render: frame %u: cannot make the directory of %s: %s\n", f, one->out,
                    strerror(errno));
            framewalk_put(one);
            return 2;
        }
        it->i++;
        return 0;
    }
    return 1;
}

void framewalk_put(framewalk_one *one)
{
    if (one->argv)
        free_args(one->argc, one->argv);
    one->argv = NULL;
}

void framewalk_wrote(framewalk_iter *it)
{
    it->rendered++;
}

void framewalk_failed(framewalk_iter *it, uint32_t number, const char *scene, const char *out, int rc)
{
    if (rc == 130)
        fprintf(stderr, "franja: interrupted at frame %u (%s): %zu of %zu frames done; rerun with --resume "
                "to go on\n", number, out, it->rendered + it->skipped, it->fl.n);
    else if (rc == FRAMES_TIME_LIMIT)
        fprintf(stderr, "franja: the time limit stopped the animation at frame %u (%s): %zu of %zu frames done; "
                "rerun with --resume to go on\n", number, out, it->rendered + it->skipped, it->fl.n);
    else
        fprintf(stderr, "franja render: frame %u (%s -> %s) failed; %zu of %zu frames done\n", number, scene, out,
                it->rendered + it->skipped, it->fl.n);
}

int framewalk_end(framewalk_iter *it, int rc)
{
    if (!rc)
        fprintf(stderr, "franja: frames: %zu of %zu done (%zu rendered, %zu skipped: output exists) in %.2f s\n",
                it->rendered + it->skipped, it->fl.n, it->rendered, it->skipped, clock_now() - it->t0);
    framelist_free(&it->fl);
    return rc;
}

