/* progress.c -- JSON progress events (see progress.h). */
#include "progress.h"

#include <errno.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "clock.h"

struct progress_reporter {
    FILE *out;
    long frame;                /* the frame every event carries; PG_NO_FRAME: none */
    char *dir;                 /* NULL: an animation's own reporter (no thread) */
    job_spec spec;
    uint32_t total;            /* rows the render needs */
    double t0;
    double tp;                 /* when this pass started (t0 without passes) */
    int rows0;                 /* rows done when this run (pass) started */
    int rows;                  /* last count printed */
    uint32_t spp;              /* rows count with this many samples (under lock) */
    pthread_t thread;
    pthread_mutex_t lock;
    pthread_cond_t wake;
    int stop;
};

/* Writes s to out as a JSON string, quoted and escaped. */
static void progress_json_string(FILE *out, const char *s)
{
    fputc('"', out);
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        if (*p == '"' || *p == '\\')
            fprintf(out, "\\%c", *p);
        else if (*p < 0x20)
            fprintf(out, "\\u%04x", *p);
        else
            fputc(*p, out);
    }
    fputc('"', out);
}

/* Starts an event's object: its name, then the frame when it has one. */
static void begin(FILE *out, const char *event, long frame)
{
    fprintf(out, "{\"event\":\"%s\"", event);
    if (frame != PG_NO_FRAME)
        fprintf(out, ",\"frame\":%ld", frame);
}

/* Prints a progress event if the count of finished rows changed. */
static void poll_once(progress_reporter *r)
{
    pthread_mutex_lock(&r->lock);
    uint32_t spp = r->spp;
    pthread_mutex_unlock(&r->lock);
    int rows = job_rows_at(r->dir, spp);
    flockfile(r->out);
    if (rows == r->rows || rows < 0 || spp != r->spp) {
        funlockfile(r->out);
        return;
    }
    r->rows = rows;
    double t = clock_now() - r->t0;
    double tp = clock_now() - r->tp;
    double rate = tp > 0 ? (rows - r->rows0) / tp : 0;
    begin(r->out, "progress", r->frame);
    fprintf(r->out, ",\"rows_done\":%d,\"rows\":%u,\"elapsed_s\":%.3f,\"rows_per_s\":%.3f,\"eta_s\":", rows,
            r->total, t, rate);
    if (rate > 0)
        fprintf(r->out, "%.1f}\n", rows < (int)r->total ? (r->total - (uint32_t)rows) / rate : 0.0);
    else
        fputs("null}\n", r->out);
    fflush(r->out);
    funlockfile(r->out);
}

void progress_event(progress_reporter *r, long frame, const char *what, const char *host, uint32_t y0, uint32_t y1,
              const char *text)
{
    if (!r)
        return;
    flockfile(r->out);
    begin(r->out, "host", frame);
    fputs(",\"what\":", r->out);
    progress_json_string(r->out, what);
    fputs(",\"host\":", r->out);
    progress_json_string(r->out, host);
    fprintf(r->out, ",\"elapsed_s\":%.3f", clock_now() - r->t0);
    if (y1 > y0)
        fprintf(r->out, ",\"y0\":%u,\"y1\":%u", y0, y1);
    fputs(",\"text\":", r->out);
    progress_json_string(r->out, text);
    fputs("}\n", r->out);
    fflush(r->out);
    funlockfile(r->out);
}

static void *run(void *arg)
{
    progress_reporter *r = arg;
    pthread_mutex_lock(&r->lock);
    while (!r->stop) {
        pthread_mutex_unlock(&r->lock);
        poll_once(r);
        pthread_mutex_lock(&r->lock);
        struct timespec until;
        clock_gettime(CLOCK_MONOTONIC, &until);
        until.tv_nsec += 500000000L;
        if (until.tv_nsec >= 1000000000L) {
            until.tv_sec++;
            until.tv_nsec -= 1000000000L;
        }
        while (!r->stop && pthread_cond_timedwait(&r->wake, &r->lock, &until) != ETIMEDOUT)
            ;
    }
    pthread_mutex_unlock(&r->lock);
    return NULL;
}

