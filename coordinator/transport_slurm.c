/* transport_slurm.c -- worker processes as Slurm job steps in the
 * allocation franja runs in (slurm.h), one step per process:
 *
 *     srun --jobid J --exclusive --nodes=1 --ntasks=1 --cpus-per-task=1
 *          --mem=0 --quiet --nodelist NODE ARGV...
 *
 * A step per process rather than one step per node feeding several workers:
 * a slab stays one process, as on the other backends, so the scheduler's
 * retries, straggler copies and kills of single copies work unchanged;
 * each worker is a step that Slurm places on its own CPU (--exclusive),
 * accounts and lists (squeue -s); a node that fails fails only its own
 * steps.  The cost is one srun per slab (tens of milliseconds against
 * slabs of seconds; tests/bench/coord_slurm.sh) and one srun process per
 * running worker on this machine (about 8 MB), which is fine for hundreds
 * of slots.  `--mem=0` lets a step use the job's memory on its node without
 * taking it from the other steps; --cpus-per-task=1 overrides one the job
 * was given.
 *
 * Stopping: an srun that gets SIGTERM cancels its step (the task is gone
 * within ~40 ms) and exits; SIGKILL would leave the step running, so it is
 * sent only to an srun still there long after its SIGTERM, at close.  An
 * srun whose node died may take Slurm's KillWait to exit: such sruns are
 * kept and reaped later instead of blocking the event loop.
 *
 * A lost node: srun reports it ("Node failure on", a failed task launch,
 * or a step that cannot be created on the node any more); service() then
 * says the host is lost, so its slabs go elsewhere without counting
 * against them.  What that does to the job's other CPUs: wait_or_share.  A node that dies silently keeps its sruns waiting until
 * the controller notices (SlurmdTimeout); meanwhile the scheduler's
 * straggler copies finish its slabs elsewhere.
 *
 * Scenes: with a node-local work directory, one upload is one sbcast to
 * that node alone, through a step held on it (sbcast -j JOB.STEP): the
 * holder creates the directory, sbcast writes a private temporary file,
 * and a last step renames it into place and reports its size.  With a
 * shared work directory the file is copied here, once per run, and every
 * node reads it. */
#include "transport_backend.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "clock.h"
#include "slurm.h"

/* What is needed to start a process's step again (see wait_or_share). */
typedef struct {
    tr_proc *p;
    char **argv;               /* the command after srun's options (owned) */
    double since;              /* when its srun started */
    int shared;                /* started with --overlap */
    int started;               /* its task has started (MARK seen) */
} step_rec;

typedef struct {
    slurm_alloc *a;
    tr_host *h;
    char node[SLURM_NODE_MAX];
    char label[400];
    pid_t leaving[64];         /* sruns told to stop, not yet reaped */
    int nleaving;
    int lost;
    step_rec *rec;
    int nrec, caprec;
} slurm_host;

/* The srun options of every step; the node and the command follow. */
#define STEP_OPTS(job) "--jobid", (job), "--nodes=1", "--ntasks=1", "--cpus-per-task=1", "--mem=0", "--quiet"

/* Every command runs as `sh -c START sh COMMAND...`: the task says on
 * stderr that it has started, then becomes the command (exec), so signals
 * reach it.  srun itself says nothing of a step that waits to be created. */
#define MARK "franja-step-started"
static const char START[] = "printf '" MARK "\\n' >&2; exec \"$@\"";

