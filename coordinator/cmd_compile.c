/* cmd_compile.c -- `franja compile`: a JSON or glTF scene into a binary scene. */
#include "cmd.h"

#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "opt.h"
#include "compile/compile.h"
#include "compile/compile_child.h"
#include "compile/confine.h"
#include "file.h"

static const char usage[] =
    "usage: franja compile SCENE(.json|.gltf|.glb) [-o SCENE.fbin] [--camera NAME]\n"
    "                      [--allow-path DIR]... [--limit NAME=VALUE]...\n"
    "\n"
    "Reads a JSON scene and the meshes it names (OBJ with MTL; PLY, STL, glTF\n"
    "and other formats through Assimp), or a whole glTF 2.0 scene, builds the\n"
    "BVH and writes the binary scene that workers map and render (format:\n"
    "common/FORMAT.md).  The output defaults to the scene's file name with .fbin\n"
    "for its extension, in the current directory.  Prints the content hash that names the scene, its size and\n"
    "what it holds.  Features of a glTF file that are not supported are named\n"
    "in warnings.\n"
    "\n"
    "  -o FILE         the binary scene to write (without -o: SCENE.fbin in the\n"
    "                  current directory)\n"
    "  --camera NAME   glTF scenes: the camera to use, by its node's or its own\n"
    "                  name (default: the first in the scene)\n"
    "  --allow-path DIR  let the scene read files in DIR too (repeatable);\n"
    "                  without it, a scene reads only files in its own folder\n"
    COMPILE_LIMIT_HELP;

static volatile sig_atomic_t stop_flag;

static void on_signal(int sig)
{
    (void)sig;
    stop_flag = 1;
}

static void print_warning(void *user, const char *msg)
{
    fprintf(stderr, "%s: warning: %s\n", (const char *)user, msg);
}

int cmd_compile(int argc, char **argv)
{
    enum { CAMERA = 0x100, ALLOW, LIMIT };
    static const struct option longopts[] = {
        {"help", no_argument, NULL, 'h'},
        {"camera", required_argument, NULL, CAMERA},
        {"allow-path", required_argument, NULL, ALLOW},
        {"limit", required_argument, NULL, LIMIT},
        {NULL, 0, NULL, 0},
    };
    const char *in = NULL, *out = NULL, *camera = NULL, *allow[CONFINE_MAX_ALLOW];
    unsigned n_allow = 0;
    fr_budget limits;
    fr_error err;
    budget_init(&limits);
    int c;
    optind = 0;
    while ((c = opt_next("compile", argc, argv, "ho:", longopts)) != -1) {
        switch (c) {
        case 'h':
            fputs(usage, stdout);
            return 0;
        case 'o':
            out = optarg;
            break;
        case CAMERA:
            camera = optarg;
            break;
        case ALLOW:
            if (n_allow == CONFINE_MAX_ALLOW) {
                fprintf(stderr, "franja compile: --allow-path: at most %d folders\n", CONFINE_MAX_ALLOW);
                return 2;
            }
            allow[n_allow++] = optarg;
            break;
        case LIMIT:
            if (budget_set(&limits, optarg, &err) < 0) {
                fprintf(stderr, "franja compile: --limit %s\n", err.msg);
                return 2;
            }
            break;
        default:
            return 2;
        }
    }
    if (argc - optind > 1) {
        fprintf(stderr, "franja compile: one scene at a time ('%s' and '%s')\n", argv[optind], argv[optind + 1]);
        return 2;
    }
    if (optind < argc)
        in = argv[optind];
    if (!in) {
        fputs(usage, stderr);
        return 2;
    }
    char def[4096];
    if (!out) {
        if (opt_default_output(in, ".fbin", def, sizeof def)) {
            fprintf(stderr, "franja compile: %s: cannot make an output name from it; give -o FILE\n", in);
            return 2;
        }
        out = def;
    }
    /* The compile runs in a child process (compile_child.h): Ctrl-C or a
     * SIGTERM stops it at once and leaves no partial output. */
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    compile_child_stats st;
    compile_opts co = {camera, print_warning, (void *)"franja compile", allow, n_allow, &limits, NULL, 0, 0.0,
                       0.0, 0.0, 0, NULL, NULL, NULL, 0, NULL};
    if (compile_child(in, &co, out, &stop_flag, &st, &err) < 0) {
        fprintf(stderr, "franja compile: %s\n", err.msg);
        return stop_flag ? 130 : 1;
    }
    /* A scene written to a device or a pipe (/dev/stdout) is not mixed
     * with the summary. */
    char placed[64] = "";
    if (st.instances)
        snprintf(placed, sizeof placed, ", %u instances of %u meshes", st.instances, st.meshes);
    fprintf(file_out_in_place(out) ? stderr : stdout,
            "%s: scene %s, %llu bytes: %u primitives (%u triangles)%s, %u materials, %u lights, "
            "%u BVH nodes, %u leaf blocks; compiled in %.3f s\n",
            out, st.hash, st.bytes, st.prims, st.triangles, placed, st.materials, st.lights, st.nodes, st.leaves,
            st.seconds);
    return 0;
}
