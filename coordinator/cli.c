/* cli.c -- option parsing shared by the subcommands. */
#include "cli.h"


#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Help text for the transport options (CLI_COMMON_LONGOPTS). */
static const char cli_transport_help[] =
    "  --known-hosts FILE   SSH known_hosts file (default ~/.ssh/known_hosts)\n"
    "  --accept-new-hosts   add the keys of hosts not yet known (never changed ones)\n"
    "  --ssh-config FILE    SSH client configuration (default ~/.ssh/config)\n"
    "  --no-ssh-config      do not read any SSH client configuration\n"
    "  --timeout S          connect time-out and longest silence of a host (default 10)\n";

const char *cli_beside_exe(const char *name, char *buf, size_t cap)
{
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0)
        return NULL;
    exe[n] = 0;
    char *slash = strrchr(exe, '/');
    if (!slash)
        return NULL;
    *slash = 0;
    int len = snprintf(buf, cap, "%s/%s", exe, name);
    return len < 0 || (size_t)len >= cap ? NULL : buf;
}

/* The franja-worker next to this executable, or NULL. */
static const char *cli_local_worker(void)
{
    static char path[PATH_MAX];
    return cli_beside_exe("franja-worker", path, sizeof path);
}

void cli_note_stderr(void *ctx, const char *line)
{
    (void)ctx;
    fprintf(stderr, "franja: %s\n", line);
}

void cli_transport_defaults(tr_options *o)
{
    memset(o, 0, sizeof *o);
    o->notes = (note_sink){cli_note_stderr, NULL};
    o->read_ssh_config = 1;
    o->timeout_s = 10;
    o->local_worker = cli_local_worker();
}

int cli_common_opt(const char *cmd, int c, const char *v, const char *usage, tr_options *o, const char **hosts)
{
    uint32_t t;
    switch (c) {
    case CLI_OPT_HELP:
        fputs(usage, stdout);
        fputs(cli_transport_help, stdout);
        return CLI_HELP;
    case CLI_OPT_HOSTS:
        *hosts = v;
        return CLI_TAKEN;
    case CLI_OPT_KNOWN_HOSTS:
        o->known_hosts = v;
        return CLI_TAKEN;
    case CLI_OPT_ACCEPT_NEW:
        o->accept_new = 1;
        return CLI_TAKEN;
    case CLI_OPT_NO_SSH_CONFIG:
        o->read_ssh_config = 0;
        return CLI_TAKEN;
    case CLI_OPT_SSH_CONFIG:
        if (access(v, R_OK)) {
            fprintf(stderr, "franja %s: --ssh-config: cannot read '%s': %s\n", cmd, v, strerror(errno));
            return CLI_BAD;
        }
        o->ssh_config = v;
        return CLI_TAKEN;
    case CLI_OPT_TIMEOUT:
        if (opt_uint(cmd, "--timeout", v, 1, 3600, &t))
            return CLI_BAD;
        o->timeout_s = (int)t;
        return CLI_TAKEN;
    }
    return CLI_OTHER;
}

int cli_slurm_opt(const char *cmd, int c, const char *v, cli_slurm *s)
{
    static const char *const names[] = {"--worker", "--workdir", "--shared-workdir"};
    if (c == CLI_OPT_SLURM) {
        s->on = 1;
        return CLI_TAKEN;
    }
    if (c != CLI_OPT_WORKER && c != CLI_OPT_WORKDIR && c != CLI_OPT_SHARED_WORKDIR)
        return CLI_OTHER;
    const char *a = names[c - CLI_OPT_WORKER];
    if (v[0] != '/') {
        fprintf(stderr, "franja %s: %s: '%s' is not an absolute path (the nodes must find it wherever they run)\n",
                cmd, a, v);
        return CLI_BAD;
    }
    if (strlen(v) >= 400) {
        fprintf(stderr, "franja %s: %s: path too long (at most 399 bytes)\n", cmd, a);
        return CLI_BAD;
    }
    if (c == CLI_OPT_WORKER)
        s->worker = v;
    else {
        if (s->workdir) {
            fprintf(stderr, "franja %s: give one of --workdir and --shared-workdir, once\n", cmd);
            return CLI_BAD;
        }
        s->workdir = v;
        s->shared = c == CLI_OPT_SHARED_WORKDIR;
    }
    return CLI_TAKEN;
}

int cli_slurm_check(const char *cmd, const cli_slurm *s, const char *hosts)
{
    if (s->on && hosts) {
        fprintf(stderr, "franja %s: --slurm and --hosts exclude each other (the allocation is the host list)\n",
                cmd);
        return -1;
    }
    if (!s->on && (s->worker || s->workdir)) {
        fprintf(stderr, "franja %s: %s applies to --slurm only (a host table has worker= and workdir=)\n", cmd,
                s->worker ? "--worker" : s->shared ? "--shared-workdir" : "--workdir");
        return -1;
    }
    return 0;
}

int cli_slurm_hosts(const char *cmd, const cli_slurm *s, int argc, char **argv, tr_options *o, slurm_alloc *a,
                    hosts_table *t)
{
    fr_error err;
    const char *worker = s->worker ? s->worker : o->local_worker;
    if (slurm_open(a, worker, o->timeout_s, &err) == 0) {
        if (s->workdir) {
            snprintf(a->workdir, sizeof a->workdir, "%s", s->workdir);
            a->shared = s->shared;
        }
        if (slurm_hosts(a, t, &err) == 0) {
            slurm_serve(a, o);
            return 0;
        }
    }
    fprintf(stderr, "franja %s: --slurm: %s\n", cmd, err.msg);
    if (!a->job[0] && !getenv("SLURM_JOB_ID")) {
        /* The command as typed, program name first. */
        char **words = calloc((size_t)argc + 1, sizeof *words);
        if (words) {
            words[0] = program_invocation_name;
            for (int k = 0; k < argc; k++)
                words[k + 1] = argv[k];
            char hint[6000];
            slurm_hint(argc + 1, words, hint, sizeof hint);
            fprintf(stderr, "%s\n", hint);
            free(words);
        }
    }
    slurm_close(a);
    return -1;
}

int cli_load_hosts(const char *cmd, const char *path, hosts_table *t)
{
    fr_error err;
    if (hosts_load(path, t, &err) == 0)
        return 0;
    fprintf(stderr, "franja %s: %s\n", cmd, err.msg);
    return -1;
}
