/** @file framewalk.h
 * `franja render PATTERN --frames LIST`: the frames of an animation, each
 * with its own output and job directory (so --resume and the job lock work
 * per frame); a frame whose output exists is skipped unless --overwrite,
 * and the directories of a frame's output are made when missing.
 *
 * framewalk_begin / framewalk_next / framewalk_end walk the list for a render that
 * runs the frames together over one set of hosts (render_anim.h), saying
 * each frame announced or skipped, a frame that fails, is interrupted or
 * is stopped by the time limit named, and a summary.
 */
#ifndef FRANJA_FRAMEWALK_H
#define FRANJA_FRAMEWALK_H

#include <stddef.h>
#include <stdint.h>

#include "framelist.h"

/** What render's command line said about frames.  scene, out, jobdir and
 * preview point into argv's strings (jobdir and preview may be NULL):
 * each argv string that holds one of them is rewritten per frame with
 * its '#' runs replaced by the frame number. */
typedef struct {
    const char *list;       /**< the --frames value */
    int overwrite;          /**< --overwrite: render frames whose output exists */
    const char *scene, *out, *jobdir, *preview;
    int one_scene;          /**< the scene is one animated file, posed per frame: it needs no # */
} framewalk_job;

/** The exit status of an animation that --time-limit stopped before
 * every frame was written (the frames in flight keep their finished slabs
 * for --resume); the status timeout(1) uses. */
#define FRAMES_TIME_LIMIT 124

/** A walk over the frames (fields private but for the counts). */
typedef struct {
    framewalk_job job;
    int argc;
    char **argv;
    frame_list fl;
    size_t i;                  /**< frames of the list looked at */
    size_t rendered, skipped;  /**< frames written by this run, frames skipped (output exists) */
    double t0;
    /** Told of each frame skipped (index: its place in the list, from 0);
     * NULL: nobody.  Set after framewalk_begin. */
    void (*on_skip)(void *ctx, size_t index, uint32_t number, const char *out);
    void *skip_ctx;
} framewalk_iter;

/** One frame to render. */
typedef struct {
    uint32_t number;           /**< its frame number */
    size_t index;              /**< its place in the list, from 1 */
    char scene[4096], out[4096];
    int argc;
    char **argv;               /**< the command line with the patterns filled in (framewalk_put frees it) */
} framewalk_one;

/** Parses the list and checks the patterns; 0, or 2 (usage error,
 * printed).  Takes nothing: argv and job's strings must outlive it. */
int framewalk_begin(framewalk_iter *it, int argc, char **argv, const framewalk_job *job);

/** The next frame to render: passes over (and says so) frames whose
 * output exists, announces the frame and makes its output's directories.
 * 0 with *one filled; 1 when no frame is left; otherwise 1 + the exit
 * status (the failure printed). */
int framewalk_next(framewalk_iter *it, framewalk_one *one);

/** Frees what framewalk_next gave *one. */
void framewalk_put(framewalk_one *one);

/** One frame written (counts it). */
void framewalk_wrote(framewalk_iter *it);

/** A frame failed with exit status rc (130: interrupted; FRAMES_TIME_LIMIT:
 * stopped by the time limit): prints which and how many frames are
 * done. */
void framewalk_failed(framewalk_iter *it, uint32_t number, const char *scene, const char *out, int rc);

/** Ends the walk: with rc 0 prints the summary; frees the list; returns rc. */
int framewalk_end(framewalk_iter *it, int rc);

/** 1 when `scene` is one file for every frame, posed per frame: a glTF
 * file (its animations) or a JSON scene with keyed values (json_keys.h)
 * or a gltf shape (or one that cannot be read: its compile says why),
 * whose name has no #. */
int framewalk_one_scene(const char *scene);

/** For a render without --frames: 0, or, when scene is a '#' pattern that
 * names no file, prints that --frames is needed and returns 2. */
int framewalk_check_plain(const char *scene);

#endif
