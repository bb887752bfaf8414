/* cmd_hosts.c -- `franja hosts check` (connect to every host and say what is
 * wrong) and `franja hosts list` (parse the table only). */
#include "cmd.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "transport/cluster.h"
#include "transport/stage.h"

static const char usage[] =
    "usage: franja hosts check --hosts FILE [options]\n"
    "       franja hosts check|clean --slurm [options]\n"
    "       franja hosts list --hosts FILE | --slurm\n"
    "       franja hosts clean --hosts FILE [options]\n"
    "\n"
    "check: connects to every host of the table, verifies its key against\n"
    "known_hosts, and reports its architecture, OS, cores, worker version and\n"
    "scene cache, or exactly what is wrong with it.  Exit status 0 only if every\n"
    "host is usable.  With --slurm the hosts are the nodes of the allocation\n"
    "this runs in, reached with job steps, and cores are the CPUs allocated.\n"
    "list:  parses the table and prints it with the defaults filled in.\n"
    "clean: empties each host's scene cache (scenes a running worker uses\n"
    "       stay) and removes the temporary files of cut-off uploads.\n"
    "\n"
    "  --hosts FILE         host table (franja-hosts(5))\n"
    CLI_SLURM_HELP;

static void list(const hosts_table *t)
{
    printf("%-16s %-24s %-10s %5s  %s\n", "name", "address", "user", "cores", "workdir / worker");
    for (int i = 0; i < t->n; i++) {
        const hosts_entry *e = &t->v[i];
        char addr[300], cores[16];
        if (e->port)
            snprintf(addr, sizeof addr, strchr(e->address, ':') ? "[%s]:%d" : "%s:%d", e->address, e->port);
        else
            snprintf(addr, sizeof addr, "%s", e->address);
        snprintf(cores, sizeof cores, e->cores ? "%d" : "auto", e->cores);
        printf("%-16s %-24s %-10s %5s  %s %s%s%s%s%s\n", e->name, addr, e->user[0] ? e->user : "-", cores,
               hosts_is_local(e) ? "-" : hosts_workdir(e), e->worker[0] ? e->worker : "(default worker)",
               e->arch[0] ? " arch=" : "", e->arch, e->os[0] ? " os=" : "", e->os);
    }
}

static int check(const hosts_table *t, const tr_options *o, int slurm)
{
    cluster_host *cl = calloc((size_t)t->n, sizeof *cl);
    if (!cl)
        return 1;
    for (int i = 0; i < t->n; i++)
        cl[i].entry = &t->v[i];
    cluster_open(cl, t->n, o, NULL, 0);
    if (slurm)
        cluster_drop_other_versions(cl, t->n);
    int bad = 0;
    printf("%-16s %-6s %-8s %-9s %5s  %-36s %-8s %s\n", "host", "state", "arch", "os", "cores", "worker", "walk",
           "scene cache");
    for (int i = 0; i < t->n; i++) {
        cluster_host *h = &cl[i];
        if (!h->tr) {
            bad++;
            printf("%-16s %-6s %s\n", h->entry->name, "FAIL", h->err.msg);
            continue;
        }
        /* The release (Debian codename) is what deploy matches builds on;
         * uname's kernel name says little. */
        char arch[64], os[64];
        fr_error e1;
        if (stage_sysinfo(h->tr, arch, os, &e1) || !os[0])
            snprintf(os, sizeof os, "%s", h->info.os);
        char warn[400] = "";
        if (h->entry->arch[0] && strcmp(h->entry->arch, h->info.arch)) {
            snprintf(warn, sizeof warn, "  PROBLEM: the table says arch=%s", h->entry->arch);
            bad++;
        } else if (h->entry->os[0] && os[0] && strcmp(h->entry->os, os)) {
            snprintf(warn, sizeof warn, "  PROBLEM: the table says os=%s", h->entry->os);
            bad++;
        }
        int files;
        uint64_t bytes;
        char cache[64];
        fr_error e2;
        if (!tr_host_workdir(h->tr)[0])
            snprintf(cache, sizeof cache, "local, none needed");
        else if (stage_cache(h->tr, &files, &bytes, &e2))
            snprintf(cache, sizeof cache, "unreadable");
        else
            snprintf(cache, sizeof cache, "%d scene%s, %.1f MB", files, files == 1 ? "" : "s", bytes / 1e6);
        /* The scene reaches the host as render sends it (SFTP). */
        fr_error e3;
        if (stage_try_upload(h->tr, &e3)) {
            size_t l = strlen(warn);
            snprintf(warn + l, sizeof warn - l, "  PROBLEM: %s", e3.msg);
            bad++;
        }
        int cores = h->entry->cores ? h->entry->cores : h->info.cores;
        printf("%-16s %-6s %-8s %-9s %5d  %-36s %-8s %s%s\n", h->entry->name, "ok", h->info.arch, os, cores,
               h->info.version, h->info.walk[0] ? h->info.walk : "-", cache, warn);
    }
    fr_error err;
    if (cluster_check_versions(cl, t->n, &err)) {
        printf("problem: %s\n", err.msg);
        bad++;
    }
    cluster_close(cl, t->n);
    free(cl);
    if (bad)
        printf("%d problem%s found\n", bad, bad == 1 ? "" : "s");
    else
        printf("all %d host%s usable\n", t->n, t->n == 1 ? "" : "s");
    return bad ? 1 : 0;
}

