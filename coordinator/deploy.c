/* deploy.c -- franja deploy: the matching worker build onto every host. */
#include "deploy.h"

#include <libssh/libssh.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "fbin.h"
#include "hosts.h"
#include "transport.h"

static const char usage[] =
    "usage: franja deploy --hosts FILE [--dist DIR] [options]\n"
    "\n"
    "Installs on every SSH host of the table the franja-worker built for it, as\n"
    "WORKDIR/franja-worker, then checks that the host's worker reports this\n"
    "build's version and scene format.  The build is DIR/OS-ARCH/franja-worker\n"
    "(made by `make dist`), where OS and ARCH are the table's os= and arch= or\n"
    "else what the host says (VERSION_CODENAME in /etc/os-release, uname -m);\n"
    "when there is no build for its OS, DIR/static-ARCH/franja-worker, which\n"
    "runs on any Linux.  Local hosts are left alone.\n"
    "\n"
    "  --hosts FILE         the host table (franja-hosts(5))\n"
    "  --dist DIR           where the builds are (default: dist in the current\n"
    "                       directory, else the dist beside this program's bin/)\n";

/* One host's deployment, run in its own thread. */
typedef struct {
    const hosts_entry *e;
    const tr_options *o;
    const char *dist;
    const char *expect;        /* the version line the worker must print */
    int local;
    int ok;
    char report[2048];
} job;

