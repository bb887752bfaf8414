/** @file cmd_frames.h
 * `franja render PATTERN --frames LIST`: renders an animation frame by
 * frame through the single-image render, each frame with its own output
 * and job directory (so --resume and the job lock work per frame), and
 * skips a frame whose output exists unless --overwrite.  The directories
 * of a frame's output are made when missing.
 */
#ifndef FRANJA_CMD_FRAMES_H
#define FRANJA_CMD_FRAMES_H

/** Renders one image: `franja render` with argv as given (argv[0] is the
 * command's name); returns its exit status. */
typedef int (*frames_render_fn)(int argc, char **argv);

/** What render's command line said about frames.  scene, out, jobdir and
 * preview point into argv's strings (jobdir and preview may be NULL):
 * each argv string that holds one of them is rewritten per frame with
 * its '#' runs replaced by the frame number. */
typedef struct {
    const char *list;       /**< the --frames value */
    int overwrite;          /**< --overwrite: render frames whose output exists */
    const char *scene, *out, *jobdir, *preview;
} frames_job;

/** Checks the patterns, then renders each frame of job->list with fn,
 * printing a line per frame and a summary on stderr.  Stops at the first
 * frame that fails and returns its status (1 failure, 2 usage error, 130
 * interrupted: the finished slabs of that frame stay for --resume); 0
 * when every frame's output exists; 2 for a bad list or pattern. */
int frames_run(int argc, char **argv, const frames_job *job, frames_render_fn fn);

/** For a render without --frames: 0, or, when scene is a '#' pattern that
 * names no file, prints that --frames is needed and returns 2. */
int frames_check_plain(const char *scene);

#endif
