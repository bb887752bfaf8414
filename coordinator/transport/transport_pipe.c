/* transport_pipe.c -- child processes of this machine: posix_spawnp,
 * non-blocking pipes for stdout and stderr, waitpid for the exit status
 * (see the tr_pipe_* functions in transport_backend.h). */
#include "transport/transport_backend.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include "clock.h"

extern char **environ;

typedef struct {
    pid_t pid;
    int fd_out, fd_err;        /* -1 once at end of file */
    int reaped;
} pipe_proc;

/* The program file execvp would run for name: name itself when it holds a
 * slash, else the first executable PATH entry.  Found here, before fork,
 * so that the child calls nothing that might take a lock (the coordinator
 * has threads). */
static int find_program(const char *name, char *out, size_t cap)
{
    if (strchr(name, '/'))
        return snprintf(out, cap, "%s", name) < (int)cap ? 0 : ENAMETOOLONG;
    const char *path = getenv("PATH");
    if (!path || !*path)
        path = "/usr/local/bin:/usr/bin:/bin";
    for (const char *d = path;; d++) {
        const char *end = strchr(d, ':');
        size_t len = end ? (size_t)(end - d) : strlen(d);
        int n = snprintf(out, cap, "%.*s%s%s", (int)len, d, len ? "/" : "", name);
        if (n > 0 && n < (int)cap && access(out, X_OK) == 0)
            return 0;
        if (!end)
            return ENOENT;
        d = end;
    }
}

/* Makes fd the descriptor target of the child, open across exec
 * (async-signal-safe). */
static int onto(int fd, int target)
{
    if (fd == target)
        return fcntl(fd, F_SETFD, 0) < 0 ? -1 : 0;
    return dup2(fd, target) < 0 ? -1 : 0;
}

/* fork and exec with the parent-death signal set: the child gets sig when
 * the thread that started it ends (the whole coordinator, for the main
 * thread), SIGKILL included.  The exec's failure comes back on a pipe. */
static int spawn_tied(pid_t *pid, const char *const *argv, int sig, int out, int err_fd)
{
    char prog[4096];
    int rc = find_program(argv[0], prog, sizeof prog);
    if (rc)
        return rc;
    int null = open("/dev/null", O_RDONLY | O_CLOEXEC);
    if (null < 0)
        return errno;
    int st[2];
    if (pipe2(st, O_CLOEXEC)) {
        rc = errno;
        close(null);
        return rc;
    }
    pid_t parent = getpid();
    pid_t c = fork();
    if (c == 0) {
        /* Only async-signal-safe calls from here on. */
        int e = 0;
        if (prctl(PR_SET_PDEATHSIG, sig) || getppid() != parent)
            e = ESRCH; /* the parent is already gone: do not start */
        else if (onto(null, 0) || onto(out, 1) || onto(err_fd, 2))
            e = errno;
        else {
            execve(prog, (char *const *)argv, environ);
            e = errno;
        }
        while (write(st[1], &e, sizeof e) < 0 && errno == EINTR) {
        }
        _exit(127);
    }
    rc = c < 0 ? errno : 0;
    close(st[1]);
    close(null);
    if (c > 0) {
        int e;
        ssize_t k;
        while ((k = read(st[0], &e, sizeof e)) < 0 && errno == EINTR) {
        }
        if (k == (ssize_t)sizeof e) {
            rc = e;
            while (waitpid(c, NULL, 0) < 0 && errno == EINTR) {
            }
        } else
            *pid = c;
    }
    close(st[0]);
    return rc;
}

static int spawn(tr_proc *p, const char *const *argv, int death_sig, fr_error *err)
{
    pipe_proc *pp = calloc(1, sizeof *pp);
    if (!pp)
        return fr_fail(err, "out of memory");
    int po[2], pe[2];
    if (pipe2(po, O_CLOEXEC)) {
        free(pp);
        return fr_fail(err, "pipe: %s", strerror(errno));
    }
    if (pipe2(pe, O_CLOEXEC)) {
        close(po[0]);
        close(po[1]);
        free(pp);
        return fr_fail(err, "pipe: %s", strerror(errno));
    }
    pid_t pid;
    int rc;
    if (death_sig)
        rc = spawn_tied(&pid, argv, death_sig, po[1], pe[1]);
    else {
        posix_spawn_file_actions_t fa;
        posix_spawn_file_actions_init(&fa);
        posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
        posix_spawn_file_actions_adddup2(&fa, po[1], 1);
        posix_spawn_file_actions_adddup2(&fa, pe[1], 2);
        rc = posix_spawnp(&pid, argv[0], &fa, NULL, (char *const *)argv, environ);
        posix_spawn_file_actions_destroy(&fa);
    }
    close(po[1]);
    close(pe[1]);
    if (rc) {
        close(po[0]);
        close(pe[0]);
        free(pp);
        return fr_fail(err, "cannot start %s: %s", argv[0], strerror(rc));
    }
    fcntl(po[0], F_SETFL, O_NONBLOCK);
    fcntl(pe[0], F_SETFL, O_NONBLOCK);
    pp->pid = pid;
    pp->fd_out = po[0];
    pp->fd_err = pe[0];
    p->impl = pp;
    p->state = TR_RUNNING;
    return 0;
}

