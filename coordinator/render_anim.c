/* render_anim.c -- the frames of an animation rendered together over one
 * set of hosts (see render_anim.h). */
#include "render_anim.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "clock.h"
#include "transport/cluster.h"
#include "cmd.h"
#include "framewalk.h"
#include "preview.h"
#include "quick.h"
#include "render_run.h"

/* One frame of an animation run together with the others. */
typedef struct {
    framewalk_one one;            /* its number, files and command line */
    frame_image *im;           /* NULL once closed */
    int written;
    int failed;                /* the exit status it failed with (said when the run ends); 0 = none */
    char label[32];            /* "frame N" */
    unsigned char *rendered_on; /* per host: it rendered rows of this frame */
    preview_writer *pv;             /* its --preview writer, or NULL */
    int rows_done;             /* rows in its job directory (for the monitor) */
} frame_slot;

typedef struct {
    framewalk_iter it;
    render_anim_parse_fn parse;         /* a frame's command line */
    const frame_settings *a;      /* the command's own */
    const hosts_table *table;
    frame_slot **fr;           /* by the scheduler's frame index */
    int nfr, capfr;
    int failed;                /* a frame failed: no frame is opened after it */
    double deadline;           /* --time-limit: clock_now() time the run stops at; 0 = none */
    progress_reporter *pg;           /* the run's --progress json, or NULL */
    mon_server *mon;           /* the run's --monitor, or NULL */
    reuse_state reuse;         /* the frame before's scene, for the next compile and patch (reuse.h) */
    uint64_t *host_scene;      /* per host: the hash of the last scene staged there, 0 none */
} anim_run;

/* The monitor's view of frame fs in state st. */
static void show_state(anim_run *fx, const frame_slot *fs, char st)
{
    int rows = fs->im ? fs->im->rows_job : 0;
    mon_frame(fx->mon, fs->one.index - 1, fs->one.number, st, fs->one.out, fs->rows_done, rows);
}

/* A frame whose output exists is passed over: said to the reporters. */
static void on_skip(void *ctx, size_t index, uint32_t number, const char *out)
{
    anim_run *fx = ctx;
    progress_skipped(fx->pg, number, out);
    mon_frame(fx->mon, index, number, 's', out, 0, 0);
}

/* Stops the preview writers of frames before fs that write fs's file (a
 * --preview without #: the file follows the newest frame). */
static void preview_take_over(anim_run *fx, const frame_slot *fs)
{
    for (int i = 0; i < fx->nfr; i++) {
        frame_slot *o = fx->fr[i];
        if (o != fs && o->pv && o->im && !strcmp(o->im->a.preview, fs->im->a.preview)) {
            preview_stop(o->pv);
            o->pv = NULL;
        }
    }
}

/* A frame's reporters, once it is open: its --progress json events, the
 * monitor's image and its --preview.  0, or the exit status (said). */
static int frame_reporters(anim_run *fx, frame_slot *fs)
{
    frame_image *im = fs->im;
    frame_settings *a = &im->a;
    fr_error err;
    fs->rows_done = im->rows_have;
    if (fx->pg && !(im->pg = progress_start(stdout, fs->one.number, a->out, im->jobdir, &im->spec, (uint32_t)im->rows_job,
                                      &err))) {
        fprintf(stderr, "franja render: --progress json: %s\n", err.msg);
        return 1;
    }
    if (fx->mon) {
        show_state(fx, fs, 'r');
        if (mon_show(fx->mon, fs->one.number, im->jobdir, &im->spec, &im->tm, &err))
            fprintf(stderr, "franja render: --monitor: %s: %s\n", fs->label, err.msg);
    }
    if (a->preview) {
        preview_take_over(fx, fs);
        if (!(fs->pv = preview_start(a->preview, im->jobdir, &im->spec, &im->tm, a->preview_every,
                                (note_sink){cli_note_stderr, NULL}, &err))) {
            fprintf(stderr, "franja render: --preview: %s\n", err.msg);
            return 1;
        }
    }
    return 0;
}

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
    int r = framewalk_next(&fx->it, &fs->one);
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
    if (!rc && (out_check(fs->im->a.out, &e) || (fs->im->a.preview && out_check_type(fs->im->a.preview, &e)))) {
        fprintf(stderr, "franja render: %s\n", e.msg);
        rc = 2;
    }
    if (!rc && fx->it.job.one_scene) {
        /* One animated file: this frame's pose. */
        fs->im->a.timed = 1;
        fs->im->a.frame = fs->one.number;
    }
    if (!rc) {
        /* The run's limit (fx->deadline), not passes of each frame. */
        fs->im->a.time_limit = 0;
        rc = frame_lock(fs->im);
    }
    if (!rc) {
        fs->im->reuse = &fx->reuse;
        rc = frame_open(fs->im);
    }
    const reuse_result *rr = fs->im ? &fs->im->reused : NULL;
    if (!rc && (rr->seconds > 0 || rr->base)) {
        render_run_clear_line();
        fprintf(stderr, "franja: %s: ", fs->label);
        if (rr->seconds > 0)
            fprintf(stderr, "scene %s in %.3f s%s", rr->reused ? "made of the frame before's" : "compiled",
                    rr->seconds, rr->base ? "; " : "");
        if (rr->base)
            fprintf(stderr, "a patch of %llu bytes from the frame before's", (unsigned long long)rr->patch_bytes);
        fputc('\n', stderr);
    }
    if (!rc)
        rc = frame_reporters(fx, fs);
    if (rc) {
        if (fs->im) {
            preview_stop(fs->pv);
            fs->pv = NULL;
            frame_close(fs->im, rc);
        }
        fs->im = NULL;
        fs->failed = fx->failed = render_run_stop ? 130 : rc;
        show_state(fx, fs, render_run_stop ? 'x' : 'f');
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
    anim_run *fx = ctx;
    (void)frame, (void)err; /* frames are opened in the scheduler's order: frame == fx->nfr */
    if (render_run_stop || (fx->deadline > 0 && clock_now() >= fx->deadline))
        return 1; /* no new frame once interrupted or at the time limit */
    render_run_clear_line();
    return rf_open(ctx, next) ? 1 : 0;
}

