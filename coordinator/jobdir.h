/** @file jobdir.h
 * The job directory: where a render keeps its finished slabs as they
 * arrive, so that nothing done is lost and `--resume` renders only what is
 * missing.  Layout:
 *
 *     DIR/job                  what render this is (scene hash, size, spp)
 *     DIR/scene.fbin           the compiled scene, for JSON inputs
 *     DIR/rows-Y0-Y1.pf        one checked partial image per finished slab
 *     DIR/.cont-Y0-Y1-N.tmp-sums  the sums of rows [Y0, Y1) at N samples, for
 *                              a worker that adds samples to them (temporary)
 *
 * Every file is written atomically (file_write_atomic), so a crash leaves
 * either the whole slab or nothing; temporaries a crash left are removed
 * by job_open and job_remove.
 *
 * Adding samples later: a path-traced render without adaptive sampling
 * keeps each pixel's sample sums in its slabs (image.h), so a later render
 * with more samples per pixel (--resume --spp N, or the passes of
 * --time-limit) continues every row from the most samples kept for it and
 * gets the bits of a render of every sample at once.  Slabs of several
 * sample counts may then be in the directory at once, each saying its own
 * in its header; overlapping slabs of the same count hold the same bits.
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
    uint32_t passes;           /**< render passes every slab carries (passes.h mask); 0 = none */
    const float *mlt_norm;     /**< Metropolis light transport: b_d per depth, computed once for the render (for
                                    each pass of --time-limit) and handed to every worker (mlt_depths entries,
                                    not owned); NULL = none */
    uint32_t mlt_depths;
} job_spec;

/** job_open's status for a job directory it will not use. */
#define JOB_REFUSED (-2)

/** Whether the slabs of this render keep each pixel's sample sums, so that
 * samples can be added later: path tracing without adaptive sampling and
 * without render passes (whose slabs carry the passes instead). */
int job_sums(const job_spec *spec);

/** Checks a partial image (PF bytes) against the spec and the rows asked
 * for.  Returns 0 if it is exactly that slab; otherwise err says what is
 * wrong (size, header, scene hash, rows, spp, the sample sums when sums is
 * set, and for a bidirectional render the splat block: one light subpath
 * per pixel sample of the rows, its hash). */
int job_check_partial(const unsigned char *buf, size_t len, const job_spec *spec, uint32_t y0,
                      uint32_t y1, int sums, fr_error *err);

/** Creates the directory for a new render (removing the slabs of an old
 * one), or, with resume, keeps it if it belongs to the same render and
 * refuses it if not.  The same render may ask for another sample count:
 * more, when its slabs keep their sums (job_sums), or fewer, down to the
 * most that a slab there holds (samples are never taken away); DIR/job
 * then records the new count.  Returns 0, -1 when the directory cannot be
 * made or written, or JOB_REFUSED when it is another render's or the
 * samples asked for cannot be had from it; err says what to do instead. */
int job_open(const char *dir, const job_spec *spec, int resume, fr_error *err);

/** Marks in have[0..height) the rows that finished slab files in dir
 * cover with spec->spp samples per pixel, and, when base is not NULL,
 * writes in base[0..height) for every other row the most samples per
 * pixel below spec->spp that a slab with sums holds for it (0: none; the
 * row is rendered from its first sample).  Files that do not check out,
 * and those with fewer samples and no sums, are deleted, each with a line
 * to notes; those with more samples are left alone.  Returns the number of
 * rows covered, or -1. */
int job_scan(const char *dir, const job_spec *spec, unsigned char *have, uint32_t *base, const note_sink *notes,
             fr_error *err);

/** Writes into a temporary file of dir the partial image, with sums, of
 * rows [y0, y1) at spp samples per pixel, gathered from the slabs with
 * sums at that count that cover them (in any split), and its path into
 * path[cap]: what `franja-worker --continue` reads.  Fails when a row is
 * not there (any more).  The caller removes the file. */
int job_cont_build(const char *dir, const job_spec *spec, uint32_t y0, uint32_t y1, uint32_t spp, char *path,
                   size_t cap, fr_error *err);

/** Counts the rows that slab files in dir cover with spp samples per pixel
 * or more, by their headers (nothing else is checked or removed). */
int job_rows_at(const char *dir, uint32_t spp);

/** Removes the slab files with fewer samples than spec->spp whose every row
 * a slab with spec->spp samples covers (by their headers). */
void job_prune(const char *dir, const job_spec *spec);

/** Largest partial image a slab of rows [y0, y1) may be: the header and
 * the pixels, and for a bidirectional render the whole image's splats. */
size_t job_max_partial(const job_spec *spec, uint32_t y0, uint32_t y1);

/** Stores a checked slab (the worker's bytes as they came). */
int job_save(const char *dir, uint32_t y0, uint32_t y1, const unsigned char *buf, size_t len, fr_error *err);

/** Reads every slab with spec->spp samples into rgb (width*height*3
 * floats, top row first); slab files that no longer check out are deleted
 * with a line to notes, as in job_scan, and those of other sample counts
 * are left alone.  Fails, naming the missing rows, unless every row is covered.
 * For a bidirectional render, the slabs used (of spec->spp samples, among
 * others a --time-limit job holds) must split the image into
 * non-overlapping rows (each light subpath counted once): their splats
 * are summed in fixed point, in any order to the same bits, and added to
 * the rows (spl_resolve); it fails if no such split is among them. */
int job_stitch(const char *dir, const job_spec *spec, float *rgb, const note_sink *notes, fr_error *err);

/** job_stitch that also copies the render passes of the slabs (spec->passes
 * not 0) into passes: width*height*pass_channels(spec->passes) floats, top
 * row first. */
int job_stitch_passes(const char *dir, const job_spec *spec, float *rgb, float *passes, const note_sink *notes,
                      fr_error *err);

/** job_gather that also copies the slabs' render passes, as
 * job_stitch_passes does, into passes (NULL: not wanted). */
int job_gather_passes(const char *dir, const job_spec *spec, float *rgb, float *passes, unsigned char *have,
                      int *skipped, fr_error *err);

/** Reads what render the job directory dir belongs to (DIR/job) into
 * *spec.  Fails naming the file and what is wrong when it is missing or
 * not one that job_open wrote. */
int job_read_spec(const char *dir, job_spec *spec, fr_error *err);

/** Reads whatever finished slabs dir holds into rgb (width*height*3
 * floats, top row first) and marks their rows in have[0..height), for an
 * image of a render in progress or cut short; each row comes from a slab
 * with the most samples per pixel there, at most spec->spp.  Unlike job_scan and
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
