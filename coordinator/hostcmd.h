/** @file hostcmd.h
 * `franja hosts check|list` (see franja(1) and franja-hosts(5)).
 */
#ifndef FRANJA_HOSTCMD_H
#define FRANJA_HOSTCMD_H

/** Runs `franja hosts ...` with argv[0] = "hosts"; returns the exit status:
 * 0 when every host is usable (check) or the table parses (list), 1 when a
 * host is not usable, 2 on a bad table or usage error. */
int cmd_hosts(int argc, char **argv);

#endif
