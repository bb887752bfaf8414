/* render_anim.c -- the frames of an animation rendered together over one
 * set of hosts (see render_anim.h). */
#include "render_anim.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "clock.h"
#include "cluster.h"
#include "cmd.h"
#include "cmd_frames.h"
#include "quick.h"
#include "render_run.h"

/* One frame of an animation run together with the others. */
typedef struct {
    frames_one one;            /* its number, files and command line */
    frame_image *im;           /* NULL once closed */
    int written;
    int failed;                /* the exit status it failed with (said when the run ends); 0 = none */
    char label[32];            /* "frame N" */
    unsigned char *rendered_on; /* per host: it rendered rows of this frame */
} frame_slot;

typedef struct {
    frames_iter it;
    ra_parse_fn parse;         /* a frame's command line */
    const hosts_table *table;
    frame_slot **fr;           /* by the scheduler's frame index */
    int nfr, capfr;
    int failed;                /* a frame failed: no frame is opened after it */
} anim_run;

/* The next frame to render, locked, compiled and its job directory open:
 * 0 with *next (frame index fx->nfr - 1); 1 when no frame is left; -1
 * when a frame failed (its reason said; fx->failed set, and the frame
 * named when the run ends). */
static int rf_open(anim_run *fx, sched_frame *next)
{
    if (fx->failed)
        return 1;
    frame_slot *fs = calloc(1, sizeof *fs);
    if (fs && fx->nfr == fx->capfr) {
        int cap = fx->capfr ? 2 * fx->capfr : 8;
        frame_slot **v = realloc(fx->fr, (size_t)cap * sizeof *v);
        if (v) {
            fx->fr = v;
            fx->capfr = cap;
        }
    }
    if (!fs || fx->nfr == fx->capfr) {
        free(fs);
        fprintf(stderr, "franja render: out of memory\n");
        fx->failed = 1;
        return -1;
    }
    int r = frames_next(&fx->it, &fs->one);
    if (r) {
        free(fs);
        if (r == 1)
            return 1;
        fx->failed = r - 1; /* said, with the frame's number */
        return -1;
    }
    fx->fr[fx->nfr++] = fs;
    snprintf(fs->label, sizeof fs->label, "frame %u", fs->one.number);
    fs->rendered_on = calloc((size_t)fx->table->n, 1);
    int status = 1;
    fs->im = fs->rendered_on ? fx->parse(fs->one.argc, fs->one.argv, &status) : NULL;
    int rc = fs->im ? 0 : status ? status : 2;
    fr_error e;
    if (!rc && out_check(fs->im->a.out, &e)) {
        fprintf(stderr, "franja render: %s\n", e.msg);
        rc = 2;
    }
    if (!rc)
        rc = frame_lock(fs->im);
    if (!rc)
        rc = frame_open(fs->im);
    if (rc) {
        if (fs->im)
            frame_close(fs->im, rc);
        fs->im = NULL;
        fs->failed = fx->failed = rr_stop ? 130 : rc;
        return -1;
    }
    frame_image *im = fs->im;
    im->ps.label = fs->label;
    *next = (sched_frame){im->ps.spec, im->jobdir, im->have, im->base, job_sums(&im->ps.spec), fs->label};
    return 0;
}

/* The scheduler asks for the next frame.  One that fails to open ends the
 * list: the frames in flight are finished first, then the run ends with
 * that frame's failure. */
static int rf_next(void *ctx, int frame, sched_frame *next, fr_error *err)
{
    (void)frame, (void)err; /* frames are opened in the scheduler's order: frame == fx->nfr */
    if (rr_stop)
        return 1; /* no new frame once interrupted */
    rr_clear_line();
    return rf_open(ctx, next) ? 1 : 0;
}

static int rf_stage(void *ctx, int frame, sched_host *h, int host_i, char *scene, size_t scene_cap, char *lease,
                    size_t lease_cap, fr_error *err)
{
    anim_run *fx = ctx;
    frame_slot *fs = fx->fr[frame];
    const hosts_entry *e = &fx->table->v[host_i];
    double t0 = clk_now();
    int uploaded = 0;
    fr_error e2;
    if (cl_stage(h->tr, e, fs->im->fbin, fs->im->spec.hash, scene, scene_cap, lease, lease_cap, &uploaded, &e2))
        return fr_fail(err, "%s: %s", fs->label, e2.msg);
    if (fx->table->path[0] != '(' || !isatty(2)) {
        rr_clear_line();
        fprintf(stderr, "franja: host %s: %s: scene %s (%.2f s)\n", h->name, fs->label,
                hosts_is_local(e) ? "local" : uploaded ? "uploaded" : "already there", clk_now() - t0);
    }
    return 0;
}

