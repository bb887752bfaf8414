/* reuse.c -- the frames of an animation compiled and sent as what changed
 * since the frame before (see reuse.h). */
#include "reuse.h"

#include <stdio.h>
#include <stdlib.h>
#include <limits.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "clock.h"
#include "compile/compile_child.h"
#include "fbin.h"
#include "file.h"
#include "fpatch.h"
#include "reuse_placed.h"

/* A patch is sent instead of the scene when it is under this fraction. */
enum { PATCH_FRACTION = 4 };

/* The frame's scene made of the frame before's full scene and the
 * sections its skeleton changed, into `out`: 1 when made, 0 when the
 * frame needs a full compile (a changed section the meshes add to, or
 * anything unexpected), -1 with err on a write error. */
static int splice(const reuse_state *st, const fr_scene *skel, const char *out, fr_error *err)
{
    fpatch_sect full[FPATCH_SECTIONS + 1], was[FPATCH_SECTIONS + 1], now[FPATCH_SECTIONS + 1];
    fr_error e;
    if (fpatch_sections(st->full.blob, st->full.blob_size, full, &e) < 0 ||
        fpatch_sections(st->skel.blob, st->skel.blob_size, was, &e) < 0 ||
        fpatch_sections(skel->blob, skel->blob_size, now, &e) < 0)
        return 0;
    for (int id = 1; id <= FPATCH_SECTIONS; id++) {
        if (fpatch_same(&was[id], &now[id]))
            continue;
        if (!fpatch_same(&was[id], &full[id]))
            return 0;
        full[id] = now[id];
    }
    void *blob;
    size_t size;
    uint64_t hash;
    if (fpatch_assemble(full, &blob, &size, &hash, &e) < 0)
        return 0;
    int rc = file_write_atomic(out, blob, size, err);
    free(blob);
    return rc < 0 ? -1 : 1;
}

/* 1 when every file of the list (compile_child.h) is as it was listed. */
static int files_unchanged(const char *list)
{
    if (!list)
        return 0;
    for (const char *line = list; *line;) {
        const char *nl = strchr(line, '\n');
        if (!nl)
            return 0;
        unsigned long long dev, ino;
        long long size, sec;
        long nsec;
        int at = 0;
        char path[PATH_MAX];
        size_t n = (size_t)(nl - line);
        struct stat st;
        if (sscanf(line, "%llu %llu %lld %lld %ld %n", &dev, &ino, &size, &sec, &nsec, &at) != 5 || at <= 0 ||
            n - (size_t)at >= sizeof path)
            return 0;
        memcpy(path, line + at, n - (size_t)at);
        path[n - (size_t)at] = 0;
        if (stat(path, &st) < 0 || (unsigned long long)st.st_dev != dev || (unsigned long long)st.st_ino != ino ||
            (long long)st.st_size != size || (long long)st.st_mtim.tv_sec != sec || st.st_mtim.tv_nsec != nsec)
            return 0;
        line = nl + 1;
    }
    return 1;
}

/* The full compile of the frame into `out`, keeping the list of the files
 * it read in st->files (none: NULL, so that no frame is made of it). */
static int full_compile(reuse_state *st, const char *scene, const compile_opts *co, const char *out,
                        volatile sig_atomic_t *stop, compile_child_stats *cs, fr_error *err)
{
    char list[4400];
    snprintf(list, sizeof list, "%s.files", out);
    unlink(list);
    compile_opts fo = *co;
    fo.files = list;
    free(st->files);
    st->files = NULL;
    if (compile_child(scene, &fo, out, stop, cs, err) < 0)
        return -1;
    char *text = NULL;
    size_t len;
    fr_error ignored;
    if (file_read(list, &text, &len, &ignored) == 0 && strlen(text) == len)
        st->files = text;
    else
        free(text);
    unlink(list);
    return 0;
}

/* The skeleton of the frame (JSON scenes) into *skel, mapped; its file
 * goes once mapped.  *key its meshes' key; *pkey (may be NULL) the key
 * of a glTF scene's placed skeleton (compile_opts.placed_key). */
