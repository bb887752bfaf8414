/** @file transport.h
 * How the coordinator reaches a host and runs processes on it.
 *
 * One interface over several backends (transport_backend.h): local child
 * processes (transport_local.c: posix_spawn and pipes), SSH
 * (transport_ssh.c: libssh, one session per host, one channel per
 * process, SFTP uploads), and whatever else implements the backend
 * contract.  The scheduler sees only tr_host and tr_proc, so it cannot
 * tell a local process from a remote one.  What to run and what the
 * answers mean (probing a host, staging a scene, the worker's command
 * line) is not here: see stage.h and protocol.h.
 *
 * Threads: different hosts may be used from different threads at once
 * (cluster.c gets hosts ready in parallel); one host and its processes
 * belong to one thread at a time.  Running processes are driven by an
 * event loop: the caller polls the descriptors from tr_pollfds (with a
 * short time-out) and then calls tr_service, which moves whatever arrived
 * into the processes' buffers and updates their states.
 */
#ifndef FRANJA_TRANSPORT_H
#define FRANJA_TRANSPORT_H

#include <poll.h>
#include <stddef.h>
#include <stdint.h>

#include "error.h"
#include "transport/hosts.h"
#include "note.h"

typedef struct tr_backend tr_backend;

/** Settings shared by all hosts of a run. */
typedef struct {
    const char *known_hosts;   /**< known_hosts file; NULL = ~/.ssh/known_hosts */
    int accept_new;            /**< add unknown host keys (never changed ones) */
    int read_ssh_config;       /**< honour the SSH client configuration */
    const char *ssh_config;    /**< that configuration file; NULL = ~/.ssh/config */
    int timeout_s;             /**< connect time-out and longest silence of a live host, seconds */
    const char *local_worker;  /**< worker binary for local hosts without worker= */
    const tr_backend *backend; /**< serves every host when set (tests); NULL = by host table entry */
    void *backend_ctx;         /**< handed to that backend (tr_host_backend_ctx) */
    note_sink notes;           /**< remarks of the backends (a key added to known_hosts);
                                    called from the thread using the host */
} tr_options;

typedef struct tr_host tr_host;
typedef struct tr_proc tr_proc;

/** Process states. */
enum {
    TR_RUNNING = 0,            /**< started, not finished */
    TR_EXITED = 1,             /**< finished; tr_proc_status gives the exit status */
    TR_FAILED = 2              /**< lost: killed, connection dropped, too much output */
};

/** Opens a connection to the host of table entry e with the backend that
 * serves it.  For SSH this checks the server key against known_hosts and
 * authenticates; every refusal says how to fix it.  On success *out is
 * owned by the caller (tr_close).  Each step takes at most o->timeout_s.
 * The entry and options are copied, except the strings o points to, which
 * must outlive the host. */
int tr_connect(const hosts_entry *e, const tr_options *o, tr_host **out, fr_error *err);

/** Starts a process on the host.  argv[0] is the program as the host names
 * it (tr_host_worker for the worker); arguments are passed as they are,
 * never interpreted by a shell.  At most max_out bytes of its standard
 * output are kept (beyond that the process is killed and TR_FAILED).  *out
 * is owned by the caller (tr_proc_free). */
int tr_spawn(tr_host *h, const char *const *argv, size_t max_out, tr_proc **out, fr_error *err);

/** Runs a short command to completion (tr_spawn, then the event loop for
 * this host only) and returns the finished process in *out (TR_EXITED or
 * TR_FAILED; caller frees).  Fails, with the process killed, when it runs
 * longer than timeout_s, or when the host is lost. */
int tr_run(tr_host *h, const char *const *argv, size_t max_out, int timeout_s, tr_proc **out, fr_error *err);

/** Copies the local file at local_path to the host as `remote` (a path as
 * the host's commands see it; relative = under the login directory) with
 * permission bits `mode`, creating its directory.  The file is written
 * under a private temporary name and renamed into place, so a reader (a
 * running worker) never sees it half-written.  Fails, leaving no temporary
 * file, for a host that shares this machine's files (tr_host_workdir ""). */
int tr_upload(tr_host *h, const char *local_path, const char *remote, int mode, fr_error *err);

/** Removes the file `remote` from the host (one that tr_upload put there
 * and nothing consumed); a file already gone is no error.  Fails for a host
 * that shares this machine's files, and on a Slurm node's own disk, which
 * this machine reaches only through a job step. */
int tr_remove(tr_host *h, const char *remote, fr_error *err);

/** Fills up to `max` poll descriptors that signal activity on the host;
 * returns how many (possibly 0: then the caller's poll time-out paces the
 * loop). */
int tr_pollfds(tr_host *h, struct pollfd *pfd, int max);

/** Reads what has arrived for the host's processes and notices the ones
 * that ended.  Returns -1 when the host is lost (connection closed, or
 * silent for longer than the time-out); its processes are then TR_FAILED
 * and err says why. */
int tr_service(tr_host *h, fr_error *err);

/** Closes the connection, killing and freeing any processes still there.
 * NULL is a no-op. */
void tr_close(tr_host *h);

/** The host table entry this host was opened from. */
const hosts_entry *tr_host_entry(const tr_host *h);

/** The options it was opened with. */
const tr_options *tr_host_options(const tr_host *h);

/** "name" or "name (user@address:port)": how messages name the host. */
const char *tr_host_label(const tr_host *h);

/** The worker program as the host's commands name it. */
const char *tr_host_worker(const tr_host *h);

/** The host's work directory as its commands name it, where scenes are
 * cached and workers installed; "" when the host sees this machine's files
 * (a local host: scenes are used where they are). */
const char *tr_host_workdir(const tr_host *h);

/** The backend that serves the host: "local", "ssh" or "slurm". */
const char *tr_host_backend(const tr_host *h);

/** Whether tr_upload works while every slot of the host runs a worker:
 * SSH (SFTP) and a Slurm shared work directory (a copy on this machine);
 * not a Slurm node's own disk (sbcast needs a step, which waits for a CPU
 * of its own). */
int tr_host_busy_upload(const tr_host *h);

/** Whether tr_upload sends the file over a network link (SFTP; sbcast to
 * a Slurm node's own disk), where a compressed scene saves time; not a
 * Slurm shared work directory (a copy on this machine). */
int tr_host_link_upload(const tr_host *h);

/** Hands a remark about host h to the person (tr_options.notes), prefixed
 * with the host's label once connect has set it. */
void tr_note(tr_host *h, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/** TR_RUNNING, TR_EXITED or TR_FAILED. */
int tr_proc_state(const tr_proc *p);

/** Exit status of an exited process (128+N for a signal N). */
int tr_proc_status(const tr_proc *p);

/** Everything the process wrote to stdout so far; owned by the process. */
const unsigned char *tr_proc_output(const tr_proc *p, size_t *len);

/** A one-line summary of why the process failed or what it printed last on
 * stderr ("" if nothing). */
const char *tr_proc_reason(const tr_proc *p);

/** Asks the process to stop now (SIGKILL locally, a KILL signal request and
 * channel close over SSH).  Its state becomes TR_FAILED. */
void tr_proc_kill(tr_proc *p);

/** Kills the process if still running and frees it.  NULL is a no-op. */
void tr_proc_free(tr_proc *p);

#endif
