/** @file transport.h
 * How the coordinator reaches a host and runs worker processes on it.
 *
 * One interface, two backends (transport_local.c: fork/exec and pipes;
 * transport_ssh.c: libssh, one session per host, one channel per worker
 * process).  The scheduler only sees tr_host and tr_proc, so it cannot tell
 * a local process from a remote one.
 *
 * Everything here is single-threaded except tr_connect, tr_probe and
 * tr_stage, which may run concurrently on different hosts.  Running
 * processes are driven by an event loop: the caller polls the descriptors
 * from tr_pollfds (with a short timeout) and then calls tr_service, which
 * moves whatever arrived into the processes' buffers and updates their state.
 */
#ifndef FRANJA_TRANSPORT_H
#define FRANJA_TRANSPORT_H

#include <poll.h>
#include <stddef.h>
#include <stdint.h>

#include "error.h"
#include "hosts.h"

/** Settings shared by all hosts of a run. */
typedef struct {
    const char *known_hosts;   /**< known_hosts file; NULL = ~/.ssh/known_hosts */
    int accept_new;            /**< add unknown host keys (never changed ones) */
    int read_ssh_config;       /**< honour the SSH client configuration */
    const char *ssh_config;    /**< that configuration file; NULL = ~/.ssh/config */
    int timeout_s;             /**< connect time-out and longest silence of a live host, seconds */
    const char *local_worker;  /**< worker binary for local hosts without worker= */
} tr_options;

/** What a host says about itself (tr_probe). */
typedef struct {
    char arch[32];             /**< uname -m */
    char os[64];               /**< uname -s */
    int cores;                 /**< online processors */
    char version[128];         /**< first line of `franja-worker --version` */
} tr_info;

typedef struct tr_host tr_host;
typedef struct tr_proc tr_proc;

/** Process states. */
enum {
    TR_RUNNING = 0,            /**< started, not finished */
    TR_EXITED = 1,             /**< finished; tr_proc_status gives the exit status */
    TR_FAILED = 2              /**< lost: killed, connection dropped, could not start */
};

/** Opens a connection to the host (nothing to do for a local one).  For SSH
 * this checks the server key against known_hosts and authenticates; every
 * refusal says how to fix it.  On success *out is owned by the caller
 * (tr_close).  Connecting takes at most o->timeout_s per step. */
int tr_connect(const hosts_entry *e, const tr_options *o, tr_host **out, fr_error *err);

/** Asks the host for its architecture, OS, core count and worker version.
 * Fails if the worker cannot be run there (with its error output). */
int tr_probe(tr_host *h, tr_info *info, fr_error *err);

/** Makes the binary scene at local_path (content hash `hash`) available on
 * the host and writes the path the worker must be given into remote[cap].
 * SSH: the file goes by SFTP to WORKDIR/scenes/HASH.fbin unless an intact
 * copy (same size, and the worker reports the same hash) is already there;
 * a bad copy is replaced.  *uploaded says whether bytes were sent. */
int tr_stage(tr_host *h, const char *local_path, uint64_t hash, char *remote, size_t cap,
             int *uploaded, fr_error *err);

/** Counts the scenes cached in the host's work directory (*files, *bytes;
 * both 0 for a local host, which needs no cache). */
int tr_cache(tr_host *h, int *files, uint64_t *bytes, fr_error *err);

/** What the host's system is, found without running its worker (so it works
 * before the first `franja deploy`): arch[32] from `uname -m`, os[64] the
 * VERSION_CODENAME of its /etc/os-release ("" when there is none). */
int tr_sysinfo(tr_host *h, char *arch, char *os, fr_error *err);

/** Installs the local file at local_path on the host as WORKDIR/name with
 * mode 0755, creating the work directory.  SSH: sent by SFTP under a private
 * temporary name, checked for size and renamed into place, so a worker still
 * running from the old copy is not disturbed.  The installed path goes to
 * remote[cap].  Local hosts refuse: they run this machine's files. */
int tr_install(tr_host *h, const char *local_path, const char *name, char *remote, size_t cap,
               fr_error *err);

/** Starts one worker process with the given arguments (argv without the
 * program name; NULL-terminated).  Remote arguments are shell-quoted.
 * *out is owned by the caller (tr_proc_free). */
int tr_spawn(tr_host *h, const char *const *args, tr_proc **out, fr_error *err);

/** Fills up to `max` poll descriptors that signal activity on the host;
 * returns how many. */
int tr_pollfds(tr_host *h, struct pollfd *pfd, int max);

/** Reads what has arrived for the host's processes and notices the ones
 * that ended.  Returns -1 when the host is lost (connection closed, or
 * silent for longer than the time-out); its processes are then TR_FAILED
 * and err says why. */
int tr_service(tr_host *h, fr_error *err);

/** Closes the connection, killing any processes still running.  NULL is a
 * no-op.  Processes must be freed before (tr_proc_free). */
void tr_close(tr_host *h);

/** The host table entry this host was opened from. */
const hosts_entry *tr_host_entry(const tr_host *h);

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

/** Quotes one word for a POSIX shell ('...' with ' as '\'') into out[cap].
 * Fails if it would not fit. */
int tr_shell_quote(const char *word, char *out, size_t cap, fr_error *err);

#endif