static int slurm_connect(tr_host *h, void **impl, tr_place *place, fr_error *err)
{
    slurm_alloc *a = tr_host_backend_ctx(h);
    const hosts_entry *e = tr_host_entry(h);
    if (!a)
        return fr_fail(err, "%s: no Slurm allocation", e->name);
    int found = 0;
    for (int i = 0; i < a->n; i++)
        found |= !strcmp(a->node[i], e->address);
    if (!found)
        return fr_fail(err, "%s: not a node of Slurm job %s", e->name, a->job);
    slurm_host *s = calloc(1, sizeof *s);
    if (!s)
        return fr_fail(err, "%s: out of memory", e->name);
    s->a = a;
    s->h = h;
    snprintf(s->node, sizeof s->node, "%s", e->address);
    snprintf(place->label, sizeof place->label, "%s (Slurm job %s)", s->node, a->job);
    snprintf(place->worker, sizeof place->worker, "%s", e->worker[0] ? e->worker : a->worker);
    snprintf(place->workdir, sizeof place->workdir, "%s", e->workdir[0] ? e->workdir : a->workdir);
    snprintf(s->label, sizeof s->label, "%s", place->label);
    *impl = s;
    return 0;
}

/* Starts argv as a step on the node: CPUs of its own (--exclusive), or
 * sharing the job's (--overlap). */
static int start_step(slurm_host *s, tr_proc *p, char *const *argv, int shared, fr_error *err)
{
    const char *full[96] = {"srun", STEP_OPTS(s->a->job), shared ? "--overlap" : "--exclusive", "--nodelist", s->node,
                            "sh", "-c", START, "sh"};
    size_t n = 0;
    while (full[n])
        n++;
    for (size_t i = 0; argv[i]; i++) {
        if (n + 1 >= sizeof full / sizeof *full)
            return fr_fail(err, "%s: too many arguments", s->label);
        full[n++] = argv[i];
    }
    full[n] = NULL;
    if (tr_pipe_spawn(p, full, err))
        return fr_fail(err, "%s: %s", s->label, err->msg);
    return 0;
}

static void free_argv(char **argv)
{
    for (size_t i = 0; argv && argv[i]; i++)
        free(argv[i]);
    free(argv);
}

static int slurm_spawn(void *impl, tr_proc *p, const char *const *argv, fr_error *err)
{
    slurm_host *s = impl;
    if (s->lost)
        return fr_fail(err, "%s: the node has left the allocation", s->label);
    if (s->nrec == s->caprec) {
        int cap = s->caprec ? 2 * s->caprec : 8;
        step_rec *r = realloc(s->rec, (size_t)cap * sizeof *r);
        if (!r)
            return fr_fail(err, "%s: out of memory", s->label);
        s->rec = r;
        s->caprec = cap;
    }
    size_t n = 0;
    while (argv[n])
        n++;
    char **copy = calloc(n + 1, sizeof *copy);
    for (size_t i = 0; copy && i < n; i++)
        if (!(copy[i] = strdup(argv[i]))) {
            free_argv(copy);
            copy = NULL;
        }
    if (!copy)
        return fr_fail(err, "%s: out of memory", s->label);
    int shared = slurm_sharing(s->a);
    if (start_step(s, p, copy, shared, err)) {
        free_argv(copy);
        return -1;
    }
    s->rec[s->nrec++] = (step_rec){p, copy, clk_now(), shared, 0};
    return 0;
}

static step_rec *rec_of(slurm_host *s, const tr_proc *p)
{
    for (int i = 0; i < s->nrec; i++)
        if (s->rec[i].p == p)
            return &s->rec[i];
    return NULL;
}

static int slurm_pollfds(void *impl, tr_proc *procs, struct pollfd *pfd, int max)
{
    (void)impl;
    return tr_pipe_pollfds(procs, pfd, max);
}

/* srun's words for a node that is gone or unusable for this job. */
static int says(const char *err, const char *const *words)
{
    for (; *words; words++)
        if (strstr(err, *words))
            return 1;
    return 0;
}

static const char *const NODE_GONE[] = {"Node failure on", "Application launch failed",
                                        "Requested node configuration is not available", NULL};
/* ... and for a job that has ended (cancelled, out of time). */
static const char *const JOB_GONE[] = {"has expired", "has been revoked", "Invalid job id", NULL};

static void reap(slurm_host *s)
{
    for (int i = s->nleaving - 1; i >= 0; i--) {
        pid_t r = waitpid(s->leaving[i], NULL, WNOHANG);
        if (r == s->leaving[i] || (r < 0 && errno == ECHILD))
            s->leaving[i] = s->leaving[--s->nleaving];
    }
}

