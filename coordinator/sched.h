/** @file sched.h
 * The scheduler: hands out row slabs to worker slots on every host, checks
 * what comes back, retries what fails and keeps what succeeds.
 *
 * - More slabs than slots, from one queue, so faster hosts take more.
 * - A slab whose worker fails, dies, or returns a partial that does not
 *   check out (size, header, scene hash, rows, spp) goes back to the queue,
 *   at most `max_attempts` times (failures on fewer than `max_attempts`
 *   hosts do not give it up while a host it has not failed on is ready or
 *   joining).  Its next attempt goes to another host
 *   when one is alive: a host takes back a slab that failed on it only when
 *   no other host is left.
 * - A host with `max_host_failures` failures in a row, or whose connection
 *   is lost, is dropped; its slabs go back to the queue (a lost connection
 *   does not count against them).
 * - A host that refuses to start a worker while it runs others (sshd's
 *   MaxSessions, a process limit) keeps the number of slots it runs.  One
 *   that refuses while running nothing is tried again after a pause, and
 *   dropped after `max_host_failures` refusals in a row.
 * - Hosts may join while the run goes on (sched_host.pending, the admit
 *   hook): slabs start on the hosts that are ready, and a host that takes
 *   long to be ready (or never is) holds nobody up.
 * - When the queue is empty and a slot is idle, the slab that has been
 *   running longest with a single copy is started again, on another host
 *   when possible; the first valid copy wins and the others are killed.
 *   Slabs are bit-identical wherever they run, so this is safe.
 * - Each accepted slab is saved in the job directory at once.
 * - A slab whose rows have sums kept in the job directory (sched_params.base)
 *   renders only the samples they lack: the coordinator gathers those sums
 *   into one file (job_cont_build), which a local worker reads where it is
 *   and a remote one gets by upload (tr_upload, next to the host's scene;
 *   the file is unlinked there as the worker starts, and read through an
 *   open descriptor).
 *
 * - Several frames (an animation) run as one stream of slabs over the same
 *   hosts (sched_hooks.next_frame): when every slab queued so far has
 *   started and a slot is free, the next frame is asked for and its slabs
 *   join the queue, so the slots that finish one frame's last slabs start
 *   the next frame's at once.  Earlier frames' slabs go first (a retry of
 *   frame 1 passes frame 2), straggler copies only once no frame is left.
 *   Each frame has its own job directory, spec and rows; its scene is put
 *   on a host (sched_hooks.stage) when the host first starts one of its
 *   slabs, once per host and frame; sched_hooks.frame_done is told as soon
 *   as all of a frame's rows are saved, so frames end as they complete.
 *
 * Nothing here prints: what happens is reported through sched_hooks, and
 * the clock and the wait for activity can be replaced (tests drive the
 * scheduler with a fake backend and a virtual clock).
 */
#ifndef FRANJA_SCHED_H
#define FRANJA_SCHED_H

#include <poll.h>
#include <signal.h>

#include "jobdir.h"
#include "transport/transport.h"

/** One host as the scheduler uses it; the caller fills the first fields,
 * the scheduler the statistics. */
typedef struct {
    tr_host *tr;               /**< connected transport (owned by the caller) */
    const char *name;
    char scene[1024];          /**< path of the binary scene on the host */
    char lease[1200];          /**< the render's lease on that scene (stage_scene), "" if none: the
                                    scheduler renews it about every minute (no new worker starts on
                                    the host during the renewal's moment) */
    double lease_t;            /**< clock_now() of its last renewal (or taking) */
    tr_proc *lease_proc;       /**< private: the renewal running now, NULL if none */
    int slots;                 /**< worker processes at once (lowered when the host refuses more) */
    /* statistics */
    int running;               /**< processes running now */
    int slabs, rows;           /**< accepted from this host */
    int failures;              /**< failed attempts and refused starts */
    int duplicates;            /**< straggler copies started here */
    int streak;                /**< failures in a row */
    int dropped;
    int pending;               /**< not ready yet: no process is started on it until the admit hook clears
                                    this (with tr, slots and scene set) or drops it; slots may hold a guess */
    int start_streak;          /**< refused starts in a row */
    double retry_at;           /**< no new process before this time (after a refused start) */
    char drop_reason[300];
    double busy_s;             /**< sum of the run time of accepted slabs */
    uint64_t sent;             /**< bytes of scenes sent to the host (set by the caller, for the summary) */
} sched_host;

/** One frame of a run: the image to render and where its slabs go.  The
 * first frame is the one sched_params names; a run with the next_frame
 * hook asks for more.  The pointers must stay valid until the frame is
 * done (frame_done) or the run ends. */
typedef struct {
    job_spec spec;
    const char *jobdir;
    const unsigned char *have; /**< rows already finished (resume), height entries; NULL = none */
    const uint32_t *base;      /**< as sched_params.base */
    int sums;                  /**< as sched_params.sums */
    const char *label;         /**< what messages call it ("frame 12"), NULL for a single image */
} sched_frame;

/** What happened (sched_event.kind). */
typedef enum {
    SCHED_SLAB_DONE,           /**< a slab was accepted and saved */
    SCHED_SLAB_FAILED,         /**< an attempt failed; the slab goes back to the queue */
    SCHED_COPY,                /**< a second copy of a straggler was started */
    SCHED_HOST_DROPPED,        /**< a host was dropped */
    SCHED_HOST_SHRUNK,         /**< a host refused a worker: its slots went down */
    SCHED_HOST_RETRY           /**< a host refused a worker while running none: later */
} sched_event_kind;

