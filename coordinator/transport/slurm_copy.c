/* slurm_copy.c -- a file to one node of the Slurm job (slurm_copy in
 * slurm.h), for the Slurm backend's uploads (scenes).
 *
 * Node-local work directory: sbcast sends to the nodes of a job or of one
 * of its steps, so the copy holds a step on the node (a shell that creates
 * the directory, checks that it and its parent are the user's own, prints
 * its step and sleeps), sends the file to that step's node alone with
 * `sbcast --jobid JOB.STEP` under a private temporary name, ends the
 * holder, and renames the file into place in a last step that reports the
 * size that arrived.  Nodes are staged in parallel (one thread each), each
 * on its own, so a slow or dead node delays only itself.
 *
 * Shared work directory: the file is copied here, under a private name and
 * renamed, once per run; the nodes that ask later find it done. */
#include "transport/slurm.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "clock.h"
#include "file.h"
#include "transport/transport_backend.h"

/* Runs a step on the node to completion: its stdout into out[cap]. */
static int step(tr_host *h, int timeout_s, const char *const *argv, char *out, size_t cap, fr_error *err)
{
    tr_proc *p;
    if (tr_run(h, argv, 65536, 3 * timeout_s, &p, err))
        return -1;
    int rc = 0;
    if (tr_proc_state(p) != TR_EXITED || tr_proc_status(p) != 0)
        rc = fr_fail(err, "%s: %s failed: %s", tr_host_label(h), argv[0], tr_proc_reason(p));
    else if (out) {
        size_t len;
        const unsigned char *o = tr_proc_output(p, &len);
        if (len >= cap)
            len = cap - 1;
        memcpy(out, o, len);
        out[len] = 0;
    }
    tr_proc_free(p);
    return rc;
}

/* Copies src to dst here, through a private temporary name. */
static int copy_local(const char *src, const char *dst, int mode, fr_error *err)
{
    char dir[PATH_MAX];
    snprintf(dir, sizeof dir, "%s", dst);
    char *slash = strrchr(dir, '/');
    if (!slash || slash == dir)
        return fr_fail(err, "%s: not an absolute path", dst);
    *slash = 0;
    for (char *c = dir + 1; *c; c++)
        if (*c == '/') {
            *c = 0;
            if (mkdir(dir, 0755) && errno != EEXIST)
                return fr_fail(err, "%s: %s", dir, strerror(errno));
            *c = '/';
        }
    if (mkdir(dir, 0755) && errno != EEXIST)
        return fr_fail(err, "%s: %s", dir, strerror(errno));
    file_out out;
    if (file_out_open(dst, &out, err))
        return -1;
    int rc = file_out_copy(&out, src, err);
    if (!rc && fchmod(out.fd, (mode_t)mode))
        rc = fr_fail(err, "%s: %s", out.tmp, strerror(errno));
    if (rc) {
        file_out_abort(&out);
        return -1;
    }
    return file_out_commit(&out, dst, err);
}

/* The shared work directory: the first node to need the file copies it. */
static int copy_shared(tr_host *h, slurm_alloc *a, const char *local_path, const char *remote, int mode,
                       fr_error *err)
{
    pthread_mutex_lock(&a->lock);
    int done = 0;
    for (int i = 0; i < a->ncopied; i++)
        done |= !strcmp(a->copied[i], remote);
    fr_error e;
    int rc = done ? 0 : copy_local(local_path, remote, mode, &e);
    if (!done && !rc && a->ncopied < (int)(sizeof a->copied / sizeof *a->copied))
        snprintf(a->copied[a->ncopied++], sizeof a->copied[0], "%s", remote);
    pthread_mutex_unlock(&a->lock);
    return rc ? fr_fail(err, "%s: copying to the shared work directory: %s", tr_host_label(h), e.msg) : 0;
}

/* `sh -c HOLD sh DIR`: creates the directory (which must be this user's,
 * and so its parent: /tmp is everyone's), says which step holds the node,
 * and waits to be cancelled. */
static const char HOLD[] =
    "mkdir -p -- \"$1\" || exit 1; "
    "if [ ! -O \"$1\" ] || [ ! -O \"${1%/*}\" ]; then echo \"$1: not this user's directory\" >&2; exit 1; fi; "
    "echo \"step $SLURM_JOB_ID.$SLURM_STEP_ID\" && exec sleep 3600";