/* Fails every running process of the host, which is lost. */
static int lost(slurm_host *s, tr_proc *procs, fr_error *err, const char *fmt, const char *detail)
{
    s->lost = 1;
    fr_fail(err, fmt, s->label, detail);
    for (tr_proc *p = procs; p; p = p->next)
        if (p->state == TR_RUNNING)
            tr_proc_fail(p, "%s", err->msg);
    return -1;
}

/* Sends an srun SIGTERM and keeps it to be reaped, without waiting long. */
static void let_go(slurm_host *s, tr_proc *p);

/* Notes the steps whose task has started, taking the mark out of what
 * their stderr says. */
static void see_starts(slurm_host *s, tr_proc *procs)
{
    for (tr_proc *p = procs; p; p = p->next) {
        step_rec *r = rec_of(s, p);
        char *m = r && !r->started ? strstr(p->err, MARK) : NULL;
        if (!m)
            continue;
        r->started = 1;
        size_t len = strlen(MARK);
        if (m[len] == ' ' || m[len] == '\n')
            len++;
        memmove(m, m + len, strlen(m + len) + 1);
        p->err_len = strlen(p->err);
    }
}

/* Slurm 22.05 keeps, in a job that lost a node (--no-kill), the CPUs of
 * the steps that were running while the node was taken out: they stay
 * counted as used after those steps end, so new --exclusive steps wait
 * for them for ever, silently.  franja never runs more workers on a node
 * than the job has CPUs there, so a step not started after the time-out
 * is such a one: it is started again with --overlap (sharing the job's
 * CPUs instead of taking its own), and so is every step after it.  The
 * waiting step never ran its command, so nothing is lost or run twice. */
static void wait_or_share(slurm_host *s, tr_proc *procs)
{
    double now = clk_now();
    for (tr_proc *p = procs; p; p = p->next) {
        step_rec *r = p->state == TR_RUNNING ? rec_of(s, p) : NULL;
        if (!r || r->started || r->shared || now - r->since < s->a->timeout_s)
            continue;
        if (!slurm_sharing(s->a)) {
            slurm_share(s->a);
            tr_note(s->h, "Slurm job %s starts no new step on CPUs of its own after %d s (it lost a node, "
                          "and keeps the CPUs of steps that ran then); from now on steps share the job's "
                          "CPUs (srun --overlap)", s->a->job, s->a->timeout_s);
        }
        let_go(s, p);
        p->err_len = 0;
        p->err[0] = 0;
        fr_error e;
        r->since = now;
        r->shared = 1;
        if (start_step(s, p, r->argv, 1, &e))
            tr_proc_fail(p, "%s", e.msg);
    }
}

static int slurm_service(void *impl, tr_proc *procs, fr_error *err)
{
    slurm_host *s = impl;
    reap(s);
    tr_pipe_service(procs);
    see_starts(s, procs);
    if (slurm_job_ended(s->a, 0))
        return lost(s, procs, err, "%s: %s", "the Slurm job has ended (cancelled, or out of time)");
    /* Processes that ended by themselves (those killed here are TR_FAILED):
     * srun's last words say whether the node or the whole job is gone. */
    for (tr_proc *p = procs; p; p = p->next) {
        if (p->state != TR_EXITED || !p->impl)
            continue;
        if (says(p->err, NODE_GONE))
            return lost(s, procs, err, "%s: the node is lost to the job (%s)", p->err);
        if ((says(p->err, JOB_GONE) || strstr(p->err, "CANCELLED")) && slurm_job_ended(s->a, 1))
            return lost(s, procs, err, "%s: %s", "the Slurm job has ended (cancelled, or out of time)");
    }
    wait_or_share(s, procs);
    return 0;
}

static void slurm_kill(void *impl, tr_proc *p)
{
    (void)impl;
    tr_pipe_signal(p, SIGTERM);
}

