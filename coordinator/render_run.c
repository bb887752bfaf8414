/* render_run.c -- one run of `franja render` over its hosts: the hosts
 * made ready while the render starts, the scheduler's run (every pass of
 * --time-limit) and its reports (see render_run.h). */
#include "render_run.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "clock.h"
#include "transport/cluster.h"
#include "statusline.h"

volatile sig_atomic_t render_run_stop;

static void on_signal(int sig)
{
    (void)sig;
    render_run_stop = 1;
}

void render_run_signals(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);
}

/* The hosts of the render: the table, a Slurm allocation or this
 * machine.  0, or 2 (said). */
int render_run_hosts(frame_settings *a, int argc, char **argv, hosts_table *table, slurm_alloc *alloc)
{
    memset(alloc, 0, sizeof *alloc);
    if (a->slurm.on)
        return cli_slurm_hosts("render", &a->slurm, argc, argv, &a->tr, alloc, table) ? 2 : 0;
    if (a->hosts)
        return cli_load_hosts("render", a->hosts, table) ? 2 : 0;
    table->n = 1;
    table->v = calloc(1, sizeof *table->v);
    if (!table->v)
        return 1;
    snprintf(table->path, sizeof table->path, "(this machine)");
    strcpy(table->v[0].name, "local");
    strcpy(table->v[0].address, "local");
    return 0;
}

/* The end of a run: how it ended first when it did not finish (ended:
 * "interrupted", "failed"), then what was rendered (rows_done of the
 * rows_asked this run had to render; samples/s over those rows), the
 * slabs, retries and second copies, and each host's share. */
static void summary(const sched_host *hs, int n, const job_spec *spec, const sched_stats *st, int rows_done,
                    int rows_asked, double wall, const char *ended)
{
    double samples = st->samples;
    double rate = wall > 0 ? samples / wall / 1e6 : 0.0;
    int slabs = 0;
    for (int i = 0; i < n; i++)
        slabs += hs[i].slabs;
    if (ended)
        fprintf(stderr, "franja: %s after %.2f s: %d of %d rows rendered (%ux%u at %u spp), %.2f Msamples/s over "
                "them; %d of %d slabs, %d retries", ended, wall, rows_done, rows_asked, spec->width, spec->height,
                spec->spp, rate, slabs, st->slabs, st->retries);
    else
        fprintf(stderr, "franja: %ux%u at %u spp in %.2f s: %.2f Msamples/s; %d slabs, %d retries", spec->width,
                spec->height, spec->spp, wall, rate, st->slabs, st->retries);
    /* Second copies of slow slabs run on idle slots only; the first
     * result wins.  Not failures: said only when there were some. */
    if (st->duplicates)
        fprintf(stderr, ", %d second cop%s of slow slabs on idle slots", st->duplicates,
                st->duplicates == 1 ? "y" : "ies");
    if (st->continued)
        fprintf(stderr, "; %d slab%s went on from kept sample sums", st->continued, st->continued == 1 ? "" : "s");
    if (st->fresh_instead)
        fprintf(stderr, " (%d attempt%s rendered every sample: the sums could not be sent)", st->fresh_instead,
                st->fresh_instead == 1 ? "" : "s");
    fputc('\n', stderr);
    if (n == 0)
        return;
    fprintf(stderr, "  %-16s %5s %6s %6s %8s %6s %8s %10s  %s\n", "host", "slots", "slabs", "rows", "failures",
            "copies", "busy s", "sent", "state");
    for (int i = 0; i < n; i++) {
        const sched_host *h = &hs[i];
        if (!h->tr)
            continue; /* never ready: said when it was given up */
        char sent[32];
        hosts_format_size(h->sent, sent);
        fprintf(stderr, "  %-16s %5d %6d %6d %8d %6d %8.2f %10s  %s%s\n", h->name, h->slots, h->slabs, h->rows,
                h->failures, h->duplicates, h->busy_s, sent, h->dropped ? "dropped: " : "ok",
                h->dropped ? h->drop_reason : "");
    }
}

/* The scheduler's reports on stderr.  Progress: on a terminal a live line
 * four times a second; otherwise (a batch job's log) a plain line every
 * LOG_EVERY seconds and one at the end.  Events are log lines, except
 * accepted slabs (the progress shows them) and, on a terminal, second
 * copies. */
