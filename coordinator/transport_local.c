/* transport_local.c -- worker processes on this machine: posix_spawn,
 * non-blocking pipes for stdout and stderr, waitpid for the exit status. */
#include "transport_backend.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/utsname.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

extern char **environ;

typedef struct {
    hosts_entry entry;
    char worker[PATH_MAX];
} local_host;

typedef struct {
    pid_t pid;
    int fd_out, fd_err;        /* -1 once at end of file */
    int reaped;
} local_proc;

static int local_connect(const hosts_entry *e, const tr_options *o, void **impl, fr_error *err)
{
    local_host *h = calloc(1, sizeof *h);
    if (!h)
        return fr_fail(err, "%s: out of memory", e->name);
    h->entry = *e;
    const char *w = e->worker[0] ? e->worker : o->local_worker;
    if (!w || !*w) {
        free(h);
        return fr_fail(err, "%s: no worker binary known (give worker= in the host table)", e->name);
    }
    snprintf(h->worker, sizeof h->worker, "%s", w);
    if (access(h->worker, X_OK)) {
        int e2 = errno;
        free(h);
        return fr_fail(err, "%s: worker '%s' cannot be run: %s (build it with make, or give worker=)",
                       e->name, w, strerror(e2));
    }
    *impl = h;
    return 0;
}

