/* test_slurm.c -- slurm_open reading an allocation from the environment,
 * with a stand-in `scontrol` first on PATH that prints a given node list
 * (with or without the final newline scontrol normally writes). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "transport/slurm.h"

static char dir[] = "/tmp/franja-test-slurm-XXXXXX";

/* Makes `scontrol show hostnames LIST` print `out` exactly. */
static void fake_scontrol(const char *out)
{
    char path[256], data[256];
    snprintf(path, sizeof path, "%s/out", dir);
    FILE *f = fopen(path, "w");
    fputs(out, f);
    fclose(f);
    snprintf(path, sizeof path, "%s/scontrol", dir);
    snprintf(data, sizeof data, "#!/bin/sh\ncat '%s/out'\n", dir);
    f = fopen(path, "w");
    fputs(data, f);
    fclose(f);
    chmod(path, 0755);
}

/* Opens an allocation of the nodes `out` names; want_n < 0: must fail. */
static void nodes(const char *what, const char *out, int want_n, const char *const *want)
{
    fake_scontrol(out);
    slurm_alloc a;
    fr_error err = {0};
    int rc = slurm_open(&a, "/bin/true", 5, &err);
    if (want_n < 0) {
        CHECK(rc != 0, "%s: accepted (%d nodes)", what, a.n);
        CHECK(rc == 0 || strstr(err.msg, "SLURM_JOB_NODELIST"), "%s: error '%s' does not name the variable", what,
              err.msg);
        slurm_close(&a);
        return;
    }
    CHECK(rc == 0, "%s: %s", what, err.msg);
    CHECK(a.n == want_n, "%s: %d nodes, want %d", what, a.n, want_n);
    for (int i = 0; rc == 0 && i < a.n && i < want_n; i++)
        CHECK(!strcmp(a.node[i], want[i]), "%s: node %d is '%s', want '%s'", what, i, a.node[i], want[i]);
    slurm_close(&a);
}

int main(void)
{
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    char path[4096];
    snprintf(path, sizeof path, "%s:%s", dir, getenv("PATH") ? getenv("PATH") : "/usr/bin:/bin");
    setenv("PATH", path, 1);
    setenv("SLURM_JOB_ID", "42", 1);
    setenv("SLURM_JOB_NODELIST", "n[1-3]", 1);
    setenv("SLURM_JOB_CPUS_PER_NODE", "2(x3)", 1);
    unsetenv("SLURM_STEP_ID");

    static const char *const three[] = {"n1", "n2", "n3"};
    nodes("three lines", "n1\nn2\nn3\n", 3, three);
    nodes("no final newline", "n1\nn2\nn3", 3, three);
    nodes("nothing", "", -1, NULL);
    nodes("a bad name", "n1\nn 2\nn3\n", -1, NULL);

    snprintf(path, sizeof path, "%s/scontrol", dir);
    unlink(path);
    snprintf(path, sizeof path, "%s/out", dir);
    unlink(path);
    rmdir(dir);
    return check_done();
}
