/* fuzz_obj.c -- libFuzzer target for the OBJ and MTL readers
 * (coordinator/compile/obj.h) and the mesh shape built from them
 * (coordinator/compile/mesh.h).
 *
 * An input whose first byte is 'M' is read as MTL.  Any other is parsed as
 * OBJ text in memory (mtllib skipped), then written to in.obj in a
 * directory made once and read from there by obj_read through a scene
 * whose mesh shape names it (as `franja compile` reads it: mtllib files
 * next to it, placement, normals, levels of detail, materials); the
 * directory holds a.mtl for its mtllib statements.  The input's first
 * byte picks one of a few shapes. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compile/freeze.h"
#include "compile/mesh.h"
#include "compile/obj.h"
#include "compile/json_scene.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char dir[64], obj_path[128], mtl_path[128], scene_path[128];

static void cleanup(void)
{
    remove(obj_path);
    remove(mtl_path);
    remove(dir);
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    snprintf(dir, sizeof dir, "/tmp/franja-fuzz-obj-XXXXXX");
    if (!mkdtemp(dir)) {
        fprintf(stderr, "fuzz_obj: cannot create a directory\n");
        exit(1);
    }
    snprintf(obj_path, sizeof obj_path, "%s/in.obj", dir);
    snprintf(mtl_path, sizeof mtl_path, "%s/a.mtl", dir);
    snprintf(scene_path, sizeof scene_path, "%s/scene.json", dir);
    atexit(cleanup);
    FILE *f = fopen(mtl_path, "w");
    if (!f || fputs("newmtl red\nKd 0.6 0.1 0.1\nnewmtl lamp\nKe 3 3 3\nnewmtl glass\nillum 7\nNi 1.5\n", f) < 0 ||
        fclose(f) != 0) {
        fprintf(stderr, "fuzz_obj: cannot write %s\n", mtl_path);
        exit(1);
    }
    return 0;
}

/* The mesh shapes a scene may use for in.obj. */
static const char *const shapes[] = {
    "{\"type\": \"mesh\", \"file\": \"in.obj\"}",
    "{\"type\": \"mesh\", \"file\": \"in.obj\", \"material\": \"m\", \"normals\": \"flat\", \"scale\": [1, -2, 1], "
    "\"rotate\": [10, 20, 30], \"translate\": [0, 1, 0]}",
    "{\"type\": \"mesh\", \"lod\": [\"in.obj\", \"in.obj\"], \"matrix\": [0,0,1,2, 0,1,0,0, -1,0,0,0, 0,0,0,1]}",
};

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    mesh_data m;
    fr_error err;
    if (size > 0 && data[0] == 'M') {
        memset(&m, 0, sizeof m);
        if (obj_parse_mtl((const char *)data + 1, size - 1, "fuzz.mtl", &m, &err) == 0)
            for (uint32_t i = 0; i < m.n_mats; i++) {
                fr_material fm;
                mesh_data_material(&m.mats[i], &fm);
            }
        mesh_data_free(&m);
        return 0;
    }
    if (obj_parse((const char *)data, size, "fuzz.obj", NULL, NULL, NULL, &m, &err) == 0)
        mesh_data_free(&m);
    FILE *f = fopen(obj_path, "wb");
    if (!f)
        return 0;
    int ok = fwrite(data, 1, size, f) == size;
    if (fclose(f) != 0 || !ok)
        return 0;
    char json[1024];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 16, \"height\": 16, \"spp\": 1},"
             " \"camera\": {\"position\": [0, 1, -6], \"target\": [0, 0, 0], \"fov\": 40},"
             " \"materials\": {\"m\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}},"
             " \"lights\": [{\"type\": \"point\", \"position\": [0, 4, -2], \"intensity\": [9, 9, 9]}],"
             " \"shapes\": [%s]}",
             shapes[(size ? data[0] : 0) % (sizeof shapes / sizeof shapes[0])]);
    const scene_hooks hooks = {mesh_add, NULL};
    fr_builder b;
    bld_init(&b);
    if (json_scene_parse(json, scene_path, &hooks, &b, &err) == 0) {
        fr_scene s;
        if (frz_scene(&b, &s, &err) == 0)
            scn_free(&s);
    }
    bld_free(&b);
    return 0;
}