static int clean_step(cluster_host *h, int i, void *ctx, fr_error *err)
{
    return stage_clean(h->tr, &((stage_cleaned *)ctx)[i], err);
}

static int clean(const hosts_table *t, const tr_options *o)
{
    cluster_host *cl = calloc((size_t)t->n, sizeof *cl);
    stage_cleaned *done = calloc((size_t)t->n, sizeof *done);
    if (!cl || !done) {
        free(cl);
        free(done);
        return 1;
    }
    for (int i = 0; i < t->n; i++)
        cl[i].entry = &t->v[i];
    cluster_each(cl, t->n, o, clean_step, done);
    int bad = 0;
    for (int i = 0; i < t->n; i++) {
        const stage_cleaned *d = &done[i];
        if (!cl[i].tr) {
            bad++;
            printf("%-16s FAIL %s\n", t->v[i].name, cl[i].err.msg);
        } else if (hosts_is_local(&t->v[i])) {
            printf("%-16s ok   local: no scene cache\n", t->v[i].name);
        } else {
            char size[32];
            hosts_format_size(d->bytes, size);
            printf("%-16s ok   removed %d scene%s (%s), %d temporary file%s", t->v[i].name, d->removed,
                   d->removed == 1 ? "" : "s", size, d->temp, d->temp == 1 ? "" : "s");
            if (d->in_use)
                printf("; kept %d in use by a running worker", d->in_use);
            printf("\n");
        }
    }
    cluster_close(cl, t->n);
    free(cl);
    free(done);
    return bad ? 1 : 0;
}

int cmd_hosts(int argc, char **argv)
{
    static const struct option longopts[] = {CLI_COMMON_LONGOPTS, CLI_SLURM_LONGOPTS, {NULL, 0, NULL, 0}};
    tr_options o;
    cli_transport_defaults(&o);
    cli_slurm sl = {0};
    const char *path = NULL, *what = NULL;
    int c, r = CLI_TAKEN;
    /* Parsed in a copy: argv stays as typed, for the salloc hint. */
    char **args = opt_copy(argc, argv);
    if (!args)
        return 1;
    optind = 0;
    while (r == CLI_TAKEN && (c = opt_next("hosts", argc, args, "h", longopts)) != -1) {
        r = c == '?' ? CLI_BAD : cli_slurm_opt("hosts", c, optarg, &sl);
        if (r == CLI_OTHER)
            r = cli_common_opt("hosts", c, optarg, usage, &o, &path);
    }
    for (int i = optind; r == CLI_TAKEN && i < argc; i++) {
        if (!what && (!strcmp(args[i], "check") || !strcmp(args[i], "list") || !strcmp(args[i], "clean")))
            what = args[i];
        else {
            fprintf(stderr, "franja hosts: unexpected '%s'%s (see franja hosts --help)\n", args[i],
                    what ? "" : "; expected check, list or clean");
            r = CLI_BAD;
        }
    }
    free(args);
    if (r != CLI_TAKEN)
        return r == CLI_HELP ? 0 : 2;
    if (!what || (!path && !sl.on)) {
        fprintf(stderr, "franja hosts: expected 'check', 'list' or 'clean' and --hosts FILE or --slurm "
                        "(see franja hosts --help)\n");
        return 2;
    }
    if (cli_slurm_check("hosts", &sl, path))
        return 2;
    hosts_table t;
    slurm_alloc alloc;
    memset(&alloc, 0, sizeof alloc);
    if (sl.on ? cli_slurm_hosts("hosts", &sl, argc, argv, &o, &alloc, &t) : cli_load_hosts("hosts", path, &t))
        return 2;
    int rc = 0;
    if (!strcmp(what, "list"))
        list(&t);
    else if (!strcmp(what, "clean"))
        rc = clean(&t, &o);
    else
        rc = check(&t, &o, sl.on);
    hosts_free(&t);
    slurm_close(&alloc);
    return rc;
}
