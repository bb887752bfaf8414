/* cmd_compile.c -- `franja compile`: a JSON scene into a binary scene. */
#include "cmd.h"

#include <stdio.h>
#include <string.h>

#include "clock.h"
#include "compile.h"
#include "fbin.h"

static const char usage[] =
    "usage: franja compile SCENE.json [-o SCENE.fbin]\n"
    "\n"
    "Reads a JSON scene and the meshes it names (OBJ with MTL; PLY, STL, glTF\n"
    "and other formats through Assimp), builds the BVH and writes the binary\n"
    "scene that workers map and render (format: common/FORMAT.md).  The output\n"
    "defaults to the scene's name with .fbin for .json.  Prints the content hash\n"
    "that names the scene, its size and what it holds.\n";

int cmd_compile(int argc, char **argv)
{
    const char *in = NULL, *out = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            fputs(usage, stdout);
            return 0;
        } else if (!strcmp(argv[i], "-o")) {
            if (i + 1 >= argc) {
                fprintf(stderr, "franja compile: -o needs a file name\n");
                return 2;
            }
            out = argv[++i];
        } else if (argv[i][0] == '-' && argv[i][1]) {
            fprintf(stderr, "franja compile: unknown option '%s' (see franja compile --help)\n", argv[i]);
            return 2;
        } else if (in) {
            fprintf(stderr, "franja compile: one scene at a time ('%s' and '%s')\n", in, argv[i]);
            return 2;
        } else {
            in = argv[i];
        }
    }
    if (!in) {
        fputs(usage, stderr);
        return 2;
    }
    char def[4096];
    if (!out) {
        size_t n = strlen(in);
        if (n > 5 && !strcmp(in + n - 5, ".json"))
            n -= 5;
        if (snprintf(def, sizeof def, "%.*s.fbin", (int)n, in) >= (int)sizeof def) {
            fprintf(stderr, "franja compile: %s: name too long\n", in);
            return 2;
        }
        out = def;
    }
    fr_scene s;
    fr_error err;
    double t0 = clk_now();
    if (compile_json(in, &s, &err) < 0) {
        fprintf(stderr, "franja compile: %s\n", err.msg);
        return 1;
    }
    double t1 = clk_now();
    if (fbin_write(&s, out, &err) < 0) {
        fprintf(stderr, "franja compile: %s\n", err.msg);
        scn_free(&s);
        return 1;
    }
    char hex[17];
    fbin_hash_hex(s.hash, hex);
    printf("%s: scene %s, %zu bytes: %u primitives (%u triangles), %u materials, %u lights, "
           "%u BVH nodes, %u leaf blocks; compiled in %.3f s\n",
           out, hex, s.blob_size, s.n_prims, s.n_triangles, s.n_materials, s.n_lights, s.n_nodes, s.n_leaves,
           t1 - t0);
    scn_free(&s);
    return 0;
}
