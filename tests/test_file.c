/* test_file.c -- files written atomically (common/file.h): the target is
 * the old file or the whole new one, temporary files keep the extension,
 * never follow a planted link and never stay behind; writers in different
 * processes (the final image and the preview of two renders) never share a
 * temporary file, nor does a process of another machine with the same pid
 * on a shared file system. */
#include <dirent.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "check.h"
#include "tmpfiles.h"
#include "file.h"

static char dir[64];

static int entries(void) { return tmpfiles_entries(dir); }

static int has(const char *path, const char *want)
{
    char *text;
    size_t len;
    fr_error err;
    if (file_read(path, &text, &len, &err))
        return 0;
    int same = len == strlen(want) && !memcmp(text, want, len);
    free(text);
    return same;
}

static void test_write_and_replace(void)
{
    char path[128];
    snprintf(path, sizeof path, "%s/a.txt", dir);
    fr_error err;
    CHECK(file_write_atomic(path, "first", 5, &err) == 0, "write: %s", err.msg);
    CHECK(has(path, "first"), "content after the first write");
    CHECK(file_write_atomic(path, "second!", 7, &err) == 0, "rewrite: %s", err.msg);
    CHECK(has(path, "second!"), "content after the second write");
    CHECK(entries() == 1, "%d files in the directory, expected only a.txt", entries());
    struct stat st;
    mode_t um = umask(022);
    umask(um);
    CHECK(stat(path, &st) == 0 && (st.st_mode & 0777) == (0666 & ~um), "mode %o", st.st_mode & 0777);
    unlink(path);
}

static void test_temporary_name(void)
{
    char path[128];
    snprintf(path, sizeof path, "%s/img.png", dir);
    file_out a, b;
    fr_error err;
    CHECK(file_out_open(path, &a, &err) == 0 && file_out_open(path, &b, &err) == 0, "open: %s", err.msg);
    CHECK(strcmp(a.tmp, b.tmp) != 0, "two writers got the same temporary file %s", a.tmp);
    size_t n = strlen(a.tmp);
    CHECK(n > 4 && !strcmp(a.tmp + n - 4, ".png"), "%s does not keep the extension", a.tmp);
    CHECK(!strncmp(a.tmp, dir, strlen(dir)) && a.tmp[strlen(dir)] == '/' && a.tmp[strlen(dir) + 1] == '.',
          "%s is not a hidden file in the target's directory", a.tmp);
    CHECK(file_out_write(&a, "aa", 2, &err) == 0 && file_out_commit(&a, path, &err) == 0, "commit: %s", err.msg);
    file_out_abort(&b);
    CHECK(has(path, "aa"), "committed content");
    CHECK(entries() == 1, "%d files after commit and abort, expected 1", entries());
    unlink(path);
}

/* Links planted at the next temporary names are skipped, not followed. */
static void test_planted_links(void)
{
    char path[128], victim[128];
    snprintf(path, sizeof path, "%s/t.bin", dir);
    snprintf(victim, sizeof victim, "%s/victim", dir);
    fr_error err;
    CHECK(file_write_atomic(victim, "keep", 4, &err) == 0, "victim: %s", err.msg);
    file_out probe;
    CHECK(file_out_open(path, &probe, &err) == 0, "open: %s", err.msg);
    /* The name is DIR/.t.bin.tmp-PID-N.bin: plant links at N+1 .. N+5. */
    char *dash = strrchr(probe.tmp, '-');
    unsigned n = (unsigned)strtoul(dash + 1, NULL, 10);
    char planted[5][256];
    for (int k = 0; k < 5; k++) {
        snprintf(planted[k], sizeof planted[k], "%.*s-%u.bin", (int)(dash - probe.tmp), probe.tmp, n + 1 + (unsigned)k);
        CHECK(symlink(victim, planted[k]) == 0, "cannot plant %s", planted[k]);
    }
    file_out_abort(&probe);
    CHECK(file_write_atomic(path, "new", 3, &err) == 0, "write past the links: %s", err.msg);
    CHECK(has(victim, "keep"), "a planted link was followed");
    CHECK(has(path, "new"), "content written past the links");
    for (int k = 0; k < 5; k++)
        unlink(planted[k]);
    unlink(path);
    unlink(victim);
}

/* Four processes open temporary files for the same target at once: four
 * different files (names and inodes), each committed whole. */
