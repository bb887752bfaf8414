/** @file transport_backend.h
 * The contract between transport.c and a backend.  A backend is mechanism
 * only: it opens a host, starts processes and streams their output, copies
 * a file there, kills, closes.  It decides nothing about what runs: probing,
 * scene staging and the worker's command line are written once, above the
 * backends (stage.c, protocol.h), in terms of tr_run and tr_upload, which
 * transport.c builds from the operations below.  The scheduler includes
 * transport.h only.
 *
 * A new backend is one file defining a `const tr_backend` and one line in
 * tr_backend_for.  A backend whose processes are local programs that reach
 * the host themselves (a job launcher such as `srun`, run once per
 * process) builds their argv and leaves the rest to the tr_pipe_* helpers
 * at the end of this header; its upload may run a local copying command
 * (`sbcast`, `scp`) with tr_pipe_run.
 *
 * Rules every operation keeps:
 * - Errors are returned as -1 with err set; the message names the host
 *   (tr_host_label) and what to do about it.  Nothing prints; a remark for
 *   the person goes to tr_note.
 * - Nothing blocks for longer than the host's time-out
 *   (tr_host_options(h)->timeout_s) except upload, which may take as long
 *   as the copy takes while data moves.
 * - One host is used by one thread at a time, but different hosts of one
 *   backend may be used from different threads at once: shared state of
 *   a backend needs a lock.
 */
#ifndef FRANJA_TRANSPORT_BACKEND_H
#define FRANJA_TRANSPORT_BACKEND_H

#include "transport/transport.h"

/** Where the host keeps things, as its own commands name them; filled by
 * connect. */
typedef struct {
    char label[400];           /**< the host in messages: "name (user@address:port)" */
    char worker[1100];         /**< the worker program (argv[0] of a worker) */
    char workdir[600];         /**< work directory; "" = the host sees this
                                    machine's files (nothing is uploaded) */
    int busy_upload;           /**< an upload works while every slot of the host runs a worker (it
                                    starts no process that needs a slot of its own) */
    int link_upload;           /**< an upload crosses a network link (SFTP, sbcast), so that a
                                    scene is worth compressing for it; 0 for a copy on this
                                    machine's files */
} tr_place;

/** The operations of one backend.  `impl` is the backend's state for one
 * host, created by connect; `procs` is the host's list of processes not
 * yet freed (linked by tr_proc.next), some of them possibly finished. */
struct tr_backend {
    const char *name;          /**< "local", "ssh" ... */

    /** Opens the host h (tr_host_entry, tr_host_options, tr_host_backend_ctx
     * say which and how), fills *place, and sets *impl.  On failure nothing
     * is left open. */
    int (*connect)(tr_host *h, void **impl, tr_place *place, fr_error *err);

    /** Starts argv (argv[0] as the host names the program) with stdin
     * empty and stdout and stderr streamed back; sets p->impl and
     * p->state = TR_RUNNING.  Arguments must reach the program unchanged
     * (quoted for any shell on the way).  A backend that cannot start one
     * more process now (a channel limit) fails here; the scheduler then
     * uses fewer slots on the host. */
    int (*spawn)(void *impl, tr_proc *p, const char *const *argv, fr_error *err);

    /** Copies local_path to `remote` on the host with mode bits `mode`,
     * creating the directory, through a private temporary name and a
     * rename (see tr_upload); checks the size that arrived. */
    int (*upload)(void *impl, const char *local_path, const char *remote, int mode, fr_error *err);

    /** Removes the file `remote` that upload put on the host; a file that
     * is not there is no error.  NULL for a backend that uploads nothing. */
    int (*remove)(void *impl, const char *remote, fr_error *err);

    /** Writes up to max descriptors whose readiness means news for procs;
     * returns the count. */
    int (*pollfds)(void *impl, tr_proc *procs, struct pollfd *pfd, int max);

