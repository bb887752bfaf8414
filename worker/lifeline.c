/* lifeline.c -- the worker ends itself when its parent or channel is gone
 * (see lifeline.h). */
#include "lifeline.h"

#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <unistd.h>

static int watch_in, watch_out;

static int is_pipe(int fd)
{
    struct stat st;
    return fstat(fd, &st) == 0 && (S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode));
}

static void gone(const char *what)
{
    static const char head[] = "franja-worker: ";
    static const char tail[] = " closed (the coordinator or its channel is gone); stopping\n";
    /* stderr may be gone too: the writes may fail, which changes nothing. */
    if (write(2, head, sizeof head - 1) > 0 && write(2, what, strlen(what)) > 0 &&
        write(2, tail, sizeof tail - 1) > 0) {
    }
    _exit(LIFELINE_STATUS);
}

/* Runs in the signal handler: poll, read and _exit only. */
static void check(int sig)
{
    (void)sig;
    int saved = errno;
    struct pollfd p[2];
    int n = 0;
    if (watch_out)
        p[n++] = (struct pollfd){1, 0, 0};
    if (watch_in)
        p[n++] = (struct pollfd){0, POLLIN, 0};
    if (n && poll(p, (nfds_t)n, 0) > 0) {
        for (int i = 0; i < n; i++) {
            const char *what = p[i].fd == 1 ? "standard output" : "standard input";
            if (p[i].revents & (POLLERR | POLLHUP | POLLNVAL))
                gone(what);
            if (p[i].fd == 0 && (p[i].revents & POLLIN)) {
                char buf[512];
                ssize_t r = read(0, buf, sizeof buf);
                if (r == 0)
                    gone(what);
            }
        }
    }
    errno = saved;
}

int lifeline_start(int to_stdout, int line)
{
    watch_out = to_stdout && is_pipe(1);
    watch_in = line && is_pipe(0);
    if (!watch_out && !watch_in)
        return 0;
    /* A parent already gone before this call is caught by the pipes. */
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = check;
    sa.sa_flags = SA_RESTART;
    sigemptyset(&sa.sa_mask);
    if (sigaction(SIGALRM, &sa, NULL))
        return -1;
    struct itimerval it = {{0, 200000}, {0, 200000}};
    if (setitimer(ITIMER_REAL, &it, NULL))
        return -1;
    check(0);
    return 0;
}

void lifeline_stop(void)
{
    struct itimerval it;
    memset(&it, 0, sizeof it);
    setitimer(ITIMER_REAL, &it, NULL);
    signal(SIGALRM, SIG_IGN);
    watch_in = watch_out = 0;
}
