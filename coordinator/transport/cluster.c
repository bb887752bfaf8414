/* cluster.c -- connect and prepare all hosts in parallel (see cluster.h). */
#include "transport/cluster.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "clock.h"
#include "fbin.h"
#include "transport/stage.h"

typedef struct {
    cluster_host *h;
    int i;
    tr_options o;              /* the caller's, with notes collected into h */
    cluster_step step;
    void *ctx;
} job;

/* Keeps a remark while the threads run; afterwards passes it on. */
static void collect(void *ctx, const char *line)
{
    cluster_host *h = ctx;
    if (h->forward) {
        note_say(h->forward, "%s", line);
        return;
    }
    int n = snprintf(h->notes + h->notes_len, sizeof h->notes - h->notes_len, "%s\n", line);
    if (n > 0)
        h->notes_len += (size_t)n < sizeof h->notes - h->notes_len ? (size_t)n : sizeof h->notes - h->notes_len - 1;
}

static void *ready_one(void *arg)
{
    job *j = arg;
    cluster_host *h = j->h;
    double t0 = clock_now();
    if (tr_connect(h->entry, &j->o, &h->tr, &h->err) == 0 && j->step && j->step(h, j->i, j->ctx, &h->err)) {
        tr_close(h->tr);
        h->tr = NULL;
    }
    h->ready_s = clock_now() - t0;
    return NULL;
}

void cluster_each(cluster_host *hosts, int n, const tr_options *o, cluster_step step, void *ctx)
{
    pthread_t tid[n > 0 ? n : 1];
    job jobs[n > 0 ? n : 1];
    int started[n > 0 ? n : 1];
    for (int i = 0; i < n; i++) {
        hosts[i].notes_len = 0;
        hosts[i].notes[0] = 0;
        hosts[i].forward = NULL;
        jobs[i] = (job){&hosts[i], i, *o, step, ctx};
        jobs[i].o.notes = (note_sink){collect, &hosts[i]};
        started[i] = pthread_create(&tid[i], NULL, ready_one, &jobs[i]) == 0;
        if (!started[i])
            ready_one(&jobs[i]);
    }
    for (int i = 0; i < n; i++)
        if (started[i])
            pthread_join(tid[i], NULL);
    for (int i = 0; i < n; i++) {
        for (char *line = hosts[i].notes, *nl; (nl = strchr(line, '\n')); line = nl + 1) {
            *nl = 0;
            note_say(&o->notes, "%s", line);
        }
        hosts[i].notes_len = 0;
        hosts[i].forward = &o->notes;
    }
}

typedef struct {
    const char *scene;
    uint64_t hash;
} open_ctx;

int cluster_stage(tr_host *tr, const hosts_entry *entry, const char *scene, uint64_t hash, const stage_patch *patch,
                  char *remote, size_t cap, char *lease, size_t lease_cap, uint64_t *sent, fr_error *err)
{
    if (stage_scene(tr, scene, hash, patch, remote, cap, lease, lease_cap, sent, err))
        return -1;
    /* The cache stays bounded; a failure to trim it does not stop the render. */
    uint64_t limit = entry->cache ? entry->cache : HOSTS_CACHE_DEFAULT, bytes;
    int removed;
    fr_error e;
    if (stage_evict(tr, remote, limit, &removed, &bytes, &e))
        tr_note(tr, "%s", e.msg);
    else if (removed) {
        char lim[32], gone[32];
        hosts_format_size(limit, lim);
        hosts_format_size(bytes, gone);
        tr_note(tr, "scene cache over its limit (%s): removed %d least recently used scene%s (%s)", lim, removed,
                removed == 1 ? "" : "s", gone);
    }
    return 0;
}

