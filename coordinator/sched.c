/* sched.c -- the slab queue and the event loop that drives every worker
 * process (see sched.h for the rules). */
#include "sched.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "protocol.h"

typedef struct {
    uint32_t y0, y1;
    int done;
    int attempts;              /* failed attempts so far */
    int copies;                /* processes running it now */
    char last_error[300];
} slab;

typedef struct {
    int slab, host;
    tr_proc *proc;
    double start;
} attempt;

typedef struct {
    const sched_params *p;
    sched_host *hosts;
    int nhosts;
    slab *slabs;
    int nslabs, next;          /* next: first slab that may still be queued */
    attempt *run;
    int nrun, caprun;
    int rows_total, rows_done;
    sched_stats *st;
    double t0, last_draw;
    int drawn;                 /* a progress line is on screen */
} sched;

/* Messages go to stderr, after clearing the live line if one is shown. */
static void say(sched *s, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void say(sched *s, const char *fmt, ...)
{
    if (s->drawn) {
        fputs("\r\033[K", stderr);
        s->drawn = 0;
    }
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "franja: [%6.1fs] ", clk_now() - s->t0);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

/* "rows 120/512 (23%)  ETA 40s  1.20 Msamples/s  alpha:8/8 3.1r/s ..." */
static void progress_text(sched *s, double t, char *line, size_t cap)
{
    double el = t - s->t0;
    double rate = el > 0 ? s->rows_done / el : 0;
    int n = snprintf(line, cap, "rows %d/%d (%3.0f%%)", s->rows_done, s->rows_total,
                     s->rows_total ? 100.0 * s->rows_done / s->rows_total : 100.0);
    if (rate > 0 && s->rows_done < s->rows_total)
        n += snprintf(line + n, cap - (size_t)n, "  ETA %.0fs", (s->rows_total - s->rows_done) / rate);
    n += snprintf(line + n, cap - (size_t)n, "  %.2f Msamples/s ", rate * s->p->spec.width * s->p->spec.spp / 1e6);
    for (int i = 0; i < s->nhosts && n < (int)cap - 40; i++) {
        sched_host *h = &s->hosts[i];
        if (h->dropped)
            n += snprintf(line + n, cap - (size_t)n, " %s:down", h->name);
        else
            n += snprintf(line + n, cap - (size_t)n, " %s:%d/%d %.1fr/s", h->name, h->running, h->slots,
                          el > 0 ? h->rows / el : 0.0);
    }
}

/* Progress: a live line on a terminal (4 times a second); otherwise (a
 * batch job's log) a plain line every LOG_EVERY seconds and at the end. */
enum { LOG_EVERY = 10 };

static void draw(sched *s, int force)
{
    double t = clk_now();
    double every = s->p->tty ? 0.25 : LOG_EVERY;
    if (!force && t - s->last_draw < every)
        return;
    s->last_draw = t;
    char line[1024];
    progress_text(s, t, line, sizeof line);
    if (!s->p->tty) {
        say(s, "%s", line);
        return;
    }
    fprintf(stderr, "\r\033[K%s", line);
    fflush(stderr);
    s->drawn = 1;
}

static int make_slabs(sched *s)
{
    const sched_params *p = s->p;
    int slots = 0;
    for (int i = 0; i < s->nhosts; i++)
        if (!s->hosts[i].dropped)
            slots += s->hosts[i].slots;
    uint32_t missing = 0;
    for (uint32_t y = 0; y < p->spec.height; y++)
        missing += !(p->have && p->have[y]);
    uint32_t per = p->slab_rows > 0 ? (uint32_t)p->slab_rows : 0;
    if (!per) {
        uint32_t want = (uint32_t)(slots > 0 ? slots : 1) * 4;
        per = (missing + want - 1) / want;
        if (per < 1)
            per = 1;
    }
    s->slabs = calloc(missing ? missing : 1, sizeof *s->slabs);
    if (!s->slabs)
        return -1;
    for (uint32_t y = 0; y < p->spec.height;) {
        if (p->have && p->have[y]) {
            y++;
            continue;
        }
        uint32_t end = y;
        while (end < p->spec.height && !(p->have && p->have[end]) && end - y < per)
            end++;
        s->slabs[s->nslabs++] = (slab){.y0 = y, .y1 = end};
        y = end;
    }
    s->rows_total = (int)missing;
    return 0;
}

static int running_on(sched *s, int slab_i, int host_i)
{
    for (int i = 0; i < s->nrun; i++)
        if (s->run[i].slab == slab_i && s->run[i].host == host_i)
            return 1;
    return 0;
}

/* The next queued slab, else the longest-running slab with one copy (a
 * straggler), preferring those not already running on this host. */
static int pick(sched *s, int host_i)
{
    while (s->next < s->nslabs && (s->slabs[s->next].done || s->slabs[s->next].copies))
        s->next++;
    for (int i = s->next; i < s->nslabs; i++)
        if (!s->slabs[i].done && !s->slabs[i].copies)
            return i;
    int best = -1, best_here = 1;
    double best_t = 0;
    for (int r = 0; r < s->nrun; r++) {
        int si = s->run[r].slab;
        if (s->slabs[si].done || s->slabs[si].copies != 1)
            continue;
        int here = running_on(s, si, host_i);
        if (best < 0 || here < best_here || (here == best_here && s->run[r].start < best_t)) {
            best = si;
            best_here = here;
            best_t = s->run[r].start;
        }
    }
    return best;
}

static int start(sched *s, int host_i, int slab_i, fr_error *err)
{
    sched_host *h = &s->hosts[host_i];
    slab *sl = &s->slabs[slab_i];
    const job_spec *sp = &s->p->spec;
    proto_slab req = {h->scene, sl->y0, sl->y1, sp->width, sp->height, sp->spp, IMG_PF, "-"};
    proto_argv pa;
    if (proto_slab_argv(&req, &pa, err))
        return -1;
    const char *argv[18] = {tr_host_worker(h->tr)};
    for (int i = 0; pa.argv[i]; i++)
        argv[i + 1] = pa.argv[i];
    /* The partial image: its header (well under 4 KB) and 12 bytes a pixel. */
    size_t max_out = 4096 + (size_t)sp->width * (sl->y1 - sl->y0) * 12;
    tr_proc *proc;
    if (tr_spawn(h->tr, argv, max_out, &proc, err))
        return -1;
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
        s->st->duplicates++;
        h->duplicates++;
        if (!s->p->tty)
            say(s, "rows %u:%u still running; starting a second copy on %s", sl->y0, sl->y1, h->name);
    }
    s->run[s->nrun++] = (attempt){slab_i, host_i, proc, clk_now()};
    sl->copies++;
    h->running++;
    return 0;
}