int tr_pipe_spawn(tr_proc *p, const char *const *argv, fr_error *err) { return spawn(p, argv, 0, err); }

int tr_pipe_spawn_tied(tr_proc *p, const char *const *argv, int sig, fr_error *err)
{
    return spawn(p, argv, sig > 0 ? sig : SIGTERM, err);
}

/* Reads what is there; closes the descriptor at end of file.  Output that
 * the process may no longer keep is read and dropped, so that the child
 * never blocks on a full pipe. */
static void drain(int *fd, tr_proc *p, int is_err)
{
    char buf[65536];
    while (*fd >= 0) {
        ssize_t n = read(*fd, buf, sizeof buf);
        if (n > 0) {
            if (is_err)
                tr_proc_add_err(p, buf, (size_t)n);
            else if (p->state == TR_RUNNING)
                tr_proc_add_out(p, buf, (size_t)n);
            continue;
        }
        if (n < 0 && (errno == EAGAIN || errno == EINTR))
            return;
        close(*fd);
        *fd = -1;
    }
}

static int wait_status(int ws) { return WIFSIGNALED(ws) ? 128 + WTERMSIG(ws) : WEXITSTATUS(ws); }

int tr_pipe_pollfds(tr_proc *procs, struct pollfd *pfd, int max)
{
    int n = 0;
    for (tr_proc *p = procs; p; p = p->next) {
        pipe_proc *pp = p->impl;
        if (p->state != TR_RUNNING || !pp)
            continue;
        int fds[2] = {pp->fd_out, pp->fd_err};
        for (int i = 0; i < 2; i++)
            if (fds[i] >= 0 && n < max)
                pfd[n++] = (struct pollfd){fds[i], POLLIN, 0};
    }
    return n;
}

void tr_pipe_service(tr_proc *procs)
{
    for (tr_proc *p = procs; p; p = p->next) {
        pipe_proc *pp = p->impl;
        if (p->state != TR_RUNNING || !pp)
            continue;
        drain(&pp->fd_out, p, 0);
        drain(&pp->fd_err, p, 1);
        if (p->state != TR_RUNNING || pp->fd_out >= 0 || pp->fd_err >= 0)
            continue;
        int ws;
        if (waitpid(pp->pid, &ws, WNOHANG) == pp->pid) {
            pp->reaped = 1;
            p->status = wait_status(ws);
            p->state = TR_EXITED;
        }
    }
}

void tr_pipe_kill(tr_proc *p)
{
    pipe_proc *pp = p->impl;
    if (pp && !pp->reaped)
        kill(pp->pid, SIGKILL);
}

void tr_pipe_signal(tr_proc *p, int sig)
{
    pipe_proc *pp = p->impl;
    if (pp && !pp->reaped)
        kill(pp->pid, sig);
}

int tr_pipe_detach(tr_proc *p)
{
    pipe_proc *pp = p->impl;
    if (!pp)
        return 0;
    int pid = pp->reaped ? 0 : (int)pp->pid;
    if (pp->fd_out >= 0)
        close(pp->fd_out);
    if (pp->fd_err >= 0)
        close(pp->fd_err);
    free(pp);
    p->impl = NULL;
    return pid;
}

void tr_pipe_release(tr_proc *p)
{
    pipe_proc *pp = p->impl;
    if (!pp)
        return;
    if (!pp->reaped) {
        kill(pp->pid, SIGKILL);
        waitpid(pp->pid, NULL, 0);
    }
    if (pp->fd_out >= 0)
        close(pp->fd_out);
    if (pp->fd_err >= 0)
        close(pp->fd_err);
    free(pp);
    p->impl = NULL;
}

int tr_pipe_run(const char *const *argv, int timeout_s, char **out, fr_error *err)
{
    tr_proc p;
    memset(&p, 0, sizeof p);
    p.out_max = (size_t)1 << 20;
    if (out)
        *out = NULL;
    if (tr_pipe_spawn(&p, argv, err))
        return -1;
    double end = clock_now() + timeout_s;
    while (p.state == TR_RUNNING && clock_now() < end) {
        struct pollfd pfd[2];
        int n = tr_pipe_pollfds(&p, pfd, 2);
        poll(pfd, (nfds_t)n, 50);
        tr_pipe_service(&p);
        if (!out)
            p.out_len = 0; /* stdout is not wanted */
    }
    int rc = 0;
    if (p.state == TR_RUNNING)
        rc = fr_fail(err, "%s did not finish within %d s", argv[0], timeout_s);
    else if (p.state == TR_FAILED)
        rc = fr_fail(err, "%s: %s", argv[0], p.why);
    else if (p.status)
        rc = fr_fail(err, "%s failed (status %d): %s", argv[0], p.status, p.err);
    else if (out && !(*out = malloc(p.out_len + 1)))
        rc = fr_fail(err, "out of memory");
    else if (out) {
        memcpy(*out, p.out, p.out_len);
        (*out)[p.out_len] = 0;
    }
    tr_pipe_release(&p);
    free(p.out);
    return rc;
}
