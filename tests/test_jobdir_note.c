/* test_jobdir_note.c -- what a failed render says it kept is checked at
 * that moment (jobdir.h, job_kept_note): finished rows kept, no finished
 * slab, or a job directory removed, or replaced by a file or a link, by
 * another process. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "jobdir.h"

static void touch(const char *dir, const char *name)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL, "cannot create %s", path);
    if (f)
        fclose(f);
}

int main(void)
{
    char top[] = "/tmp/franja-note.XXXXXX", dir[512], note[4400], path[512];
    if (!mkdtemp(top)) {
        perror("mkdtemp");
        return 1;
    }
    snprintf(dir, sizeof dir, "%s/out.png.franja-job", top);
    CHECK(mkdir(dir, 0700) == 0, "mkdir %s", dir);

    job_kept_note(dir, note, sizeof note);
    CHECK(strstr(note, "no finished slab is in") && strstr(note, dir) && strstr(note, "nothing was kept") &&
              !strstr(note, "--resume"),
          "an empty job directory: %s", note);

    touch(dir, "rows-0-4.pf");
    touch(dir, "rows-8-16.pf");
    touch(dir, ".rows-4-8.pf.tmp-1-0.pf");
    job_kept_note(dir, note, sizeof note);
    CHECK(strstr(note, "12 finished rows are kept in") && strstr(note, dir) && strstr(note, "rerun with --resume"),
          "two finished slabs (12 rows) and a temporary file: %s", note);

    /* Another process removes the directory. */
    snprintf(path, sizeof path, "%s/rows-0-4.pf", dir);
    unlink(path);
    snprintf(path, sizeof path, "%s/rows-8-16.pf", dir);
    unlink(path);
    snprintf(path, sizeof path, "%s/.rows-4-8.pf.tmp-1-0.pf", dir);
    unlink(path);
    CHECK(rmdir(dir) == 0, "rmdir %s", dir);
    job_kept_note(dir, note, sizeof note);
    CHECK(strstr(note, "was removed by another process; nothing was kept") && !strstr(note, "--resume"),
          "a removed job directory: %s", note);

    /* ... or puts a file, or a link to a directory with slabs, in its place. */
    touch(top, "out.png.franja-job");
    job_kept_note(dir, note, sizeof note);
    CHECK(strstr(note, "was removed by another process") != NULL, "a file in its place: %s", note);
    unlink(dir);
    char other[512];
    snprintf(other, sizeof other, "%s/other", top);
    CHECK(mkdir(other, 0700) == 0, "mkdir %s", other);
    touch(other, "rows-0-4.pf");
    CHECK(symlink(other, dir) == 0, "symlink");
    job_kept_note(dir, note, sizeof note);
    CHECK(strstr(note, "was removed by another process") != NULL, "a link in its place: %s", note);
    unlink(dir);
    snprintf(path, sizeof path, "%s/rows-0-4.pf", other);
    unlink(path);
    rmdir(other);
    rmdir(top);
    return check_done();
}
