/* slurm.c -- the allocation franja runs in, from the job's environment
 * (see slurm.h). */
#include "transport/slurm.h"

#include <pwd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "transport/transport_backend.h"

int slurm_parse_cpus(const char *s, int n, int *cpus, fr_error *err)
{
    const char *v = "SLURM_JOB_CPUS_PER_NODE";
    int k = 0;
    const char *p = s;
    for (;;) {
        const char *item = p;
        long c = 0, rep = 1;
        if (*p < '0' || *p > '9')
            return fr_fail(err, "%s='%s': expected a CPU count at offset %d", v, s, (int)(p - s));
        for (; *p >= '0' && *p <= '9'; p++)
            if (c <= HOSTS_MAX_CORES)
                c = c * 10 + (*p - '0');
        if (c < 1 || c > HOSTS_MAX_CORES)
            return fr_fail(err, "%s='%s': CPU count at offset %d is not in 1..%d", v, s, (int)(item - s),
                           HOSTS_MAX_CORES);
        if (p[0] == '(') {
            if (p[1] != 'x' || p[2] < '1' || p[2] > '9')
                return fr_fail(err, "%s='%s': expected (xN) at offset %d", v, s, (int)(p - s));
            p += 2;
            rep = 0;
            for (; *p >= '0' && *p <= '9'; p++)
                if (rep <= n)
                    rep = rep * 10 + (*p - '0');
            if (*p++ != ')')
                return fr_fail(err, "%s='%s': expected ')' at offset %d", v, s, (int)(p - 1 - s));
        }
        if (rep > n - k)
            return fr_fail(err, "%s='%s' describes more than the %d nodes of SLURM_JOB_NODELIST", v, s, n);
        for (long i = 0; i < rep; i++)
            cpus[k++] = (int)c;
        if (*p == 0)
            break;
        if (*p++ != ',')
            return fr_fail(err, "%s='%s': expected ',' at offset %d", v, s, (int)(p - 1 - s));
    }
    if (k != n)
        return fr_fail(err, "%s='%s' describes %d nodes, SLURM_JOB_NODELIST has %d", v, s, k, n);
    return 0;
}

/* A node name goes into srun's -w and into messages: letters, digits and
 * . _ - only. */