static int probe_and_stage(cluster_host *h, int i, void *vctx, fr_error *err)
{
    (void)i;
    open_ctx *c = vctx;
    if (stage_probe(h->tr, &h->info, err))
        return -1;
    if (!c->scene)
        return 0;
    return cluster_stage(h->tr, h->entry, c->scene, c->hash, NULL, h->scene, sizeof h->scene, h->lease, sizeof h->lease,
                    &h->sent, err);
}

void cluster_open(cluster_host *hosts, int n, const tr_options *o, const char *scene, uint64_t hash)
{
    open_ctx c = {scene, hash};
    cluster_each(hosts, n, o, probe_and_stage, &c);
}

int cluster_check_versions(const cluster_host *hosts, int n, fr_error *err)
{
    const cluster_host *first = NULL;
    for (int i = 0; i < n; i++) {
        const cluster_host *h = &hosts[i];
        if (!h->tr)
            continue;
        proto_version v;
        fr_error e;
        if (proto_parse_version(h->info.version, &v, &e) || v.scene_format != FBIN_VERSION)
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

int cluster_check_version(cluster_host *h)
{
    char want[128];
    proto_version_line("franja-worker", want, sizeof want);
    if (!h->tr || !strcmp(h->info.version, want))
        return 0;
    fr_fail(&h->err, "its worker reports '%s', this franja needs '%s'", h->info.version, want);
    tr_close(h->tr);
    h->tr = NULL;
    return -1;
}

void cluster_drop_other_versions(cluster_host *hosts, int n)
{
    for (int i = 0; i < n; i++)
        cluster_check_version(&hosts[i]);
}

/* One host of a group: its thread's own copy of everything it touches. */
typedef struct {
    cluster_group *g;
    int i;
    hosts_entry entry;
    cluster_host host;
    tr_options o;
    int done;                  /* the thread has finished (under g->mu) */
    int handed;                /* given to the caller */
} cluster_slot;

struct cluster_group {
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int n, refs, ended;
    note_sink notes;           /* the caller's */
    open_ctx ctx;
    char scene[4096];
    pthread_t *tid;
    int *started;
    cluster_slot *slot;
};

static void group_free(cluster_group *g)
{
    pthread_mutex_destroy(&g->mu);
    pthread_cond_destroy(&g->cv);
    free(g->tid);
    free(g->started);
    free(g->slot);
    free(g);
}

/* Drops one reference (under g->mu); frees the group with the last. */
static void group_unref(cluster_group *g)
{
    int last = --g->refs == 0;
    pthread_mutex_unlock(&g->mu);
    if (last)
        group_free(g);
}

static void *prepare(void *arg)
{
    cluster_slot *s = arg;
    cluster_group *g = s->g;
    job j = {&s->host, s->i, s->o, probe_and_stage, &g->ctx};
    ready_one(&j);
    pthread_mutex_lock(&g->mu);
    s->done = 1;
    if (g->ended && !s->handed && s->host.tr) {
        /* Abandoned: nobody will use it. */
        tr_close(s->host.tr);
        s->host.tr = NULL;
    }
    pthread_cond_broadcast(&g->cv);
    group_unref(g);
    return NULL;
}

cluster_group *cluster_start(const cluster_host *hosts, int n, const tr_options *o, const char *scene, uint64_t hash)
{
    cluster_group *g = calloc(1, sizeof *g);
    if (!g)
        return NULL;
    g->tid = calloc((size_t)(n > 0 ? n : 1), sizeof *g->tid);
    g->started = calloc((size_t)(n > 0 ? n : 1), sizeof *g->started);
    g->slot = calloc((size_t)(n > 0 ? n : 1), sizeof *g->slot);
    if (!g->tid || !g->started || !g->slot || (scene && strlen(scene) >= sizeof g->scene)) {
        free(g->tid);
        free(g->started);
        free(g->slot);
        free(g);
        return NULL;
    }
    pthread_mutex_init(&g->mu, NULL);
    pthread_cond_init(&g->cv, NULL);
    g->n = n;
    g->notes = o->notes;
    if (scene)
        snprintf(g->scene, sizeof g->scene, "%s", scene);
    g->ctx = (open_ctx){scene ? g->scene : NULL, hash};
    g->refs = 1;
    for (int i = 0; i < n; i++) {
        cluster_slot *s = &g->slot[i];
        s->g = g;
        s->i = i;
        s->entry = *hosts[i].entry;
        s->host = (cluster_host){.entry = &s->entry};
        s->o = *o;
        s->o.notes = (note_sink){collect, &s->host};
    }
    pthread_mutex_lock(&g->mu);
    for (int i = 0; i < n; i++) {
        g->refs++;
        g->started[i] = pthread_create(&g->tid[i], NULL, prepare, &g->slot[i]) == 0;
        if (!g->started[i]) {
            /* No thread: this host is prepared later, in cluster_next_ready. */
            g->refs--;
        }
    }
    pthread_mutex_unlock(&g->mu);
    return g;
}

static int cluster_pending_locked(const cluster_group *g)
{
    int n = 0;
    for (int i = 0; i < g->n; i++)
        n += !g->slot[i].handed;
    return n;
}

int cluster_pending(cluster_group *g)
{
    pthread_mutex_lock(&g->mu);
    int n = cluster_pending_locked(g);
    pthread_mutex_unlock(&g->mu);
    return n;
}

int cluster_end(cluster_group *g, int wait)
{
    if (!g)
        return 0;
    if (wait)
        for (int i = 0; i < g->n; i++)
            if (g->started[i])
                pthread_join(g->tid[i], NULL);
    pthread_mutex_lock(&g->mu);
    int abandoned = 0;
    g->ended = 1;
    for (int i = 0; i < g->n; i++) {
        cluster_slot *s = &g->slot[i];
        if (s->handed)
            continue;
        if (s->done || !g->started[i]) {
            tr_close(s->host.tr); /* ended, never handed over */
            s->host.tr = NULL;
        } else {
            abandoned++;
        }
    }
    if (!wait)
        for (int i = 0; i < g->n; i++)
            if (g->started[i])
                pthread_detach(g->tid[i]);
    group_unref(g);
    return abandoned;
}

static int take(cluster_group *g, cluster_host *out)
{
    for (int i = 0; i < g->n; i++) {
        cluster_slot *s = &g->slot[i];
        if (s->handed || !(s->done || !g->started[i]))
            continue;
        if (!g->started[i]) {
            job j = {&s->host, i, s->o, probe_and_stage, &g->ctx};
            pthread_mutex_unlock(&g->mu);
            ready_one(&j);
            pthread_mutex_lock(&g->mu);
            s->done = 1;
        }
        s->handed = 1;
        for (char *line = s->host.notes, *nl; (nl = strchr(line, '\n')); line = nl + 1) {
            *nl = 0;
            note_say(&g->notes, "%s", line);
        }
        s->host.notes_len = 0;
        s->host.forward = &g->notes;
        *out = s->host;
        return i;
    }
    return -1;
}

int cluster_next_ready(cluster_group *g, cluster_host *out, int ms)
{
    pthread_mutex_lock(&g->mu);
    int i = take(g, out);
    if (i < 0 && ms > 0) {
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        ts.tv_sec += ms / 1000;
        ts.tv_nsec += (long)(ms % 1000) * 1000000L;
        if (ts.tv_nsec >= 1000000000L) {
            ts.tv_sec++;
            ts.tv_nsec -= 1000000000L;
        }
        while (i < 0 && cluster_pending_locked(g) && pthread_cond_timedwait(&g->cv, &g->mu, &ts) == 0)
            i = take(g, out);
        if (i < 0)
            i = take(g, out);
    }
    pthread_mutex_unlock(&g->mu);
    return i;
}

void cluster_close(cluster_host *hosts, int n)
{
    for (int i = 0; i < n; i++) {
        tr_close(hosts[i].tr);
        hosts[i].tr = NULL;
    }
}