/* Ends attempt r (its process is finished or killed) and removes it. */
static void finish(sched *s, int r)
{
    attempt *a = &s->run[r];
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
    say(s, "dropping host %s: %s", h->name, why);
    for (int r = s->nrun - 1; r >= 0; r--)
        if (s->run[r].host == host_i) {
            tr_proc_kill(s->run[r].proc);
            finish(s, r);
        }
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
    h->failures++;
    h->streak++;
    s->st->retries++;
    snprintf(sl->last_error, sizeof sl->last_error, "%s: %s", h->name, why);
    say(s, "rows %u:%u failed on %s (attempt %d of %d): %s", sl->y0, sl->y1, h->name, sl->attempts,
        s->p->max_attempts, why);
    if (sl->attempts >= s->p->max_attempts && !sl->copies)
        return fr_fail(err, "rows %u:%u failed %d times, last on %s", sl->y0, sl->y1, sl->attempts,
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
    size_t len;
    const unsigned char *out = tr_proc_output(a.proc, &len);
    fr_error why;
    if (job_check_partial(out, len, &s->p->spec, sl->y0, sl->y1, &why)) {
        char msg[600];
        snprintf(msg, sizeof msg, "bad partial image: %s", why.msg);
        return fail_attempt(s, r, msg, err);
    }
    h->streak = 0;
    if (sl->done) {
        finish(s, r);
        return 0;
    }
    if (job_save(s->p->jobdir, sl->y0, sl->y1, out, len, err))
        return -1;
    double dt = clk_now() - a.start;
    sl->done = 1;
    h->slabs++;
    h->rows += (int)(sl->y1 - sl->y0);
    h->busy_s += dt;
    s->rows_done += (int)(sl->y1 - sl->y0);
    finish(s, r);
    /* First valid copy wins: the others are killed, without blame. */
    for (int k = s->nrun - 1; k >= 0; k--)
        if (s->run[k].slab == a.slab) {
            tr_proc_kill(s->run[k].proc);
            finish(s, k);
        }
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

static int alive_hosts(sched *s)
{
    int n = 0;
    for (int i = 0; i < s->nhosts; i++)
        n += !s->hosts[i].dropped;
    return n;
}

static void missing_text(sched *s, char *out, size_t cap)
{
    unsigned char *have = calloc(s->p->spec.height, 1);
    if (!have) {
        snprintf(out, cap, "(unknown)");
        return;
    }
    for (uint32_t y = 0; y < s->p->spec.height; y++)
        have[y] = s->p->have && s->p->have[y];
    for (int i = 0; i < s->nslabs; i++)
        if (s->slabs[i].done)
            memset(have + s->slabs[i].y0, 1, s->slabs[i].y1 - s->slabs[i].y0);
    job_missing_rows(have, s->p->spec.height, out, cap);
    free(have);
}

static int loop(sched *s, fr_error *err)
{
    struct pollfd *pfd = NULL;
    int cap_pfd = 0;
    int rc = 0;
    while (s->rows_done < s->rows_total) {
        if (*s->p->stop) {
            rc = fr_fail(err, "interrupted");
            break;
        }
        for (int i = 0; i < s->nhosts; i++) {
            sched_host *h = &s->hosts[i];
            while (!h->dropped && h->running < h->slots && clk_now() >= h->retry_at) {
                int si = pick(s, i);
                if (si < 0)
                    break;
                fr_error e2;
                if (start(s, i, si, &e2) == 0) {
                    h->start_streak = 0;
                    continue;
                }
                if (h->running > 0) {
                    /* The host takes fewer processes than it has cores (sshd's
                     * MaxSessions, a process limit): use what it takes. */
                    say(s, "host %s: cannot start more than %d workers (%s); using %d slots", h->name,
                        h->running, e2.msg, h->running);
                    h->slots = h->running;
                } else if (++h->start_streak >= s->p->max_host_failures) {
                    h->failures++;
                    drop_host(s, i, e2.msg);
                } else {
                    /* The server may still be tearing down the channels of
                     * the set-up (probe, SFTP): try again a little later. */
                    h->failures++;
                    h->retry_at = clk_now() + 0.5 * h->start_streak;
                    say(s, "host %s: %s; trying again", h->name, e2.msg);
                }
                break;
            }
        }
        int waiting = 0;
        for (int i = 0; i < s->nhosts; i++)
            waiting |= !s->hosts[i].dropped && s->hosts[i].retry_at > clk_now();
        if (s->nrun == 0 && !waiting) {
            rc = fr_fail(err, alive_hosts(s) ? "nothing left to run" : "no host left to render on");
            break;
        }
        int need = 0;
        for (int i = 0; i < s->nhosts; i++)
            need += s->hosts[i].slots * 2 + 1;
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
            if (!s->hosts[i].dropped)
                n += tr_pollfds(s->hosts[i].tr, pfd + n, cap_pfd - n);
        poll(pfd, (nfds_t)n, 100);
        for (int i = 0; i < s->nhosts; i++) {
            fr_error e2;
            if (!s->hosts[i].dropped && tr_service(s->hosts[i].tr, &e2))
                drop_host(s, i, e2.msg); /* its slabs go back to the queue, not blamed */
        }
        if (collect(s, err)) {
            rc = -1;
            break;
        }
        draw(s, 0);
    }
    free(pfd);
    return rc;
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
    s.t0 = s.last_draw = clk_now();
    if (make_slabs(&s))
        return fr_fail(err, "out of memory");
    st->slabs = s.nslabs;
    int rc = loop(&s, err);
    for (int r = s.nrun - 1; r >= 0; r--) {
        tr_proc_kill(s.run[r].proc);
        finish(&s, r);
    }
    draw(&s, 1);
    if (s.drawn)
        fputc('\n', stderr);
    if (rc) {
        char missing[400], why[sizeof err->msg];
        snprintf(why, sizeof why, "%s", err->msg);
        missing_text(&s, missing, sizeof missing);
        char kept[4400];
        job_kept_note(p->jobdir, kept, sizeof kept);
        fr_fail(err, "%s; rows %s not rendered (%s)", why, missing, kept);
    }
    st->wall_s = clk_now() - s.t0;
    free(s.slabs);
    free(s.run);
    return rc;
}