/* `sh -c PLACE sh TMP DEST MODE`: puts the broadcast copy in place. */
static const char PLACE[] = "chmod \"$3\" \"$1\" && mv -f -- \"$1\" \"$2\" && wc -c < \"$2\"";

/* Waits until the holder printed its step, or ended. */
static int held_step(tr_host *h, int timeout_s, tr_proc *p, char *stepid, size_t cap, fr_error *err)
{
    double end = clock_now() + 3 * timeout_s;
    for (;;) {
        size_t len;
        const char *o = (const char *)tr_proc_output(p, &len);
        const char *nl = len ? memchr(o, '\n', len) : NULL;
        if (nl) {
            unsigned long j, st;
            char extra;
            char line[128];
            snprintf(line, sizeof line, "%.*s", (int)(nl - o), o);
            if (sscanf(line, "step %lu.%lu%c", &j, &st, &extra) != 2)
                return fr_fail(err, "%s: unexpected answer from the holding step: %s", tr_host_label(h), line);
            snprintf(stepid, cap, "%lu.%lu", j, st);
            return 0;
        }
        if (tr_proc_state(p) != TR_RUNNING)
            return fr_fail(err, "%s: cannot hold a step on the node: %s", tr_host_label(h), tr_proc_reason(p));
        if (clock_now() > end)
            return fr_fail(err, "%s: no step could be started on the node within %d s", tr_host_label(h),
                           3 * timeout_s);
        struct pollfd pfd[16];
        int n = tr_pollfds(h, pfd, 16);
        poll(pfd, (nfds_t)n, 20);
        fr_error e2;
        if (tr_service(h, &e2))
            return fr_fail(err, "%s", e2.msg);
    }
}

int slurm_copy(tr_host *h, slurm_alloc *a, const char *node, const char *local_path, const char *remote, int mode,
               fr_error *err)
{
    if (a->shared)
        return copy_shared(h, a, local_path, remote, mode, err);
    struct stat st;
    if (stat(local_path, &st))
        return fr_fail(err, "%s: %s", local_path, strerror(errno));
    char dir[1024], tmp[1200], stepid[64], modes[16], got[64];
    snprintf(dir, sizeof dir, "%s", remote);
    char *slash = strrchr(dir, '/');
    if (!slash || remote[0] != '/')
        return fr_fail(err, "%s: %s: the work directory on the nodes must be an absolute path", tr_host_label(h),
                       remote);
    *slash = 0;
    snprintf(tmp, sizeof tmp, "%s/.%s.%s.%ld.tmp", dir, slash + 1, node, (long)getpid());
    snprintf(modes, sizeof modes, "%o", mode & 07777);
    const char *hold[] = {"sh", "-c", HOLD, "sh", dir, NULL};
    tr_proc *holder;
    if (tr_spawn(h, hold, 4096, &holder, err))
        return -1;
    int rc = held_step(h, a->timeout_s, holder, stepid, sizeof stepid, err);
    if (rc == 0) {
        char to[16];
        snprintf(to, sizeof to, "%d", a->timeout_s);
        const char *bcast[] = {"sbcast", "--force", "--timeout", to, "--jobid", stepid, local_path, tmp, NULL};
        /* As long as the copy takes: a big scene on a slow link is no hang. */
        fr_error e;
        rc = tr_pipe_run(bcast, 3600, NULL, &e);
        if (rc)
            fr_fail(err, "%s: sbcast to the node failed: %s", tr_host_label(h), e.msg);
    }
    tr_proc_free(holder); /* ends the holding step */
    if (rc)
        return -1;
    const char *place[] = {"sh", "-c", PLACE, "sh", tmp, remote, modes, NULL};
    if (step(h, a->timeout_s, place, got, sizeof got, err))
        return -1;
    char *end;
    unsigned long long size = strtoull(got, &end, 10);
    if (end == got || (*end && *end != '\n') || size != (unsigned long long)st.st_size)
        return fr_fail(err, "%s: %s arrived with %s bytes instead of %lld", tr_host_label(h), remote, got,
                       (long long)st.st_size);
    return 0;
}
