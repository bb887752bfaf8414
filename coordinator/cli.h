/** @file cli.h
 * Command-line pieces shared by the franja subcommands.
 */
#ifndef FRANJA_CLI_H
#define FRANJA_CLI_H

#include <stddef.h>
#include <stdint.h>

#include "hosts.h"
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