static int skeleton(const char *scene, const compile_opts *co, const char *out, volatile sig_atomic_t *stop,
                    fr_scene *skel, uint64_t *key, uint64_t *pkey, fr_error *err)
{
    char path[4400];
    snprintf(path, sizeof path, "%s.skeleton", out);
    compile_child_sweep(path); /* what a compile killed with its render left */
    compile_opts so = *co;
    so.skeleton = 1;
    so.warn = NULL; /* the full compile of the first frame says them */
    compile_child_stats cs;
    if (compile_child(scene, &so, path, stop, &cs, err) < 0)
        return -1;
    *key = cs.mesh_key;
    if (pkey)
        *pkey = cs.placed_key;
    int rc = fbin_load(path, skel, err);
    unlink(path);
    return rc;
}

/* What moves while a shutter is open may be blurred, and a shutter is
 * open at most a frame (--shutter, a camera's `shutter`): the meshes' keys
 * half a frame before and after (skeletons posed there, without a
 * shutter) are folded into *key too, so that a mesh moving around one
 * frame and not around the frame before is seen. */
static int shutter_keys(const char *scene, const compile_opts *co, const char *out, volatile sig_atomic_t *stop,
                        uint64_t *key)
{
    for (int side = -1; side <= 1; side += 2) {
        compile_opts at = *co;
        at.frame = co->frame + 0.5 * side;
        at.shutter = 0.0;
        fr_scene s;
        uint64_t k = 0;
        fr_error ignored;
        if (skeleton(scene, &at, out, stop, &s, &k, NULL, &ignored) < 0)
            return -1;
        scn_free(&s);
        *key = *key * 0x9e3779b97f4a7c15ull ^ k;
    }
    return 0;
}

/* The patch from the frame before's scene to `now` into `patch` when it
 * is small enough (r->base, r->patch_bytes), else no patch file. */
static int write_patch(const reuse_state *st, const fr_scene *now, const char *patch, reuse_result *r,
                       fr_error *err)
{
    unlink(patch);
    if (!st->have)
        return 0;
    void *p;
    size_t n;
    uint64_t changed;
    fr_error e;
    if (fpatch_make(st->full.blob, st->full.blob_size, now->blob, now->blob_size, &p, &n, &changed, &e) < 0)
        return 0; /* no patch: the scene travels whole */
    int rc = 0;
    if (n < now->blob_size / PATCH_FRACTION && (rc = file_write_atomic(patch, p, n, err)) == 0) {
        r->base = st->full.hash;
        r->patch_bytes = n;
    }
    free(p);
    return rc;
}

/* The skeleton of the frame with the meshes' bounds st->bounds into *s,
 * its key (the meshes' content, and half a frame around with a shutter)
 * into *key; 0, or -1 (no such skeleton). */
static int placed_skeleton(const reuse_state *st, const char *scene, const compile_opts *co, const char *out,
                           volatile sig_atomic_t *stop, fr_scene *s, uint64_t *key)
{
    compile_opts bo = *co;
    bo.mesh_bounds = st->bounds;
    bo.n_mesh_bounds = st->n_bounds;
    fr_error ignored;
    if (skeleton(scene, &bo, out, stop, s, key, NULL, &ignored) < 0)
        return -1;
    /* A glTF placed skeleton reads every mesh it does not stand in for, so
     * its sections say all the poses around the frame would. */
    if (co->timed && !compile_is_gltf(scene) && shutter_keys(scene, &bo, out, stop, key) < 0) {
        scn_free(s);
        return -1;
    }
    return 0;
}

/* The frame made of the frame before's meshes placed anew
 * (reuse_placed.h) into `out`: 1 made (its skeleton into *s, key *key), 0
 * not, -1 with err on a write error.  gkey: the key the frame's skeleton
 * gave for a glTF scene's placed skeleton, which is not made unless it is
 * the frame before's (it reads the meshes it does not stand in for). */
static int placed(const reuse_state *st, const char *scene, const compile_opts *co, const char *out,
                  volatile sig_atomic_t *stop, uint64_t gkey, fr_scene *s, uint64_t *key, fr_error *err)
{
    if (!st->have || !st->placed.blob || !st->n_bounds || !files_unchanged(st->files) ||
        (compile_is_gltf(scene) && gkey != st->placed_key) ||
        placed_skeleton(st, scene, co, out, stop, s, key) < 0)
        return 0;
    int made = *key == st->placed_key ? reuse_placed_splice(&st->full, &st->placed, s, out, err) : 0;
    if (made <= 0)
        scn_free(s);
    return made;
}