enum { LOG_EVERY = 10 };

typedef struct {
    int tty;
    const sched_host *hosts;
    int nhosts;
    const job_spec *spec;
    double last_draw;
    double t;                  /* the latest progress report */
    int done, total;
    struct joiner *join;       /* hosts joining the render */
    progress_reporter *pg;           /* --progress json, or NULL */
    mon_server *mon;           /* --monitor, or NULL */
    int rows_before;           /* rows done before this run (resumed) */
    mon_host *mh;              /* nhosts entries for the monitor */
    char (*mstate)[320];       /* their state strings */
    const render_run_frames *fx;       /* the frames of an animation run together, or NULL */
} reporter;

/* A host's event to the JSON stream and the monitor; frame: the frame
 * number of an animation's rows y0:y1, else PG_NO_FRAME. */
static void host_event(reporter *r, long frame, const char *what, const char *host, uint32_t y0, uint32_t y1,
                       double t, const char *text)
{
    progress_event(r->pg, frame, what, host, y0, y1, text);
    mon_event(r->mon, t, host, what, text);
}

static int line_drawn;          /* a live status line is on the terminal */

void render_run_scene_state(const hosts_entry *e, uint64_t sent, char *out)
{
    char size[32];
    hosts_format_size(sent, size);
    if (hosts_is_local(e))
        snprintf(out, 64, "local");
    else if (sent)
        snprintf(out, 64, "uploaded (%s)", size);
    else
        snprintf(out, 64, "already there");
}

void render_run_clear_line(void)
{
    if (line_drawn) {
        fputs("\r\033[K", stderr);
        line_drawn = 0;
    }
}

static void on_event(void *ctx, const sched_event *ev)
{
    reporter *r = ctx;
    static const char *const what[] = {
        [SCHED_SLAB_DONE] = "done", [SCHED_SLAB_FAILED] = "failed", [SCHED_COPY] = "copy",
        [SCHED_HOST_DROPPED] = "dropped", [SCHED_HOST_SHRUNK] = "shrunk", [SCHED_HOST_RETRY] = "retry",
    };
    /* A slab's event is about a frame of an animation: its number goes with it. */
    long frame = r->fx && ev->y1 > ev->y0 ? r->fx->number(r->fx->ctx, ev->frame) : PG_NO_FRAME;
    if (ev->kind != SCHED_SLAB_DONE && ev->host >= 0 && ev->host < r->nhosts)
        host_event(r, frame, what[ev->kind], r->hosts[ev->host].name, ev->y0, ev->y1, ev->t, ev->text);
    if (ev->kind == SCHED_SLAB_DONE && r->fx)
        r->fx->rendered(r->fx->ctx, ev->frame, ev->host, ev->y0, ev->y1);
    if (ev->kind == SCHED_SLAB_DONE || (r->tty && ev->kind == SCHED_COPY))
        return;
    render_run_clear_line();
    fprintf(stderr, "franja: [%6.1fs] %s\n", ev->t, ev->text);
}

static void draw(reporter *r, int force)
{
    if (!force && r->t - r->last_draw < (r->tty ? 0.25 : LOG_EVERY))
        return;
    r->last_draw = r->t;
    char line[1024];
    statusline_figures f = {r->t, r->done, r->total, (double)r->spec->width * r->spec->spp, 0, 0, 0};
    if (r->fx)
        r->fx->counts(r->fx->ctx, &f.frames_done, &f.frames, &f.rows_ahead);
    statusline_format(line, sizeof line, r->tty ? statusline_columns(2) : 0, &f, r->hosts, r->nhosts);
    if (r->tty) {
        fprintf(stderr, "\r\033[K%s", line);
        fflush(stderr);
        line_drawn = 1;
    } else {
        fprintf(stderr, "franja: [%6.1fs] %s\n", r->t, line);
    }
}

