/* fuzz_json.c -- libFuzzer target for the JSON scene reader: parse any
 * text and, when it is a valid scene, freeze it (BVH build, serialization
 * and the loader's validation of what the builder wrote).
 *
 * The scene reads its assets through the compiler's hooks, as `franja
 * compile` does: meshes through the coordinator's mesh hook (mesh_add:
 * OBJ + MTL reading, placement, levels of detail, materials) and image
 * textures through a hook that makes up pixels (OpenImageIO stays out of
 * the fuzzer).  The scene lives in a directory made once, holding
 * mesh.obj (UVs, normals, mtllib mesh.mtl), mesh.mtl, lod1.obj, and
 * rgb.png (4x2 RGB), grey.png (3x3 grey), rgba.exr (2x2 RGBA), wide.png
 * (65537x1: too wide); the seeds in tests/fuzz/corpus/json name them.
 * Only .obj meshes are loaded: other formats go to Assimp in a child
 * process, which a fuzzer must not fork for every input. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compile/freeze.h"
#include "compile/mesh.h"
#include "compile/json_scene.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char dir[64], scene_path[128];

static void put(const char *name, const char *text)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f || fputs(text, f) < 0 || fclose(f) != 0) {
        fprintf(stderr, "fuzz_json: cannot write %s\n", path);
        exit(1);
    }
}

static const char *const files[] = {"mesh.obj", "mesh.mtl", "lod1.obj", "rgb.png", "grey.png", "rgba.exr",
                                    "wide.png", NULL};

static void cleanup(void)
{
    char path[256];
    for (int i = 0; files[i]; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, files[i]);
        remove(path);
    }
    remove(dir);
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    snprintf(dir, sizeof dir, "/tmp/franja-fuzz-json-XXXXXX");
    if (!mkdtemp(dir)) {
        fprintf(stderr, "fuzz_json: cannot create a directory\n");
        exit(1);
    }
    atexit(cleanup);
    snprintf(scene_path, sizeof scene_path, "%s/fuzz.json", dir);
    put("mesh.obj", "mtllib mesh.mtl\n"
                    "v -1 0 -1\nv 1 0 -1\nv 1 0.3 1\nv -1 0 1\nv 0 1 0\n"
                    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 1 0\nvn 0.2 1 0\nvn 0 1 0.2\n"
                    "usemtl gold\nf 1/1/1 2/2/2 3/3/3 4/4/1\n"
                    "usemtl lamp\nf 1/1 2/2 5/3\nusemtl glass\nf 3//3 4//1 5//2\n");
    put("mesh.mtl", "newmtl gold\nKd 0.6 0.5 0.1\nKs 0.3 0.3 0.1\nNs 80\n"
                    "newmtl lamp\nKe 4 4 3\n"
                    "newmtl glass\nillum 7\nNi 1.45\nTf 0.9 1 0.9\n");
    put("lod1.obj", "v -1 0 -1\nv 1 0 -1\nv 0 1 1\nf 1 2 3\n");
    put("rgb.png", "");
    put("grey.png", "");
    put("rgba.exr", "");
    put("wide.png", "");
    return 0;
}

/* Pixels for the image files of the directory, by name. */
static int texture(const char *path, const void *data, size_t len, scene_image *img, fr_error *err)
{
    (void)data;
    (void)len;
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    uint32_t w, h, c;
    if (!strcmp(base, "rgb.png"))
        w = 4, h = 2, c = 3;
    else if (!strcmp(base, "grey.png"))
        w = 3, h = 3, c = 1;
    else if (!strcmp(base, "rgba.exr"))
        w = 2, h = 2, c = 4;
    else if (!strcmp(base, "wide.png"))
        w = 65537, h = 1, c = 1;
    else
        return fr_fail(err, "%s: no such image", path);
    img->width = w, img->height = h, img->channels = c;
    img->pixels = malloc(sizeof(float) * w * h * c);
    if (!img->pixels)
        return fr_fail(err, "%s: out of memory", path);
    for (uint32_t i = 0; i < w * h * c; i++)
        img->pixels[i] = (float)(i % 7) / 6.0f;
    return 0;
}

/* 1 if s names an OBJ file. */
static int is_obj(const cJSON *s)
{
    size_t n = cJSON_IsString(s) ? strlen(s->valuestring) : 0;
    return n >= 4 && !strcmp(s->valuestring + n - 4, ".obj");
}

/* The compiler's mesh hook, for OBJ files only (see the top). */
static int mesh(fr_builder *b, const cJSON *node, const char *where, const char *d, const confine *scope,
                uint32_t material, fr_error *err)
{
    const cJSON *file = cJSON_GetObjectItemCaseSensitive(node, "file");
    const cJSON *lod = cJSON_GetObjectItemCaseSensitive(node, "lod");
    if (file && !is_obj(file))
        return fr_fail(err, "%s.file: only OBJ meshes here", where);
    for (const cJSON *l = cJSON_IsArray(lod) ? lod->child : NULL; l; l = l->next)
        if (!is_obj(l))
            return fr_fail(err, "%s.lod: only OBJ meshes here", where);
    return mesh_add(b, node, where, d, scope, material, err);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = 0;
    const scene_hooks hooks = {mesh, texture};
    fr_builder b;
    fr_error err;
    bld_init(&b);
    if (json_scene_parse(text, scene_path, &hooks, &b, &err) == 0) {
        fr_scene s;
        if (frz_scene(&b, &s, &err) == 0)
            scn_free(&s);
    }
    bld_free(&b);
    free(text);
    return 0;
}
