/** @file jobdir.h
 * The job directory: where a render keeps its finished slabs as they
 * arrive, so that nothing done is lost and `--resume` renders only what is
 * missing.  Layout:
 *
 *     DIR/job                  what render this is (scene hash, size, spp)
 *     DIR/scene.fbin           the compiled scene, for JSON inputs
 *     DIR/rows-Y0-Y1.pf        one checked partial image per finished slab
 *
 * Every file is written atomically (file_write_atomic), so a crash leaves
 * either the whole slab or nothing; temporaries a crash left are removed
 * by job_open and job_remove.
 */
#ifndef FRANJA_JOBDIR_H
#define FRANJA_JOBDIR_H

#include <stddef.h>
#include <stdint.h>

#include "error.h"
#include "image.h"
#include "note.h"

/** What a render produces: every partial must match it exactly. */
typedef struct {
    uint64_t hash;             /**< scene content hash */
    uint32_t width, height;    /**< full image, pixels */
    uint32_t spp;              /**< samples per pixel */
    uint32_t integrator;       /**< FR_INTEGRATOR_* (scene.h): bidirectional partials carry splats */
    float noise_threshold;     /**< adaptive sampling threshold the workers render with (pathtrace.h); 0 = off */
} job_spec;

/** Checks a partial image (PF bytes) against the spec and the rows asked
 * for.  Returns 0 if it is exactly that slab; otherwise err says what is
 * wrong (size, header, scene hash, rows, spp, and for a bidirectional
 * render the splat block: one light subpath per pixel sample of the rows,
 * its hash). */
int job_check_partial(const unsigned char *buf, size_t len, const job_spec *spec, uint32_t y0,
                      uint32_t y1, fr_error *err);

/** Creates the directory for a new render (removing the slabs of an old
 * one), or, with resume, keeps it if it belongs to the same render and
 * refuses it if not. */
int job_open(const char *dir, const job_spec *spec, int resume, fr_error *err);

/** Marks in have[0..height) the rows that finished slab files in dir
 * cover.  Files that do not check out are deleted, each with a line to
 * notes.  Returns the number of rows covered, or -1. */
int job_scan(const char *dir, const job_spec *spec, unsigned char *have, const note_sink *notes, fr_error *err);

/** Largest partial image a slab of rows [y0, y1) may be: the header and
 * the pixels, and for a bidirectional render the whole image's splats. */
size_t job_max_partial(const job_spec *spec, uint32_t y0, uint32_t y1);

/** Stores a checked slab (the worker's bytes as they came). */
int job_save(const char *dir, uint32_t y0, uint32_t y1, const unsigned char *buf, size_t len, fr_error *err);

/** Reads every slab into rgb (width*height*3 floats, top row first); slab
 * files that no longer check out are deleted with a line to notes, as in
 * job_scan.  Fails, naming the missing rows, unless every row is covered.
 * For a bidirectional render, the slabs used must split the image into
 * non-overlapping rows (each light subpath counted once): their splats are
 * summed in fixed point, in any order to the same bits, and added to the
 * rows (spl_resolve); it fails if no such split is among the slabs. */
int job_stitch(const char *dir, const job_spec *spec, float *rgb, const note_sink *notes, fr_error *err);

/** Reads what render the job directory dir belongs to (DIR/job) into
 * *spec.  Fails naming the file and what is wrong when it is missing or
 * not one that job_open wrote. */
int job_read_spec(const char *dir, job_spec *spec, fr_error *err);

/** Reads whatever finished slabs dir holds into rgb (width*height*3
 * floats, top row first) and marks their rows in have[0..height), for an
 * image of a render in progress or cut short.  Unlike job_scan and
 * job_stitch it changes nothing in dir: a slab that does not check out is
 * skipped and counted in *skipped (when not NULL).  Rows not covered are
 * left as they were in rgb.  Returns the number of rows covered, or -1
 * when dir cannot be read. */
int job_gather(const char *dir, const job_spec *spec, float *rgb, unsigned char *have, int *skipped,
               fr_error *err);

/** Counts the rows that slab files in dir cover, whatever render they
 * belong to (by their names only; nothing is read or removed).  0 when dir
 * does not exist. */
int job_rows_present(const char *dir);

/** Says truthfully what a failed render leaves in dir, checked now: "N rows
 * are kept in DIR; rerun with --resume", that no finished slab is there, or
 * that the directory was removed by another process.  Written to
 * out[cap]. */
void job_kept_note(const char *dir, char *out, size_t cap);

/** Deletes the job directory and what franja put in it. */
void job_remove(const char *dir);

/** Formats the rows not set in have[0..height) as "a:b, c:d" into out. */
void job_missing_rows(const unsigned char *have, uint32_t height, char *out, size_t cap);

#endif