/* What the next frame's placed() needs of this frame's scene st->full:
 * its meshes' bounds and its skeleton with them (made here unless given
 * as *s, which st then owns). */
static void keep_placed(reuse_state *st, const char *scene, const compile_opts *co, const char *out,
                        volatile sig_atomic_t *stop, fr_scene *s, uint64_t key)
{
    scn_free(&st->placed);
    if (s->blob) {
        st->placed = *s;
        st->placed_key = key;
        return;
    }
    free(st->bounds);
    st->bounds = NULL;
    st->n_bounds = 0;
    fr_error ignored;
    if (reuse_placed_bounds(&st->full, &st->bounds, &st->n_bounds, &ignored) < 0 || !st->n_bounds ||
        placed_skeleton(st, scene, co, out, stop, &st->placed, &st->placed_key) < 0)
        memset(&st->placed, 0, sizeof st->placed);
}

int reuse_compile(reuse_state *st, const char *scene, const compile_opts *co, const char *out, const char *patch,
                  volatile sig_atomic_t *stop, reuse_result *r, fr_error *err)
{
    memset(r, 0, sizeof *r);
    double t0 = clock_now();
    fr_scene skel = {0}, now = {0}, pskel = {0};
    uint64_t key = 0, pkey = 0, gkey = 0;
    /* A skeleton that does not compile leaves the frame to a full compile,
     * which says what is wrong. */
    fr_error ignored;
    int have_skel = skeleton(scene, co, out, stop, &skel, &key, &gkey, &ignored) == 0;
    uint64_t key_now = key; /* the frame's own, as its full compile's */
    if (have_skel && co->timed && shutter_keys(scene, co, out, stop, &key) < 0) {
        scn_free(&skel);
        have_skel = 0;
    }
    if (!have_skel && stop && *stop)
        return fr_fail(err, "%s: compile interrupted", scene);
    int made = 0;
    if (have_skel && st->have && st->skel.blob && key == st->key && files_unchanged(st->files) &&
        (made = splice(st, &skel, out, err)) < 0) {
        scn_free(&skel);
        return -1;
    }
    /* Else the meshes may be the frame before's placed elsewhere. */
    if (!made && (made = placed(st, scene, co, out, stop, gkey, &pskel, &pkey, err)) < 0) {
        scn_free(&skel);
        return -1;
    }
    compile_child_stats cs = {0};
    if (!made && full_compile(st, scene, co, out, stop, &cs, err) < 0) {
        scn_free(&skel);
        return -1;
    }
    if (fbin_load(out, &now, err) < 0 || write_patch(st, &now, patch, r, err) < 0) {
        scn_free(&skel);
        scn_free(&pskel);
        scn_free(&now);
        return -1;
    }
    r->reused = made;
    st->reused += made;
    /* The skeleton stands for the full scene only when both read the same
     * meshes (key_now: the frame's key without the shutter's). */
    if (have_skel && !made && cs.mesh_key != key_now)
        scn_free(&skel);
    scn_free(&st->full);
    scn_free(&st->skel);
    st->full = now;
    st->skel = skel;
    st->key = key;
    st->have = 1;
    keep_placed(st, scene, co, out, stop, &pskel, pkey);
    r->seconds = clock_now() - t0;
    return 0;
}

int reuse_loaded(reuse_state *st, const char *path, const char *patch, reuse_result *r, fr_error *err)
{
    memset(r, 0, sizeof *r);
    fr_scene now;
    if (fbin_load(path, &now, err) < 0)
        return -1;
    if (write_patch(st, &now, patch, r, err) < 0) {
        scn_free(&now);
        return -1;
    }
    scn_free(&st->full);
    scn_free(&st->skel); /* a compiled scene has no skeleton: the next frame compiles whole */
    scn_free(&st->placed);
    free(st->bounds);
    st->bounds = NULL;
    st->n_bounds = 0;
    free(st->files);
    st->files = NULL;
    st->full = now;
    st->key = 0;
    st->have = 1;
    return 0;
}

void reuse_free(reuse_state *st)
{
    free(st->files);
    free(st->bounds);
    scn_free(&st->full);
    scn_free(&st->skel);
    scn_free(&st->placed);
    memset(st, 0, sizeof *st);
}
