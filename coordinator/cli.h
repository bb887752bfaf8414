/** @file cli.h
 * Command-line pieces shared by the franja subcommands.
 */
#ifndef FRANJA_CLI_H
#define FRANJA_CLI_H

#include <stddef.h>
#include <stdint.h>

#include "hosts.h"
#include "slurm.h"
#include "transport.h"

/** Help text for the options cli_transport_option understands. */
extern const char cli_transport_help[];

/** Sets o's defaults: ~/.ssh/known_hosts, ~/.ssh/config read, 10 s time-out,
 * the worker next to this executable, remarks (tr_options.notes) printed on
 * stderr as "franja: LINE". */
void cli_transport_defaults(tr_options *o);

/** If argv[*i] is a transport option (--known-hosts, --accept-new-hosts,
 * --no-ssh-config, --timeout), consumes it (and its value) and returns 1;
 * returns 0 if it is not one, -1 (after a message) if its value is bad. */
int cli_transport_option(int argc, char **argv, int *i, tr_options *o);

/** What cli_common_option did with an argument. */
enum {
    CLI_BAD = -1,              /**< a bad or missing value; a message is on stderr */
    CLI_OTHER = 0,             /**< not one of the common options: the caller's */
    CLI_TAKEN = 1,             /**< consumed, with its value if it has one */
    CLI_HELP = 2               /**< usage and cli_transport_help printed on stdout */
};

/** Handles argv[*i] if it is an option that every subcommand reading a host
 * table takes: a transport option (cli_transport_option), --hosts FILE (sets
 * *hosts, which points into argv) or --help / -h (prints usage, then
 * cli_transport_help).  Advances *i past a consumed value. */
int cli_common_option(int argc, char **argv, int *i, const char *usage, tr_options *o, const char **hosts);

/** Where the hosts come from when they are a Slurm allocation (--slurm). */
typedef struct {
    int on;                    /**< --slurm */
    const char *worker;        /**< --worker PATH, or NULL */
    const char *workdir;       /**< --workdir DIR or --shared-workdir DIR, or NULL */
    int shared;                /**< it was --shared-workdir */
} cli_slurm;

/** Help text for the options cli_slurm_option understands (a string
 * literal, to be joined to a command's usage). */
#define CLI_SLURM_HELP                                                                    \
    "  --slurm              run the workers as job steps of the Slurm allocation this\n" \
    "                       runs in (salloc, sbatch): one per allocated CPU\n"           \
    "  --worker PATH        (--slurm) the worker program on the nodes (default: the\n"   \
    "                       franja-worker beside this franja)\n"                         \
    "  --workdir DIR        (--slurm) scene cache on each node's own disk, filled\n"     \
    "                       with sbcast (default /tmp/franja-USER)\n"                    \
    "  --shared-workdir DIR (--slurm) a directory that this machine and every node\n"    \
    "                       share: scenes are copied there once, no sbcast\n"

/** If argv[*i] is --slurm, --worker, --workdir or --shared-workdir,
 * consumes it (and its value) into *s and returns CLI_TAKEN; CLI_OTHER if
 * it is not one; CLI_BAD (after a message) for a missing or relative path. */
int cli_slurm_option(int argc, char **argv, int *i, cli_slurm *s);

/** Opens the Slurm allocation franja runs in (slurm_open) as the host
 * table t: one host per node, served by the Slurm backend (o->backend and
 * o->backend_ctx point at *a, which must outlive the hosts).  Refuses
 * --hosts with --slurm, and --worker or a work directory without it.  On
 * failure prints "franja CMD: ..." (outside an allocation: the salloc and
 * sbatch lines to use, built from argv) and returns -1 with nothing to
 * free; on success free with hosts_free and slurm_close. */
int cli_slurm_hosts(const char *cmd, const cli_slurm *s, int argc, char **argv, tr_options *o, slurm_alloc *a,
                    hosts_table *t);

/** Checks the combination of --slurm and its options with --hosts; on a
 * conflict prints "franja CMD: ..." and returns -1. */
int cli_slurm_check(const char *cmd, const cli_slurm *s, const char *hosts);

/** Loads the host table at path into t (freed with hosts_free); on failure
 * prints "franja CMD: <what is wrong, with file:line>" on stderr and returns
 * -1, with nothing to free. */
int cli_load_hosts(const char *cmd, const char *path, hosts_table *t);

/** The note_sink function that prints "franja: LINE" on stderr (ctx
 * unused). */
void cli_note_stderr(void *ctx, const char *line);

/** Parses a decimal integer in [lo, hi]; -1 if it is not one. */
int cli_uint(const char *s, uint32_t lo, uint32_t hi, uint32_t *out);

/** The franja-worker next to this executable, or NULL. */
const char *cli_local_worker(void);

/** Writes "<directory of this executable>/name" into buf[cap] and returns
 * buf; NULL when /proc/self/exe cannot be read or the path does not fit. */
const char *cli_beside_exe(const char *name, char *buf, size_t cap);

#endif
