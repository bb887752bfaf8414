/* transport_slurm.c -- worker processes as Slurm job steps in the
 * allocation franja runs in (slurm.h), one step per process:
 *
 *     srun --jobid J --nodes=1 --ntasks=1 --cpus-per-task=1 --mem=0 --quiet
 *          --exclusive --nodelist NODE sh -c START sh ARGV...
 *
 * A step per process rather than one step per node feeding several workers:
 * a slab stays one process, as on the other backends, so the scheduler's
 * retries, straggler copies and kills of single copies work unchanged;
 * each worker is a step that Slurm places on its own CPU (--exclusive),
 * accounts and lists (squeue -s); a node that fails fails only its own
 * steps.  The cost is one srun per slab (a launch is short against slabs
 * of seconds; tests/bench/coord_slurm.sh) and one srun process per
 * running worker on this machine (a few megabytes each), which is fine
 * for hundreds of slots (tests/bench/README.md, "srun's cost").
 * `--mem=0` lets a step use the job's memory on its node without taking it
 * from the other steps; --cpus-per-task=1 overrides one the job was given.
 *
 * Stopping: an srun that gets SIGTERM cancels its step (the task is gone
 * almost at once, as measured in the same section) and exits; after
 * SIGKILL only srun's helper process cancels the step, seconds later, so
 * SIGKILL is sent only to an srun still there long after its SIGTERM, at
 * close.  An srun whose node died may take Slurm's KillWait to exit: such sruns are kept and reaped later
 * instead of blocking the event loop.  Every srun gets SIGTERM from the
 * kernel when franja dies (tr_pipe_spawn_tied): a franja killed by
 * SIGKILL leaves no step running.  Steps are started by the thread that
 * renders (the main one); the short steps of the per-node threads (probes,
 * scene copies) end before their thread. 
 *
 * A lost node: srun reports it ("Node failure on", a failed task launch,
 * or a step that cannot be created on the node any more); service() then
 * says the host is lost, so its slabs go elsewhere without counting
 * against them.  A node that dies silently keeps its sruns waiting until
 * the controller notices (SlurmdTimeout); meanwhile the scheduler's
 * straggler copies finish its slabs elsewhere.  What a lost node does to
 * the job's other CPUs, and the way around it: wait_or_share.
 *
 * Uploads (scenes) are slurm_copy.c's: sbcast to the node, or a copy into
 * a shared work directory. */
#include "transport/transport_backend.h"

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "clock.h"
#include "transport/slurm.h"

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
    place->busy_upload = a->shared; /* a copy here; sbcast would need a step of its own */
    place->link_upload = !a->shared;
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
    fr_error e;
    if (tr_pipe_spawn_tied(p, full, SIGTERM, &e))
        return fr_fail(err, "%s: %s", s->label, e.msg);
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
    s->rec[s->nrec++] = (step_rec){p, copy, clock_now(), shared, 0};
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
    double now = clock_now();
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
    double end = clock_now() + 0.2;
    while (clock_now() < end) {
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
    double end = clock_now() + s->a->timeout_s;
    while (s->nleaving && clock_now() < end) {
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

static int slurm_upload(void *impl, const char *local_path, const char *remote, int mode, fr_error *err)
{
    slurm_host *s = impl;
    return slurm_copy(s->h, s->a, s->node, local_path, remote, mode, err);
}

/* Only a shared work directory is reachable from here without a step. */
static int slurm_remove(void *impl, const char *remote, fr_error *err)
{
    slurm_host *s = impl;
    if (!s->a->shared)
        return fr_fail(err, "%s: a node's own disk is reached only through a job step", tr_host_label(s->h));
    if (unlink(remote) && errno != ENOENT)
        return fr_fail(err, "%s: cannot remove '%s': %s", tr_host_label(s->h), remote, strerror(errno));
    return 0;
}

const tr_backend tr_slurm_backend = {
    .name = "slurm",
    .connect = slurm_connect,
    .spawn = slurm_spawn,
    .upload = slurm_upload,
    .remove = slurm_remove,
    .pollfds = slurm_pollfds,
    .service = slurm_service,
    .kill = slurm_kill,
    .release = slurm_release,
    .close = slurm_host_close,
};