static int good_node(const char *s, size_t len)
{
    if (len == 0 || len >= SLURM_NODE_MAX)
        return 0;
    for (size_t i = 0; i < len; i++)
        if (!strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-", s[i]))
            return 0;
    return 1;
}

static int nodes_from(const char *list, int timeout_s, slurm_alloc *a, fr_error *err)
{
    const char *argv[] = {"scontrol", "show", "hostnames", list, NULL};
    char *text;
    fr_error e;
    if (tr_pipe_run(argv, timeout_s, &text, &e))
        return fr_fail(err, "cannot expand SLURM_JOB_NODELIST='%s': %s", list, e.msg);
    /* One name a line; the last line may lack its newline. */
    int n = 0;
    for (const char *c = text; *c; c++)
        n += *c == '\n' || c[1] == '\0';
    if (n == 0 || n > 1000000) {
        free(text);
        return fr_fail(err, "SLURM_JOB_NODELIST='%s' names no node", list);
    }
    a->node = calloc((size_t)n, sizeof *a->node);
    if (!a->node) {
        free(text);
        return fr_fail(err, "out of memory for %d nodes", n);
    }
    int k = 0;
    for (char *l = text; *l && k < n;) {
        char *e = strchr(l, '\n');
        size_t len = e ? (size_t)(e - l) : strlen(l);
        if (!good_node(l, len)) {
            fr_fail(err, "SLURM_JOB_NODELIST='%s': unexpected node name '%.*s' from scontrol", list,
                    (int)(len < 80 ? len : 80), l);
            free(text);
            return -1;
        }
        memcpy(a->node[k++], l, len);
        l += len + (e != NULL);
    }
    free(text);
    a->n = k;
    return 0;
}

int slurm_open(slurm_alloc *a, const char *worker, int timeout_s, fr_error *err)
{
    memset(a, 0, sizeof *a);
    pthread_mutex_init(&a->lock, NULL);
    a->timeout_s = timeout_s > 0 ? timeout_s : 10;
    const char *job = getenv("SLURM_JOB_ID");
    const char *list = getenv("SLURM_JOB_NODELIST");
    const char *cpus = getenv("SLURM_JOB_CPUS_PER_NODE");
    const char *step = getenv("SLURM_STEP_ID");
    if (!job || !*job)
        return fr_fail(err, "not inside a Slurm allocation (SLURM_JOB_ID is not set)");
    if (strspn(job, "0123456789") != strlen(job) || strlen(job) >= sizeof a->job)
        return fr_fail(err, "SLURM_JOB_ID='%s' is not a job number", job);
    if (step && *step)
        return fr_fail(err, "running inside job step %s.%s, which holds the CPUs the workers need; run "
                       "franja directly in the allocation (after salloc, or in the batch script, without srun)",
                       job, step);
    if (!list || !*list || !cpus || !*cpus)
        return fr_fail(err, "job %s: SLURM_JOB_NODELIST or SLURM_JOB_CPUS_PER_NODE is not set", job);
    snprintf(a->job, sizeof a->job, "%s", job);
    if (nodes_from(list, a->timeout_s, a, err))
        return -1;
    a->cpus = calloc((size_t)a->n, sizeof *a->cpus);
    if (!a->cpus)
        return fr_fail(err, "out of memory");
    if (slurm_parse_cpus(cpus, a->n, a->cpus, err))
        return -1;
    struct passwd *pw = getpwuid(getuid());
    if (pw && good_node(pw->pw_name, strlen(pw->pw_name)))
        snprintf(a->workdir, sizeof a->workdir, "/tmp/franja-%s", pw->pw_name);
    else
        snprintf(a->workdir, sizeof a->workdir, "/tmp/franja-%u", (unsigned)getuid());
    if (!worker || worker[0] != '/')
        return fr_fail(err, "no worker program beside this franja to run on the nodes");
    snprintf(a->worker, sizeof a->worker, "%s", worker);
    return 0;
}

int slurm_job_ended(slurm_alloc *a, int ask)
{
    pthread_mutex_lock(&a->lock);
    int ended = a->ended;
    pthread_mutex_unlock(&a->lock);
    if (ended || !ask)
        return ended;
    const char *argv[] = {"squeue", "--noheader", "--jobs", a->job, "--format", "%T", NULL};
    char *text;
    fr_error e;
    if (tr_pipe_run(argv, a->timeout_s, &text, &e)) {
        /* squeue fails for a job the controller no longer knows. */
        ended = strstr(e.msg, "Invalid job id") != NULL;
    } else {
        static const char *const alive[] = {"RUNNING", "SUSPENDED", "CONFIGURING", "RESIZING"};
        ended = 1;
        for (size_t i = 0; i < sizeof alive / sizeof *alive; i++)
            if (!strncmp(text, alive[i], strlen(alive[i])))
                ended = 0;
        free(text);
    }
    pthread_mutex_lock(&a->lock);
    a->ended |= ended;
    pthread_mutex_unlock(&a->lock);
    return ended;
}

int slurm_sharing(slurm_alloc *a)
{
    pthread_mutex_lock(&a->lock);
    int v = a->sharing;
    pthread_mutex_unlock(&a->lock);
    return v;
}

void slurm_share(slurm_alloc *a)
{
    pthread_mutex_lock(&a->lock);
    a->sharing = 1;
    pthread_mutex_unlock(&a->lock);
}

void slurm_close(slurm_alloc *a)
{
    free(a->node);
    free(a->cpus);
    pthread_mutex_destroy(&a->lock);
    a->node = NULL;
    a->cpus = NULL;
    a->n = 0;
}

int slurm_hosts(const slurm_alloc *a, hosts_table *t, fr_error *err)
{
    memset(t, 0, sizeof *t);
    t->v = calloc((size_t)a->n, sizeof *t->v);
    if (!t->v)
        return fr_fail(err, "out of memory");
    t->n = a->n;
    snprintf(t->path, sizeof t->path, "(Slurm job %s)", a->job);
    for (int i = 0; i < a->n; i++) {
        hosts_entry *e = &t->v[i];
        snprintf(e->name, sizeof e->name, "%s", a->node[i]);
        snprintf(e->address, sizeof e->address, "%s", a->node[i]);
        snprintf(e->worker, sizeof e->worker, "%s", a->worker);
        snprintf(e->workdir, sizeof e->workdir, "%s", a->workdir);
        e->cores = a->cpus[i];
    }
    return 0;
}

/* Appends s to out (bounded), shell-quoted when it needs quoting. */
static void add_word(char *out, size_t cap, const char *s)
{
    size_t n = strlen(out);
    if (n && n + 1 < cap)
        out[n++] = ' ', out[n] = 0;
    char q[1024];
    fr_error e;
    int plain = *s && strspn(s, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-/=:,+@%") == strlen(s);
    if (plain)
        snprintf(out + n, cap - n, "%s", s);
    else if (tr_shell_quote(s, q, sizeof q, &e) == 0)
        snprintf(out + n, cap - n, "%s", q);
    else
        snprintf(out + n, cap - n, "...");
}

void slurm_hint(int argc, char **argv, char *out, size_t cap)
{
    char cmd[2048] = "";
    for (int i = 0; i < argc; i++)
        add_word(cmd, sizeof cmd, argv[i]);
    char wrap[2100] = "--wrap=";
    add_word(wrap + 7, sizeof wrap - 7, cmd);
    snprintf(out, cap,
             "ask Slurm for nodes and run the same command inside the allocation, for example:\n"
             "  salloc --nodes=4 --ntasks=32 --no-kill %s\n"
             "or as a batch job (hosts/franja.sbatch is a script to start from):\n"
             "  sbatch --nodes=4 --ntasks=32 --no-kill %s",
             cmd, wrap);
}

void slurm_serve(slurm_alloc *a, tr_options *o)
{
    o->backend = &tr_slurm_backend;
    o->backend_ctx = a;
}
