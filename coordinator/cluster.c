/* cluster.c -- connect and prepare all hosts in parallel (see cluster.h). */
#include "cluster.h"

#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "clock.h"
#include "fbin.h"
#include "stage.h"

typedef struct {
    cl_host *h;
    int i;
    tr_options o;              /* the caller's, with notes collected into h */
    cl_step step;
    void *ctx;
} job;

/* Keeps a remark while the threads run; afterwards passes it on. */
static void collect(void *ctx, const char *line)
{
    cl_host *h = ctx;
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
    cl_host *h = j->h;
    double t0 = clk_now();
    if (tr_connect(h->entry, &j->o, &h->tr, &h->err) == 0 && j->step && j->step(h, j->i, j->ctx, &h->err)) {
        tr_close(h->tr);
        h->tr = NULL;
    }
    h->ready_s = clk_now() - t0;
    return NULL;
}

void cl_each(cl_host *hosts, int n, const tr_options *o, cl_step step, void *ctx)
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

static int probe_and_stage(cl_host *h, int i, void *vctx, fr_error *err)
{
    (void)i;
    open_ctx *c = vctx;
    if (stage_probe(h->tr, &h->info, err))
        return -1;
    return c->scene ? stage_scene(h->tr, c->scene, c->hash, h->scene, sizeof h->scene, &h->uploaded, err) : 0;
}

void cl_open(cl_host *hosts, int n, const tr_options *o, const char *scene, uint64_t hash)
{
    open_ctx c = {scene, hash};
    cl_each(hosts, n, o, probe_and_stage, &c);
}

int cl_check_versions(const cl_host *hosts, int n, fr_error *err)
{
    const cl_host *first = NULL;
    for (int i = 0; i < n; i++) {
        const cl_host *h = &hosts[i];
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

void cl_drop_other_versions(cl_host *hosts, int n)
{
    char want[128];
    proto_version_line("franja-worker", want, sizeof want);
    for (int i = 0; i < n; i++) {
        cl_host *h = &hosts[i];
        if (!h->tr || !strcmp(h->info.version, want))
            continue;
        fr_fail(&h->err, "its worker reports '%s', this franja needs '%s'", h->info.version, want);
        tr_close(h->tr);
        h->tr = NULL;
    }
}

void cl_close(cl_host *hosts, int n)
{
    for (int i = 0; i < n; i++) {
        tr_close(hosts[i].tr);
        hosts[i].tr = NULL;
    }
}
