/** @file cli.h
 * Command-line pieces shared by the franja subcommands.
 */
#ifndef FRANJA_CLI_H
#define FRANJA_CLI_H

#include <stddef.h>
#include <stdint.h>

#include "transport/hosts.h"
#include "opt.h"
#include "transport/slurm.h"
#include "transport/transport.h"


/** Sets o's defaults: ~/.ssh/known_hosts, ~/.ssh/config read, 10 s time-out,
 * the worker next to this executable, remarks (tr_options.notes) printed on
 * stderr as "franja: LINE". */
void cli_transport_defaults(tr_options *o);

/** getopt_long values of the options cli_common_opt and cli_slurm_opt
 * handle (above every character, so a command's own may be letters). */
enum {
    CLI_OPT_HELP = 'h',
    CLI_OPT_KNOWN_HOSTS = 0x100,
    CLI_OPT_ACCEPT_NEW,
    CLI_OPT_SSH_CONFIG,
    CLI_OPT_NO_SSH_CONFIG,
    CLI_OPT_TIMEOUT,
    CLI_OPT_HOSTS,
    CLI_OPT_SLURM,
    CLI_OPT_WORKER,
    CLI_OPT_WORKDIR,
    CLI_OPT_SHARED_WORKDIR,
    CLI_OPT_OWN                /**< the first value free for a command's own options */
};

/** The getopt_long entries (struct option initializers) of --help, --hosts
 * and the transport options, for a command's table. */
#define CLI_COMMON_LONGOPTS                                                     {"help", no_argument, NULL, CLI_OPT_HELP},                                  {"hosts", required_argument, NULL, CLI_OPT_HOSTS},                          {"known-hosts", required_argument, NULL, CLI_OPT_KNOWN_HOSTS},              {"accept-new-hosts", no_argument, NULL, CLI_OPT_ACCEPT_NEW},                {"ssh-config", required_argument, NULL, CLI_OPT_SSH_CONFIG},                {"no-ssh-config", no_argument, NULL, CLI_OPT_NO_SSH_CONFIG},                {"timeout", required_argument, NULL, CLI_OPT_TIMEOUT}

/** The getopt_long entries of the --slurm options. */
#define CLI_SLURM_LONGOPTS                                                      {"slurm", no_argument, NULL, CLI_OPT_SLURM},                                {"worker", required_argument, NULL, CLI_OPT_WORKER},                        {"workdir", required_argument, NULL, CLI_OPT_WORKDIR},                      {"shared-workdir", required_argument, NULL, CLI_OPT_SHARED_WORKDIR}

/** What cli_common_opt and cli_slurm_opt did with an option. */
enum {
    CLI_BAD = -1,              /**< a bad value; a message is on stderr */
    CLI_OTHER = 0,             /**< not one of theirs: the caller's */
    CLI_TAKEN = 1,             /**< consumed */
    CLI_HELP = 2               /**< usage and the transport options' help printed on stdout */
};

/** Handles option c (a CLI_COMMON_LONGOPTS value, as opt_next returned it,
 * with its value v) for command cmd: sets o, or *hosts (pointing at v) for
 * --hosts; for --help prints usage, then the transport options' help.  Returns
 * one of the values above. */
int cli_common_opt(const char *cmd, int c, const char *v, const char *usage, tr_options *o, const char **hosts);

/** Where the hosts come from when they are a Slurm allocation (--slurm). */
typedef struct {
    int on;                    /**< --slurm */
    const char *worker;        /**< --worker PATH, or NULL */
    const char *workdir;       /**< --workdir DIR or --shared-workdir DIR, or NULL */
    int shared;                /**< it was --shared-workdir */
} cli_slurm;

/** Help text for the options cli_slurm_opt understands (a string
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

/** Handles option c (a CLI_SLURM_LONGOPTS value, with its value v) into
 * *s: CLI_TAKEN, CLI_OTHER if it is not one, CLI_BAD (after a message) for
 * a relative or too long path, or a second work directory. */
int cli_slurm_opt(const char *cmd, int c, const char *v, cli_slurm *s);

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

/** Writes "<directory of this executable>/name" into buf[cap] and returns
 * buf; NULL when /proc/self/exe cannot be read or the path does not fit. */
const char *cli_beside_exe(const char *name, char *buf, size_t cap);

#endif
