/** @file monitor.h
 * `franja render --monitor PORT`: a small live web page of the render,
 * served on 127.0.0.1 only by libmicrohttpd from a thread of its own.
 *
 *     /              the page (HTML, its script polls the two below)
 *     /state.json    the render now: rows, elapsed time, ETA, each host's
 *                    state, slots, rows, rows/s and failures, the last events;
 *                    for an animation its frames too (below)
 *     /image.png     the image so far (preview.h: rows not rendered yet as a
 *                    checkerboard), tone-mapped like an LDR output; for an
 *                    animation, that of the frame shown (mon_show)
 *
 * An animation's monitor (mon_start_frames) knows each frame of the list
 * by its place in it: waiting, rendering (with its rows), written, skipped
 * (its output existed), failed or stopped (interrupted or stopped by the
 * time limit, its finished slabs kept).  state.json then has "frames":
 * {"list", "count", "states" (a letter a frame in list order: w r d s f x),
 * "waiting", "rendering", "done", "skipped", "failed", "stopped" (counts),
 * "current" (the frames rendering: frame, output, rows_done, rows),
 * "shown" (the frame whose image is served, null before one)}, and its
 * eta_s is the animation's: the rows left of the frames rendering, and of
 * each frame waiting as many as the last frame opened has, at the rate of
 * the rows done so far.
 *
 * Only GET and HEAD are answered, only for a Host header naming this
 * machine (localhost, 127.0.0.1, [::1], any port: a page of another site
 * cannot read the monitor through a rebound DNS name), and unless the
 * monitor is open only with its token: every request carries
 * `?token=HEX`, as the address mon_url gives does and the page's script
 * does after it; others get 403, so another user of this machine cannot
 * watch the render.  Each connection has 5 s to send a request and 30 s
 * to take the reply, whatever it trickles, and at most 64 are kept (48
 * from one address), the longest waiting closed first
 * (monitor_guard.h).  The image is read from
 * the job directory (like --preview), at most once a second and only when
 * its rows changed; nothing the scheduler owns is touched by the server's
 * thread: the render hands it copies (mon_progress, mon_event).
 */
#ifndef FRANJA_MONITOR_H
#define FRANJA_MONITOR_H

#include <stdint.h>

#include "error.h"
#include "jobdir.h"
#include "scene.h"

/** A running monitor. */
typedef struct mon_server mon_server;

/** One host as the page shows it (strings are copied by mon_progress). */
typedef struct {
    const char *name;
    const char *state;         /**< "starting", "ready", "dropped: REASON" ... */
    int running, slots;        /**< worker processes now, and at most */
    int rows, failures;        /**< accepted rows, failed attempts */
} mon_host;

/** Starts serving on 127.0.0.1:port (0: a free port the system picks, in
 * mon_url) the render of output from job directory dir; open: without a
 * token (--monitor-open).  Strings are copied.  NULL with err set when the
 * port cannot be bound (in use, privileged), there are no random bytes
 * for the token or the server cannot start. */
mon_server *mon_start(uint16_t port, int open, const char *output, const char *dir, const job_spec *spec,
                      const fr_tonemap *tm, fr_error *err);

/** Starts serving an animation on 127.0.0.1:port: output is the output
 * pattern, list the --frames value, n the frames in it (each waiting);
 * there is no image until mon_show.  As mon_start otherwise. */
mon_server *mon_start_frames(uint16_t port, int open, const char *output, const char *list, size_t n, fr_error *err);

/** A frame's state: index is its place in the list (from 0; others are
 * ignored), state one of 'w' waiting, 'r' rendering, 'd' written, 's'
 * skipped, 'f' failed, 'x' stopped; for 'r', rows_done of rows are done
 * and output is its file.  Copies everything; any thread. */
void mon_frame(mon_server *m, size_t index, uint32_t number, char state, const char *output, int rows_done,
               int rows);

/** Serves the image of frame number (a frame rendering) from its job
 * directory dir from now on.  Strings are copied.  -1 with err when out
 * of memory (the image before stays). */
int mon_show(mon_server *m, uint32_t number, const char *dir, const job_spec *spec, const fr_tonemap *tm,
             fr_error *err);

/** The page's address, http://127.0.0.1:PORT/?token=HEX (no token when
 * open), owned by m: what to print for the user to open. */
const char *mon_url(const mon_server *m);

/** The render's state now: t seconds since it began, rows done of total
 * (rows_before of them were done before this run: resumed), and the
 * hosts.  Copies everything; any thread. */
void mon_progress(mon_server *m, double t, int rows_done, int rows_total, int rows_before, const mon_host *hosts,
                  int nhosts);

/** Adds an event (a host's failure, a dropped host ...) to the page's
 * list of the last 50: t seconds since the render began, the host's name
 * (NULL: none), a short kind ("failed", "dropped" ...) and a line. */
void mon_event(mon_server *m, double t, const char *host, const char *kind, const char *text);

/** Sets the render's status shown on the page ("rendering" at the start;
 * "done", "failed", "interrupted"). */
void mon_status(mon_server *m, const char *status);

/** Stops serving and frees m (NULL: nothing). */
void mon_stop(mon_server *m);

/** The page itself (monitor_page.c). */
extern const char mon_page_html[];

#endif