    /** Without blocking: appends what arrived to each running process
     * (tr_proc_add_out, tr_proc_add_err) and sets p->state to TR_EXITED
     * (with p->status) or TR_FAILED (tr_proc_fail) for those that ended,
     * only after their output is all read.  Returns -1 when the host is
     * lost, after failing all of its running processes. */
    int (*service)(void *impl, tr_proc *procs, fr_error *err);

    /** Stops process p now, without waiting (it may still be running when
     * this returns; transport.c marks it TR_FAILED). */
    void (*kill)(void *impl, tr_proc *p);

    /** Frees p->impl and sets it NULL; p is killed or finished. */
    void (*release)(void *impl, tr_proc *p);

    /** Closes the host; every process is already released. */
    void (*close)(void *impl);
};

extern const tr_backend tr_local_backend;
extern const tr_backend tr_ssh_backend;
extern const tr_backend tr_slurm_backend;

/** A process as transport.c and its backend see it. */
struct tr_proc {
    tr_host *host;
    int state;                 /**< TR_* */
    int status;                /**< exit status, TR_EXITED */
    unsigned char *out;        /**< stdout so far */
    size_t out_len, out_cap;
    size_t out_max;            /**< more than this fails the process */
    int kill_pending;          /**< failed for its output: transport.c kills it */
    char err[512];             /**< last line(s) of stderr, NUL-terminated */
    size_t err_len;
    char why[256];             /**< TR_FAILED: reason given by the transport */
    void *impl;                /**< the backend's per-process state */
    tr_proc *next;             /**< the host's list of unfreed processes */
};

/** Appends n bytes to p's stdout; past p->out_max or out of memory the
 * process is failed (and should be killed by the caller) and -1 returned. */
int tr_proc_add_out(tr_proc *p, const void *data, size_t n);

/** Keeps the tail of what p writes on stderr. */
void tr_proc_add_err(tr_proc *p, const void *data, size_t n);

/** Marks p failed with a reason (printf-style). */
void tr_proc_fail(tr_proc *p, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/** The options' backend_ctx. */
void *tr_host_backend_ctx(const tr_host *h);

/** Quotes one word for a POSIX shell ('...' with ' as '\'') into out[cap].
 * Fails if it would not fit. */
int tr_shell_quote(const char *word, char *out, size_t cap, fr_error *err);

/** @name Child processes of this machine
 * posix_spawnp with stdin from /dev/null and stdout and stderr on
 * non-blocking pipes, waitpid for the status.  The local backend is these
 * and nothing more; a launcher backend uses them for its launcher
 * processes.  p->impl belongs to these functions.
 * @{ */
int tr_pipe_spawn(tr_proc *p, const char *const *argv, fr_error *err);
/** tr_pipe_spawn for a process that must not outlive its starter: it gets
 * signal sig (SIGTERM when sig <= 0) when the thread that called this ends
 * (PR_SET_PDEATHSIG), however it ends, SIGKILL of the whole process
 * included; it is not started if this process has already gone.  Call it
 * from a thread that lives as long as the process may run (the main
 * thread, for processes that outlive a helper thread).  Fails like
 * tr_pipe_spawn ("cannot start NAME: REASON"). */
int tr_pipe_spawn_tied(tr_proc *p, const char *const *argv, int sig, fr_error *err);
int tr_pipe_pollfds(tr_proc *procs, struct pollfd *pfd, int max);
void tr_pipe_service(tr_proc *procs);
void tr_pipe_kill(tr_proc *p);
/** Sends signal sig to the process unless it has been reaped. */
void tr_pipe_signal(tr_proc *p, int sig);
void tr_pipe_release(tr_proc *p);
/** Like tr_pipe_release, but neither kills nor waits: returns the PID of
 * a child still to be reaped (the caller waits for it), or 0. */
int tr_pipe_detach(tr_proc *p);
/** Runs a local command to completion (at most timeout_s); fails with its
 * status and the tail of its stderr.  With out, its standard output (at
 * most 1 MB, NUL-terminated, the caller frees it) is returned in *out (NULL
 * on failure); without, it is discarded. */
int tr_pipe_run(const char *const *argv, int timeout_s, char **out, fr_error *err);
/** @} */

#endif