static int is_dir(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

static int is_file(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

/* The Debian name of an architecture as uname -m (or a host table) gives it. */
static const char *debian_arch(const char *a)
{
    if (!strcmp(a, "x86_64") || !strcmp(a, "amd64"))
        return "amd64";
    if (!strcmp(a, "aarch64") || !strcmp(a, "arm64"))
        return "arm64";
    return a;
}

/* dist/OS-ARCH/franja-worker if os is given and that build exists, else
 * dist/static-ARCH/franja-worker; the build's name goes to build[128]. */
static int pick(const char *dist, const char *os, const char *arch, char *path, size_t cap, char *build,
                fr_error *err)
{
    if (os[0]) {
        snprintf(build, 128, "%s-%s", os, arch);
        snprintf(path, cap, "%s/%s/franja-worker", dist, build);
        if (is_file(path))
            return 0;
    }
    snprintf(build, 128, "static-%s", arch);
    snprintf(path, cap, "%s/%s/franja-worker", dist, build);
    if (is_file(path))
        return 0;
    if (os[0])
        return fr_fail(err, "no worker build for it: neither %s/%s-%s nor %s/static-%s has franja-worker "
                       "(make dist)", dist, os, arch, dist, arch);
    return fr_fail(err, "no worker build for it: %s/static-%s has no franja-worker and its OS is unknown "
                   "(make dist, or give os= in the host table)", dist, arch);
}

static void *deploy_one(void *arg)
{
    job *j = arg;
    const hosts_entry *e = j->e;
    if (hosts_is_local(e)) {
        j->local = 1;
        snprintf(j->report, sizeof j->report, "%s: local host, runs this machine's worker; skipped", e->name);
        return NULL;
    }
    fr_error err;
    tr_host *h = NULL;
    tr_info info;
    char arch[32], os[64], path[PATH_MAX], build[128], remote[1024], note[700] = "";
    if (tr_connect(e, j->o, &h, &err) || tr_sysinfo(h, arch, os, &err))
        goto fail;
    /* The table wins over what the host says: an emulated or chrooted host
     * may report the machine it runs on. */
    const char *want = debian_arch(e->arch[0] ? e->arch : arch);
    if (e->arch[0] && strcmp(want, debian_arch(arch)))
        snprintf(note, sizeof note, " (the table says arch=%s, the host reports %s)", e->arch, arch);
    if (pick(j->dist, e->os[0] ? e->os : os, want, path, sizeof path, build, &err) ||
        tr_install(h, path, "franja-worker", remote, sizeof remote, &err) || tr_probe(h, &info, &err))
        goto fail;
    if (strcmp(info.version, j->expect)) {
        fr_fail(&err, "installed %s as %s, but the host's worker%s%s reports '%s', not '%s'", build, remote,
                e->worker[0] ? " " : "", e->worker, info.version, j->expect);
        goto fail;
    }
    if (e->worker[0] && strcmp(e->worker, remote))
        snprintf(note + strlen(note), sizeof note - strlen(note), " (checked through the table's worker=%s)",
                 e->worker);
    snprintf(j->report, sizeof j->report, "%s: %s -> %s: %s%s", e->name, build, remote, info.version, note);
    j->ok = 1;
    tr_close(h);
    return NULL;
fail:
    snprintf(j->report, sizeof j->report, "%s: FAILED: %s%s", e->name, err.msg, note);
    tr_close(h);
    return NULL;
}

/* ./dist, else the dist beside the bin/ directory this program is in. */
static const char *default_dist(char *buf, size_t cap)
{
    if (is_dir("dist"))
        return "dist";
    return cli_beside_exe("../dist", buf, cap) && is_dir(buf) ? buf : NULL;
}

static int deploy_all(const hosts_table *t, const tr_options *o, const char *dist)
{
    char expect[128];
    snprintf(expect, sizeof expect, "franja-worker %s scene-format %d", FRANJA_VERSION, FBIN_VERSION);
    job jobs[t->n > 0 ? t->n : 1];
    pthread_t tid[t->n > 0 ? t->n : 1];
    int started[t->n > 0 ? t->n : 1];
    for (int i = 0; i < t->n; i++) {
        jobs[i] = (job){.e = &t->v[i], .o = o, .dist = dist, .expect = expect};
        started[i] = pthread_create(&tid[i], NULL, deploy_one, &jobs[i]) == 0;
        if (!started[i])
            deploy_one(&jobs[i]);
    }
    int remote = 0, done = 0;
    for (int i = 0; i < t->n; i++) {
        if (started[i])
            pthread_join(tid[i], NULL);
        printf("%s\n", jobs[i].report);
        remote += !jobs[i].local;
        done += jobs[i].ok;
    }
    if (remote == 0)
        printf("no SSH host in %s: nothing to deploy\n", t->path);
    else
        printf("deployed to %d of %d SSH host%s\n", done, remote, remote == 1 ? "" : "s");
    return done == remote ? 0 : 1;
}

int cmd_deploy(int argc, char **argv)
{
    tr_options o;
    cli_transport_defaults(&o);
    const char *path = NULL, *dist = NULL;
    for (int i = 1; i < argc; i++) {
        int c = cli_common_option(argc, argv, &i, usage, &o, &path);
        if (c != CLI_OTHER) {
            if (c == CLI_TAKEN)
                continue;
            return c == CLI_HELP ? 0 : 2;
        }
        if (!strcmp(argv[i], "--dist") && i + 1 < argc)
            dist = argv[++i];
        else {
            fprintf(stderr, "franja deploy: unexpected '%s' (see franja deploy --help)\n", argv[i]);
            return 2;
        }
    }
    if (!path) {
        fprintf(stderr, "franja deploy: --hosts FILE is required (see franja deploy --help)\n");
        return 2;
    }
    char buf[PATH_MAX + 16];
    if (!dist && !(dist = default_dist(buf, sizeof buf))) {
        fprintf(stderr, "franja deploy: no dist directory here or beside this program; build one with "
                        "`make dist` or give --dist DIR\n");
        return 2;
    }
    if (!is_dir(dist)) {
        fprintf(stderr, "franja deploy: --dist %s: not a directory\n", dist);
        return 2;
    }
    hosts_table t;
    if (cli_load_hosts("deploy", path, &t))
        return 2;
    ssh_init();
    int rc = deploy_all(&t, &o, dist);
    ssh_finalize();
    hosts_free(&t);
    return rc;
}
