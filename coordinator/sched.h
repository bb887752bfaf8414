/** @file sched.h
 * The scheduler: hands out row slabs to worker slots on every host, checks
 * what comes back, retries what fails and keeps what succeeds.
 *
 * - More slabs than slots, from one queue, so faster hosts take more.
 * - A slab whose worker fails, dies, or returns a partial that does not
 *   check out (size, header, scene hash, rows, spp) goes back to the queue,
 *   at most `max_attempts` times.
 * - A host with `max_host_failures` failures in a row, or whose connection
 *   is lost, is dropped with a message; its slabs go back to the queue.
 * - When the queue is empty and a slot is idle, the slab that has been
 *   running longest is started again (elsewhere when possible); the first
 *   valid copy wins and the others are killed.  Slabs are bit-identical
 *   wherever they run, so this is safe.
 * - Each accepted slab is saved in the job directory at once.
 */
#ifndef FRANJA_SCHED_H
#define FRANJA_SCHED_H

#include <signal.h>

#include "jobdir.h"
#include "transport.h"

/** One host as the scheduler uses it; the caller fills the first fields,
 * the scheduler the statistics. */
typedef struct {
    tr_host *tr;               /**< connected transport (owned by the caller) */
    const char *name;
    char scene[1024];          /**< path of the binary scene on the host */
    int slots;                 /**< worker processes at once */
    /* statistics */
    int running;
    int slabs, rows;           /**< accepted from this host */
    int failures;              /**< failed attempts */
    int duplicates;            /**< straggler copies started here */
    int streak;                /**< failures in a row */
    int dropped;
    int start_streak;          /**< failed process starts in a row */
    double retry_at;           /**< no new process before this time (after a failed start) */
    char drop_reason[300];
    double busy_s;             /**< sum of the run time of accepted slabs */
} sched_host;

/** What to render and how. */
typedef struct {
    job_spec spec;
    const char *jobdir;
    const unsigned char *have; /**< rows already finished (resume), height entries */
    int slab_rows;             /**< rows per slab; 0 = about 4 slabs per slot */
    int max_attempts;          /**< failed attempts per slab before giving up */
    int max_host_failures;     /**< failures in a row before a host is dropped */
    int tty;                   /**< a live progress line; else a plain line every 10 s */
    volatile sig_atomic_t *stop; /**< set asynchronously (SIGINT): stop and keep what is done */
} sched_params;

/** Totals of a run. */
typedef struct {
    int slabs;                 /**< slabs in this run (not counting resumed rows) */
    int retries;               /**< failed attempts */
    int duplicates;            /**< straggler copies started */
    double wall_s;
} sched_stats;

/** Renders every row not in p->have.  Returns 0 when all rows are saved in
 * the job directory; otherwise -1 with err naming the missing rows and the
 * reason (no host left, a slab failed too often, interrupted). */
int sched_run(const sched_params *p, sched_host *hosts, int nhosts, sched_stats *st, fr_error *err);

#endif
