/** @file progress.h
 * `franja render --progress json`: one JSON object a line on standard
 * output for wrapper tools, written by a thread of its own that watches the
 * job directory (the rows of the finished slabs there), so it depends on no
 * scheduler state.  Events:
 *
 *     {"event":"start","output":OUT,"width":W,"height":H,"spp":N,"rows":N,"rows_done":R,"time":T}
 *     {"event":"progress","rows_done":R,"rows":N,"elapsed_s":S,"rows_per_s":V,"eta_s":E}
 *     {"event":"host","what":W,"host":NAME,"elapsed_s":S[,"y0":Y0,"y1":Y1],"text":LINE}
 *     {"event":"done","status":"ok"|"failed"|"interrupted","rows_done":R,"rows":N,"elapsed_s":S}
 *
 * "progress" comes when the count of finished rows changes (checked every
 * half second); N is the number of rows the render needs (H, or the rows
 * of a --crop window); eta_s is null until a row has been rendered in this run.
 * "host" events say what happened to a host: W is "ready", "unused" (it
 * could not be prepared), "failed" (an attempt at rows Y0:Y1 failed),
 * "copy" (a second copy of rows Y0:Y1 started there), "dropped", "shrunk"
 * (it refused a worker: fewer slots) or "retry" (it refused one while
 * running none); LINE is the log line.
 */
#ifndef FRANJA_PROGRESS_H
#define FRANJA_PROGRESS_H

#include <stdint.h>
#include <stdio.h>

#include "error.h"
#include "jobdir.h"

/** A running JSON progress reporter. */
typedef struct pg_reporter pg_reporter;

/** Prints the start event to out and starts the thread that prints the
 * progress events of the job directory dir.  Strings are copied; out must
 * stay open until pg_stop.  NULL with err set if the thread cannot start. */
pg_reporter *pg_start(FILE *out, const char *output, const char *dir, const job_spec *spec, uint32_t rows,
                      fr_error *err);

/** Stops the thread, prints the last progress (if the count changed) and
 * the done event with status ("ok", "failed", "interrupted"), and frees r
 * (NULL: nothing). */
void pg_stop(pg_reporter *r, const char *status);

/** Prints a host event (see above) from the calling thread; lines of
 * the reporter's thread and of this one never mix.  r NULL: nothing. */
void pg_event(pg_reporter *r, const char *what, const char *host, uint32_t y0, uint32_t y1, const char *text);

/** Writes s to out as a JSON string, quoted and escaped. */
void pg_json_string(FILE *out, const char *s);

#endif
