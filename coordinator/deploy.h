/** @file deploy.h
 * `franja deploy --hosts FILE`: installs the worker build that matches each
 * host in its work directory and checks that it runs (see franja(1)).
 */
#ifndef FRANJA_DEPLOY_H
#define FRANJA_DEPLOY_H

/** Runs `franja deploy ...` with argv[0] = "deploy"; returns the exit
 * status: 0 when every SSH host of the table got a worker that reports this
 * build's version and scene format, 1 when a host did not, 2 on a bad table,
 * a missing dist directory or a usage error.  Local hosts are skipped: they
 * run this machine's worker. */
int cmd_deploy(int argc, char **argv);

#endif
