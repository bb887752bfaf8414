/* transport_local.c -- the local backend: worker processes on this machine
 * (tr_pipe_*), which sees this machine's files, so nothing is uploaded. */
#include "transport/transport_backend.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int local_connect(tr_host *h, void **impl, tr_place *place, fr_error *err)
{
    const hosts_entry *e = tr_host_entry(h);
    const char *w = e->worker[0] ? e->worker : tr_host_options(h)->local_worker;
    if (!w || !*w)
        return fr_fail(err, "%s: no worker binary known (give worker= in the host table)", e->name);
    if (access(w, X_OK))
        return fr_fail(err, "%s: worker '%s' cannot be run: %s (build it with make, or give worker=)", e->name, w,
                       strerror(errno));
    /* A name without a slash is a file here, as access() took it, not a
     * program to look for in PATH. */
    snprintf(place->worker, sizeof place->worker, "%s%s", strchr(w, '/') ? "" : "./", w);
    snprintf(place->label, sizeof place->label, "%s", e->name);
    place->workdir[0] = 0;
    *impl = NULL;
    return 0;
}

static int local_spawn(void *impl, tr_proc *p, const char *const *argv, fr_error *err)
{
    (void)impl;
    return tr_pipe_spawn(p, argv, err);
}

static int local_upload(void *impl, const char *local_path, const char *remote, int mode, fr_error *err)
{
    (void)impl, (void)local_path, (void)mode;
    return fr_fail(err, "%s: a local host uses this machine's files; nothing to upload", remote);
}

static int local_pollfds(void *impl, tr_proc *procs, struct pollfd *pfd, int max)
{
    (void)impl;
    return tr_pipe_pollfds(procs, pfd, max);
}

static int local_service(void *impl, tr_proc *procs, fr_error *err)
{
    (void)impl, (void)err;
    tr_pipe_service(procs);
    return 0;
}

static void local_kill(void *impl, tr_proc *p)
{
    (void)impl;
    tr_pipe_kill(p);
}

static void local_release(void *impl, tr_proc *p)
{
    (void)impl;
    tr_pipe_release(p);
}

static void local_close(void *impl) { (void)impl; }

const tr_backend tr_local_backend = {
    .name = "local",
    .connect = local_connect,
    .spawn = local_spawn,
    .upload = local_upload,
    .pollfds = local_pollfds,
    .service = local_service,
    .kill = local_kill,
    .release = local_release,
    .close = local_close,
};