static void let_go(slurm_host *s, tr_proc *p)
{
    tr_pipe_signal(p, SIGTERM);
    pid_t pid = tr_pipe_detach(p);
    if (pid <= 0)
        return;
    /* Most sruns leave within tens of milliseconds of their SIGTERM. */
    double end = clk_now() + 0.2;
    while (clk_now() < end) {
        if (waitpid(pid, NULL, WNOHANG) == pid)
            return;
        usleep(5000);
    }
    if (s->nleaving < (int)(sizeof s->leaving / sizeof *s->leaving)) {
        s->leaving[s->nleaving++] = pid;
        return;
    }
    kill(pid, SIGKILL);
    waitpid(pid, NULL, 0);
}

static void slurm_release(void *impl, tr_proc *p)
{
    slurm_host *s = impl;
    step_rec *r = rec_of(s, p);
    if (r) {
        free_argv(r->argv);
        *r = s->rec[--s->nrec];
    }
    if (p->impl)
        let_go(s, p);
}

static void slurm_host_close(void *impl)
{
    slurm_host *s = impl;
    double end = clk_now() + s->a->timeout_s;
    while (s->nleaving && clk_now() < end) {
        reap(s);
        if (s->nleaving)
            usleep(20000);
    }
    for (int i = 0; i < s->nleaving; i++) {
        kill(s->leaving[i], SIGKILL);
        waitpid(s->leaving[i], NULL, 0);
    }
    for (int i = 0; i < s->nrec; i++)
        free_argv(s->rec[i].argv);
    free(s->rec);
    free(s);
}

/* Runs a step on the node to completion: its stdout into out[cap]. */
static int step(slurm_host *s, const char *const *argv, char *out, size_t cap, fr_error *err)
{
    tr_proc *p;
    if (tr_run(s->h, argv, 65536, 3 * s->a->timeout_s, &p, err))
        return -1;
    int rc = 0;
    if (tr_proc_state(p) != TR_EXITED || tr_proc_status(p) != 0)
        rc = fr_fail(err, "%s: %s failed: %s", s->label, argv[0], tr_proc_reason(p));
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
    char dir[PATH_MAX], tmp[PATH_MAX + 64];
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
    snprintf(tmp, sizeof tmp, "%s/.%s.%ld.tmp", dir, slash + 1, (long)getpid());
    int in = open(src, O_RDONLY | O_CLOEXEC);
    if (in < 0)
        return fr_fail(err, "%s: %s", src, strerror(errno));
    int out = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, mode);
    if (out < 0) {
        close(in);
        return fr_fail(err, "%s: %s", tmp, strerror(errno));
    }
    char buf[1 << 16];
    ssize_t n;
    int rc = 0;
    while ((n = read(in, buf, sizeof buf)) > 0)
        if (write(out, buf, (size_t)n) != n) {
            rc = fr_fail(err, "%s: %s", tmp, strerror(errno));
            break;
        }
    if (n < 0 && !rc)
        rc = fr_fail(err, "%s: %s", src, strerror(errno));
    if ((fchmod(out, (mode_t)mode) || fsync(out)) && !rc)
        rc = fr_fail(err, "%s: %s", tmp, strerror(errno));
    if (close(out) && !rc)
        rc = fr_fail(err, "%s: %s", tmp, strerror(errno));
    close(in);
    if (!rc && rename(tmp, dst))
        rc = fr_fail(err, "%s: %s", dst, strerror(errno));
    if (rc)
        unlink(tmp);
    return rc;
}

