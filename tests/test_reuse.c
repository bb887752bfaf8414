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
#include "reusedir.h"

static char dir[64];

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/franja-test-reuse-XXXXXX");
    if (!mkdtemp(dir))
        return 1;
    reusedir_put(dir, "mesh.obj",
                 "mtllib m.mtl\nv -1 0 0\nv 1 0 0\nv 0 1.5 0\nv 0 0 1\nusemtl red\nf 1 2 3\nf 1 3 4\nf 2 4 3\n");
    reusedir_put(dir, "m.mtl", "newmtl red\nKd 0.8 0.1 0.1\n");
    reusedir_put(dir, "scene.json",
        "{ \"image\": { \"width\": 16, \"height\": 12, \"spp\": 1 },"
        "  \"camera\": { \"position\": { \"keys\": [[1, [0, 0.5, -4]], [3, [1, 0.5, -4]]] }, \"target\": [0, 0.5, 0],"
        "              \"fov\": 40 },"
        "  \"materials\": { \"w\": { \"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5] } },"
        "  \"lights\": [ { \"type\": \"point\", \"position\": [0, 3, -2], \"intensity\": [5, 5, 5] } ],"
        "  \"shapes\": [ { \"type\": \"mesh\", \"file\": \"mesh.obj\" },"
        "              { \"type\": \"plane\", \"point\": [0, -1, 0], \"normal\": [0, 1, 0], \"material\": \"w\" } ] }");
    char out[128], patch[128];
    snprintf(patch, sizeof patch, "%s/scene.patch", dir);
    compile_opts co;
    reusedir_opts(&co);
    reuse_state st;
    memset(&st, 0, sizeof st);
    reuse_result r;
    fr_error err;
    uint64_t hash[4] = {0};
    for (int f = 1; f <= 3; f++) {
        if (f == 3) {
            /* The MTL file changes (and its time with it) between frames 2 and 3. */
            reusedir_rewrite(dir, "m.mtl", "newmtl red\nKd 0.1 0.8 0.1\n");
        }
        int rc = reusedir_frame(dir, &st, &co, f, out, sizeof out, &r, &err);
        CHECK(rc == 0, "frame %d: %s", f, rc ? err.msg : "");
        CHECK(r.reused == (f == 2), "frame %d: reused %d", f, r.reused);
        CHECK(reusedir_same_as_full(dir, out, &co, f), "frame %d: the bytes of its full compile", f);
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
    const char *const names[] = {"mesh.obj", "m.mtl", "scene.json", "scene.patch", "f1.fbin", "f2.fbin", "f3.fbin"};
    CHECK(reusedir_clean(dir, names, sizeof names / sizeof *names) == 0, "nothing else left in %s", dir);
    return check_done();
}
