/* sched.c -- the slab queue and the event loop that drives every worker
 * process (see sched.h for the rules). */
#include "sched.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "clock.h"
#include "protocol.h"

typedef struct {
    int frame;                 /* index into sched.frames */
    uint32_t y0, y1;
    int done;
    int attempts;              /* failed attempts so far */
    int copies;                /* processes running it now */
    int failed_on;             /* host of the last failed attempt, -1 if none */
    int *failed_hosts;         /* the distinct hosts it failed on, nfailed of them */
    int nfailed;
    char last_error[300];
    uint32_t base;             /* samples per pixel its rows continue from; 0 = none */
    char *cont;                /* the sums file for the workers (job_cont_build), NULL until made */
} slab;

typedef struct {
    int slab, host;
    tr_proc *proc;
    double start;
    uint32_t from;             /* samples the attempt continues from */
    char *remote;              /* the sums uploaded for it, NULL if none */
} attempt;

/* One host's copy of a frame's scene (the stage hook's). */
typedef struct {
    int staged;
    char scene[1024];
    char lease[1200];          /* "" = none */
    double lease_t;
} frame_host;

typedef struct {
    sched_frame f;
    int rows_total, rows_done;
    int done;                  /* every row saved, frame_done told */
    frame_host *fh;            /* per host, with the stage hook; NULL otherwise */
} frame;

typedef struct {
    const sched_params *p;
    sched_host *hosts;
    int nhosts;
    frame *frames;
    int nframes, capframes;
    int fed_all;               /* no frame is left to ask for */
    slab *slabs;
    int nslabs, capslabs, next; /* next: first slab that may still be queued */
    attempt *run;
    int nrun, caprun;
    int rows_total, rows_done;
    double acc_s;              /* run time of accepted attempts, summed */
    int acc_rows;              /* their rows */
    sched_stats *st;
    double t0;
    struct leftover {          /* uploaded sums that could not be removed yet */
        int host;
        char *remote;
    } *left;
    int nleft;
} sched;

static double now(const sched *s)
{
    const sched_hooks *k = &s->p->hooks;
    return k->now ? k->now(k->ctx) : clock_now();
}

