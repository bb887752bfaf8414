/** @file cli.h
 * Command-line pieces shared by the franja subcommands.
 */
#ifndef FRANJA_CLI_H
#define FRANJA_CLI_H

#include <stdint.h>

#include "transport.h"

/** The version line printed by `franja --version`. */
#define FRANJA_VERSION "0.1.0"

/** Help text for the options cli_transport_option understands. */
extern const char cli_transport_help[];

/** Sets o's defaults: ~/.ssh/known_hosts, ~/.ssh/config read, 10 s time-out,
 * the worker next to this executable. */
void cli_transport_defaults(tr_options *o);

/** If argv[*i] is a transport option (--known-hosts, --accept-new-hosts,
 * --no-ssh-config, --timeout), consumes it (and its value) and returns 1;
 * returns 0 if it is not one, -1 (after a message) if its value is bad. */
int cli_transport_option(int argc, char **argv, int *i, tr_options *o);

/** Parses a decimal integer in [lo, hi]; -1 if it is not one. */
int cli_uint(const char *s, uint32_t lo, uint32_t hi, uint32_t *out);

/** The franja-worker next to this executable, or NULL. */
const char *cli_local_worker(void);

#endif
