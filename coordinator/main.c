/* main.c -- the franja command: dispatches to its subcommands. */
#include <libssh/libssh.h>
#include <stdio.h>
#include <string.h>

#include "cmd.h"
#include "protocol.h"

static const char usage[] =
    "usage: franja render SCENE [-o OUT] [--hosts FILE | --slurm [--worker PATH]\n"
    "                     [--workdir DIR | --shared-workdir DIR]] [-j N] [--spp N]\n"
    "                     [--size WxH | --scale S] [--crop X0:Y0:X1:Y1 [--crop-output]]\n"
    "                     [--camera NAME] [--allow-path DIR]... [--integrator path|bdpt|mlt]\n"
    "                     [--noise-threshold E] [--passes LIST]\n"
    "                     [--exposure E] [--tonemap none|filmic] [--exr-half]\n"
    "                     [--exr-compression C] [--jpeg-quality Q] [--reproducible]\n"
    "                     [--frames LIST [--overwrite] [--fps F] [--shutter S]]\n"
    "                     [--time-limit T]\n"
    "                     [--limit NAME=VALUE]...\n"
    "                     [--resume | --fresh]\n"
    "                     [--job DIR] [--keep-job] [--no-lock] [--slab-rows N]\n"
    "                     [--retries N] [--preview FILE [--preview-every S]]\n"
    "                     [--progress auto|json] [--monitor PORT [--monitor-open]]\n"
    "                     [SSH-OPTIONS]\n"
    "       franja compile SCENE [-o FILE] [--camera NAME] [--allow-path DIR]...\n"
    "                      [--limit NAME=VALUE]...\n"
    "       franja hosts check|list|clean --hosts FILE | --slurm [--worker PATH]\n"
    "                     [--workdir DIR | --shared-workdir DIR] [SSH-OPTIONS]\n"
    "       franja deploy --hosts FILE [--dist DIR] [SSH-OPTIONS]\n"
    "       franja stitch JOBDIR -o OUT [--exposure E] [--tonemap none|filmic]\n"
    "       franja help [COMMAND]\n"
    "       franja version | -V | --version\n"
    "SSH-OPTIONS: [--known-hosts FILE] [--accept-new-hosts]\n"
    "             [--ssh-config FILE | --no-ssh-config] [--timeout S]\n"
    "\n"
    "Franja renders a scene with a path tracer, on this machine's cores, on a\n"
    "cluster over SSH, or on the CPUs of a Slurm allocation.  `franja help\n"
    "COMMAND` or `franja COMMAND --help` describes each command; the manual\n"
    "pages are franja(1), franja-worker(1) and franja-hosts(5).\n";

typedef int (*command_fn)(int argc, char **argv);

/* The subcommand called name, or NULL. */
static command_fn lookup(const char *name)
{
    static const struct {
        const char *name;
        command_fn fn;
    } cmds[] = {{"render", cmd_render}, {"compile", cmd_compile}, {"hosts", cmd_hosts}, {"deploy", cmd_deploy},
                  {"stitch", cmd_stitch}};
    for (size_t i = 0; i < sizeof cmds / sizeof *cmds; i++)
        if (!strcmp(name, cmds[i].name))
            return cmds[i].fn;
    return NULL;
}

static int run(command_fn fn, int argc, char **argv)
{
    /* Only the commands that reach hosts need libssh set up; doing it for
     * every one costs nothing worth avoiding. */
    ssh_init();
    int rc = fn(argc, argv);
    ssh_finalize();
    return rc;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fputs(usage, stderr);
        return 2;
    }
    const char *cmd = argv[1];
    if (!strcmp(cmd, "--version") || !strcmp(cmd, "-V") || !strcmp(cmd, "version")) {
        if (argc > 2) {
            fprintf(stderr, "franja %s: takes no arguments\n", cmd);
            return 2;
        }
        char line[128];
        proto_version_line("franja", line, sizeof line);
        printf("%s\n", line);
        return 0;
    }
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h") || !strcmp(cmd, "help")) {
        if (argc == 2) {
            fputs(usage, stdout);
            return 0;
        }
        command_fn fn = lookup(argv[2]);
        if (!fn || argc > 3) {
            fprintf(stderr, "franja help: %s '%s'; the commands are render, compile, hosts, deploy and stitch\n",
                    fn ? "one command at a time, not" : "no command", argc > 3 && fn ? argv[3] : argv[2]);
            return 2;
        }
        char *args[] = {argv[2], (char *)"--help", NULL};
        return run(fn, 2, args);
    }
    command_fn fn = lookup(cmd);
    if (fn)
        return run(fn, argc - 1, argv + 1);
    fprintf(stderr, "franja: unknown command '%s'\n\n%s", cmd, usage);
    return 2;
}
