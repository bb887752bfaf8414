/** @file frame.h
 * One image of `franja render`, from its job lock to its output, without
 * the hosts: the render of one scene, or one frame of an animation (which
 * opens one of these per frame while the others render).  frame_lock
 * takes the job directory's lock and checks it against --resume and
 * --fresh; frame_open compiles or loads the scene, works out the image's
 * spec and opens the job directory (the rows it holds, the passes of
 * --time-limit); the slabs are then rendered into the job directory by the
 * caller's scheduler; frame_write stitches the rows, writes the output
 * and removes the job directory; frame_close ends it, keeping the finished
 * slabs of a failed image for --resume.  Each step says what went wrong on
 * stderr and returns the exit status for it.
 */
#ifndef FRANJA_FRAME_H
#define FRANJA_FRAME_H

#include <signal.h>
#include <stdint.h>

#include "compile/budget.h"
#include "cli.h"
#include "compile/confine.h"
#include "crop.h"
#include "jobdir.h"
#include "joblock.h"
#include "monitor.h"
#include "output.h"
#include "progress.h"
#include "protocol.h"
#include "reuse.h"
#include "scene.h"
#include "sched.h"
#include "tonemap.h"

/** `franja render`'s command line, parsed (cmd_render.c). */
typedef struct {
    const char *scene, *out, *hosts, *jobdir, *camera;
    const char *allow[CONFINE_MAX_ALLOW]; /* --allow-path folders */
    unsigned n_allow;
    uint32_t jobs, spp, width, height, slab_rows, retries;
    float exposure;
    int exposure_set;          /* --exposure given: overrides the scene's */
    const char *curve;         /* --tonemap, or NULL for the scene's */
    char out_buf[4096];        /* out when -o is omitted */
    const char *preview;       /* --preview FILE, or NULL */
    uint32_t preview_every;    /* seconds */
    int integrator;            /* 1 + FR_INTEGRATOR_*, 0 for the scene's */
    float noise_threshold;     /* --noise-threshold, 0 for the scene's */
    int json;                  /* --progress json */
    int crop, crop_output;     /* --crop given, --crop-output */
    iio_options io;            /* --exr-half, --exr-compression, --jpeg-quality */
    double scale;              /* --scale, 0 when not given */
    crop_window win;
    int monitor;               /* --monitor given */
    int monitor_open;          /* --monitor-open: no token */
    uint32_t monitor_port;
    int resume, keep_job, fresh, no_lock;
    const char *frames;        /* --frames LIST, or NULL */
    int overwrite;             /* --overwrite */
    double fps;                /* --fps, 0 when not given (GANIM_FPS) */
    double shutter;            /* --shutter, a fraction of a frame; 0 when not given */
    int timed;                 /* an animation's frame of one scene file: posed at `frame` (set per frame) */
    uint32_t frame;            /* the frame number, when timed */
    int reproducible;          /* --reproducible: no render time or hosts in the metadata */
    double time_limit;         /* --time-limit, seconds; 0 when not given */
    uint32_t passes;           /* --passes: render passes (passes.h mask) */
    int passes_set;            /* --passes given: overrides the scene's */
    fr_budget limits;          /* --limit: the compile's (budget.h) */
    tr_options tr;
    cli_slurm slurm;
} frame_settings;

/** The passes of a render.  Without --time-limit there is one, to the
 * samples asked for.  With it, each pass brings every row the render needs
 * to twice the fewest samples kept for a row (1 at first; never fewer than
 * the most kept for a row; at most the samples asked for), adding samples
 * to the kept sums, and the image of each complete pass is kept in memory:
 * when the limit stops a pass, that image is written.  Slabs with render
 * passes keep no sums: each pass then renders its rows from the first
 * sample, to twice the samples of the last complete pass, and its passes
 * are kept in memory with its image.  So do Metropolis light transport's
 * (whose chains keep no state to go on from): each pass is the render of
 * its samples (mutations) per pixel, its normalisation computed for them
 * (frame_normalise), so its image is that of a render asked for them. */
typedef struct {
    const frame_settings *a;
    const char *jobdir;
    job_spec spec;             /* the pass being planned or run (spp) */
    uint32_t cap;              /* the samples per pixel asked for */
    int crop_rows;             /* only the rows of a's --crop window */
    unsigned char *have;       /* rows the pass does not render (done, or outside a crop) */
    uint32_t *base;            /* samples with sums that each row goes on from (job_scan) */
    int rows_job, rows_missing;
    int rows_kept;             /* rows the job directory holds at spec.spp, needed or not */
    double deadline;           /* clock_now() time of --time-limit; 0 = none */
    float *rgb;                /* --time-limit: the image of the last complete pass */
    float *passes;             /* --time-limit: its render passes (the frame_image's), or NULL */
    unsigned char *scratch;    /* height bytes */
    uint32_t reached;          /* the samples per pixel of rgb; 0 = none yet */
    uint32_t first;            /* no sums, no rgb yet: the samples of the first pass, when more than 1
                                  (Metropolis, resumed: the most kept for a chain); else 0 */
    int npass;                 /* passes run */
    uint32_t stopped;          /* the samples per pixel of the pass the limit stopped; 0 = none */
    sched_stats total;         /* over the frame_passes */
    const char *label;         /* an animation's frame: "frame N"; NULL otherwise */
    fr_scene *mlt_scene;       /* --time-limit with mlt: the scene each pass's normalisation is computed
                                  from (owned by the frame_image), else NULL */
    float *mlt_norm;           /* that normalisation, spec.mlt_norm (the frame_image's) */
    uint32_t mlt_samples;      /* the bidirectional samples it was computed from; 0 = not yet */
    volatile sig_atomic_t *stop; /* the frame_image's: stops a normalisation (not owned) */
} frame_passes;