/* Starts argv[0] with stdout and stderr on fresh non-blocking pipes. */
static int start(const char *const *argv, local_proc *lp, fr_error *err)
{
    int po[2], pe[2];
    if (pipe2(po, O_CLOEXEC))
        return fr_fail(err, "pipe: %s", strerror(errno));
    if (pipe2(pe, O_CLOEXEC)) {
        close(po[0]);
        close(po[1]);
        return fr_fail(err, "pipe: %s", strerror(errno));
    }
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_adddup2(&fa, po[1], 1);
    posix_spawn_file_actions_adddup2(&fa, pe[1], 2);
    pid_t pid;
    int rc = posix_spawn(&pid, argv[0], &fa, NULL, (char *const *)argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    close(po[1]);
    close(pe[1]);
    if (rc) {
        close(po[0]);
        close(pe[0]);
        return fr_fail(err, "cannot start %s: %s", argv[0], strerror(rc));
    }
    fcntl(po[0], F_SETFL, O_NONBLOCK);
    fcntl(pe[0], F_SETFL, O_NONBLOCK);
    lp->pid = pid;
    lp->fd_out = po[0];
    lp->fd_err = pe[0];
    lp->reaped = 0;
    return 0;
}

/* Reads what is there; closes the descriptor at end of file. */
static void drain(int *fd, tr_proc *p, int is_err)
{
    char buf[65536];
    while (*fd >= 0) {
        ssize_t n = read(*fd, buf, sizeof buf);
        if (n > 0) {
            if (is_err)
                tr_proc_add_err(p, buf, (size_t)n);
            else if (tr_proc_add_out(p, buf, (size_t)n))
                tr_proc_fail(p, "out of memory for the worker's output");
            continue;
        }
        if (n < 0 && (errno == EAGAIN || errno == EINTR))
            return;
        close(*fd);
        *fd = -1;
    }
}

static int wait_status(int ws) { return WIFSIGNALED(ws) ? 128 + WTERMSIG(ws) : WEXITSTATUS(ws); }

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

/* Runs a short command to completion and keeps the first line of stdout. */
static int run_line(const char *const *argv, char *line, size_t cap, int timeout_s, fr_error *err)
{
    local_proc lp;
    tr_proc p;
    memset(&p, 0, sizeof p);
    if (start(argv, &lp, err))
        return -1;
    double end = now_s() + timeout_s;
    while ((lp.fd_out >= 0 || lp.fd_err >= 0) && now_s() < end) {
        struct pollfd pfd[2] = {{lp.fd_out, POLLIN, 0}, {lp.fd_err, POLLIN, 0}};
        poll(pfd, 2, 100);
        drain(&lp.fd_out, &p, 0);
        drain(&lp.fd_err, &p, 1);
    }
    int timed_out = lp.fd_out >= 0 || lp.fd_err >= 0;
    if (timed_out)
        kill(lp.pid, SIGKILL);
    int ws = 0;
    waitpid(lp.pid, &ws, 0);
    if (lp.fd_out >= 0)
        close(lp.fd_out);
    if (lp.fd_err >= 0)
        close(lp.fd_err);
    int rc = 0;
    if (timed_out)
        rc = fr_fail(err, "%s did not finish within %d s", argv[0], timeout_s);
    else if (wait_status(ws))
        rc = fr_fail(err, "%s %s failed (status %d): %s", argv[0], argv[1], wait_status(ws), p.err);
    else {
        size_t n = 0;
        while (n < p.out_len && n + 1 < cap && p.out[n] != '\n')
            n++;
        memcpy(line, p.out, n);
        line[n] = 0;
    }
    free(p.out);
    return rc;
}

static int local_probe(void *impl, tr_info *info, fr_error *err)
{
    local_host *h = impl;
    struct utsname u;
    if (uname(&u) == 0) {
        snprintf(info->arch, sizeof info->arch, "%.31s", u.machine);
        snprintf(info->os, sizeof info->os, "%.63s", u.sysname);
    }
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    info->cores = n > 0 ? (int)n : 1;
    const char *argv[] = {h->worker, "--version", NULL};
    if (run_line(argv, info->version, sizeof info->version, 30, err))
        return fr_fail(err, "%s: %s", h->entry.name, err->msg);
    return 0;
}

static int local_stage(void *impl, const char *local_path, uint64_t hash, char *remote, size_t cap,
                       int *uploaded, fr_error *err)
{
    local_host *h = impl;
    (void)hash;
    *uploaded = 0;
    char abs[PATH_MAX];
    if (!realpath(local_path, abs))
        return fr_fail(err, "%s: %s: %s", h->entry.name, local_path, strerror(errno));
    if (strlen(abs) >= cap)
        return fr_fail(err, "%s: scene path too long", h->entry.name);
    strcpy(remote, abs);
    return 0;
}

static int local_cache(void *impl, int *files, uint64_t *bytes, fr_error *err)
{
    (void)impl, (void)files, (void)bytes, (void)err;
    return 0;
}

static int local_sysinfo(void *impl, char *arch, char *os, fr_error *err)
{
    (void)impl, (void)err;
    struct utsname u;
    if (uname(&u) == 0)
        snprintf(arch, 32, "%.31s", u.machine);
    char text[4096];
    FILE *f = fopen("/etc/os-release", "r");
    size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
    if (f)
        fclose(f);
    text[n] = 0;
    tr_os_codename(text, os);
    return 0;
}

static int local_install(void *impl, const char *local_path, const char *name, char *remote, size_t cap,
                         fr_error *err)
{
    local_host *h = impl;
    (void)local_path, (void)name, (void)remote, (void)cap;
    return fr_fail(err, "%s: a local host runs this machine's worker (%s); nothing to install", h->entry.name,
                   h->worker);
}

static int local_spawn(void *impl, tr_proc *p, const char *const *args, fr_error *err)
{
    local_host *h = impl;
    const char *argv[64];
    size_t n = 0;
    argv[n++] = h->worker;
    for (; args[n - 1] && n < 63; n++)
        argv[n] = args[n - 1];
    argv[n] = NULL;
    if (args[n - 1])
        return fr_fail(err, "%s: too many worker arguments", h->entry.name);
    local_proc *lp = calloc(1, sizeof *lp);
    if (!lp)
        return fr_fail(err, "%s: out of memory", h->entry.name);
    if (start(argv, lp, err)) {
        free(lp);
        return fr_fail(err, "%s: %s", h->entry.name, err->msg);
    }
    p->impl = lp;
    p->state = TR_RUNNING;
    return 0;
}

static int local_pollfds(void *impl, tr_proc *procs, struct pollfd *pfd, int max)
{
    (void)impl;
    int n = 0;
    for (tr_proc *p = procs; p; p = p->next) {
        local_proc *lp = p->impl;
        if (p->state != TR_RUNNING || !lp)
            continue;
        int fds[2] = {lp->fd_out, lp->fd_err};
        for (int i = 0; i < 2; i++)
            if (fds[i] >= 0 && n < max)
                pfd[n++] = (struct pollfd){fds[i], POLLIN, 0};
    }
    return n;
}

static int local_service(void *impl, tr_proc *procs, fr_error *err)
{
    (void)impl;
    (void)err;
    for (tr_proc *p = procs; p; p = p->next) {
        local_proc *lp = p->impl;
        if (p->state != TR_RUNNING || !lp)
            continue;
        drain(&lp->fd_out, p, 0);
        drain(&lp->fd_err, p, 1);
        if (p->state != TR_RUNNING || lp->fd_out >= 0 || lp->fd_err >= 0)
            continue;
        int ws;
        if (waitpid(lp->pid, &ws, WNOHANG) == lp->pid) {
            lp->reaped = 1;
            p->status = wait_status(ws);
            p->state = TR_EXITED;
        }
    }
    return 0;
}

static void local_kill(tr_proc *p)
{
    local_proc *lp = p->impl;
    if (lp && !lp->reaped)
        kill(lp->pid, SIGKILL);
}

static void local_release(tr_proc *p)
{
    local_proc *lp = p->impl;
    if (!lp)
        return;
    if (!lp->reaped) {
        kill(lp->pid, SIGKILL);
        waitpid(lp->pid, NULL, 0);
    }
    if (lp->fd_out >= 0)
        close(lp->fd_out);
    if (lp->fd_err >= 0)
        close(lp->fd_err);
    free(lp);
    p->impl = NULL;
}

static void local_close(void *impl) { free(impl); }

const tr_backend tr_local_backend = {
    "local", local_connect, local_probe, local_stage, local_cache, local_spawn, local_pollfds,
    local_service, local_kill, local_release, local_close, local_sysinfo, local_install,
};
