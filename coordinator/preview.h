/** @file preview.h
 * The image so far: what the finished slabs of a job directory make, rows
 * not rendered yet shown as a grey checkerboard.  `franja stitch` writes it
 * once; `franja render --preview FILE` writes it every few seconds while
 * the render runs, from a thread of its own that only reads the job
 * directory and writes FILE (it touches no host, session or scheduler
 * state).
 */
#ifndef FRANJA_PREVIEW_H
#define FRANJA_PREVIEW_H

#include "error.h"
#include "jobdir.h"
#include "note.h"
#include "scene.h"

/** Side of the checkerboard's squares, pixels. */
#define PV_CHECKER 8
/** The checkerboard's two linear values (dark greys at exposure 0). */
#define PV_DARK 0.02f
#define PV_LIGHT 0.08f

/** Fills rgb (width*height*3 floats, allocated by the caller) from the
 * finished slabs of dir (job_gather: nothing in dir changes) and paints the
 * rows not covered as the checkerboard.  have (height bytes, the caller's)
 * receives the rows covered.  Returns their number, or -1 when dir cannot
 * be read; *skipped counts slab files that did not check out.  For a
 * bidirectional job the light-traced splats are in the image only once
 * every row is there (job_stitch); until then the rows have the camera
 * paths' part alone. */
int preview_image(const char *dir, const job_spec *spec, float *rgb, unsigned char *have, int *skipped, fr_error *err);

/** A running preview writer. */
typedef struct preview_writer preview_writer;

/** Starts a thread that writes the image so far of the job directory dir
 * to path (out_write: atomically, in the format of its extension, tone
 * mapped by tm) at once and then every period_s seconds.  A failed write
 * is handed to notes (from that thread) once, until a write succeeds again.
 * Returns NULL with err set when the thread cannot be started.  The strings
 * are copied. */
preview_writer *preview_start(const char *path, const char *dir, const job_spec *spec, const fr_tonemap *tm, double period_s,
                    note_sink notes, fr_error *err);

/** Writes the image once more (the last state of dir), stops the thread
 * and frees w (NULL: nothing).  Returns the number of images written. */
int preview_stop(preview_writer *w);

#endif