/** One event of a run. */
typedef struct {
    sched_event_kind kind;
    double t;                  /**< seconds since sched_run began */
    int host;                  /**< index into the hosts array */
    int frame;                 /**< the slab's frame: 0 for the first (sched_params'), 1 for the next... */
    uint32_t y0, y1;           /**< the slab (SLAB_*, COPY); 0 and 0 otherwise */
    const char *text;          /**< one line saying what happened, for a log */
} sched_event;

/** How the scheduler reports and keeps time.  Every member may be NULL. */
typedef struct {
    /** Called for every event, from sched_run's thread. */
    void (*event)(void *ctx, const sched_event *ev);
    /** Called after every turn of the loop (about every 100 ms) and once at
     * the end: rows done of the total; the hosts' statistics are current. */
    void (*progress)(void *ctx, double t, int rows_done, int rows_total);
    /** The clock in seconds; NULL = clock_now (clock.h). */
    double (*now)(void *ctx);
    /** Waits up to ms milliseconds for activity on pfd[0..n); NULL = poll. */
    int (*wait)(void *ctx, struct pollfd *pfd, int n, int ms);
    /** Called every turn while a host is pending: makes pending hosts ready
     * (tr, slots, scene set, pending cleared) or drops them (dropped and
     * drop_reason set, pending cleared), from sched_run's thread.  A run
     * with pending hosts and no admit hook waits for nothing: they are
     * dropped at once. */
    void (*admit)(void *ctx, sched_host *hosts, int nhosts);
    /** Frames after the first: called when every slab queued so far has
     * started and a slot is free, with the index the frame will have (1,
     * 2, ...).  Fills *next and returns 0; 1 when there is no frame left;
     * -1 with err set to end the run (as a failure).  A frame with no rows
     * to render is done at once.  NULL: the run is the first frame alone. */
    int (*next_frame)(void *ctx, int frame, sched_frame *next, fr_error *err);
    /** Puts frame's scene on host i before the host starts the first of
     * that frame's slabs (once per host and frame): the worker's path of it
     * into scene[scene_cap], and the render's lease on it (stage_scene) into
     * lease[lease_cap] ("" for none), which the scheduler renews while the
     * frame runs and removes (tr_remove) once it is done or the run ends.
     * -1 with err: the host is dropped.  NULL: every frame uses the host's
     * scene (sched_host.scene). */
    int (*stage)(void *ctx, int frame, sched_host *h, int host_i, char *scene, size_t scene_cap, char *lease,
                 size_t lease_cap, fr_error *err);
    /** Every row of frame is saved in its job directory (its other slabs'
     * copies are stopped): called at once, so frames finish in the order
     * they complete.  -1 with err ends the run (as a failure). */
    int (*frame_done)(void *ctx, int frame, fr_error *err);
    void *ctx;
} sched_hooks;

/** What to render and how. */
typedef struct {
    job_spec spec;
    const char *jobdir;
    const unsigned char *have; /**< rows already finished (resume), height entries; NULL = none */
    const uint32_t *base;      /**< per row (height entries), the samples per pixel kept with their sums in
                                    the job directory that the row continues from (job_scan); 0 = from
                                    the first sample; NULL = every row from the first sample.  A slab
                                    never spans rows of two bases */
    int sums;                  /**< workers keep each pixel's sample sums (--sums), and a partial without
                                    them does not check out (job_sums) */
    const char *label;         /**< what messages call this first frame (sched_frame.label); NULL = none */
    double stop_at;            /**< on the hooks' clock: stop there, as when stop is set, with
                                    sched_stats.timed_out; 0 = no limit */
    int slab_rows;             /**< rows per slab; 0 = slabs that shrink toward the end (the rows left over
                                    twice the slots, at least a sixteenth of the rows per slot) */
    int max_attempts;          /**< failed attempts per slab before giving up */
    int max_host_failures;     /**< failures in a row before a host is dropped */
    volatile sig_atomic_t *stop; /**< set asynchronously (SIGINT): stop and keep what is done; may be NULL */
    int lifeline;              /**< start workers with --lifeline: they end when their standard input does
                                    (for backends that hold it open while they want the slab: SSH; not
                                    Slurm, whose tasks see their input end at once) */
    sched_hooks hooks;
} sched_params;

/** Totals of a run. */
typedef struct {
    int slabs;                 /**< slabs in this run (not counting resumed rows), every frame's */
    int frames;                /**< frames in this run (1 without next_frame), and done of them */
    int frames_done;
    int retries;               /**< failed attempts */
    int duplicates;            /**< straggler copies started */
    double wall_s;
    double samples;            /**< pixel samples rendered into accepted slabs (added samples only, for
                                    continued rows) */
    int continued;             /**< accepted slabs that continued from kept sums */
    int fresh_instead;         /**< attempts that rendered a continuable slab from its first sample
                                    (its sums could not be made or sent): the same bits, more work */
    int timed_out;             /**< stopped at stop_at */
} sched_stats;

/** Renders every row not in p->have on hosts[0..nhosts), and those of
 * each frame the next_frame hook gives.  Returns 0 when all rows of every
 * frame are saved in their job directories; otherwise -1 with err naming
 * the missing rows (of the first frame not done) and the reason (no host left, a slab failed too often,
 * interrupted, the job directory cannot be written).  Every process it
 * started is gone when it returns. */
int sched_run(const sched_params *p, sched_host *hosts, int nhosts, sched_stats *st, fr_error *err);

#endif
