/* nolockfs.c -- a FUSE file system that refuses locks, for tests/it_joblock.sh.
 *
 *   nolockfs BACKING_DIR MOUNTPOINT      (as root; unmount with umount)
 *
 * Mounts BACKING_DIR at MOUNTPOINT: files and directories pass through to
 * it (create, read, write, rename, unlink, mkdir, rmdir, chmod, stat ...),
 * but every fcntl lock (POSIX and open file description locks) and flock
 * is answered with ENOLCK, as an NFS mount without a lock manager answers.
 * The kernel asks the file system about locks because it implements them
 * (libfuse then tells the kernel it handles POSIX and flock locks itself).
 * Runs in the background once mounted (libfuse's daemon mode); single
 * threaded.  Exits 1 with libfuse's message when it cannot mount. */
#define FUSE_USE_VERSION 31
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <fuse.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

static char backing[PATH_MAX];

/* The backing file of a path inside the mount. */
static int real(const char *path, char out[PATH_MAX])
{
    if (snprintf(out, PATH_MAX, "%s%s", backing, path) >= PATH_MAX)
        return -ENAMETOOLONG;
    return 0;
}

#define REAL(p)                                                                                                  \
    char p##_r[PATH_MAX];                                                                                        \
    if (real(p, p##_r))                                                                                          \
        return -ENAMETOOLONG

static void *nl_init(struct fuse_conn_info *conn, struct fuse_config *cfg)
{
    (void)conn;
    cfg->use_ino = 1;
    /* No caching: every access reaches the backing directory at once. */
    cfg->entry_timeout = cfg->attr_timeout = cfg->negative_timeout = 0;
    cfg->direct_io = 1;
    /* An unlinked open file goes at once (not renamed to .fuse_hidden*),
     * so a directory can be removed while a file of it is still open. */
    cfg->hard_remove = 1;
    return NULL;
}

static int nl_getattr(const char *path, struct stat *st, struct fuse_file_info *fi)
{
    if (fi)
        return fstat((int)fi->fh, st) ? -errno : 0;
    REAL(path);
    return lstat(path_r, st) ? -errno : 0;
}

static int nl_readlink(const char *path, char *buf, size_t size)
{
    REAL(path);
    ssize_t n = readlink(path_r, buf, size - 1);
    if (n < 0)
        return -errno;
    buf[n] = 0;
    return 0;
}

static int nl_readdir(const char *path, void *buf, fuse_fill_dir_t fill, off_t off, struct fuse_file_info *fi,
                      enum fuse_readdir_flags flags)
{
    (void)off, (void)fi, (void)flags;
    REAL(path);
    DIR *d = opendir(path_r);
    if (!d)
        return -errno;
    struct dirent *e;
    while ((e = readdir(d))) {
        struct stat st = {.st_ino = e->d_ino, .st_mode = (mode_t)(e->d_type << 12)};
        if (fill(buf, e->d_name, &st, 0, 0))
            break;
    }
    closedir(d);
    return 0;
}

static int nl_mkdir(const char *path, mode_t mode)
{
    REAL(path);
    return mkdir(path_r, mode) ? -errno : 0;
}

static int nl_unlink(const char *path)
{
    REAL(path);
    return unlink(path_r) ? -errno : 0;
}

static int nl_rmdir(const char *path)
{
    REAL(path);
    return rmdir(path_r) ? -errno : 0;
}

static int nl_symlink(const char *to, const char *path)
{
    REAL(path);
    return symlink(to, path_r) ? -errno : 0;
}

static int nl_rename(const char *from, const char *to, unsigned int flags)
{
    if (flags)
        return -EINVAL;
    REAL(from);
    REAL(to);
    return rename(from_r, to_r) ? -errno : 0;
}

static int nl_chmod(const char *path, mode_t mode, struct fuse_file_info *fi)
{
    if (fi)
        return fchmod((int)fi->fh, mode) ? -errno : 0;
    REAL(path);
    return chmod(path_r, mode) ? -errno : 0;
}

static int nl_chown(const char *path, uid_t uid, gid_t gid, struct fuse_file_info *fi)
{
    if (fi)
        return fchown((int)fi->fh, uid, gid) ? -errno : 0;
    REAL(path);
    return lchown(path_r, uid, gid) ? -errno : 0;
}

static int nl_truncate(const char *path, off_t size, struct fuse_file_info *fi)
{
    if (fi)
        return ftruncate((int)fi->fh, size) ? -errno : 0;
    REAL(path);
    return truncate(path_r, size) ? -errno : 0;
}

static int nl_utimens(const char *path, const struct timespec tv[2], struct fuse_file_info *fi)
{
    if (fi)
        return futimens((int)fi->fh, tv) ? -errno : 0;
    REAL(path);
    return utimensat(AT_FDCWD, path_r, tv, AT_SYMLINK_NOFOLLOW) ? -errno : 0;
}

static int nl_open(const char *path, struct fuse_file_info *fi)
{
    REAL(path);
    int fd = open(path_r, fi->flags | O_NOFOLLOW);
    if (fd < 0)
        return -errno;
    fi->fh = (uint64_t)fd;
    return 0;
}

static int nl_create(const char *path, mode_t mode, struct fuse_file_info *fi)
{
    REAL(path);
    int fd = open(path_r, fi->flags | O_NOFOLLOW, mode);
    if (fd < 0)
        return -errno;
    fi->fh = (uint64_t)fd;
    return 0;
}

static int nl_read(const char *path, char *buf, size_t size, off_t off, struct fuse_file_info *fi)
{
    (void)path;
    ssize_t n = pread((int)fi->fh, buf, size, off);
    return n < 0 ? -errno : (int)n;
}

static int nl_write(const char *path, const char *buf, size_t size, off_t off, struct fuse_file_info *fi)
{
    (void)path;
    ssize_t n = pwrite((int)fi->fh, buf, size, off);
    return n < 0 ? -errno : (int)n;
}

static int nl_statfs(const char *path, struct statvfs *st)
{
    REAL(path);
    return statvfs(path_r, st) ? -errno : 0;
}

static int nl_release(const char *path, struct fuse_file_info *fi)
{
    (void)path;
    close((int)fi->fh);
    return 0;
}

static int nl_fsync(const char *path, int datasync, struct fuse_file_info *fi)
{
    (void)path;
    return (datasync ? fdatasync((int)fi->fh) : fsync((int)fi->fh)) ? -errno : 0;
}

/* The point of this file system: no locks, of any kind. */
static int nl_lock(const char *path, struct fuse_file_info *fi, int cmd, struct flock *lock)
{
    (void)path, (void)fi, (void)cmd, (void)lock;
    return -ENOLCK;
}

static int nl_flock(const char *path, struct fuse_file_info *fi, int op)
{
    (void)path, (void)fi, (void)op;
    return -ENOLCK;
}

static const struct fuse_operations ops = {
    .init = nl_init,
    .getattr = nl_getattr,
    .readlink = nl_readlink,
    .readdir = nl_readdir,
    .mkdir = nl_mkdir,
    .unlink = nl_unlink,
    .rmdir = nl_rmdir,
    .symlink = nl_symlink,
    .rename = nl_rename,
    .chmod = nl_chmod,
    .chown = nl_chown,
    .truncate = nl_truncate,
    .utimens = nl_utimens,
    .open = nl_open,
    .create = nl_create,
    .read = nl_read,
    .write = nl_write,
    .statfs = nl_statfs,
    .release = nl_release,
    .fsync = nl_fsync,
    .lock = nl_lock,
    .flock = nl_flock,
};

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: nolockfs BACKING_DIR MOUNTPOINT\n");
        return 2;
    }
    if (!realpath(argv[1], backing)) {
        perror(argv[1]);
        return 1;
    }
    umask(0);
    /* -o default_permissions: the kernel checks modes as for a local file
     * system; allow_other: the mount serves every user, not only root. */
    char *fargv[] = {argv[0], argv[2], "-s", "-o", "default_permissions,allow_other,fsname=nolockfs", NULL};
    return fuse_main(5, fargv, &ops, NULL) ? 1 : 0;
}