/** One image of a render, from its job lock to its output: the render of
 * one scene, or one frame of an animation.  The caller fills a (parsed),
 * argc, argv and stop; the rest is frame_lock's and frame_open's. */
typedef struct {
    frame_settings a;
    volatile sig_atomic_t *stop; /* set on SIGINT/SIGTERM (not owned) */
    int argc;
    char **argv;               /* as typed, for the lock file (not owned) */
    char jobdir[4096], fbin[4200];
    joblock lk;
    int locked;
    job_spec spec;
    fr_tonemap tm;
    int crop_rows;
    unsigned char *have;
    uint32_t *base;
    float *rgb;
    float *passes;             /* the render passes (passes.h) once stitched, or NULL */
    fr_name *mat_names;        /* the materials' names (n_mat_names, 0 or n_materials), for the passes' metadata */
    uint32_t n_mat_names, n_materials;
    fr_name *obj_names;        /* the objects' names (n_obj_names), for the passes' metadata */
    uint32_t n_obj_names;
    fr_name *group_names;      /* the light groups' names (n_group_names), for the passes' layers */
    uint32_t n_group_names;
    frame_passes ps;
    int rows_job, rows_have;
    double t0;
    progress_reporter *pg;           /* --progress json, or NULL */
    mon_server *mon;           /* --monitor, or NULL */
    reuse_state *reuse;        /* an animation's frame: what the run keeps of the frame before (reuse.h;
                                  not owned), or NULL */
    char patch[4300];          /* set by frame_open: a scene patch from the frame before's scene, or "" */
    reuse_result reused;       /* set by frame_open with reuse: what reuse_compile did */
    float mlt_norm[PROTO_MLT_DEPTHS]; /* --integrator mlt: the normalisation every worker gets (spec.mlt_norm) */
} frame_image;

/** What a pass to spp samples per pixel renders: the rows the job
 * directory does not hold with spp samples (ps->have), each from the most
 * samples kept for it with their sums (ps->base).  -1 with err when the
 * job directory cannot be read. */
int frame_plan(frame_passes *ps, uint32_t spp, fr_error *err);

/** The samples per pixel of the next pass of a --time-limit render into
 * *spp, 0 when every needed row has the samples asked for.  -1 with err
 * when the job directory cannot be read. */
int frame_next_pass(frame_passes *ps, uint32_t *spp, fr_error *err);

/** Metropolis light transport with --time-limit: the normalisation of the
 * pass just planned (ps->spec.spp) into ps->mlt_norm, as a render asked
 * for its samples computes it (mlt_path.h), unless the one there was
 * computed from the same number of bidirectional samples (the same
 * numbers); nothing for another render.  Computed on every core and
 * given up between blocks: 1 when ps->deadline passes first (after the
 * first pass; the pass is then stopped), -1 with err on SIGINT (ps->stop)
 * or when out of memory. */
int frame_normalise(frame_passes *ps, fr_error *err);

/** The image of the pass just planned and complete into ps->rgb.  -1 with
 * err when a row is missing or unreadable. */
int frame_pass_image(frame_passes *ps, fr_error *err);

/** Takes im's job lock (its job directory: --job, else OUT.franja-job)
 * and refuses a job directory with finished rows unless --resume or
 * --fresh, and a --resume of a single render that finished.  0, or the
 * exit status (said; frame_close gives the lock up). */
int frame_lock(frame_image *im);

/** Gets the binary scene (compiled into the job directory when needed),
 * checks the options against it, and opens the job directory: im->spec,
 * im->tm, the rows held (im->ps, im->rows_have of im->rows_job).  0, or
 * the exit status (said; 130 when interrupted). */
int frame_open(frame_image *im);

/** Every row the image needs is in its job directory (or, with
 * --time-limit, the last complete pass in memory): stitches, writes the
 * output, removes the job directory (unless --keep-job), gives up the lock
 * and says "franja: wrote ...".  used: the hosts that rendered rows, for
 * the metadata.  0, or 1 (said: the rows stay for --resume). */
int frame_write(frame_image *im, const char *used);

/** Frees the pixels and row tables of a written image; its settings
 * stay. */
void frame_shrink(frame_image *im);

/** Ends the image: after a failure (rc not 0) a job directory without
 * finished rows goes, one with rows stays for --resume, and the lock is
 * given up; frees im. */
void frame_close(frame_image *im, int rc);

#endif