/* The hosts' state for the monitor. */
static void monitor_update(reporter *r)
{
    if (!r->mon)
        return;
    for (int i = 0; i < r->nhosts; i++) {
        const sched_host *h = &r->hosts[i];
        if (h->pending)
            snprintf(r->mstate[i], sizeof r->mstate[i], "starting");
        else if (h->dropped)
            snprintf(r->mstate[i], sizeof r->mstate[i], "dropped: %s", h->drop_reason);
        else
            snprintf(r->mstate[i], sizeof r->mstate[i], "%s", h->running ? "rendering" : "idle");
        r->mh[i] = (mon_host){h->name, r->mstate[i], h->running, h->slots, h->rows, h->failures};
    }
    mon_progress(r->mon, r->t, r->rows_before + r->done, r->rows_before + r->total, r->rows_before, r->mh, r->nhosts);
}

static void on_progress(void *ctx, double t, int done, int total)
{
    reporter *r = ctx;
    r->t = t;
    r->done = done;
    r->total = total;
    draw(r, 0);
    monitor_update(r);
}

/* Hosts joining the render as they become ready (the scheduler's admit
 * hook): each is checked (version), given its slots and announced. */
typedef struct joiner {
    const frame_settings *a;
    cluster_group *g;
    cluster_host *cl;
    reporter *rep;
    int ready;                 /* hosts handed over ready */
} joiner;

/* Takes every host whose preparation has ended, waiting up to ms for the
 * first one. */
static void join_hosts(joiner *j, sched_host *sh, int ms)
{
    cluster_host h;
    int i;
    while ((i = cluster_next_ready(j->g, &h, ms)) >= 0) {
        ms = 0;
        j->cl[i] = h;
        sched_host *s = &sh[i];
        s->pending = 0;
        if (j->rep)
            render_run_clear_line();
        if (j->cl[i].tr)
            cluster_check_version(&j->cl[i]);
        if (!j->cl[i].tr) {
            fprintf(stderr, "franja: host %s is not used: %s\n", h.entry->name, j->cl[i].err.msg);
            if (j->rep) {
                char line[1200];
                snprintf(line, sizeof line, "host %s is not used: %s", h.entry->name, j->cl[i].err.msg);
                host_event(j->rep, PG_NO_FRAME, "unused", h.entry->name, 0, 0, j->rep->t, line);
            }
            s->dropped = 1;
            snprintf(s->drop_reason, sizeof s->drop_reason, "%s", j->cl[i].err.msg);
            continue;
        }
        j->ready++;
        const frame_settings *a = j->a;
        int slots = h.entry->cores ? h.entry->cores : h.info.cores;
        if (!h.entry->cores && h.info.cores_reported > (uint32_t)h.info.cores)
            fprintf(stderr, "franja: host %s reports %u processors; using %d (give its cores in the host table "
                    "if it has more)\n", h.entry->name, h.info.cores_reported, h.info.cores);
        int table = a->hosts || a->slurm.on;
        if (a->jobs && (!table || slots > (int)a->jobs))
            slots = (int)a->jobs;
        s->tr = h.tr;
        s->slots = slots > 0 ? slots : 1;
        snprintf(s->scene, sizeof s->scene, "%s", h.scene);
        snprintf(s->lease, sizeof s->lease, "%s", h.lease);
        s->lease_t = clock_now();
        if ((table || !isatty(2)) && j->rep && j->rep->fx) /* each frame's scene is said as it is staged */
            fprintf(stderr, "franja: host %s: %s %s, %d slots, %s (%.2f s)\n", s->name, h.info.os, h.info.arch,
                    s->slots, h.info.version, h.ready_s);
        else if (table || !isatty(2)) {
            char how[64];
            render_run_scene_state(h.entry, h.sent, how);
            fprintf(stderr, "franja: host %s: %s %s, %d slots, %s, scene %s (%.2f s)\n", s->name, h.info.os,
                    h.info.arch, s->slots, h.info.version, how, h.ready_s);
        }
        s->sent += h.sent;
        if (j->rep) {
            char line[600];
            snprintf(line, sizeof line, "host %s ready: %s %s, %d slots (%.2f s)", s->name, h.info.os, h.info.arch,
                     s->slots, h.ready_s);
            host_event(j->rep, PG_NO_FRAME, "ready", s->name, 0, 0, j->rep->t, line);
        }
    }
}

static void on_admit(void *ctx, sched_host *hosts, int nhosts)
{
    (void)nhosts;
    reporter *r = ctx;
    join_hosts(r->join, hosts, 0);
}

