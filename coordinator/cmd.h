/** @file cmd.h
 * The franja subcommands (see franja(1)).  Each takes the arguments after
 * `franja` (argv[0] is the subcommand's name), prints what the person
 * asked for and its own errors, and returns the process exit status.
 */
#ifndef FRANJA_CMD_H
#define FRANJA_CMD_H

/** `franja render SCENE -o OUT ...`: 0 when the image is written, 1 when
 * the render failed, 2 on a usage error, 130 when interrupted (finished
 * slabs are kept for --resume). */
int cmd_render(int argc, char **argv);

/** `franja hosts check|list|clean --hosts FILE`: 0 when every host is
 * usable (check), the table parses (list) or every host's scene cache was
 * cleaned (clean), 1 when a host is not usable or could not be cleaned, 2
 * on a bad table or usage error. */
int cmd_hosts(int argc, char **argv);

/** `franja deploy --hosts FILE [--dist DIR]`: installs the worker build
 * that matches each SSH host in its work directory and checks that it
 * runs.  0 when every SSH host of the table got a worker that reports this
 * build's version and scene format, 1 when a host did not, 2 on a bad
 * table, a missing dist directory or a usage error.  Local hosts are
 * skipped: they run this machine's worker. */
int cmd_deploy(int argc, char **argv);

/** `franja compile SCENE.json [-o SCENE.fbin]`: 0 ok, 1 failure, 2 usage
 * error. */
int cmd_compile(int argc, char **argv);

/** `franja stitch JOBDIR -o OUT`: writes the image a job directory's
 * finished slabs make, rows not yet rendered shown as a checkerboard, and
 * says how many rows are present.  0 when written, 1 when the directory is
 * not a readable job directory or the image cannot be written, 2 on a
 * usage error. */
int cmd_stitch(int argc, char **argv);

#endif