/* The shared work directory: the first node to need the file copies it. */
static int upload_shared(slurm_host *s, const char *local_path, const char *remote, int mode, fr_error *err)
{
    slurm_alloc *a = s->a;
    pthread_mutex_lock(&a->lock);
    int done = 0;
    for (int i = 0; i < a->ncopied; i++)
        done |= !strcmp(a->copied[i], remote);
    int rc = done ? 0 : copy_local(local_path, remote, mode, err);
    if (!done && !rc && a->ncopied < (int)(sizeof a->copied / sizeof *a->copied))
        snprintf(a->copied[a->ncopied++], sizeof a->copied[0], "%s", remote);
    pthread_mutex_unlock(&a->lock);
    return rc ? fr_fail(err, "%s: copying to the shared work directory: %s", s->label, err->msg) : 0;
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
static int held_step(slurm_host *s, tr_proc *p, char *stepid, size_t cap, fr_error *err)
{
    double end = clk_now() + 3 * s->a->timeout_s;
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
                return fr_fail(err, "%s: unexpected answer from the holding step: %s", s->label, line);
            snprintf(stepid, cap, "%lu.%lu", j, st);
            return 0;
        }
        if (tr_proc_state(p) != TR_RUNNING)
            return fr_fail(err, "%s: cannot hold a step on the node: %s", s->label, tr_proc_reason(p));
        if (clk_now() > end)
            return fr_fail(err, "%s: no step could be started on the node within %d s", s->label,
                           3 * s->a->timeout_s);
        struct pollfd pfd[16];
        int n = tr_pollfds(s->h, pfd, 16);
        poll(pfd, (nfds_t)n, 20);
        fr_error e2;
        if (tr_service(s->h, &e2))
            return fr_fail(err, "%s", e2.msg);
    }
}

static int slurm_upload(void *impl, const char *local_path, const char *remote, int mode, fr_error *err)
{
    slurm_host *s = impl;
    if (s->a->shared)
        return upload_shared(s, local_path, remote, mode, err);
    struct stat st;
    if (stat(local_path, &st))
        return fr_fail(err, "%s: %s", local_path, strerror(errno));
    char dir[1024], tmp[1200], stepid[64], modes[16], got[64];
    snprintf(dir, sizeof dir, "%s", remote);
    char *slash = strrchr(dir, '/');
    if (!slash || remote[0] != '/')
        return fr_fail(err, "%s: %s: the work directory on the nodes must be an absolute path", s->label, remote);
    *slash = 0;
    snprintf(tmp, sizeof tmp, "%s/.%s.%s.%ld.tmp", dir, slash + 1, s->node, (long)getpid());
    snprintf(modes, sizeof modes, "%o", mode & 07777);
    const char *hold[] = {"sh", "-c", HOLD, "sh", dir, NULL};
    tr_proc *holder;
    if (tr_spawn(s->h, hold, 4096, &holder, err))
        return -1;
    int rc = held_step(s, holder, stepid, sizeof stepid, err);
    if (rc == 0) {
        char to[16];
        snprintf(to, sizeof to, "%d", s->a->timeout_s);
        const char *bcast[] = {"sbcast", "--force", "--timeout", to, "--jobid", stepid, local_path, tmp, NULL};
        /* As long as the copy takes: a big scene on a slow link is no hang. */
        rc = tr_pipe_run(bcast, 3600, err);
        if (rc)
            fr_fail(err, "%s: sbcast to the node failed: %s", s->label, err->msg);
    }
    tr_proc_free(holder); /* ends the holding step */
    if (rc)
        return -1;
    const char *place[] = {"sh", "-c", PLACE, "sh", tmp, remote, modes, NULL};
    if (step(s, place, got, sizeof got, err))
        return -1;
    char *end;
    unsigned long long size = strtoull(got, &end, 10);
    if (end == got || (*end && *end != '\n') || size != (unsigned long long)st.st_size)
        return fr_fail(err, "%s: %s arrived with %s bytes instead of %lld", s->label, remote, got,
                       (long long)st.st_size);
    return 0;
}

const tr_backend tr_slurm_backend = {
    .name = "slurm",
    .connect = slurm_connect,
    .spawn = slurm_spawn,
    .upload = slurm_upload,
    .pollfds = slurm_pollfds,
    .service = slurm_service,
    .kill = slurm_kill,
    .release = slurm_release,
    .close = slurm_host_close,
};