static void test_processes(void)
{
    enum { K = 4 };
    char path[128];
    snprintf(path, sizeof path, "%s/shared.png", dir);
    int up[2], go[2];
    CHECK(pipe(up) == 0 && pipe(go) == 0, "pipe");
    pid_t kids[K];
    for (int k = 0; k < K; k++) {
        kids[k] = fork();
        if (kids[k] == 0) {
            close(up[0]);
            close(go[1]);
            file_out o;
            fr_error err;
            char line[4500] = "";
            struct stat st;
            if (file_out_open(path, &o, &err) == 0 && fstat(o.fd, &st) == 0)
                snprintf(line, sizeof line, "%lu %s\n", (unsigned long)st.st_ino, o.tmp);
            else
                snprintf(line, sizeof line, "0 failed\n");
            /* One line, written at once: the pipe keeps it whole. */
            if (write(up[1], line, strlen(line)) < 0)
                _exit(1);
            char c;
            if (read(go[0], &c, 1) != 1)
                _exit(1);
            char body[32];
            int n = snprintf(body, sizeof body, "writer %d", k);
            _exit(file_out_write(&o, body, (size_t)n, &err) || file_out_commit(&o, path, &err) ? 1 : 0);
        }
    }
    close(up[1]);
    close(go[0]);
    /* Every child holds its temporary file open before any commits. */
    char buf[K * 4600];
    size_t got = 0;
    int lines = 0;
    while (lines < K && got < sizeof buf - 1) {
        ssize_t n = read(up[0], buf + got, sizeof buf - 1 - got);
        if (n <= 0)
            break;
        for (ssize_t i = 0; i < n; i++)
            lines += buf[got + (size_t)i] == '\n';
        got += (size_t)n;
    }
    buf[got] = 0;
    close(up[0]);
    CHECK(lines == K, "%d of %d writers reported a temporary file", lines, K);
    char names[K][4500];
    unsigned long inos[K];
    char *p = buf;
    for (int k = 0; k < K && lines == K; k++) {
        CHECK(sscanf(p, "%lu %4499s", &inos[k], names[k]) == 2 && inos[k] != 0, "writer line: %s", p);
        p = strchr(p, '\n') + 1;
        for (int j = 0; j < k; j++) {
            CHECK(strcmp(names[j], names[k]) != 0, "two processes got the temporary name %s", names[k]);
            CHECK(inos[j] != inos[k], "two processes got the same temporary file (inode %lu)", inos[k]);
        }
    }
    CHECK(entries() == K, "%d files while %d writers hold theirs", entries(), K);
    if (write(go[1], "gggg", K) != K)
        CHECK(0, "cannot release the writers");
    close(go[1]);
    for (int k = 0; k < K; k++) {
        int st;
        CHECK(waitpid(kids[k], &st, 0) == kids[k] && WIFEXITED(st) && WEXITSTATUS(st) == 0, "writer %d failed", k);
    }
    int whole = 0;
    for (int k = 0; k < K; k++) {
        char body[32];
        snprintf(body, sizeof body, "writer %d", k);
        whole += has(path, body);
    }
    CHECK(whole == 1, "the target is not one writer's whole file");
    CHECK(entries() == 1, "%d files after every commit, expected the target alone", entries());
    unlink(path);
}

/* A regular file at this process's next temporary name, as a process of
 * another machine with the same pid would make on a shared file system:
 * skipped, and left as it is. */
static void test_same_pid_elsewhere(void)
{
    char path[128];
    snprintf(path, sizeof path, "%s/t.exr", dir);
    fr_error err;
    file_out probe;
    CHECK(file_out_open(path, &probe, &err) == 0, "open: %s", err.msg);
    char *dash = strrchr(probe.tmp, '-');
    unsigned n = (unsigned)strtoul(dash + 1, NULL, 10);
    char theirs[4500];
    snprintf(theirs, sizeof theirs, "%.*s-%u.exr", (int)(dash - probe.tmp), probe.tmp, n + 1);
    file_out_abort(&probe);
    FILE *f = fopen(theirs, "wx");
    CHECK(f && fputs("theirs", f) >= 0 && fclose(f) == 0, "cannot plant %s", theirs);
    CHECK(file_write_atomic(path, "ours", 4, &err) == 0, "write beside their file: %s", err.msg);
    CHECK(has(theirs, "theirs"), "the other machine's temporary file was touched");
    CHECK(has(path, "ours"), "content written past their file");
    unlink(theirs);
    unlink(path);
}

static void test_failures(void)
{
    fr_error err = {{0}};
    char path[160];
    snprintf(path, sizeof path, "%s/no/such/dir/x.txt", dir);
    CHECK(file_write_atomic(path, "x", 1, &err) < 0, "a file in a missing directory was written");
    CHECK(strstr(err.msg, "no/such/dir") != NULL, "message does not name the path: %s", err.msg);
    /* A target that is a non-empty directory: the rename fails, nothing stays. */
    char sub[128], inner[160];
    snprintf(sub, sizeof sub, "%s/sub", dir);
    snprintf(inner, sizeof inner, "%s/f", sub);
    mkdir(sub, 0755);
    CHECK(file_write_atomic(inner, "x", 1, &err) == 0, "inner: %s", err.msg);
    CHECK(file_write_atomic(sub, "y", 1, &err) < 0, "a directory was replaced by a file");
    CHECK(entries() == 1, "%d entries after a failed commit, expected the directory alone", entries());
    unlink(inner);
    rmdir(sub);
}

/* A device or a FIFO is written in place, never replaced by a file: the
 * target stays what it was, and nothing is left beside it. */
