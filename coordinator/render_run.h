/** @file render_run.h
 * One run of `franja render` over its hosts: the hosts of the render (a
 * host table, a Slurm allocation or this machine), made ready while the
 * render starts on the first of them, the scheduler's run over them (every
 * pass of --time-limit), and what the run says: the status line on
 * stderr (live on a terminal, a line every ten seconds in a log), the
 * hosts' events to --progress json and --monitor, and the summary at the
 * end.  An animation (render_anim.h) adds its frames to the same run.
 */
#ifndef FRANJA_RENDER_RUN_H
#define FRANJA_RENDER_RUN_H

#include <signal.h>
#include <stddef.h>
#include <stdint.h>

#include "error.h"
#include "frame.h"
#include "transport/hosts.h"
#include "monitor.h"
#include "progress.h"
#include "sched.h"
#include "transport/slurm.h"

/** Set by SIGINT and SIGTERM once render_run_signals has run: stop and keep the
 * finished slabs. */
extern volatile sig_atomic_t render_run_stop;

/** Catches SIGINT and SIGTERM (they set render_run_stop) and ignores SIGPIPE. */
void render_run_signals(void);

/** The hosts of a render into *table (hosts_free frees it): a's host
 * table, the nodes of a Slurm allocation (*alloc, which slurm_close ends;
 * zeroed when a is not under Slurm), or this machine as "local".  argv is
 * the command line as typed (for the salloc hint).  0, or the exit status
 * with the reason said on stderr. */
int render_run_hosts(frame_settings *a, int argc, char **argv, hosts_table *table, slurm_alloc *alloc);

/** An animation's part of a run: the scheduler's frame hooks (sched.h,
 * called here with ctx); `number`, the frame number of the scheduler's
 * frame index (for the reporters' events); `rendered`, told of each
 * accepted slab which host rendered rows y0:y1 of which frame; `counts`,
 * the frames for the status line; and the run's --time-limit.  The hooks print after render_run_clear_line. */
typedef struct {
    int (*next_frame)(void *ctx, int frame, sched_frame *next, fr_error *err);
    int (*stage)(void *ctx, int frame, sched_host *h, int host_i, char *scene, size_t scene_cap, char *lease,
                 size_t lease_cap, fr_error *err);
    int (*frame_done)(void *ctx, int frame, fr_error *err);
    void (*rendered)(void *ctx, int frame, int host, uint32_t y0, uint32_t y1);
    long (*number)(void *ctx, int frame);
    /** For the status line: frames written or skipped, frames in the list,
     * and the rows of those not started yet (estimated). */
    void (*counts)(void *ctx, int *done, int *frames, double *rows_ahead);
    void *ctx;
    double deadline;           /**< clock_now() time at which the run stops (--time-limit); 0 = none */
    int *timed_out;            /**< set to 1 when the run stopped at deadline */
} render_run_frames;

/** Connects the hosts of table and renders the rows of ps (its passes,
 * with --time-limit) that its job directory lacks; fbin is the scene the
 * hosts get.  The render starts as soon as one host is ready and the
 * others join when they are (a host that accepts a connection and never
 * answers costs nothing unless it is the only one).  pg and mon (NULL:
 * none) get the hosts' events.  With fx, ps is the first frame of an
 * animation and the next ones follow over the same hosts (fx stages each
 * frame's scene and writes each frame; its deadline stops the run, with
 * -1 and *fx->timed_out set); fbin is then not used.  used
 * (used_cap bytes) gets the names of the hosts that rendered rows,
 * comma-separated, for the image's metadata.  Prints the summary.  0, or
 * -1 with *err set (the slabs finished stay in the job directory; render_run_stop
 * says whether it was interrupted). */
int render_run(const frame_settings *a, const hosts_table *table, const char *fbin, frame_passes *ps, progress_reporter *pg,
           mon_server *mon, char *used, size_t used_cap, const render_run_frames *fx, fr_error *err);

/** Ends the live status line on a terminal, if one is drawn, so that a
 * log line can follow. */
void render_run_clear_line(void);

/** How a host got its scene, for the log: "local", "already there" (in its
 * cache) or "uploaded (SIZE)" with the bytes sent, into out[64]. */
void render_run_scene_state(const hosts_entry *e, uint64_t sent, char *out);

#endif
