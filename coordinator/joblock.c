/* joblock.c -- one writer per job directory (see joblock.h). */
#include "joblock.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* Checks that dir, if it exists, is a directory (not a link) owned by this
 * user and not writable by group or others.  0 when it is, or does not
 * exist; otherwise -1 with the reason and what to do. */
static int joblock_check_dir(const char *dir, fr_error *err)
{
    struct stat st;
    if (lstat(dir, &st)) {
        if (errno == ENOENT)
            return 0;
        return fr_fail(err, "%s: %s", dir, strerror(errno));
    }
    if (S_ISLNK(st.st_mode))
        return fr_fail(err, "%s: the job directory is a symbolic link; refusing to use it (remove it, or "
                       "choose another with --job)", dir);
    if (!S_ISDIR(st.st_mode))
        return fr_fail(err, "%s: exists and is not a directory; remove it or choose another job "
                       "directory with --job", dir);
    if (st.st_uid != geteuid())
        return fr_fail(err, "%s: the job directory belongs to uid %u, not to you (uid %u); refusing to "
                       "use it (remove it, or choose another with --job)", dir, (unsigned)st.st_uid,
                       (unsigned)geteuid());
    if (st.st_mode & (S_IWGRP | S_IWOTH))
        return fr_fail(err, "%s: the job directory is writable by others (mode %03o); refusing to use it "
                       "(chmod go-w it, or remove it)", dir, (unsigned)(st.st_mode & 0777));
    return 0;
}

/* Copies the value of "key=" from the lock file's text into out[cap]. */
static void field(const char *text, const char *key, char *out, size_t cap)
{
    size_t k = strlen(key);
    snprintf(out, cap, "?");
    for (const char *p = text; p && *p; p = strchr(p, '\n'), p = p ? p + 1 : NULL)
        if (!strncmp(p, key, k) && p[k] == '=') {
            const char *v = p + k + 1;
            size_t n = strcspn(v, "\n");
            if (n >= cap)
                n = cap - 1;
            memcpy(out, v, n);
            out[n] = 0;
            /* The text is another process's: show it printable only. */
            for (char *c = out; *c; c++)
                if ((unsigned char)*c < 0x20 || *c == 0x7f)
                    *c = '?';
            return;
        }
}

static int busy(int fd, const char *what, fr_error *err)
{
    char text[2048] = "", pid[32], host[256], since[64];
    /* The holder writes its note right after it takes the lock; give it a
     * moment if the file is still empty. */
    for (int i = 0; i < 20; i++) {
        ssize_t n = pread(fd, text, sizeof text - 1, 0);
        text[n > 0 ? n : 0] = 0;
        if (n > 0)
            break;
        usleep(10000);
    }
    field(text, "pid", pid, sizeof pid);
    field(text, "host", host, sizeof host);
    field(text, "since", since, sizeof since);
    fr_fail(err, "%s is being rendered by another franja (pid %s on host %s, since %s)", what, pid, host, since);
    return JLK_BUSY;
}

static void note(int fd, const char *cmdline)
{
    char host[256] = "?", since[64] = "?", text[8192];
    gethostname(host, sizeof host - 1);
    host[sizeof host - 1] = 0;
    time_t now = time(NULL);
    struct tm tm;
    if (localtime_r(&now, &tm))
        strftime(since, sizeof since, "%Y-%m-%d %H:%M:%S", &tm);
    int n = snprintf(text, sizeof text, "pid=%ld\nhost=%s\nsince=%s\ncommand=%s\n", (long)getpid(), host, since,
                     cmdline ? cmdline : "");
    if (n < 0)
        return;
    if ((size_t)n >= sizeof text)
        n = (int)sizeof text - 1;
    if (ftruncate(fd, 0) == 0 && pwrite(fd, text, (size_t)n, 0) == n)
        fsync(fd);
}

int joblock_acquire(const char *dir, const char *what, const char *cmdline, int unlocked_ok, joblock *lk,
                fr_error *err)
{
    lk->fd = -1;
    lk->created = 0;
    lk->unlocked = 0;
    if (snprintf(lk->dir, sizeof lk->dir, "%s", dir) >= (int)sizeof lk->dir ||
        snprintf(lk->path, sizeof lk->path, "%s/lock", dir) >= (int)sizeof lk->path)
        return fr_fail(err, "%s: job directory name too long", dir);
    if (mkdir(dir, 0700) == 0)
        lk->created = 1;
    else if (errno != EEXIST)
        return fr_fail(err, "%s: cannot create job directory: %s", dir, strerror(errno));
    if (joblock_check_dir(dir, err))
        return -1;
    /* The holder removes the lock file as it finishes: a file opened just
     * before that is no longer the lock, so check the name still leads to
     * the file locked, and start again if not. */
    for (int attempt = 0; attempt < 50; attempt++) {
        int fd = open(lk->path, O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK, 0600);
        if (fd < 0) {
            if (errno == ENOENT)
                return fr_fail(err, "%s: the job directory was removed while starting; try again", dir);
            return fr_fail(err, "%s: cannot open the lock file: %s", lk->path,
                           errno == ELOOP ? "it is a symbolic link" : strerror(errno));
        }
        struct stat st, now;
        if (fstat(fd, &st) || !S_ISREG(st.st_mode) || st.st_uid != geteuid()) {
            close(fd);
            return fr_fail(err, "%s: the lock file is not a regular file of yours; remove it", lk->path);
        }
        struct flock fl;
        memset(&fl, 0, sizeof fl);
        fl.l_type = F_WRLCK;
        fl.l_whence = SEEK_SET;
        if (fcntl(fd, F_OFD_SETLK, &fl)) {
            int e = errno;
            if (e == EAGAIN || e == EACCES) {
                int rc = busy(fd, what, err);
                close(fd);
                return rc;
            }
            if (e == ENOLCK || e == EOPNOTSUPP || e == EINVAL || e == ENOSYS) {
                if (!unlocked_ok) {
                    close(fd);
                    /* Refused: what this call made goes again. */
                    if (lk->created) {
                        unlink(lk->path);
                        rmdir(dir);
                    }
                    fr_fail(err, "%s: the file system refuses locks (%s), so two renders of one output "
                            "could not be kept apart; use a local job directory (--job DIR), or "
                            "--no-lock to go on without the lock", dir, strerror(e));
                    return JLK_NOLOCKS;
                }
                note(fd, cmdline);
                lk->fd = fd;
                lk->unlocked = 1;
                return 0;
            }
            close(fd);
            return fr_fail(err, "%s: cannot lock: %s", lk->path, strerror(e));
        }
        if (stat(lk->path, &now) == 0 && now.st_ino == st.st_ino && now.st_dev == st.st_dev) {
            note(fd, cmdline);
            lk->fd = fd;
            return 0;
        }
        close(fd);
        if (mkdir(dir, 0700) == 0)
            lk->created = 1;
        if (joblock_check_dir(dir, err))
            return -1;
    }
    return fr_fail(err, "%s: could not take the lock (the directory keeps being removed)", dir);
}

void joblock_release(joblock *lk, int remove_dir)
{
    if (lk->fd < 0)
        return;
    if (remove_dir) {
        unlink(lk->path);
        rmdir(lk->dir);
    }
    close(lk->fd);
    lk->fd = -1;
}
