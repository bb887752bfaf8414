/* main.c -- the franja command: dispatches to its subcommands. */
#include <libssh/libssh.h>
#include <stdio.h>
#include <string.h>

#include "cmd.h"
#include "protocol.h"

static const char usage[] =
    "usage: franja render SCENE -o OUT [--hosts FILE | --slurm] [-j N] [--spp N]\n"
    "                     [--size WxH] [--exposure E] [--resume] [--accept-new-hosts] ...\n"
    "       franja compile ...\n"
    "       franja hosts check|list --hosts FILE | --slurm\n"
    "       franja deploy --hosts FILE [--dist DIR]\n"
    "       franja --help | --version\n"
    "\n"
    "Franja renders a scene with a path tracer, on this machine's cores, on a\n"
    "cluster over SSH, or on the CPUs of a Slurm allocation.  `franja COMMAND\n"
    "--help` describes each command; the manual pages are franja(1),\n"
    "franja-worker(1) and franja-hosts(5).\n";

int main(int argc, char **argv)
{
    if (argc < 2) {
        fputs(usage, stderr);
        return 2;
    }
    const char *cmd = argv[1];
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h") || !strcmp(cmd, "help")) {
        fputs(usage, stdout);
        return 0;
    }
    if (!strcmp(cmd, "--version")) {
        char line[128];
        proto_version_line("franja", line, sizeof line);
        printf("%s\n", line);
        return 0;
    }
    if (!strcmp(cmd, "compile"))
        return cmd_compile(argc - 1, argv + 1);
    if (!strcmp(cmd, "deploy"))
        return cmd_deploy(argc - 1, argv + 1);
    int rc;
    if (!strcmp(cmd, "render") || !strcmp(cmd, "hosts")) {
        ssh_init();
        rc = !strcmp(cmd, "render") ? cmd_render(argc - 1, argv + 1) : cmd_hosts(argc - 1, argv + 1);
        ssh_finalize();
        return rc;
    }
    fprintf(stderr, "franja: unknown command '%s'\n\n%s", cmd, usage);
    return 2;
}
