/* test_reuse_placed.c -- an animation whose mesh moves by its instances is
 * made of the frame before's mesh sections (coordinator/reuse_placed.h):
 * byte for byte the full compile of each frame; a mesh file rewritten
 * between two frames makes the next frame compile whole, to the full
 * compile's bytes; reuse_placed_bounds gives the mesh's vertex bounds and
 * a splice is refused when the frame before's skeleton was not its full
 * scene but for the meshes. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "reuse.h"
#include "reusedir.h"
#include "reuse_placed.h"

static char dir[64];

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/franja-test-placed-XXXXXX");
    if (!mkdtemp(dir))
        return 1;
    reusedir_put(dir, "mesh.obj", "v -1 0 0\nv 1 0 0\nv 0 1.5 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 2 4 3\n");
    reusedir_put(dir, "scene.json",
                 "{ \"image\": { \"width\": 12, \"height\": 8, \"spp\": 1 },"
                 "  \"camera\": { \"position\": [0, 0.5, -5], \"target\": [0, 0, 0], \"fov\": 50 },"
                 "  \"materials\": { \"grey\": { \"type\": \"lambert\", \"albedo\": [0.4, 0.4, 0.4] } },"
                 "  \"lights\": [ { \"type\": \"point\", \"position\": [1, 3, -3], \"intensity\": [4, 4, 4] } ],"
                 "  \"shapes\": [ { \"type\": \"mesh\", \"file\": \"mesh.obj\", \"material\": \"grey\", \"instances\": ["
                 "    { \"translate\": { \"keys\": [[1, [0, 0, 0]], [4, [1.5, 0, 0]]] } }, { \"translate\": [-2, 0, 1] } ] },"
                 "    { \"type\": \"plane\", \"point\": [0, -1, 0], \"normal\": [0, 1, 0], \"material\": \"grey\" } ] }");
    reuse_state st = {0};
    compile_opts co;
    reusedir_opts(&co);
    reuse_result r;
    fr_error err;
    char out[128];
    for (int f = 1; f <= 4; f++) {
        if (f == 4) {
            /* The mesh file changes (and its time with it) between frames 3 and 4. */
            reusedir_rewrite(dir, "mesh.obj", "v -1 0 0\nv 1 0 0\nv 0 2 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 2 4 3\n");
        }
        int rc = reusedir_frame(dir, &st, &co, f, out, sizeof out, &r, &err);
        CHECK(rc == 0, "frame %d: %s", f, rc ? err.msg : "");
        CHECK(r.reused == (f == 2 || f == 3), "frame %d: reused %d", f, r.reused);
        CHECK(reusedir_same_as_full(dir, out, &co, f), "frame %d: the bytes of its full compile", f);
    }
    CHECK(st.reused == 2, "two frames made of the frame before's, not %d", st.reused);
    /* The bounds of frame 4's mesh: the new file's vertices. */
    CHECK(st.n_bounds == 1 && st.bounds[0] == -1.0f && st.bounds[1] == 0.0f && st.bounds[2] == 0.0f &&
              st.bounds[3] == 1.0f && st.bounds[4] == 2.0f && st.bounds[5] == 1.0f,
          "the mesh's bounds (%u meshes)", st.n_bounds);
    /* The camera-only skeleton is not the full scene but for the meshes. */
    CHECK(st.skel.blob && reuse_placed_splice(&st.full, &st.skel, &st.placed, out, &err) == 0,
          "a splice from a skeleton that was not the full scene is refused");
    CHECK(st.placed.blob && reuse_placed_splice(&st.full, &st.placed, &st.placed, out, &err) == 1 &&
              reusedir_same_as_full(dir, out, &co, 4),
          "frame 4 made again of itself is its full compile");
    reuse_free(&st);
    const char *const names[] = {"mesh.obj", "scene.json", "scene.patch", "f1.fbin", "f2.fbin", "f3.fbin",
                                 "f4.fbin"};
    CHECK(reusedir_clean(dir, names, sizeof names / sizeof *names) == 0, "nothing else left in %s", dir);
    return check_done();
}