static void add_stats(sched_stats *to, const sched_stats *st)
{
    to->slabs += st->slabs;
    to->retries += st->retries;
    to->duplicates += st->duplicates;
    to->wall_s += st->wall_s;
    to->samples += st->samples;
    to->continued += st->continued;
    to->fresh_instead += st->fresh_instead;
    to->timed_out |= st->timed_out;
}

/* An animation's hooks, called with the reporter as the scheduler's
 * context. */
static int fx_next(void *ctx, int frame, sched_frame *next, fr_error *err)
{
    const render_run_frames *fx = ((reporter *)ctx)->fx;
    return fx->next_frame(fx->ctx, frame, next, err);
}

static int fx_stage(void *ctx, int frame, sched_host *h, int host_i, char *scene, size_t scene_cap, char *lease,
                    size_t lease_cap, fr_error *err)
{
    const render_run_frames *fx = ((reporter *)ctx)->fx;
    return fx->stage(fx->ctx, frame, h, host_i, scene, scene_cap, lease, lease_cap, err);
}

static int fx_done(void *ctx, int frame, fr_error *err)
{
    const render_run_frames *fx = ((reporter *)ctx)->fx;
    return fx->frame_done(fx->ctx, frame, err);
}

int render_run(const frame_settings *a, const hosts_table *table, const char *fbin, frame_passes *ps, progress_reporter *pg,
           mon_server *mon, char *used, size_t used_cap, const render_run_frames *fx, fr_error *err)
{
    const job_spec *spec = &ps->spec;
    const char *jobdir = ps->jobdir;
    int rows_job = ps->rows_job, rows_missing = ps->rows_missing;
    int n = table->n;
    cluster_host *cl = calloc((size_t)n, sizeof *cl);
    sched_host *sh = calloc((size_t)n, sizeof *sh);
    mon_host *mh = calloc((size_t)n, sizeof *mh);
    char(*mstate)[320] = calloc((size_t)n, sizeof *mstate);
    cluster_group *g = NULL;
    if (cl && sh && mh && mstate) {
        for (int i = 0; i < n; i++)
            cl[i].entry = &table->v[i];
        g = cluster_start(cl, n, &a->tr, fx ? NULL : fbin, spec->hash);
    }
    if (!g) {
        free(cl);
        free(sh);
        free(mh);
        free(mstate);
        return fr_fail(err, "out of memory");
    }
    for (int i = 0; i < n; i++) {
        sh[i].name = table->v[i].name;
        sh[i].pending = 1;
        sh[i].slots = table->v[i].cores; /* a guess for the slab size until it is ready */
    }
    reporter rep = {.tty = isatty(2), .hosts = sh, .nhosts = n, .spec = spec, .pg = pg, .mon = mon,
                    .rows_before = rows_job - rows_missing, .mh = mh, .mstate = mstate, .total = rows_missing,
                    .fx = fx};
    joiner j = {a, g, cl, &rep, 0};
    rep.join = &j;
    monitor_update(&rep);
    /* The first host (or the end of them all). */
    while (!j.ready && cluster_pending(g)) {
        join_hosts(&j, sh, 1000);
        monitor_update(&rep);
    }
    int rc = 0;
    if (!j.ready)
        rc = fr_fail(err, "no host could be used (see the messages above)");
    if (rc == 0) {
        /* Hosts not ready yet count in the slab size with the slots of the
         * first ready one, unless the table says. */
        int guess = 1;
        for (int i = 0; i < n; i++)
            if (!sh[i].pending && !sh[i].dropped && sh[i].slots > guess)
                guess = sh[i].slots;
        for (int i = 0; i < n; i++)
            if (sh[i].pending && sh[i].slots < 1)
                sh[i].slots = guess;
        double t0 = clock_now();
        sched_stats st;
        memset(&ps->total, 0, sizeof ps->total);
        for (;;) {
            uint32_t spp = ps->cap;
            if (ps->deadline > 0) {
                if (frame_next_pass(ps, &spp, err)) {
                    rc = -1;
                    break;
                }
                if (spp == 0)
                    break;
                if (ps->reached && clock_now() >= ps->deadline) {
                    ps->stopped = spp;
                    break;
                }
                int norm = 0;
                if (frame_plan(ps, spp, err) || (ps->rows_missing && (norm = frame_normalise(ps, err)) < 0)) {
                    rc = -1;
                    break;
                }
                if (norm > 0) {
                    ps->stopped = spp; /* the limit came during its normalisation */
                    break;
                }
                ps->npass++;
                render_run_clear_line();
                fprintf(stderr, "franja: pass %d: %u samples per pixel, %d rows to render\n", ps->npass, spp,
                        ps->rows_missing);
                progress_pass(pg, ps->npass, spp);
            } else if (ps->npass++ > 0) {
                break;
            }
            rows_missing = ps->rows_missing;
            rep.total = rows_missing;
            rep.done = 0;
            rep.rows_before = rows_job - rows_missing;
            sched_params p = {.spec = *spec,
                              .jobdir = jobdir,
                              .have = ps->have,
                              .base = ps->base,
                              .sums = job_sums(spec),
                              /* The first pass of a --time-limit render
                               * always ends: it is the least image there is.
                               * An animation's limit is the whole run's. */
                              .stop_at = ps->deadline > 0 && ps->reached ? ps->deadline : fx ? fx->deadline : 0,
                              .slab_rows = (int)a->slab_rows,
                              .max_attempts = (int)a->retries,
                              .max_host_failures = 3,
                              .stop = &render_run_stop,
                              /* An SSH channel closed (a losing copy, a dropped
                               * host, this process gone) ends the worker, even
                               * where signals do not reach it (worker/lifeline.h). */
                              .lifeline = !a->slurm.on,
                              .hooks = {.event = on_event, .progress = on_progress, .admit = on_admit, .ctx = &rep}};
            if (fx) {
                p.label = ps->label;
                p.hooks.next_frame = fx_next;
                p.hooks.stage = fx_stage;
                p.hooks.frame_done = fx_done;
            }
            rc = sched_run(&p, sh, n, &st, err);
            add_stats(&ps->total, &st);
            if (rc && st.timed_out && !render_run_stop && fx) {
                /* An animation's limit: the frames in flight stop, their
                 * finished slabs stay. */
                *fx->timed_out = 1;
                break;
            }
            if (rc && st.timed_out && !render_run_stop) {
                /* The pass in flight is given up; its finished slabs stay. */
                ps->stopped = spp;
                rc = 0;
                break;
            }
            if (rc || ps->deadline <= 0)
                break;
            if (frame_pass_image(ps, err)) {
                rc = -1;
                break;
            }
            ps->reached = spp;
            draw(&rep, 1);
            render_run_clear_line();
            fprintf(stderr, "franja: pass %d done: %u samples per pixel at %.2f s\n", ps->npass, spp,
                    clock_now() - t0);
        }
        draw(&rep, 1);
        if (line_drawn) {
            fputc('\n', stderr);
            line_drawn = 0;
        }
        job_spec shown = *spec;
        if (ps->deadline > 0 && ps->reached)
            shown.spp = ps->reached;
        const char *ended = rc == 0 ? NULL : render_run_stop ? "interrupted" : "failed";
        if (rc && !render_run_stop && fx && ps->total.timed_out)
            ended = "stopped by the time limit";
        summary(sh, n, &shown, &ps->total, rep.done, rows_missing, clock_now() - t0, ended);
        /* The hosts that rendered rows, for the image's metadata. */
        for (int i = 0, k = 0; i < n && used_cap; i++)
            if (sh[i].rows > 0 && k >= 0 && (size_t)k < used_cap)
                k += snprintf(used + k, used_cap - (size_t)k, "%s%s", k ? "," : "", sh[i].name);
    }
    for (int i = 0; i < n; i++)
        if (sh[i].pending)
            fprintf(stderr, "franja: host %s was not ready before the render ended\n", table->v[i].name);
    /* The render no longer needs its scenes: other renders may evict them. */
    for (int i = 0; i < n; i++)
        if (cl[i].tr && cl[i].lease[0]) {
            fr_error e;
            tr_remove(cl[i].tr, cl[i].lease, &e);
        }
    cluster_close(cl, n);
    /* A host still being prepared is not waited for (its time-out would
     * add to the render), except under Slurm, whose shared state goes with
     * the allocation. */
    cluster_end(g, a->slurm.on);
    free(cl);
    free(sh);
    free(mh);
    free(mstate);
    return rc;
}