static int rf_stage(void *ctx, int frame, sched_host *h, int host_i, char *scene, size_t scene_cap, char *lease,
                    size_t lease_cap, fr_error *err)
{
    anim_run *fx = ctx;
    frame_slot *fs = fx->fr[frame];
    const hosts_entry *e = &fx->table->v[host_i];
    double t0 = clock_now();
    uint64_t sent = 0;
    fr_error e2;
    /* A patch only to a host given its base scene in this run. */
    stage_patch patch = {fs->im->patch, fs->im->reused.base};
    const stage_patch *pp = fs->im->patch[0] && fx->host_scene[host_i] == patch.base ? &patch : NULL;
    if (cluster_stage(h->tr, e, fs->im->fbin, fs->im->spec.hash, pp, scene, scene_cap, lease, lease_cap, &sent,
                      &e2))
        return fr_fail(err, "%s: %s", fs->label, e2.msg);
    fx->host_scene[host_i] = fs->im->spec.hash;
    h->sent += sent;
    if (fx->table->path[0] != '(' || !isatty(2)) {
        render_run_clear_line();
        char how[64];
        render_run_scene_state(e, sent, how);
        fprintf(stderr, "franja: host %s: %s: scene %s (%.2f s, %llu bytes sent)\n", h->name, fs->label, how,
                clock_now() - t0, (unsigned long long)sent);
    }
    return 0;
}

static void rf_rendered(void *ctx, int frame, int host, uint32_t y0, uint32_t y1)
{
    anim_run *fx = ctx;
    if (frame < 0 || frame >= fx->nfr)
        return;
    frame_slot *fs = fx->fr[frame];
    if (host >= 0 && host < fx->table->n && fs->rendered_on)
        fs->rendered_on[host] = 1;
    fs->rows_done += (int)(y1 - y0);
    if (fs->im && !fs->written)
        show_state(fx, fs, 'r');
}

static long rf_number(void *ctx, int frame)
{
    anim_run *fx = ctx;
    return frame >= 0 && frame < fx->nfr ? (long)fx->fr[frame]->one.number : PG_NO_FRAME;
}

static void rf_counts(void *ctx, int *done, int *frames, double *rows_ahead)
{
    anim_run *fx = ctx;
    const frame_slot *last = fx->nfr ? fx->fr[fx->nfr - 1] : NULL;
    *done = (int)(fx->it.rendered + fx->it.skipped);
    *frames = (int)fx->it.fl.n;
    /* The frames not looked at yet, each with the rows of the last one
     * opened (some may be skipped: an estimate from above). */
    *rows_ahead = last && last->im ? (double)(fx->it.fl.n - fx->it.i) * last->im->rows_job : 0;
}

static int rf_done(void *ctx, int frame, fr_error *err)
{
    anim_run *fx = ctx;
    frame_slot *fs = fx->fr[frame];
    char used[1024] = "";
    for (int i = 0, k = 0; i < fx->table->n; i++)
        if (fs->rendered_on[i] && (size_t)k < sizeof used)
            k += snprintf(used + k, sizeof used - (size_t)k, "%s%s", k ? "," : "", fx->table->v[i].name);
    render_run_clear_line();
    preview_stop(fs->pv); /* its last image: the whole frame */
    fs->pv = NULL;
    if (frame_write(fs->im, used)) {
        fs->failed = fx->failed = 1;
        show_state(fx, fs, 'f');
        return fr_fail(err, "%s could not be written", fs->label);
    }
    fs->written = 1;
    show_state(fx, fs, 'd');
    framewalk_wrote(&fx->it);
    frame_shrink(fs->im); /* the settings stay: the scheduler's run may still read the first frame's */
    return 0;
}

/* The run's reporters: --progress json's frames event and the monitor.
 * 0, or the exit status (said). */
