/* cluster.c -- connect, probe and stage all hosts in parallel. */
#include "cluster.h"

#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "fbin.h"

typedef struct {
    cl_host *h;
    const tr_options *o;
    const char *scene;
    uint64_t hash;
} job;

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

static void *ready_one(void *arg)
{
    job *j = arg;
    cl_host *h = j->h;
    double t0 = now_s();
    if (tr_connect(h->entry, j->o, &h->tr, &h->err) == 0) {
        if (tr_probe(h->tr, &h->info, &h->err) ||
            (j->scene && tr_stage(h->tr, j->scene, j->hash, h->scene, sizeof h->scene, &h->uploaded, &h->err))) {
            tr_close(h->tr);
            h->tr = NULL;
        }
    }
    h->ready_s = now_s() - t0;
    return NULL;
}

void cl_open(cl_host *hosts, int n, const tr_options *o, const char *scene, uint64_t hash)
{
    pthread_t tid[n > 0 ? n : 1];
    job jobs[n > 0 ? n : 1];
    int started[n > 0 ? n : 1];
    for (int i = 0; i < n; i++) {
        jobs[i] = (job){&hosts[i], o, scene, hash};
        started[i] = pthread_create(&tid[i], NULL, ready_one, &jobs[i]) == 0;
        if (!started[i])
            ready_one(&jobs[i]);
    }
    for (int i = 0; i < n; i++)
        if (started[i])
            pthread_join(tid[i], NULL);
}

/* The N of "... scene-format N", or -1. */
static int scene_format(const char *version)
{
    const char *p = strstr(version, "scene-format ");
    int v;
    return p && sscanf(p + 13, "%d", &v) == 1 ? v : -1;
}

int cl_check_versions(const cl_host *hosts, int n, fr_error *err)
{
    const cl_host *first = NULL;
    for (int i = 0; i < n; i++) {
        const cl_host *h = &hosts[i];
        if (!h->tr)
            continue;
        int fmt = scene_format(h->info.version);
        if (fmt != FBIN_VERSION)
            return fr_fail(err, "host %s: its worker ('%s') does not read scene format %d; install the "
                           "matching build (franja deploy)", h->entry->name, h->info.version, FBIN_VERSION);
        if (!first)
            first = h;
        else if (strcmp(first->info.version, h->info.version))
            return fr_fail(err, "host %s runs '%s' but host %s runs '%s': refusing to mix worker versions",
                           h->entry->name, h->info.version, first->entry->name, first->info.version);
    }
    return 0;
}

void cl_close(cl_host *hosts, int n)
{
    for (int i = 0; i < n; i++) {
        tr_close(hosts[i].tr);
        hosts[i].tr = NULL;
    }
}
