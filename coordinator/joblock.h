/** @file joblock.h
 * One writer per job directory.
 *
 * A render takes an exclusive lock on DIR/lock before it reads or writes
 * anything else in its job directory, and keeps it until the output is
 * written and the directory removed.  The lock is an open file description
 * lock (fcntl F_OFD_SETLK): the kernel drops it when the process ends, however
 * it ends, so a crashed or killed render never leaves a stale lock, and NFSv4
 * with a lock manager shares it between machines.  The lock file's text (pid,
 * host, start time, command line) only explains who holds it; the lock
 * itself decides.
 *
 * The directory must be a real directory (not a symbolic link) owned by
 * this user that no one else may write, so that nobody can plant files or
 * links in it; a new one is created with mode 0700.
 */
#ifndef FRANJA_JOBLOCK_H
#define FRANJA_JOBLOCK_H

#include "error.h"

/** A held lock. */
typedef struct {
    int fd;                    /**< the lock file, open; -1 when not held */
    char path[4200];           /**< DIR/lock */
    char dir[4096];            /**< the job directory */
    int created;               /**< 1 if joblock_acquire created the directory */
    int unlocked;              /**< 1 if used without a lock (file system without locks, --no-lock) */
} joblock;

/** joblock_acquire's results besides 0 (held) and -1 (an error, err says which). */
enum {
    JLK_BUSY = -2,             /**< another live process holds the lock */
    JLK_NOLOCKS = -3           /**< the file system refuses locks */
};

/** Creates dir if needed, checks it (joblock_check_dir) and takes the lock.
 * `what` names the render's output in the busy message ("OUT is being
 * rendered by another franja (pid P on host H, since T)"); cmdline is
 * recorded in the lock file.  Where the file system refuses locks:
 * JLK_NOLOCKS (a directory this call created is removed again), unless
 * unlocked_ok, in which case the directory is used without a lock (the
 * caller warns).  On 0, lk must be given to
 * joblock_release. */
int joblock_acquire(const char *dir, const char *what, const char *cmdline, int unlocked_ok, joblock *lk,
                fr_error *err);

/** Gives the lock up.  With remove_dir, first removes the lock file and
 * then the directory (which must be empty of everything else by then; if
 * it is not, it stays). */
void joblock_release(joblock *lk, int remove_dir);

#endif
