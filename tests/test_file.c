/* test_file.c -- files written atomically (common/file.h): the target is
 * the old file or the whole new one, temporary files keep the extension,
 * never follow a planted link and never stay behind. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "file.h"

static char dir[64];

/* Entries of dir other than . and .. */
static int entries(void)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
    if (d)
        closedir(d);
    return n;
}

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

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/franja-file.XXXXXX");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_write_and_replace();
    test_temporary_name();
    test_planted_links();
    test_failures();
    rmdir(dir);
    return check_done();
}
