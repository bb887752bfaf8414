/** @file progress.h
 * `franja render --progress json`: one JSON object a line on standard
 * output for wrapper tools.  An image's events come from a thread of its
 * own that watches the job directory (the rows of the finished slabs
 * there), so they depend on no scheduler state.  Events of one image:
 *
 *     {"event":"start","output":OUT,"width":W,"height":H,"spp":N,"rows":N,"rows_done":R,"time":T}
 *     {"event":"progress","rows_done":R,"rows":N,"elapsed_s":S,"rows_per_s":V,"eta_s":E}
 *     {"event":"host","what":W,"host":NAME,"elapsed_s":S[,"y0":Y0,"y1":Y1],"text":LINE}
 *     {"event":"pass","pass":K,"spp":N,"rows_done":R,"elapsed_s":S}
 *     {"event":"done","status":"ok"|"failed"|"interrupted","spp":N,"rows_done":R,"rows":N,"elapsed_s":S}
 *
 * "progress" comes when the count of finished rows changes (checked every
 * half second); N is the number of rows the render needs (H, or the rows
 * of a --crop window); a row counts once a slab with the samples per pixel
 * of the render (of its pass, with --time-limit) holds it; eta_s is null
 * until a row has been rendered in this run (pass).  "pass" starts pass K
 * (1, 2 ...) of a --time-limit render, to N samples per pixel.  "done"
 * says the samples per pixel of the image written ("ok"), which with
 * --time-limit are those of the last complete pass.
 * "host" events say what happened to a host: W is "ready", "unused" (it
 * could not be prepared), "failed" (an attempt at rows Y0:Y1 failed),
 * "copy" (a second copy of rows Y0:Y1 started there), "dropped", "shrunk"
 * (it refused a worker: fewer slots) or "retry" (it refused one while
 * running none); LINE is the log line.
 *
 * An animation (--frames) is one stream for the run, its frames' events
 * interleaved as the frames render together.  Every event of a frame has
 * "frame":NUMBER after "event" (start, progress and done as above, their
 * elapsed_s counted from the frame's start; "done" may also have the
 * status "time_limit": the run's --time-limit stopped the frame, its
 * finished slabs kept for --resume), and so do the host events about a
 * frame's rows ("failed", "copy"); the other host events are the run's and
 * have none (elapsed_s from the run's start).  The run adds:
 *
 *     {"event":"frames","list":LIST,"frames":N,"time":T}
 *     {"event":"skipped","frame":F,"output":OUT}
 *     {"event":"frames_done","status":S,"frames":N,"rendered":R,"skipped":K,"elapsed_s":E}
 *
 * "frames" comes first (LIST as given to --frames, N frames in it);
 * "skipped" for a frame whose output exists (not rendered, without
 * --overwrite); "frames_done" last, with S "ok", "failed", "interrupted"
 * or "time_limit", R frames written by this run and K skipped.
 */
#ifndef FRANJA_PROGRESS_H
#define FRANJA_PROGRESS_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "error.h"
#include "jobdir.h"

/** A running JSON progress reporter. */
typedef struct progress_reporter progress_reporter;

/** No frame: the events of a single image, or the run's own. */
#define PG_NO_FRAME (-1L)

/** Prints the start event to out and starts the thread that prints the
 * progress events of the job directory dir.  frame: the frame number that
 * every event of this image carries, or PG_NO_FRAME for a single image.
 * Strings are copied; out must stay open until progress_stop.  NULL with err set
 * if the thread cannot start. */
progress_reporter *progress_start(FILE *out, long frame, const char *output, const char *dir, const job_spec *spec,
                      uint32_t rows, fr_error *err);

/** An animation's own reporter (no thread, no job directory): prints the
 * frames event (list as given, n frames) to out; its progress_event lines are
 * the run's host events.  End it with progress_run_end.  NULL with err when out
 * of memory. */
progress_reporter *progress_run_start(FILE *out, const char *list, size_t n, fr_error *err);

/** Prints the skipped event of frame (its output exists).  r NULL:
 * nothing. */
void progress_skipped(progress_reporter *r, long frame, const char *output);

/** Prints the frames_done event (status "ok", "failed", "interrupted" or
 * "time_limit"; n frames in the list, rendered and skipped of them) and
 * frees r (NULL: nothing). */
void progress_run_end(progress_reporter *r, const char *status, size_t n, size_t rendered, size_t skipped);

/** Prints the pass event of pass k to spp samples per pixel; from then on
 * rows count when they have spp samples.  r NULL: nothing. */
void progress_pass(progress_reporter *r, int k, uint32_t spp);

/** Stops the thread, prints the last progress (if the count changed) and
 * the done event with status ("ok", "failed", "interrupted", and for a
 * frame "time_limit") and spp, the
 * samples per pixel of the image written, and frees r (NULL: nothing). */
void progress_stop(progress_reporter *r, const char *status, uint32_t spp);

/** Prints a host event (see above) from the calling thread; lines of
 * the reporters' threads and of this one never mix.  frame: the frame
 * whose rows y0:y1 it is about, or PG_NO_FRAME.  r NULL: nothing. */
void progress_event(progress_reporter *r, long frame, const char *what, const char *host, uint32_t y0, uint32_t y1,
              const char *text);

#endif
