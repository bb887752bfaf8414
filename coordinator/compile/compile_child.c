/* compile_child.c -- the scene compiled in a child process that an
 * interruption can stop at once, and that ends with the process that
 * started it (PR_SET_PDEATHSIG), even one killed by SIGKILL. */
#include "compile/compile_child.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "fbin.h"
#include "file.h"
#include "clock.h"
#include "compile/confine.h"
#include "compile/rlimit.h"

/* What the child sends back, in one write. */
typedef struct {
    int rc;
    fr_error err;
    compile_child_stats st;
} answer;

/* The files a compile read (compile_child.h), as text. */
typedef struct {
    char *text;
    size_t len, cap;
    int failed;                /* out of memory: the list is not written */
} read_list;

static void note_read(void *user, const char *real, const struct stat *st)
{
    read_list *l = user;
    char line[PATH_MAX + 128];
    int n = strchr(real, '\n') ? snprintf(line, sizeof line, "!\n")
                               : snprintf(line, sizeof line, "%llu %llu %lld %lld %ld %s\n",
                                          (unsigned long long)st->st_dev, (unsigned long long)st->st_ino,
                                          (long long)st->st_size, (long long)st->st_mtim.tv_sec,
                                          (long)st->st_mtim.tv_nsec, real);
    if (n < 0 || (size_t)n >= sizeof line)
        n = snprintf(line, sizeof line, "!\n");
    if (l->len + (size_t)n > l->cap) {
        size_t cap = 2 * l->cap + (size_t)n + 4096;
        char *t = realloc(l->text, cap);
        if (!t) {
            l->failed = 1;
            return;
        }
        l->text = t;
        l->cap = cap;
    }
    memcpy(l->text + l->len, line, (size_t)n);
    l->len += (size_t)n;
}

static void child(const char *scene, const compile_opts *o, const char *file, int fd)
{
    answer a;
    memset(&a, 0, sizeof a);
    fr_scene s;
    fr_budget lim;
    if (o && o->limits)
        lim = *o->limits;
    else
        budget_init(&lim);
    /* CPU: SIGXCPU at the limit, SIGKILL a little later if that is caught. */
    rlimit_child(lim.limit[BUDGET_MEMORY], lim.limit[BUDGET_CPU], lim.limit[BUDGET_CPU] + 5);
    /* The scene goes to `file` as it is made: never in memory twice. */
    compile_opts co;
    if (o)
        co = *o;
    else
        memset(&co, 0, sizeof co);
    co.fbin = file;
    co.mesh_key = &a.st.mesh_key;
    co.placed_key = &a.st.placed_key;
    read_list reads = {NULL, 0, 0, 0};
    if (co.files)
        confine_watch(note_read, &reads);
    double t0 = clock_now();
    a.rc = compile_scene(scene, &co, &s, &a.err);
    confine_watch(NULL, NULL);
    fr_error fe;
    if (a.rc == 0 && co.files && (reads.failed || file_write_atomic(co.files, reads.text ? reads.text : "",
                                                                    reads.len, &fe) < 0))
        unlink(co.files); /* no list: the caller reads none */
    free(reads.text);
    if (a.rc && strstr(a.err.msg, "out of memory")) {
        size_t n = strlen(a.err.msg);
        snprintf(a.err.msg + n, sizeof a.err.msg - n, " (the compile may map %llu MiB: --limit memory=BYTES raises it)",
                 (unsigned long long)(lim.limit[BUDGET_MEMORY] >> 20));
    }
    if (a.rc == 0) {
        a.st.seconds = clock_now() - t0;
        fbin_hash_hex(s.hash, a.st.hash);
        a.st.bytes = s.blob_size;
        a.st.prims = s.n_prims;
        a.st.triangles = s.n_triangles;
        a.st.materials = s.n_materials;
        a.st.lights = s.n_lights;
        a.st.nodes = s.n_nodes;
        a.st.leaves = s.n_leaves;
        a.st.instances = s.n_instances;
        a.st.meshes = s.n_meshes;
        scn_free(&s);
    }
    const char *p = (const char *)&a;
    for (size_t left = sizeof a; left;) {
        ssize_t k = write(fd, p, left);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            break;
        p += k;
        left -= (size_t)k;
    }
}

