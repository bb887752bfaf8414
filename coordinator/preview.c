/* preview.c -- the image so far (see preview.h). */
#include "preview.h"

#include <errno.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "output.h"

int preview_image(const char *dir, const job_spec *spec, float *rgb, unsigned char *have, int *skipped, fr_error *err)
{
    int bad = 0;
    int rows = job_gather(dir, spec, rgb, have, &bad, err);
    if (skipped)
        *skipped = bad;
    if (rows < 0)
        return -1;
    /* A whole bidirectional job: the rows with every slab's splats added,
     * as the render's own image has them. */
    if (fr_integrator_splats(spec->integrator) && (uint32_t)rows == spec->height && !bad)
        return job_stitch(dir, spec, rgb, NULL, err) ? -1 : rows;
    for (uint32_t y = 0; y < spec->height; y++) {
        if (have[y])
            continue;
        float *p = rgb + (size_t)y * spec->width * 3;
        for (uint32_t x = 0; x < spec->width; x++, p += 3)
            p[0] = p[1] = p[2] = ((x / PV_CHECKER + y / PV_CHECKER) & 1) ? PV_LIGHT : PV_DARK;
    }
    return rows;
}

struct preview_writer {
    char *path, *dir;
    job_spec spec;
    fr_tonemap tm;
    double period_s;
    note_sink notes;
    float *rgb;
    unsigned char *have;
    pthread_t thread;
    pthread_mutex_t lock;
    pthread_cond_t wake;
    int stop;                  /* under lock */
    int written;
    int failing;               /* the last write failed (said once) */
};

/* One image of the job directory as it is now. */
static void write_once(preview_writer *w)
{
    fr_error err;
    int rows = preview_image(w->dir, &w->spec, w->rgb, w->have, NULL, &err);
    if (rows >= 0 && out_write(w->path, w->rgb, &w->spec, &w->tm, &err) == 0) {
        w->written++;
        w->failing = 0;
        return;
    }
    if (!w->failing)
        note_say(&w->notes, "--preview %s: not written: %s", w->path, err.msg);
    w->failing = 1;
}

static void *run(void *arg)
{
    preview_writer *w = arg;
    pthread_mutex_lock(&w->lock);
    while (!w->stop) {
        pthread_mutex_unlock(&w->lock);
        write_once(w);
        pthread_mutex_lock(&w->lock);
        struct timespec until;
        clock_gettime(CLOCK_MONOTONIC, &until);
        long long ns = (long long)(w->period_s * 1e9);
        until.tv_sec += (time_t)(ns / 1000000000LL);
        until.tv_nsec += (long)(ns % 1000000000LL);
        if (until.tv_nsec >= 1000000000L) {
            until.tv_sec++;
            until.tv_nsec -= 1000000000L;
        }
        while (!w->stop && pthread_cond_timedwait(&w->wake, &w->lock, &until) != ETIMEDOUT)
            ;
    }
    pthread_mutex_unlock(&w->lock);
    return NULL;
}

static void release(preview_writer *w)
{
    free(w->path);
    free(w->dir);
    free(w->rgb);
    free(w->have);
    free(w);
}

preview_writer *preview_start(const char *path, const char *dir, const job_spec *spec, const fr_tonemap *tm, double period_s,
                    note_sink notes, fr_error *err)
{
    preview_writer *w = calloc(1, sizeof *w);
    if (!w) {
        fr_fail(err, "out of memory");
        return NULL;
    }
    w->path = strdup(path);
    w->dir = strdup(dir);
    w->spec = *spec;
    w->tm = *tm;
    w->period_s = period_s > 0.05 ? period_s : 0.05;
    w->notes = notes;
    w->rgb = malloc((size_t)spec->width * spec->height * 3 * sizeof *w->rgb);
    w->have = malloc(spec->height);
    if (!w->path || !w->dir || !w->rgb || !w->have) {
        release(w);
        fr_fail(err, "out of memory for a %ux%u preview", spec->width, spec->height);
        return NULL;
    }
    pthread_condattr_t ca;
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
    pthread_cond_init(&w->wake, &ca);
    pthread_condattr_destroy(&ca);
    pthread_mutex_init(&w->lock, NULL);
    int e = pthread_create(&w->thread, NULL, run, w);
    if (e) {
        pthread_cond_destroy(&w->wake);
        pthread_mutex_destroy(&w->lock);
        release(w);
        fr_fail(err, "cannot start the preview thread: %s", strerror(e));
        return NULL;
    }
    return w;
}

int preview_stop(preview_writer *w)
{
    if (!w)
        return 0;
    pthread_mutex_lock(&w->lock);
    w->stop = 1;
    pthread_cond_signal(&w->wake);
    pthread_mutex_unlock(&w->lock);
    pthread_join(w->thread, NULL);
    write_once(w);
    int n = w->written;
    pthread_cond_destroy(&w->wake);
    pthread_mutex_destroy(&w->lock);
    release(w);
    return n;
}
