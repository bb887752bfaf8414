/* test_reuse.c -- an animation's frames compiled from the frame before's
 * sections (coordinator/reuse.h): a camera move over an OBJ mesh with an
 * MTL file is made of the frame before's scene, byte for byte the full
 * compile of the frame, with a patch from the frame before's; a change to
 * the MTL file (which only the mesh file names) between two frames makes
 * the next frame compile whole, again to the full compile's bytes. */
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "compile/compile_child.h"
#include "fbin.h"
#include "file.h"
#include "fpatch.h"
#include "reuse.h"

static char dir[64];

static void put(const char *name, const char *text)
{
    char path[256];
    fr_error err;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    if (file_write_atomic(path, text, strlen(text), &err) < 0) {
        printf("FAIL write %s: %s\n", path, err.msg);
        exit(1);
    }
}

/* The bytes of the file at path equal those of the full compile of frame f. */
static int same_as_full(const char *path, const compile_opts *co, double f)
{
    char scene[128], ref[128];
    snprintf(scene, sizeof scene, "%s/scene.json", dir);
    snprintf(ref, sizeof ref, "%s/ref.fbin", dir);
    compile_opts o = *co;
    o.frame = f;
    fr_error err;
    char *a = NULL, *b = NULL;
    size_t na = 0, nb = 0;
    int same = compile_child(scene, &o, ref, NULL, NULL, &err) == 0 && file_read(path, &a, &na, &err) == 0 &&
               file_read(ref, &b, &nb, &err) == 0 && na == nb && !memcmp(a, b, na);
    free(a);
    free(b);
    unlink(ref);
    return same;
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/franja-test-reuse-XXXXXX");
    if (!mkdtemp(dir))
        return 1;
    put("mesh.obj", "mtllib m.mtl\nv -1 0 0\nv 1 0 0\nv 0 1.5 0\nv 0 0 1\nusemtl red\nf 1 2 3\nf 1 3 4\nf 2 4 3\n");
    put("m.mtl", "newmtl red\nKd 0.8 0.1 0.1\n");
    put("scene.json",
        "{ \"image\": { \"width\": 16, \"height\": 12, \"spp\": 1 },"
        "  \"camera\": { \"position\": { \"keys\": [[1, [0, 0.5, -4]], [3, [1, 0.5, -4]]] }, \"target\": [0, 0.5, 0],"
        "              \"fov\": 40 },"
        "  \"materials\": { \"w\": { \"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5] } },"
        "  \"lights\": [ { \"type\": \"point\", \"position\": [0, 3, -2], \"intensity\": [5, 5, 5] } ],"
        "  \"shapes\": [ { \"type\": \"mesh\", \"file\": \"mesh.obj\" },"
        "              { \"type\": \"plane\", \"point\": [0, -1, 0], \"normal\": [0, 1, 0], \"material\": \"w\" } ] }");
    char scene[128], out[128], patch[128];
    snprintf(scene, sizeof scene, "%s/scene.json", dir);
    snprintf(patch, sizeof patch, "%s/scene.patch", dir);
    compile_opts co;
    memset(&co, 0, sizeof co);
    co.timed = 1;
    co.fps = 24.0;
    reuse_state st;
    memset(&st, 0, sizeof st);
    reuse_result r;
    fr_error err;
    uint64_t hash[4] = {0};
    for (int f = 1; f <= 3; f++) {
        if (f == 3) {
            /* The MTL file changes (and its time with it) between frames 2 and 3. */
            put("m.mtl", "newmtl red\nKd 0.1 0.8 0.1\n");
            char mtl[128];
            snprintf(mtl, sizeof mtl, "%s/m.mtl", dir);
            struct timespec t[2] = {{1000000000, 0}, {1000000000, 0}};
            utimensat(AT_FDCWD, mtl, t, 0);
        }
        co.frame = f;
        snprintf(out, sizeof out, "%s/f%d.fbin", dir, f);
        int rc = reuse_compile(&st, scene, &co, out, patch, NULL, &r, &err);
        CHECK(rc == 0, "frame %d: %s", f, rc ? err.msg : "");
        CHECK(r.reused == (f == 2), "frame %d: reused %d", f, r.reused);
        CHECK(same_as_full(out, &co, f), "frame %d: the bytes of its full compile", f);
        fr_scene s;
        CHECK(fbin_load(out, &s, &err) == 0, "frame %d loads: %s", f, err.msg);
        hash[f] = s.hash;
        scn_free(&s);
        if (f == 1) {
            CHECK(r.base == 0 && access(patch, F_OK) != 0, "frame 1: no patch");
            continue;
        }
        CHECK(r.base == hash[f - 1], "frame %d: a patch from the frame before's scene", f);
        char *p = NULL;
        size_t n = 0;
        uint64_t base = 0;
        CHECK(file_read(patch, &p, &n, &err) == 0 && fpatch_base(p, n, &base, &err) == 0 && base == hash[f - 1],
              "frame %d: the patch names its base", f);
        CHECK(n == r.patch_bytes, "frame %d: the patch's size", f);
        free(p);
    }
    CHECK(st.reused == 1, "one frame made of the frame before's, not %d", st.reused);
    reuse_free(&st);
    const char *names[] = {"mesh.obj", "m.mtl", "scene.json", "scene.patch", "f1.fbin", "f2.fbin", "f3.fbin"};
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        char path[160];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        unlink(path);
    }
    CHECK(rmdir(dir) == 0, "nothing else left in %s", dir);
    return check_done();
}
