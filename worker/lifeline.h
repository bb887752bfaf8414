/** @file lifeline.h
 * A worker that streams its image to the process that started it ends
 * itself when that process, or the channel to it, is gone.
 *
 * The coordinator reads a worker's standard output for as long as it wants
 * the slab, and over SSH keeps its standard input open (--lifeline).  When the coordinator
 * dies (even by SIGKILL), when the SSH connection drops, or when the
 * channel of a losing duplicate is closed, the worker's end of those pipes
 * reports it: standard output's reader is gone, or standard input reaches
 * its end.  Signals alone do not cover these cases (OpenSSH does not pass
 * channel signal requests to the processes of root logins, and a killed
 * coordinator sends none), so the worker checks for itself, a few times a
 * second, from a SIGALRM handler (poll and read, nothing else), and ends
 * with status LIFELINE_STATUS.  It also asks the kernel for SIGTERM when
 * its parent process ends (PR_SET_PDEATHSIG): the coordinator itself for
 * local workers, sshd for remote ones.
 *
 * Only pipes and sockets count: a terminal, /dev/null or a regular file,
 * or an image written to a file (-o FILE), leaves the worker alone.
 */
#ifndef FRANJA_LIFELINE_H
#define FRANJA_LIFELINE_H

/** The worker's exit status when it ends itself. */
#define LIFELINE_STATUS 3

/** Starts watching.  to_stdout: the image goes to standard output (then
 * standard output is watched, when it is a pipe or a socket); line: the
 * coordinator asked for --lifeline (then standard input is watched too,
 * when it is a pipe or a socket: a shell's pipe that happens to be there
 * must not stop a worker run by hand).  Returns 0, or -1 (with errno) when
 * the timer or the handler cannot be set up; the worker then runs
 * unwatched. */
int lifeline_start(int to_stdout, int line);

/** Stops watching (before the worker writes its image: from then on, a
 * closed output is reported by the write itself). */
void lifeline_stop(void);

#endif
