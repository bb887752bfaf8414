/* fakehost.c -- scripted in-process hosts for the scheduler's tests (see
 * fakehost.h). */
#include "fakehost.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image.h"
#include "protocol.h"

typedef struct {
    fake_world *w;
    int i;                     /* index of the host in w */
    int nspawned;              /* processes started on it so far */
    int lost;
} fake_host;

typedef struct {
    int rec;                   /* index into w->spawn */
    double end;                /* when it ends (virtual) */
    int fails, hangs;
    fake_lie lie;
} fake_proc;

float fake_pixel(uint32_t x, uint32_t y, int c) { return (float)(y * 1000 + x) + 0.25f * (float)c; }

static int partial(const fake_world *w, uint64_t hash, uint32_t y0, uint32_t y1, unsigned char **buf, size_t *len)
{
    size_t n = (size_t)w->width * (y1 - y0) * 3;
    float *rgb = malloc((n ? n : 1) * sizeof *rgb);
    if (!rgb)
        return -1;
    for (uint32_t y = y0; y < y1; y++)
        for (uint32_t x = 0; x < w->width; x++)
            for (int c = 0; c < 3; c++)
                rgb[((size_t)(y - y0) * w->width + x) * 3 + (size_t)c] = fake_pixel(x, y, c);
    char *mem = NULL;
    size_t mlen = 0;
    FILE *f = open_memstream(&mem, &mlen);
    int rc = -1;
    if (f) {
        img_partial_info info = {.scene = hash, .y0 = y0, .y1 = y1, .spp = w->spp, .width = w->width,
                                 .height = w->height};
        fr_error err;
        rc = img_write(f, IMG_PF, &info, rgb, NULL, &err);
        if (fclose(f))
            rc = -1;
    }
    free(rgb);
    if (rc) {
        free(mem);
        return -1;
    }
    *buf = (unsigned char *)mem;
    *len = mlen;
    return 0;
}

int fake_partial(const fake_world *w, uint32_t y0, uint32_t y1, unsigned char **buf, size_t *len)
{
    return partial(w, w->hash, y0, y1, buf, len);
}

double fake_now(void *ctx) { return ((fake_world *)ctx)->now; }

int fake_wait(void *ctx, struct pollfd *pfd, int n, int ms)
{
    (void)pfd, (void)n;
    ((fake_world *)ctx)->now += ms / 1000.0;
    return 0;
}

static int fake_connect(tr_host *h, void **impl, tr_place *place, fr_error *err)
{
    fake_world *w = tr_host_backend_ctx(h);
    const char *name = tr_host_entry(h)->name;
    for (int i = 0; i < w->nhosts; i++)
        if (!strcmp(w->host[i].name, name)) {
            fake_host *fh = calloc(1, sizeof *fh);
            if (!fh)
                return fr_fail(err, "%s: out of memory", name);
            fh->w = w;
            fh->i = i;
            w->connected[i] = 1;
            snprintf(place->label, sizeof place->label, "%s (fake)", name);
            snprintf(place->worker, sizeof place->worker, "franja-worker");
            place->workdir[0] = 0;
            *impl = fh;
            return 0;
        }
    return fr_fail(err, "%s: no such fake host", name);
}

static int fake_spawn_proc(void *impl, tr_proc *p, const char *const *argv, fr_error *err)
{
    fake_host *fh = impl;
    fake_world *w = fh->w;
    fake_script *s = &w->host[fh->i];
    if (fh->lost)
        return fr_fail(err, "%s: connection lost", s->name);
    if (s->refuse_all || (s->max_procs && w->running[fh->i] >= s->max_procs)) {
        w->refused[fh->i]++;
        return fr_fail(err, "%s: channel refused", s->name);
    }
    int argc = 0;
    while (argv[argc])
        argc++;
    proto_request r;
    if (proto_parse_args(argc, (char *const *)argv, &r, err) || r.mode != PROTO_RENDER)
        return fr_fail(err, "%s: not a slab command line", s->name);
    if (w->nspawn >= FAKE_MAX_SPAWNS)
        return fr_fail(err, "%s: too many processes for the test", s->name);
    fake_proc *fp = calloc(1, sizeof *fp);
    if (!fp)
        return fr_fail(err, "%s: out of memory", s->name);
    int k = fh->nspawned++;
    double d = k < 16 && s->durations[k] > 0 ? s->durations[k] : s->duration > 0 ? s->duration : 1.0;
    fp->rec = w->nspawn++;
    fp->end = w->now + d;
    fp->fails = s->fail_always || k < s->fail_first;
    fp->hangs = s->hang;
    fp->lie = s->lie;
    w->spawn[fp->rec] = (fake_spawn){fh->i, r.slab.y0, r.slab.y1, w->now, 0, 0, 0, ""};
    snprintf(w->spawn[fp->rec].scene, sizeof w->spawn[fp->rec].scene, "%s", r.slab.scene);
    if (++w->running[fh->i] > w->peak[fh->i])
        w->peak[fh->i] = w->running[fh->i];
    p->impl = fp;
    p->state = TR_RUNNING;
    return 0;
}