static int run_reporters(anim_run *fx, const frame_settings *a)
{
    fr_error err;
    if (a->json && !(fx->pg = progress_run_start(stdout, a->frames, fx->it.fl.n, &err))) {
        fprintf(stderr, "franja render: --progress json: %s\n", err.msg);
        return 1;
    }
    if (a->monitor) {
        if (!(fx->mon = mon_start_frames((uint16_t)a->monitor_port, a->monitor_open, a->out, a->frames, fx->it.fl.n,
                                         &err))) {
            fprintf(stderr, "franja render: --monitor: %s\n", err.msg);
            return 1;
        }
        mon_status(fx->mon, "rendering");
        fprintf(stderr, "franja: monitor on %s\n", mon_url(fx->mon));
    }
    return 0;
}

/* `franja render PATTERN --frames LIST`: the frames run together over one
 * set of hosts, each written as soon as its rows are in. */
int render_anim(int argc, char **argv, frame_settings *a, render_anim_parse_fn parse)
{
    double t_start = clock_now();
    framewalk_job fj = {a->frames, a->overwrite, a->scene, a->out, a->jobdir, a->preview,
                        framewalk_one_scene(a->scene)};
    anim_run fx;
    memset(&fx, 0, sizeof fx);
    fx.parse = parse;
    fx.a = a;
    if (framewalk_begin(&fx.it, argc, argv, &fj))
        return 2;
    fx.it.on_skip = on_skip;
    fx.it.skip_ctx = &fx;
    if (a->time_limit > 0)
        fx.deadline = t_start + a->time_limit;
    render_run_signals();
    fr_error err;
    uint32_t probe = UINT32_MAX;
    if (quick_spp(&probe, &err) < 0) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        return framewalk_end(&fx.it, 2);
    }
    int rc = run_reporters(&fx, a);
    hosts_table table = {0};
    slurm_alloc alloc = {0};
    if (!rc)
        rc = render_run_hosts(a, argc, argv, &table, &alloc);
    int timed_out = 0, hosts_ok = !rc;
    fx.table = &table;
    if (!rc && !(fx.host_scene = calloc((size_t)(table.n > 0 ? table.n : 1), sizeof *fx.host_scene))) {
        fprintf(stderr, "franja render: out of memory\n");
        rc = 1;
    }
    sched_frame first;
    if (!rc && rf_open(&fx, &first) == 0) {
        char used[1024];
        render_run_frames hooks = {rf_next,   rf_stage, rf_done,     rf_rendered, rf_number,
                           rf_counts, &fx,      fx.deadline, &timed_out};
        if (render_run(a, &table, NULL, &fx.fr[0]->im->ps, fx.pg, fx.mon, used, sizeof used, &hooks, &err)) {
            if (!timed_out)
                fprintf(stderr, "franja render: %s\n", err.msg);
            rc = 1;
        }
    }
    /* The frame to name: after an interrupt the first not written, else
     * the one that failed, else (the hosts failed, the time limit) the
     * first not written. */
    frame_slot *named = NULL;
    for (int i = 0; i < fx.nfr && !named; i++)
        if (fx.fr[i]->failed && !render_run_stop)
            named = fx.fr[i];
    for (int i = 0; i < fx.nfr && !named; i++)
        if (!fx.fr[i]->written)
            named = fx.fr[i];
    if (render_run_stop && (rc || fx.failed))
        rc = 130;
    else if (fx.failed)
        rc = fx.failed;
    else if (timed_out)
        rc = FRAMES_TIME_LIMIT;
    if (timed_out && rc == FRAMES_TIME_LIMIT)
        fprintf(stderr, "franja: time limit of %g s reached\n", a->time_limit);
    if (rc && named)
        framewalk_failed(&fx.it, named->one.number, named->one.scene, named->one.out, rc);
    /* The frames still open are closed; their finished slabs stay for
     * --resume. */
    const char *how = rc == 130 ? "interrupted" : rc == FRAMES_TIME_LIMIT ? "time_limit" : "failed";
    for (int i = 0; i < fx.nfr; i++) {
        frame_slot *fs = fx.fr[i];
        preview_stop(fs->pv);
        if (fs->im && !fs->written) {
            progress_stop(fs->im->pg, how, fs->im->spec.spp);
            fs->im->pg = NULL;
            show_state(&fx, fs, fs->failed && rc != 130 ? 'f' : 'x');
        }
        if (fs->im)
            frame_close(fs->im, fs->written ? 0 : rc ? rc : 1);
        framewalk_put(&fs->one);
        free(fs->rendered_on);
        free(fs);
    }
    free(fx.fr);
    free(fx.host_scene);
    reuse_free(&fx.reuse);
    progress_run_end(fx.pg, rc == 0 ? "ok" : how, fx.it.fl.n, fx.it.rendered, fx.it.skipped);
    mon_status(fx.mon, rc == 0 ? "done" : rc == 130 ? "interrupted" : rc == FRAMES_TIME_LIMIT ? "stopped" : "failed");
    mon_stop(fx.mon);
    if (hosts_ok) {
        hosts_free(&table);
        slurm_close(&alloc);
    }
    return framewalk_end(&fx.it, rc);
}