progress_reporter *progress_start(FILE *out, long frame, const char *output, const char *dir, const job_spec *spec,
                      uint32_t rows, fr_error *err)
{
    progress_reporter *r = calloc(1, sizeof *r);
    if (!r || !(r->dir = strdup(dir))) {
        free(r);
        fr_fail(err, "out of memory");
        return NULL;
    }
    r->out = out;
    r->frame = frame;
    r->spec = *spec;
    r->total = rows;
    r->t0 = r->tp = clock_now();
    r->spp = spec->spp;
    r->rows0 = r->rows = job_rows_at(dir, spec->spp);
    flockfile(out);
    begin(out, "start", frame);
    fputs(",\"output\":", out);
    progress_json_string(out, output);
    fprintf(out, ",\"width\":%u,\"height\":%u,\"spp\":%u,\"rows\":%u,\"rows_done\":%d,\"time\":%lld}\n",
            spec->width, spec->height, spec->spp, rows, r->rows0, (long long)time(NULL));
    fflush(out);
    funlockfile(out);
    pthread_condattr_t ca;
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
    pthread_cond_init(&r->wake, &ca);
    pthread_condattr_destroy(&ca);
    pthread_mutex_init(&r->lock, NULL);
    int e = pthread_create(&r->thread, NULL, run, r);
    if (e) {
        pthread_cond_destroy(&r->wake);
        pthread_mutex_destroy(&r->lock);
        free(r->dir);
        free(r);
        fr_fail(err, "cannot start the progress thread: %s", strerror(e));
        return NULL;
    }
    return r;
}

void progress_pass(progress_reporter *r, int k, uint32_t spp)
{
    if (!r)
        return;
    int rows = job_rows_at(r->dir, spp);
    flockfile(r->out);
    pthread_mutex_lock(&r->lock);
    r->spp = spp;
    pthread_mutex_unlock(&r->lock);
    r->tp = clock_now();
    r->rows0 = r->rows = rows;
    begin(r->out, "pass", r->frame);
    fprintf(r->out, ",\"pass\":%d,\"spp\":%u,\"rows_done\":%d,\"elapsed_s\":%.3f}\n", k, spp, rows, clock_now() - r->t0);
    fflush(r->out);
    funlockfile(r->out);
}

void progress_stop(progress_reporter *r, const char *status, uint32_t spp)
{
    if (!r)
        return;
    pthread_mutex_lock(&r->lock);
    r->stop = 1;
    pthread_cond_signal(&r->wake);
    pthread_mutex_unlock(&r->lock);
    pthread_join(r->thread, NULL);
    flockfile(r->out);
    if (!strcmp(status, "ok") && r->rows != (int)r->total) {
        /* Every row is in the image now, whatever the directory shows. */
        double t = clock_now() - r->t0;
        begin(r->out, "progress", r->frame);
        fprintf(r->out, ",\"rows_done\":%u,\"rows\":%u,\"elapsed_s\":%.3f,\"rows_per_s\":%.3f,\"eta_s\":0}\n", r->total,
                r->total, t, clock_now() > r->tp ? (r->total - (uint32_t)r->rows0) / (clock_now() - r->tp) : 0.0);
        r->rows = (int)r->total;
    } else if (strcmp(status, "ok")) {
        poll_once(r);
    }
    begin(r->out, "done", r->frame);
    fprintf(r->out, ",\"status\":\"%s\",\"spp\":%u,\"rows_done\":%d,\"rows\":%u,\"elapsed_s\":%.3f}\n", status, spp,
            r->rows, r->total, clock_now() - r->t0);
    fflush(r->out);
    funlockfile(r->out);
    pthread_cond_destroy(&r->wake);
    pthread_mutex_destroy(&r->lock);
    free(r->dir);
    free(r);
}

progress_reporter *progress_run_start(FILE *out, const char *list, size_t n, fr_error *err)
{
    progress_reporter *r = calloc(1, sizeof *r);
    if (!r) {
        fr_fail(err, "out of memory");
        return NULL;
    }
    r->out = out;
    r->frame = PG_NO_FRAME;
    r->t0 = r->tp = clock_now();
    flockfile(out);
    fputs("{\"event\":\"frames\",\"list\":", out);
    progress_json_string(out, list);
    fprintf(out, ",\"frames\":%zu,\"time\":%lld}\n", n, (long long)time(NULL));
    fflush(out);
    funlockfile(out);
    return r;
}

void progress_skipped(progress_reporter *r, long frame, const char *output)
{
    if (!r)
        return;
    flockfile(r->out);
    begin(r->out, "skipped", frame);
    fputs(",\"output\":", r->out);
    progress_json_string(r->out, output);
    fputs("}\n", r->out);
    fflush(r->out);
    funlockfile(r->out);
}

void progress_run_end(progress_reporter *r, const char *status, size_t n, size_t rendered, size_t skipped)
{
    if (!r)
        return;
    flockfile(r->out);
    fprintf(r->out, "{\"event\":\"frames_done\",\"status\":\"%s\",\"frames\":%zu,\"rendered\":%zu,\"skipped\":%zu,"
                    "\"elapsed_s\":%.3f}\n",
            status, n, rendered, skipped, clock_now() - r->t0);
    fflush(r->out);
    funlockfile(r->out);
    free(r);
}