/* Reports an event with a one-line text (printf-style). */
static void emit(sched *s, sched_event_kind kind, int host, const slab *sl, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
static void emit(sched *s, sched_event_kind kind, int host, const slab *sl, const char *fmt, ...)
{
    const sched_hooks *k = &s->p->hooks;
    if (!k->event)
        return;
    char text[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    sched_event ev = {kind, now(s) - s->t0, host, sl ? sl->frame : 0, sl ? sl->y0 : 0, sl ? sl->y1 : 0, text};
    k->event(k->ctx, &ev);
}

static void progress(sched *s)
{
    const sched_hooks *k = &s->p->hooks;
    if (k->progress)
        k->progress(k->ctx, now(s) - s->t0, s->rows_done, s->rows_total);
}

/* "rows A:B" of slab sl, with its frame's label before them when it has
 * one ("frame 12 rows A:B"). */
static const char *rows_of(const sched *s, const slab *sl, char *buf, size_t cap)
{
    const char *label = s->frames[sl->frame].f.label;
    snprintf(buf, cap, "%s%srows %u:%u", label ? label : "", label ? " " : "", sl->y0, sl->y1);
    return buf;
}

static int frame_done(sched *s, int fi, fr_error *err);

/* Adds frame f's slabs to the queue (frame index s->nframes). */
static int add_frame(sched *s, const sched_frame *f)
{
    const sched_frame *p = f;
    if (s->nframes == s->capframes) {
        int cap = s->capframes ? 2 * s->capframes : 4;
        frame *nf = realloc(s->frames, (size_t)cap * sizeof *nf);
        if (!nf)
            return -1;
        s->frames = nf;
        s->capframes = cap;
    }
    int fi = s->nframes;
    frame *fr = &s->frames[fi];
    memset(fr, 0, sizeof *fr);
    fr->f = *f;
    if (s->p->hooks.stage && !(fr->fh = calloc((size_t)(s->nhosts > 0 ? s->nhosts : 1), sizeof *fr->fh)))
        return -1;
    s->nframes++;
    int slots = 0;
    for (int i = 0; i < s->nhosts; i++)
        if (!s->hosts[i].dropped)
            slots += s->hosts[i].slots;
    uint32_t missing = 0;
    for (uint32_t y = 0; y < p->spec.height; y++)
        missing += !(p->have && p->have[y]);
    /* --slab-rows: every slab that size.  Otherwise slabs shrink toward
     * the end (guided scheduling): each is the rows still to cut over
     * twice the slots, at least a sixteenth per slot of the whole, so the
     * first are large (few worker starts) and the last small (the slots
     * finish close together). */
    uint32_t per = s->p->slab_rows > 0 ? (uint32_t)s->p->slab_rows : 0, n_slots = (uint32_t)(slots > 0 ? slots : 1);
    uint32_t least = (missing + 16 * n_slots - 1) / (16 * n_slots), left = missing;
    if (least < 1)
        least = 1;
    if ((size_t)s->nslabs + missing > (size_t)s->capslabs) {
        size_t cap = (size_t)s->nslabs + missing + (size_t)s->capslabs;
        slab *ns = realloc(s->slabs, cap * sizeof *ns);
        if (!ns)
            return -1;
        s->slabs = ns;
        s->capslabs = (int)cap;
    }
    for (uint32_t y = 0; y < p->spec.height;) {
        if (p->have && p->have[y]) {
            y++;
            continue;
        }
        uint32_t size = per;
        if (!per) {
            size = (left + 2 * n_slots - 1) / (2 * n_slots);
            if (size < least)
                size = least;
        }
        uint32_t end = y, base = p->base ? p->base[y] : 0;
        while (end < p->spec.height && !(p->have && p->have[end]) && end - y < size &&
               (p->base ? p->base[end] : 0) == base)
            end++;
        left -= end - y;
        s->slabs[s->nslabs++] = (slab){.frame = fi, .y0 = y, .y1 = end, .failed_on = -1, .base = base};
        s->st->slabs++;
        y = end;
    }
    fr->rows_total = (int)missing;
    s->rows_total += (int)missing;
    s->st->frames++;
    return 0;
}

/* Asks the next_frame hook for one more frame and queues its slabs; a
 * frame with nothing to render is done at once.  0 when a frame came (or
 * none is left: fed_all), -1 with err. */
static int feed(sched *s, fr_error *err)
{
    const sched_hooks *k = &s->p->hooks;
    while (!s->fed_all) {
        sched_frame f;
        memset(&f, 0, sizeof f);
        int r = k->next_frame ? k->next_frame(k->ctx, s->nframes, &f, err) : 1;
        if (r < 0)
            return -1;
        if (r > 0) {
            s->fed_all = 1;
            return 0;
        }
        if (add_frame(s, &f))
            return fr_fail(err, "out of memory");
        if (s->frames[s->nframes - 1].rows_total > 0)
            return 0;
        if (frame_done(s, s->nframes - 1, err))
            return -1;
    }
    return 0;
}

static int running_on(sched *s, int slab_i, int host_i)
{
    for (int i = 0; i < s->nrun; i++)
        if (s->run[i].slab == slab_i && s->run[i].host == host_i)
            return 1;
    return 0;
}

/* 1 if a live, ready host other than host_i could run a slab. */
static int other_host_alive(const sched *s, int host_i)
{
    for (int i = 0; i < s->nhosts; i++)
        if (i != host_i && !s->hosts[i].dropped && !s->hosts[i].pending)
            return 1;
    return 0;
}

/* Hosts still to be made ready. */
static int pending_hosts(const sched *s)
{
    int n = 0;
    for (int i = 0; i < s->nhosts; i++)
        n += s->hosts[i].pending && !s->hosts[i].dropped;
    return n;
}

/* Lets the caller make pending hosts ready (or drop them). */
static void admit(sched *s)
{
    if (!pending_hosts(s))
        return;
    const sched_hooks *k = &s->p->hooks;
    if (k->admit)
        k->admit(k->ctx, s->hosts, s->nhosts);
    for (int i = 0; i < s->nhosts; i++) {
        sched_host *h = &s->hosts[i];
        if (!k->admit && h->pending) {
            h->pending = 0;
            h->dropped = 1;
            snprintf(h->drop_reason, sizeof h->drop_reason, "never ready");
        }
        if (!h->pending && !h->dropped && h->slots < 1)
            h->slots = 1;
    }
}

/* Most processes one slab runs at once (its first and two copies). */
enum { MAX_COPIES = 3 };

/* What host_i should run next: the first queued slab, passing over those
 * that last failed on this host while another host is alive to take them;
 * else a second copy of a straggler: a slab that is not running here, with
 * the fewest copies, the one that has run longest; else, only when no slab
 * runs elsewhere, a second copy here of this host's own oldest slab (a
 * stuck process is overtaken even on a single host).  -1 if nothing. */
static int pick(sched *s, int host_i, fr_error *err)
{
    int others = other_host_alive(s, host_i);
    for (;;) {
        while (s->next < s->nslabs && (s->slabs[s->next].done || s->slabs[s->next].copies))
            s->next++;
        for (int i = s->next; i < s->nslabs; i++) {
            const slab *sl = &s->slabs[i];
            if (!sl->done && !sl->copies && !(others && sl->failed_on == host_i))
                return i;
        }
        /* Nothing queued for this slot: the next frame's slabs, if any. */
        if (s->fed_all)
            break;
        int before = s->nslabs;
        if (feed(s, err))
            return -2;
        if (s->nslabs == before)
            break;
    }
    int best = -1, best_here = 1, best_copies = MAX_COPIES;
    double best_t = 0;
    for (int r = 0; r < s->nrun; r++) {
        int si = s->run[r].slab;
        const slab *sl = &s->slabs[si];
        int here = running_on(s, si, host_i);
        if (sl->done || sl->copies >= MAX_COPIES || (here && sl->copies != 1))
            continue;
        int better = best < 0 || here < best_here || (here == best_here && sl->copies < best_copies) ||
                     (here == best_here && sl->copies == best_copies && s->run[r].start < best_t);
        if (better) {
            best = si;
            best_here = here;
            best_copies = sl->copies;
            best_t = s->run[r].start;
        }
    }
    return best;
}

/* `sh -c CONT_SCRIPT WORKER FILE ARGS...`: the worker reads the uploaded
 * sums through descriptor 3 (--continue /dev/fd/3), and the file is gone
 * from the host's disk before the worker starts, however it ends. */
static const char CONT_SCRIPT[] = "exec 3<\"$1\" || exit 97; rm -f -- \"$1\"; shift; exec \"$0\" \"$@\"";

/* The path of slab sl's scene on host_i: the host's, or its frame's copy
 * there. */
static const char *scene_on(const sched *s, int host_i, const slab *sl)
{
    const frame *fr = &s->frames[sl->frame];
    return fr->fh ? fr->fh[host_i].scene : s->hosts[host_i].scene;
}

/* Where slab sl's sums go on a host with a work directory: beside the
 * scene, a name no other attempt or coordinator uses. */
static void remote_name(const sched *s, int host_i, const slab *sl, char *out, size_t cap)
{
    static unsigned counter;
    char dir[1024];
    snprintf(dir, sizeof dir, "%s", scene_on(s, host_i, sl));
    char *slash = strrchr(dir, '/');
    if (slash)
        slash[1] = 0;
    else
        dir[0] = 0;
    snprintf(out, cap, "%scont-%016llx-%u-%u-%u-%ld-%.0f-%u.pf", dir, (unsigned long long)s->frames[sl->frame].f.spec.hash, sl->y0,
             sl->y1, sl->base, (long)getpid(), clock_now() * 1e3, counter++);
}

/* The sums file of slab sl, made once; NULL when it cannot be made: the
 * slab is then rendered from its first sample (the same bits). */
static const char *cont_file(sched *s, slab *sl)
{
    if (!sl->base)
        return NULL;
    if (!sl->cont) {
        char path[4400];
        fr_error e;
        const sched_frame *f = &s->frames[sl->frame].f;
        if (job_cont_build(f->jobdir, &f->spec, sl->y0, sl->y1, sl->base, path, sizeof path, &e) ||
            !(sl->cont = strdup(path))) {
            sl->base = 0;
            return NULL;
        }
    }
    return sl->cont;
}

/* Removes the sums uploaded as `remote` to host_i; when that fails (the
 * host has no channel free for SFTP this instant: it refused a worker a
 * moment ago) the name is kept for sched_run's end, when no worker holds
 * a channel.  Takes remote. */
static void remove_remote(sched *s, int host_i, char *remote)
{
    fr_error ignore;
    if (!remote)
        return;
    if (tr_remove(s->hosts[host_i].tr, remote, &ignore) == 0) {
        free(remote);
        return;
    }
    struct leftover *l = realloc(s->left, (size_t)(s->nleft + 1) * sizeof *l);
    if (!l) {
        free(remote);
        return;
    }
    s->left = l;
    s->left[s->nleft++] = (struct leftover){host_i, remote};
}

/* At the end of a run: the leftovers, a few tries each, 200 ms apart (a
 * host frees a closed channel a moment after it is closed). */
static void remove_leftovers(sched *s)
{
    for (int i = 0; i < s->nleft; i++) {
        sched_host *h = &s->hosts[s->left[i].host];
        fr_error ignore;
        for (int k = 0; tr_remove(h->tr, s->left[i].remote, &ignore) && k < 4 && !h->dropped; k++)
            nanosleep(&(struct timespec){0, 200000000}, NULL);
        free(s->left[i].remote);
    }
    free(s->left);
    s->left = NULL;
    s->nleft = 0;
}

static void cont_drop(slab *sl)
{
    if (sl->cont)
        unlink(sl->cont);
    free(sl->cont);
    sl->cont = NULL;
}

/* Puts slab sl's frame's scene on host_i when it is not there yet (the
 * stage hook).  -1 with err when it cannot be. */
static int stage(sched *s, int host_i, const slab *sl, fr_error *err)
{
    frame *fr = &s->frames[sl->frame];
    if (!fr->fh || fr->fh[host_i].staged)
        return 0;
    frame_host *fh = &fr->fh[host_i];
    const sched_hooks *k = &s->p->hooks;
    fh->lease[0] = 0;
    if (k->stage(k->ctx, sl->frame, &s->hosts[host_i], host_i, fh->scene, sizeof fh->scene, fh->lease,
                 sizeof fh->lease, err))
        return -1;
    fh->staged = 1;
    fh->lease_t = clock_now();
    return 0;
}

static int start(sched *s, int host_i, int slab_i, fr_error *err)
{
    sched_host *h = &s->hosts[host_i];
    slab *sl = &s->slabs[slab_i];
    const sched_frame *f = &s->frames[sl->frame].f;
    const job_spec *sp = &f->spec;
    proto_slab req = {scene_on(s, host_i, sl), sl->y0, sl->y1, sp->width, sp->height, sp->spp, IMG_PF, "-",
                      s->p->lifeline, 1 + (int)sp->integrator, sp->noise_threshold, f->sums, NULL, sp->passes,
                      sp->mlt_norm, sp->mlt_depths};
    const char *cont = cont_file(s, sl);
    char remote[1400];
    int sent = 0;
    if (cont && !*tr_host_workdir(h->tr)) {
        req.continue_from = cont; /* the host sees this machine's files */
    } else if (cont && tr_host_busy_upload(h->tr)) {
        fr_error e;
        remote_name(s, host_i, sl, remote, sizeof remote);
        if (tr_upload(h->tr, cont, remote, 0600, &e) == 0) {
            req.continue_from = "/dev/fd/3";
            sent = 1;
        }
    }
    if (sl->base && !req.continue_from)
        s->st->fresh_instead++;
    proto_argv pa;
    if (proto_slab_argv(&req, &pa, err)) {
        if (sent)
            remove_remote(s, host_i, strdup(remote));
        return -1;
    }
    const char *argv[sizeof pa.argv / sizeof *pa.argv + 6] = {tr_host_worker(h->tr)};
    int k = 1;
    if (sent) {
        argv[0] = "sh";
        argv[k++] = "-c";
        argv[k++] = CONT_SCRIPT;
        argv[k++] = tr_host_worker(h->tr);
        argv[k++] = remote;
    }
    for (int i = 0; pa.argv[i]; i++)
        argv[k++] = pa.argv[i];
    argv[k] = NULL;
    /* The partial image: its header (well under 4 KB), 12 bytes a pixel,
     * the sums or the splats of a bidirectional render. */
    size_t max_out = job_max_partial(sp, sl->y0, sl->y1);
    tr_proc *proc;
    if (tr_spawn(h->tr, argv, max_out, &proc, err)) {
        if (sent)
            remove_remote(s, host_i, strdup(remote));
        return -1;
    }
    if (s->nrun == s->caprun) {
        int cap = s->caprun ? s->caprun * 2 : 16;
        attempt *r = realloc(s->run, (size_t)cap * sizeof *r);
        if (!r) {
            tr_proc_free(proc);
            return fr_fail(err, "out of memory");
        }
        s->run = r;
        s->caprun = cap;
    }
    if (sl->copies) {
        char rows[200];
        s->st->duplicates++;
        h->duplicates++;
        emit(s, SCHED_COPY, host_i, sl, "%s still running; starting a second copy on %s",
             rows_of(s, sl, rows, sizeof rows), h->name);
    }
    s->run[s->nrun++] = (attempt){slab_i, host_i, proc, now(s), req.continue_from ? sl->base : 0,
                                  sent ? strdup(remote) : NULL};
    sl->copies++;
    h->running++;
    return 0;
}

/* Ends attempt r (its process is finished or killed) and removes it.  The
 * sums uploaded for it leave the host: the worker's shell removes them as
 * it starts, but an attempt killed or lost before that leaves them. */
static void finish(sched *s, int r)
{
    attempt *a = &s->run[r];
    if (a->remote) {
        if (tr_proc_state(a->proc) != TR_EXITED || tr_proc_status(a->proc) != 0)
            remove_remote(s, a->host, a->remote);
        else
            free(a->remote);
    }
    if (--s->slabs[a->slab].copies == 0 && !s->slabs[a->slab].done && a->slab < s->next)
        s->next = a->slab; /* back in the queue */
    s->hosts[a->host].running--;
    tr_proc_free(a->proc);
    s->run[r] = s->run[--s->nrun];
}

static void drop_host(sched *s, int host_i, const char *why)
{
    sched_host *h = &s->hosts[host_i];
    if (h->dropped)
        return;
    h->dropped = 1;
    snprintf(h->drop_reason, sizeof h->drop_reason, "%s", why);
    emit(s, SCHED_HOST_DROPPED, host_i, NULL, "dropping host %s: %s", h->name, why);
    for (int r = s->nrun - 1; r >= 0; r--)
        if (s->run[r].host == host_i) {
            tr_proc_kill(s->run[r].proc);
            finish(s, r);
        }
}

/* Notes that slab sl failed on host_i; -1 when out of memory. */
static int note_failed_host(slab *sl, int host_i)
{
    for (int i = 0; i < sl->nfailed; i++)
        if (sl->failed_hosts[i] == host_i)
            return 0;
    int *f = realloc(sl->failed_hosts, (size_t)(sl->nfailed + 1) * sizeof *f);
    if (!f)
        return -1;
    sl->failed_hosts = f;
    sl->failed_hosts[sl->nfailed++] = host_i;
    return 0;
}

/* Whether a host that is ready or still joining has not yet failed sl. */
static int untried_host(const sched *s, const slab *sl)
{
    for (int h = 0; h < s->nhosts; h++) {
        if (s->hosts[h].dropped)
            continue;
        int tried = 0;
        for (int i = 0; i < sl->nfailed && !tried; i++)
            tried = sl->failed_hosts[i] == h;
        if (!tried)
            return 1;
    }
    return 0;
}

static int fail_attempt(sched *s, int r, const char *why, fr_error *err)
{
    attempt a = s->run[r];
    sched_host *h = &s->hosts[a.host];
    slab *sl = &s->slabs[a.slab];
    finish(s, r);
    if (sl->done)
        return 0; /* another copy already won; this one does not matter */
    sl->attempts++;
    sl->failed_on = a.host;
    h->failures++;
    h->streak++;
    s->st->retries++;
    snprintf(sl->last_error, sizeof sl->last_error, "%s: %s", h->name, why);
    char rows[200];
    emit(s, SCHED_SLAB_FAILED, a.host, sl, "%s failed on %s (attempt %d of %d): %s",
         rows_of(s, sl, rows, sizeof rows), h->name, sl->attempts, s->p->max_attempts, why);
    if (note_failed_host(sl, a.host))
        return fr_fail(err, "out of memory");
    /* A slab is given up once it has failed max_attempts times, unless
     * those failures came from fewer than max_attempts hosts and a host it
     * has not failed on is ready or still joining: a few broken hosts that
     * are ready first must not doom the render before a good one joins. */
    if (sl->attempts >= s->p->max_attempts && !sl->copies &&
        (sl->nfailed >= s->p->max_attempts || !untried_host(s, sl)))
        return fr_fail(err, "%s failed %d times, last on %s", rows_of(s, sl, rows, sizeof rows), sl->attempts,
                       sl->last_error);
    if (h->streak >= s->p->max_host_failures) {
        char msg[320];
        snprintf(msg, sizeof msg, "%d failures in a row", h->streak);
        drop_host(s, a.host, msg);
    }
    return 0;
}

static int accept_attempt(sched *s, int r, fr_error *err)
{
    attempt a = s->run[r];
    sched_host *h = &s->hosts[a.host];
    slab *sl = &s->slabs[a.slab];
    frame *fr = &s->frames[sl->frame];
    size_t len;
    const unsigned char *out = tr_proc_output(a.proc, &len);
    fr_error why;
    if (job_check_partial(out, len, &fr->f.spec, sl->y0, sl->y1, fr->f.sums, &why)) {
        char msg[600];
        snprintf(msg, sizeof msg, "bad partial image: %s", why.msg);
        return fail_attempt(s, r, msg, err);
    }
    h->streak = 0;
    if (sl->done) {
        finish(s, r);
        return 0;
    }
    if (job_save(fr->f.jobdir, sl->y0, sl->y1, out, len, err))
        return -1;
    double dt = now(s) - a.start;
    s->acc_s += dt;
    s->acc_rows += (int)(sl->y1 - sl->y0);
    sl->done = 1;
    s->st->samples += (double)(sl->y1 - sl->y0) * fr->f.spec.width * (fr->f.spec.spp - a.from);
    s->st->continued += a.from > 0;
    h->slabs++;
    h->rows += (int)(sl->y1 - sl->y0);
    h->busy_s += dt;
    s->rows_done += (int)(sl->y1 - sl->y0);
    fr->rows_done += (int)(sl->y1 - sl->y0);
    finish(s, r);
    /* First valid copy wins: the others are killed, without blame. */
    for (int k = s->nrun - 1; k >= 0; k--)
        if (s->run[k].slab == a.slab) {
            tr_proc_kill(s->run[k].proc);
            finish(s, k);
        }
    cont_drop(sl);
    char rows[200];
    emit(s, SCHED_SLAB_DONE, a.host, sl, "%s from %s in %.2f s (%d/%d rows)", rows_of(s, sl, rows, sizeof rows),
         h->name, dt, s->rows_done, s->rows_total);
    int fi = sl->frame;
    if (s->frames[fi].rows_done == s->frames[fi].rows_total)
        return frame_done(s, fi, err);
    return 0;
}

static int collect(sched *s, fr_error *err)
{
    for (int r = s->nrun - 1; r >= 0; r--) {
        if (r >= s->nrun)
            continue; /* the list shrank under us (a win killed copies) */
        tr_proc *pr = s->run[r].proc;
        int state = tr_proc_state(pr);
        int rc = 0;
        if (state == TR_RUNNING)
            continue;
        if (state == TR_EXITED && tr_proc_status(pr) == 0) {
            rc = accept_attempt(s, r, err);
        } else {
            char why[600];
            if (state == TR_EXITED)
                snprintf(why, sizeof why, "worker exited with status %d%s%s", tr_proc_status(pr),
                         *tr_proc_reason(pr) ? ": " : "", tr_proc_reason(pr));
            else
                snprintf(why, sizeof why, "%s", tr_proc_reason(pr));
            rc = fail_attempt(s, r, why, err);
        }
        if (rc)
            return -1;
    }
    return 0;
}

/* Slab deadlines.  Once three slabs are accepted, the seconds a row takes
 * one process are known (all hosts together, or the host's own when it is
 * slower); an attempt that runs DEADLINE_FACTOR times longer than its rows
 * should take, plus DEADLINE_SLACK seconds (start-up, a busy machine), is a
 * stuck stream: it is given up as a failure of its host, and the slab goes
 * to another host.  Stragglers short of that get second copies (pick). */
enum { DEADLINE_MIN_SLABS = 3 };
#define DEADLINE_FACTOR 8.0
#define DEADLINE_SLACK 5.0

static double deadline(const sched *s, const attempt *a)
{
    int accepted = 0;
    for (int i = 0; i < s->nhosts; i++)
        accepted += s->hosts[i].slabs;
    if (accepted < DEADLINE_MIN_SLABS || s->acc_rows <= 0)
        return 0;
    double per_row = s->acc_s / s->acc_rows;
    const sched_host *h = &s->hosts[a->host];
    if (h->rows > 0 && h->busy_s / h->rows > per_row)
        per_row = h->busy_s / h->rows;
    const slab *sl = &s->slabs[a->slab];
    return DEADLINE_FACTOR * per_row * (sl->y1 - sl->y0) + DEADLINE_SLACK;
}

static int give_up_stuck(sched *s, fr_error *err)
{
    for (int r = s->nrun - 1; r >= 0; r--) {
        if (r >= s->nrun)
            continue;
        attempt *a = &s->run[r];
        double limit = deadline(s, a), ran = now(s) - a->start;
        if (limit <= 0 || ran <= limit)
            continue;
        char why[200];
        snprintf(why, sizeof why, "no result after %.1f s (the other slabs took %.2f s a row)", ran,
                 s->acc_s / s->acc_rows);
        tr_proc_kill(a->proc);
        if (fail_attempt(s, r, why, err))
            return -1;
    }
    return 0;
}

static int alive_hosts(sched *s)
{
    int n = 0;
    for (int i = 0; i < s->nhosts; i++)
        n += !s->hosts[i].dropped;
    return n;
}

/* The first frame not done (0 when every one is). */
static int first_open_frame(const sched *s)
{
    for (int i = 0; i < s->nframes; i++)
        if (!s->frames[i].done)
            return i;
    return 0;
}

/* The rows frame fi lacks, as job_missing_rows says them. */
static void missing_text(sched *s, int fi, char *out, size_t cap)
{
    const sched_frame *f = &s->frames[fi].f;
    unsigned char *have = calloc(f->spec.height, 1);
    if (!have) {
        snprintf(out, cap, "(unknown)");
        return;
    }
    for (uint32_t y = 0; y < f->spec.height; y++)
        have[y] = f->have && f->have[y];
    for (int i = 0; i < s->nslabs; i++)
        if (s->slabs[i].done && s->slabs[i].frame == fi)
            memset(have + s->slabs[i].y0, 1, s->slabs[i].y1 - s->slabs[i].y0);
    job_missing_rows(have, f->spec.height, out, cap);
    free(have);
}

/* Seconds between two renewals of a host's lease on its scene: well within
 * the ten minutes after which a lease is stale (stage.h). */
enum { LEASE_RENEW_S = 60 };

/* Renews a lease of host i that is due (the host's own, or one of a frame
 * not done), one at a time; frees a renewal that has ended. */
static void lease_tick(sched *s, int i)
{
    sched_host *h = &s->hosts[i];
    if (h->lease_proc && tr_proc_state(h->lease_proc) != TR_RUNNING) {
        tr_proc_free(h->lease_proc);
        h->lease_proc = NULL;
    }
    double t = clock_now();
    if (h->lease_proc || h->dropped || h->pending)
        return;
    const char *lease = NULL;
    double *lease_t = NULL;
    if (h->lease[0] && t - h->lease_t >= LEASE_RENEW_S)
        lease = h->lease, lease_t = &h->lease_t;
    for (int f = 0; !lease && f < s->nframes; f++) {
        frame_host *fh = s->frames[f].fh ? &s->frames[f].fh[i] : NULL;
        if (fh && !s->frames[f].done && fh->staged && fh->lease[0] && t - fh->lease_t >= LEASE_RENEW_S)
            lease = fh->lease, lease_t = &fh->lease_t;
    }
    if (!lease)
        return;
    *lease_t = t;
    const char *argv[] = {"touch", "-c", "--", lease, NULL};
    fr_error e;
    if (tr_spawn(h->tr, argv, 256, &h->lease_proc, &e))
        h->lease_proc = NULL; /* tried again in a minute; a running worker has the scene mapped meanwhile */
}

/* Removes the leases frame fi took on the hosts (stage hook): the run no
 * longer needs its scenes. */
static void release_leases(sched *s, int fi)
{
    frame *fr = &s->frames[fi];
    for (int i = 0; fr->fh && i < s->nhosts; i++) {
        frame_host *fh = &fr->fh[i];
        fr_error ignore;
        if (fh->staged && fh->lease[0] && !s->hosts[i].dropped && s->hosts[i].tr)
            tr_remove(s->hosts[i].tr, fh->lease, &ignore); /* one left behind goes stale in ten minutes */
        fh->lease[0] = 0;
    }
}

/* Every row of frame fi is saved: its leases go and the caller is told. */
static int frame_done(sched *s, int fi, fr_error *err)
{
    frame *fr = &s->frames[fi];
    if (fr->done)
        return 0;
    fr->done = 1;
    s->st->frames_done++;
    release_leases(s, fi);
    const sched_hooks *k = &s->p->hooks;
    return k->frame_done ? k->frame_done(k->ctx, fi, err) : 0;
}

/* Every frame asked for and every row saved. */
static int all_done(const sched *s)
{
    return s->fed_all && s->rows_done >= s->rows_total;
}

static int loop(sched *s, fr_error *err)
{
    struct pollfd *pfd = NULL;
    int cap_pfd = 0;
    int rc = 0;
    while (!all_done(s)) {
        if (s->p->stop && *s->p->stop) {
            rc = fr_fail(err, "interrupted");
            break;
        }
        if (s->p->stop_at > 0 && now(s) >= s->p->stop_at) {
            s->st->timed_out = 1;
            rc = fr_fail(err, "the time limit was reached");
            break;
        }
        admit(s);
        for (int i = 0; i < s->nhosts; i++) {
            sched_host *h = &s->hosts[i];
            lease_tick(s, i);
            /* A renewal holds a channel for a moment: a worker started then
             * could be refused one on a host that takes just its slots. */
            while (!rc && !h->dropped && !h->pending && !h->lease_proc && h->running < h->slots &&
                   now(s) >= h->retry_at) {
                int si = pick(s, i, err);
                if (si == -2)
                    rc = -1;
                if (si < 0)
                    break;
                fr_error e2;
                if (stage(s, i, &s->slabs[si], &e2)) {
                    h->failures++;
                    drop_host(s, i, e2.msg);
                    break;
                }
                if (start(s, i, si, &e2) == 0) {
                    h->start_streak = 0;
                    continue;
                }
                if (h->running > 0) {
                    /* The host takes fewer processes than it has cores (sshd's
                     * MaxSessions, a process limit): use what it takes. */
                    emit(s, SCHED_HOST_SHRUNK, i, NULL, "host %s: cannot start more than %d workers (%s); using %d slots",
                         h->name, h->running, e2.msg, h->running);
                    h->slots = h->running;
                } else if (++h->start_streak >= s->p->max_host_failures) {
                    h->failures++;
                    drop_host(s, i, e2.msg);
                } else {
                    /* The server may still be tearing down the channels of
                     * the set-up (probe, SFTP): try again a little later. */
                    h->failures++;
                    h->retry_at = now(s) + 0.5 * h->start_streak;
                    emit(s, SCHED_HOST_RETRY, i, NULL, "host %s: %s; trying again", h->name, e2.msg);
                }
                break;
            }
        }
        if (rc)
            break;
        if (all_done(s))
            break; /* the last frames came with nothing to render */
        int waiting = pending_hosts(s) > 0;
        for (int i = 0; i < s->nhosts; i++)
            waiting |= !s->hosts[i].dropped && s->hosts[i].retry_at > now(s);
        if (s->nrun == 0 && !waiting) {
            rc = fr_fail(err, alive_hosts(s) ? "nothing left to run" : "no host left to render on");
            break;
        }
        int need = 0;
        for (int i = 0; i < s->nhosts; i++)
            need += s->hosts[i].pending ? 0 : s->hosts[i].slots * 2 + 1;
        if (need > cap_pfd) {
            struct pollfd *np = realloc(pfd, (size_t)need * sizeof *np);
            if (!np) {
                rc = fr_fail(err, "out of memory");
                break;
            }
            pfd = np;
            cap_pfd = need;
        }
        int n = 0;
        for (int i = 0; i < s->nhosts; i++)
            if (!s->hosts[i].dropped && !s->hosts[i].pending)
                n += tr_pollfds(s->hosts[i].tr, pfd + n, cap_pfd - n);
        if (s->p->hooks.wait)
            s->p->hooks.wait(s->p->hooks.ctx, pfd, n, 100);
        else
            poll(pfd, (nfds_t)n, 100);
        for (int i = 0; i < s->nhosts; i++) {
            fr_error e2;
            if (!s->hosts[i].dropped && !s->hosts[i].pending && tr_service(s->hosts[i].tr, &e2))
                drop_host(s, i, e2.msg); /* its slabs go back to the queue, not blamed */
        }
        if (collect(s, err) || give_up_stuck(s, err)) {
            rc = -1;
            break;
        }
        progress(s);
    }
    free(pfd);
    return rc;
}

static void free_all(sched *s)
{
    for (int i = 0; i < s->nslabs; i++) {
        free(s->slabs[i].failed_hosts);
        cont_drop(&s->slabs[i]);
    }
    for (int i = 0; i < s->nframes; i++)
        free(s->frames[i].fh);
    free(s->frames);
    free(s->slabs);
    free(s->run);
}

int sched_run(const sched_params *p, sched_host *hosts, int nhosts, sched_stats *st, fr_error *err)
{
    sched s;
    memset(&s, 0, sizeof s);
    memset(st, 0, sizeof *st);
    s.p = p;
    s.hosts = hosts;
    s.nhosts = nhosts;
    s.st = st;
    s.t0 = now(&s);
    sched_frame first = {p->spec, p->jobdir, p->have, p->base, p->sums, p->label};
    if (add_frame(&s, &first)) {
        free_all(&s);
        return fr_fail(err, "out of memory");
    }
    s.fed_all = !p->hooks.next_frame;
    int rc = s.frames[0].rows_total ? 0 : frame_done(&s, 0, err);
    if (!rc)
        rc = loop(&s, err);
    for (int r = s.nrun - 1; r >= 0; r--) {
        tr_proc_kill(s.run[r].proc);
        finish(&s, r);
    }
    for (int i = 0; i < nhosts; i++) {
        tr_proc_free(hosts[i].lease_proc); /* a renewal cut short is no harm: the lease is a minute old at most */
        hosts[i].lease_proc = NULL;
    }
    remove_leftovers(&s);
    for (int f = 0; f < s.nframes; f++)
        release_leases(&s, f);
    progress(&s);
    if (rc) {
        char missing[400], why[sizeof err->msg];
        snprintf(why, sizeof why, "%s", err->msg);
        int fi = first_open_frame(&s);
        const char *label = s.frames[fi].f.label;
        missing_text(&s, fi, missing, sizeof missing);
        char kept[4400];
        job_kept_note(s.frames[fi].f.jobdir, kept, sizeof kept);
        fr_fail(err, "%s; %s%srows %s not rendered (%s)", why, label ? label : "", label ? " " : "", missing, kept);
    }
    st->wall_s = now(&s) - s.t0;
    free_all(&s);
    return rc;
}