static int fake_upload(void *impl, const char *local_path, const char *remote, int mode, fr_error *err)
{
    (void)impl, (void)local_path, (void)mode;
    return fr_fail(err, "%s: fake hosts take no files", remote);
}

static int fake_pollfds(void *impl, tr_proc *procs, struct pollfd *pfd, int max)
{
    (void)impl, (void)procs, (void)pfd, (void)max;
    return 0;
}

/* The process ends: out of the running count, with an outcome. */
static void end(fake_host *fh, fake_proc *fp, int outcome)
{
    fake_spawn *rec = &fh->w->spawn[fp->rec];
    if (rec->outcome)
        return;
    rec->outcome = outcome;
    rec->end = fh->w->now;
    fh->w->running[fh->i]--;
}

static void answer(fake_host *fh, tr_proc *p, fake_proc *fp)
{
    fake_world *w = fh->w;
    const fake_spawn *rec = &w->spawn[fp->rec];
    if (fp->fails) {
        tr_proc_add_err(p, "scripted failure\n", 17);
        p->status = 1;
        p->state = TR_EXITED;
        end(fh, fp, 2);
        return;
    }
    uint32_t y0 = rec->y0, y1 = rec->y1;
    uint64_t hash = w->hash;
    if (fp->lie == FAKE_WRONG_ROWS && y1 < w->height)
        y0++, y1++;
    if (fp->lie == FAKE_WRONG_SCENE)
        hash ^= 1;
    unsigned char *buf;
    size_t len;
    if (partial(w, hash, y0, y1, &buf, &len)) {
        tr_proc_fail(p, "fake host out of memory");
        end(fh, fp, 3);
        return;
    }
    if (fp->lie == FAKE_TRUNCATED)
        len /= 2;
    if (tr_proc_add_out(p, buf, len) == 0) {
        p->status = 0;
        p->state = TR_EXITED;
    }
    free(buf);
    end(fh, fp, 1);
}

static int fake_service(void *impl, tr_proc *procs, fr_error *err)
{
    fake_host *fh = impl;
    fake_world *w = fh->w;
    const fake_script *s = &w->host[fh->i];
    if (!fh->lost && s->die_at > 0 && w->now >= s->die_at) {
        fh->lost = 1;
        for (tr_proc *p = procs; p; p = p->next)
            if (p->state == TR_RUNNING && p->impl) {
                tr_proc_fail(p, "%s: connection lost (scripted)", s->name);
                end(fh, p->impl, 3);
            }
        return fr_fail(err, "%s: connection lost (scripted)", s->name);
    }
    if (fh->lost)
        return fr_fail(err, "%s: connection lost", s->name);
    for (tr_proc *p = procs; p; p = p->next) {
        fake_proc *fp = p->impl;
        if (p->state == TR_RUNNING && fp && !fp->hangs && w->now >= fp->end)
            answer(fh, p, fp);
    }
    return 0;
}

static void fake_kill(void *impl, tr_proc *p)
{
    fake_host *fh = impl;
    fake_proc *fp = p->impl;
    if (!fp || fh->w->spawn[fp->rec].outcome)
        return;
    fh->w->spawn[fp->rec].killed = 1;
    end(fh, fp, 3);
}

static void fake_release(void *impl, tr_proc *p)
{
    fake_kill(impl, p);
    free(p->impl);
    p->impl = NULL;
}

static void fake_close(void *impl)
{
    fake_host *fh = impl;
    fh->w->connected[fh->i] = 0;
    free(fh);
}

const tr_backend fake_backend = {
    .name = "fake",
    .connect = fake_connect,
    .spawn = fake_spawn_proc,
    .upload = fake_upload,
    .pollfds = fake_pollfds,
    .service = fake_service,
    .kill = fake_kill,
    .release = fake_release,
    .close = fake_close,
};