static void rf_rendered(void *ctx, int frame, int host)
{
    anim_run *fx = ctx;
    if (frame >= 0 && frame < fx->nfr && host >= 0 && host < fx->table->n && fx->fr[frame]->rendered_on)
        fx->fr[frame]->rendered_on[host] = 1;
}

static int rf_done(void *ctx, int frame, fr_error *err)
{
    anim_run *fx = ctx;
    frame_slot *fs = fx->fr[frame];
    char used[1024] = "";
    for (int i = 0, k = 0; i < fx->table->n; i++)
        if (fs->rendered_on[i] && (size_t)k < sizeof used)
            k += snprintf(used + k, sizeof used - (size_t)k, "%s%s", k ? "," : "", fx->table->v[i].name);
    rr_clear_line();
    if (frame_write(fs->im, used)) {
        fs->failed = fx->failed = 1;
        return fr_fail(err, "%s could not be written", fs->label);
    }
    fs->written = 1;
    frames_wrote(&fx->it);
    frame_shrink(fs->im); /* the settings stay: the scheduler's run may still read the first frame's */
    return 0;
}

/* `franja render PATTERN --frames LIST`: the frames run together over one
 * set of hosts, each written as soon as its rows are in; a frame-by-frame
 * run where an option works on one image at a time (--time-limit,
 * --preview, --monitor, --progress json). */
int ra_render(int argc, char **argv, render_args *a, ra_parse_fn parse)
{
    frames_job fj = {a->frames, a->overwrite, a->scene, a->out, a->jobdir, a->preview};
    if (a->time_limit > 0 || a->preview || a->monitor || a->json)
        return frames_run(argc, argv, &fj, cmd_render);
    anim_run fx;
    memset(&fx, 0, sizeof fx);
    fx.parse = parse;
    if (frames_begin(&fx.it, argc, argv, &fj))
        return 2;
    rr_signals();
    fr_error err;
    uint32_t probe = UINT32_MAX;
    if (quick_spp(&probe, &err) < 0) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        return frames_end(&fx.it, 2);
    }
    hosts_table table;
    slurm_alloc alloc;
    int rc = rr_hosts(a, argc, argv, &table, &alloc);
    if (rc)
        return frames_end(&fx.it, rc);
    fx.table = &table;
    sched_frame first;
    if (rf_open(&fx, &first) == 0) {
        char used[1024];
        rr_frames hooks = {rf_next, rf_stage, rf_done, rf_rendered, &fx};
        if (rr_run(a, &table, NULL, &fx.fr[0]->im->ps, NULL, NULL, used, sizeof used, &hooks, &err)) {
            fprintf(stderr, "franja render: %s\n", err.msg);
            rc = 1;
        }
    }
    /* The frame to name: after an interrupt the first not written, else
     * the one that failed, else (the hosts failed) the first not written. */
    frame_slot *named = NULL;
    for (int i = 0; i < fx.nfr && !named; i++)
        if (fx.fr[i]->failed && !rr_stop)
            named = fx.fr[i];
    for (int i = 0; i < fx.nfr && !named; i++)
        if (!fx.fr[i]->written)
            named = fx.fr[i];
    if (rr_stop && (rc || fx.failed))
        rc = 130;
    else if (fx.failed)
        rc = fx.failed;
    if (rc && named)
        frames_failed(&fx.it, named->one.number, named->one.scene, named->one.out, rc);
    /* The frames still open are closed; their finished slabs stay for
     * --resume. */
    for (int i = 0; i < fx.nfr; i++) {
        frame_slot *fs = fx.fr[i];
        if (fs->im)
            frame_close(fs->im, fs->written ? 0 : rc ? rc : 1);
        frames_put(&fs->one);
        free(fs->rendered_on);
        free(fs);
    }
    free(fx.fr);
    hosts_free(&table);
    slurm_close(&alloc);
    return frames_end(&fx.it, rc);
}