static void test_devices(void)
{
    fr_error err;
    struct stat st;
    CHECK(file_write_atomic("/dev/null", "gone", 4, &err) == 0, "/dev/null: %s", err.msg);
    CHECK(stat("/dev/null", &st) == 0 && S_ISCHR(st.st_mode), "/dev/null is no longer a character device");
    file_out o;
    CHECK(file_out_in_place("/dev/null"), "/dev/null is not said to be written in place");
    CHECK(file_out_open("/dev/null", &o, &err) == 0 && o.direct, "/dev/null is not written in place");
    file_out_abort(&o);
    CHECK(stat("/dev/null", &st) == 0 && S_ISCHR(st.st_mode), "an abort removed /dev/null");

    char fifo[128];
    snprintf(fifo, sizeof fifo, "%s/pipe.ppm", dir);
    CHECK(mkfifo(fifo, 0600) == 0, "mkfifo");
    int r = open(fifo, O_RDONLY | O_NONBLOCK);
    CHECK(r >= 0, "open the FIFO for reading");
    CHECK(file_write_atomic(fifo, "P6 data", 7, &err) == 0, "FIFO: %s", err.msg);
    char got[16] = "";
    CHECK(read(r, got, sizeof got - 1) == 7 && !strcmp(got, "P6 data"), "the FIFO's reader got '%s'", got);
    close(r);
    CHECK(file_out_in_place(fifo), "a FIFO is not said to be written in place");
    CHECK(lstat(fifo, &st) == 0 && S_ISFIFO(st.st_mode), "the FIFO was replaced");
    CHECK(entries() == 1, "%d entries beside the FIFO, expected 1", entries());
    unlink(fifo);

    /* A link of the user's to a device is replaced, not followed. */
    char link[128];
    snprintf(link, sizeof link, "%s/out.pfm", dir);
    CHECK(symlink("/dev/null", link) == 0, "symlink");
    CHECK(!file_out_in_place(link), "a user's link to /dev/null is said to be written in place");
    CHECK(file_write_atomic(link, "mine", 4, &err) == 0, "link: %s", err.msg);
    CHECK(!file_out_in_place(link), "a plain file is said to be written in place");
    CHECK(lstat(link, &st) == 0 && S_ISREG(st.st_mode) && has(link, "mine"), "the link was followed");
    CHECK(stat("/dev/null", &st) == 0 && S_ISCHR(st.st_mode), "/dev/null changed");
    unlink(link);

    /* /dev/stdout reaching a plain file: the file is written, the link kept. */
    char out[128];
    snprintf(out, sizeof out, "%s/stdout.ppm", dir);
    CHECK(file_write_atomic(out, "old content", 11, &err) == 0, "out: %s", err.msg);
    fflush(stdout);
    int saved = dup(1), f = open(out, O_WRONLY);
    CHECK(saved >= 0 && f >= 0 && dup2(f, 1) == 1, "stdout to a file");
    int in_place = file_out_in_place("/dev/stdout");
    int rc = file_write_atomic("/dev/stdout", "new", 3, &err);
    dup2(saved, 1);
    close(saved);
    close(f);
    CHECK(in_place, "/dev/stdout to a file is not said to be written in place");
    CHECK(rc == 0, "/dev/stdout: %s", err.msg);
    CHECK(has(out, "new"), "the file behind /dev/stdout holds the new content only");
    CHECK(lstat("/dev/stdout", &st) == 0 && S_ISLNK(st.st_mode), "/dev/stdout is no longer a link");
    unlink(out);

    char sub[128];
    snprintf(sub, sizeof sub, "%s/sub", dir);
    CHECK(mkdir(sub, 0700) == 0, "mkdir");
    CHECK(!file_out_in_place(sub), "a directory is said to be written in place");
    CHECK(file_write_atomic(sub, "x", 1, &err) < 0 && strstr(err.msg, "cannot write over a directory"),
          "a directory: %s", err.msg);
    rmdir(sub);
}

/* file_read_max takes a file of exactly its limit and refuses one byte
 * more, naming the limit (a job's partial images can pass FILE_READ_MAX). */
static void test_read_max(void)
{
    char path[128];
    snprintf(path, sizeof path, "%s/max.bin", dir);
    fr_error err;
    CHECK(file_write_atomic(path, "0123456789", 10, &err) == 0, "write: %s", err.msg);
    char *text;
    size_t len;
    CHECK(file_read_max(path, 10, &text, &len, &err) == 0 && len == 10 && !memcmp(text, "0123456789", 10),
          "a file of exactly the limit: %s", err.msg);
    free(text);
    CHECK(file_read_max(path, 9, &text, &len, &err) < 0 && !text && strstr(err.msg, "more than the 9"),
          "a file one byte past the limit: %s", err.msg);
    unlink(path);
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/franja-file.XXXXXX");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_write_and_replace();
    test_read_max();
    test_temporary_name();
    test_planted_links();
    test_processes();
    test_same_pid_elsewhere();
    test_failures();
    test_devices();
    rmdir(dir);
    return check_done();
}