/* CPU seconds (user and system) of a child's usage. */
static double cpu_seconds(struct rusage u)
{
    return (double)u.ru_utime.tv_sec + (double)u.ru_stime.tv_sec +
           1e-6 * (double)(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

/* Removes the private directory and whatever the child left in it. */
static void remove_dir(const char *dir)
{
    DIR *d = opendir(dir);
    if (d) {
        struct dirent *e;
        char path[4400];
        while ((e = readdir(d)))
            if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
                snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
                unlink(path);
            }
        closedir(d);
    }
    rmdir(dir);
}

/* Reads the answer, polling stop.  Returns 1 when read whole, 0 when the
 * child ended without one, -1 when stopped. */
static int wait_answer(int fd, answer *a, volatile sig_atomic_t *stop)
{
    size_t got = 0;
    while (got < sizeof *a) {
        if (stop && *stop)
            return -1;
        struct pollfd p = {fd, POLLIN, 0};
        int r = poll(&p, 1, 100);
        if (r < 0 && errno != EINTR)
            return 0;
        if (r <= 0)
            continue;
        ssize_t k = read(fd, (char *)a + got, sizeof *a - got);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            return 0;
        got += (size_t)k;
    }
    return 1;
}

int compile_child_sweep(const char *out)
{
    const char *slash = strrchr(out, '/');
    const char *base = slash ? slash + 1 : out;
    char dirname_[4200], prefix[4200], path[4400];
    int dirlen = slash ? (int)(slash - out) : 0;
    if (snprintf(dirname_, sizeof dirname_, "%.*s", dirlen, slash ? out : ".") >= (int)sizeof dirname_ ||
        snprintf(prefix, sizeof prefix, ".%s.compile-", base) >= (int)sizeof prefix)
        return 0;
    if (slash && dirlen == 0)
        snprintf(dirname_, sizeof dirname_, "/");
    DIR *d = opendir(dirname_);
    if (!d)
        return 0;
    int n = 0;
    struct dirent *e;
    size_t plen = strlen(prefix);
    while ((e = readdir(d)))
        if (!strncmp(e->d_name, prefix, plen) && strlen(e->d_name) == plen + 6) {
            struct stat sb;
            snprintf(path, sizeof path, "%s/%s", dirname_, e->d_name);
            /* Only a directory of this user's, never through a link. */
            if (lstat(path, &sb) == 0 && S_ISDIR(sb.st_mode) && sb.st_uid == geteuid()) {
                remove_dir(path);
                n++;
            }
        }
    closedir(d);
    return n;
}

/* Puts the compiled file into out, a target written in place (a device
 * or a FIFO): its bytes are copied there, the target itself never
 * replaced. */
static int copy_into(const char *file, const char *out, fr_error *err)
{
    file_out o;
    if (file_out_open(out, &o, err))
        return -1;
    if (file_out_copy(&o, file, err)) {
        file_out_abort(&o);
        return -1;
    }
    return file_out_commit(&o, out, err);
}

int compile_child(const char *scene, const compile_opts *o, const char *out, volatile sig_atomic_t *stop,
                  compile_child_stats *st, fr_error *err)
{
    char dir[4200], file[4300];
    const char *slash = strrchr(out, '/');
    int dirlen = slash ? (int)(slash - out + 1) : 0;
    /* A device or a FIFO (/dev/null, /dev/stdout) is written in place: the
     * compile goes to the current directory, not into /dev. */
    int in_place = file_out_in_place(out);
    if (snprintf(dir, sizeof dir, "%.*s.%s.compile-XXXXXX", in_place ? 0 : dirlen, out, out + dirlen) >=
        (int)sizeof dir)
        return fr_fail(err, "%s: name too long", out);
    if (!mkdtemp(dir))
        return fr_fail(err, "%s: cannot create a directory %s to compile into: %s", out,
                       in_place ? "in the current directory" : "beside it", strerror(errno));
    snprintf(file, sizeof file, "%s/scene.fbin", dir);
    int p[2];
    if (pipe2(p, O_CLOEXEC) < 0) {
        int e = errno;
        rmdir(dir);
        return fr_fail(err, "%s: cannot start the compiler: %s", scene, strerror(e));
    }
    fflush(NULL);
    pid_t parent = getpid();
    pid_t pid = fork();
    if (pid < 0) {
        int e = errno;
        close(p[0]);
        close(p[1]);
        rmdir(dir);
        return fr_fail(err, "%s: cannot start the compiler: %s", scene, strerror(e));
    }
    if (pid == 0) {
        /* The child holds what the parent held (the job lock): it must not
         * outlive a parent killed by SIGKILL, which could not stop it.  A
         * parent gone before the signal was set is seen by getppid. */
        if (prctl(PR_SET_PDEATHSIG, SIGKILL) || getppid() != parent)
            _exit(1);
        close(p[0]);
        child(scene, o, file, p[1]);
        fflush(NULL);
        _exit(0);
    }
    close(p[1]);
    answer a;
    int got = wait_answer(p[0], &a, stop);
    close(p[0]);
    if (got < 0)
        kill(pid, SIGKILL);
    int status = 0;
    struct rusage pid_usage;
    memset(&pid_usage, 0, sizeof pid_usage);
    while (wait4(pid, &status, 0, &pid_usage) < 0 && errno == EINTR) {
    }
    int rc;
    if (got < 0) {
        rc = fr_fail(err, "%s: compile interrupted", scene);
    } else if (got == 0) {
        const fr_budget *lim = o ? o->limits : NULL;
        fr_budget def;
        if (!lim) {
            budget_init(&def);
            lim = &def;
        }
        /* SIGXCPU at the soft limit; SIGKILL at the hard one, 5 s later. */
        if (WIFSIGNALED(status) && (WTERMSIG(status) == SIGXCPU ||
                                    (WTERMSIG(status) == SIGKILL &&
                                     cpu_seconds(pid_usage) >= (double)lim->limit[BUDGET_CPU])))
            rc = fr_fail(err, "%s: the compile used its %llu s of CPU time (--limit cpu=SECONDS raises it)", scene,
                         (unsigned long long)lim->limit[BUDGET_CPU]);
        else if (WIFSIGNALED(status))
            rc = fr_fail(err, "%s: the compiling process died (signal %d: %s)", scene, WTERMSIG(status),
                         strsignal(WTERMSIG(status)));
        else
            rc = fr_fail(err, "%s: the compiling process stopped without an answer (exit status %d)", scene,
                         WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    } else if (a.rc) {
        a.err.msg[sizeof a.err.msg - 1] = 0;
        *err = a.err;
        rc = -1;
    } else if (stop && *stop) {
        rc = fr_fail(err, "%s: compile interrupted", scene);
    } else if (in_place) {
        rc = copy_into(file, out, err);
    } else if (rename(file, out)) {
        rc = fr_fail(err, "%s: %s", out, strerror(errno));
    } else {
        rc = 0;
    }
    if (rc == 0 && st) {
        *st = a.st;
        st->hash[sizeof st->hash - 1] = 0;
    }
    remove_dir(dir);
    return rc;
}
