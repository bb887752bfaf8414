/* cmd_deploy.c -- franja deploy: the matching worker build onto every host. */
#include "cmd.h"

#include <libssh/libssh.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "transport/cluster.h"
#include "transport/hosts.h"
#include "protocol.h"
#include "transport/stage.h"

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

/* What every host's deployment needs, and what each one found. */
typedef struct {
    const char *dist;
    const char *expect;        /* the version line the worker must print */
    char (*report)[1200];      /* per host: what was installed */
    char (*note)[700];         /* per host: remarks */
} deploy_ctx;

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

/* 1 if s may be a part of a file name under dist/: letters, digits and
 * . _ + -, not starting with . or - (so no "..", no "/", nothing a
 * terminal would act on). */
static int plain_name(const char *s)
{
    if (!s[0] || s[0] == '.' || s[0] == '-')
        return 0;
    for (; *s; s++)
        if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || (*s >= '0' && *s <= '9') || *s == '.' ||
              *s == '_' || *s == '+' || *s == '-'))
            return 0;
    return 1;
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

/* One host's deployment (a cluster_step, in the host's own thread). */
static int deploy_one(cluster_host *ch, int i, void *vctx, fr_error *err)
{
    deploy_ctx *c = vctx;
    const hosts_entry *e = ch->entry;
    tr_host *h = ch->tr;
    char *note = c->note[i];
    char arch[32], os[64], path[PATH_MAX], build[128], remote[1024];
    if (stage_sysinfo(h, arch, os, err))
        return -1;
    /* The table wins over what the host says: an emulated or chrooted host
     * may report the machine it runs on. */
    const char *want = debian_arch(e->arch[0] ? e->arch : arch);
    if (e->arch[0] && strcmp(want, debian_arch(arch)))
        snprintf(note, 700, " (the table says arch=%s, the host reports %s)", e->arch, arch);
    /* What the host says becomes part of a local path: plain names only. */
    const char *use_os = e->os[0] ? e->os : os;
    if (!plain_name(want))
        return fr_fail(err, "the architecture '%s' it reports is not a plain name; give arch= in the host table",
                       proto_printable(arch));
    if (use_os[0] && !plain_name(use_os))
        return fr_fail(err, "the OS name '%s' it reports (VERSION_CODENAME) is not a plain name; give os= in "
                       "the host table", proto_printable(os));
    proto_host info;
    if (pick(c->dist, use_os, want, path, sizeof path, build, err) ||
        stage_install(h, path, "franja-worker", remote, sizeof remote, err) || stage_probe(h, &info, err))
        return -1;
    if (strcmp(info.version, c->expect))
        return fr_fail(err, "installed %s as %s, but the host's worker%s%s reports '%s', not '%s'", build, remote,
                       e->worker[0] ? " " : "", e->worker, info.version, c->expect);
    if (e->worker[0] && strcmp(e->worker, remote))
        snprintf(note + strlen(note), 700 - strlen(note), " (checked through the table's worker=%s)", e->worker);
    snprintf(c->report[i], 1200, "%s -> %s: %s", build, remote, info.version);
    return 0;
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
    proto_version_line("franja-worker", expect, sizeof expect);
    int n = t->n;
    cluster_host *hosts = calloc((size_t)n, sizeof *hosts);
    int *remote_of = calloc((size_t)n, sizeof *remote_of);
    deploy_ctx c = {dist, expect, calloc((size_t)n, sizeof *c.report), calloc((size_t)n, sizeof *c.note)};
    if (!hosts || !remote_of || !c.report || !c.note) {
        free(hosts), free(remote_of), free(c.report), free(c.note);
        fprintf(stderr, "franja deploy: out of memory\n");
        return 1;
    }
    /* Local hosts run this machine's worker: only SSH hosts are deployed to. */
    int remote = 0;
    for (int i = 0; i < n; i++)
        if (!hosts_is_local(&t->v[i])) {
            remote_of[i] = remote;
            hosts[remote++].entry = &t->v[i];
        }
    cluster_each(hosts, remote, o, deploy_one, &c);
    int done = 0;
    for (int i = 0; i < n; i++) {
        const hosts_entry *e = &t->v[i];
        if (hosts_is_local(e)) {
            printf("%s: local host, runs this machine's worker; skipped\n", e->name);
            continue;
        }
        int k = remote_of[i];
        if (hosts[k].tr) {
            printf("%s: %s%s\n", e->name, c.report[k], c.note[k]);
            done++;
        } else {
            printf("%s: FAILED: %s%s\n", e->name, hosts[k].err.msg, c.note[k]);
        }
    }
    if (remote == 0)
        printf("no SSH host in %s: nothing to deploy\n", t->path);
    else
        printf("deployed to %d of %d SSH host%s\n", done, remote, remote == 1 ? "" : "s");
    cluster_close(hosts, remote);
    free(hosts), free(remote_of), free(c.report), free(c.note);
    return done == remote ? 0 : 1;
}

int cmd_deploy(int argc, char **argv)
{
    enum { DIST = CLI_OPT_OWN };
    static const struct option longopts[] = {CLI_COMMON_LONGOPTS, {"dist", required_argument, NULL, DIST},
                                             {NULL, 0, NULL, 0}};
    tr_options o;
    cli_transport_defaults(&o);
    const char *path = NULL, *dist = NULL;
    int c;
    optind = 0;
    while ((c = opt_next("deploy", argc, argv, "h", longopts)) != -1) {
        if (c == DIST) {
            dist = optarg;
            continue;
        }
        int r = c == '?' ? CLI_BAD : cli_common_opt("deploy", c, optarg, usage, &o, &path);
        if (r == CLI_OTHER) {
            fprintf(stderr, "franja deploy: unexpected option (see franja deploy --help)\n");
            return 2;
        }
        if (r != CLI_TAKEN)
            return r == CLI_HELP ? 0 : 2;
    }
    if (optind < argc) {
        fprintf(stderr, "franja deploy: unexpected '%s' (see franja deploy --help)\n", argv[optind]);
        return 2;
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
