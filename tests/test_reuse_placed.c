/* test_reuse_placed.c -- an animation whose mesh moves by its instances is
 * made of the frame before's mesh sections (coordinator/reuse_placed.h):
 * byte for byte the full compile of each frame; a mesh file rewritten
 * between two frames makes the next frame compile whole, to the full
 * compile's bytes; reuse_placed_bounds gives the mesh's vertex bounds and
 * a splice is refused when the frame before's skeleton was not its full
 * scene but for the meshes. */
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
#include "reuse.h"
#include "reuse_placed.h"

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
    snprintf(dir, sizeof dir, "/tmp/franja-test-placed-XXXXXX");
    if (!mkdtemp(dir))
        return 1;
    put("mesh.obj", "v -1 0 0\nv 1 0 0\nv 0 1.5 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 2 4 3\n");
    put("scene.json",
        "{ \"image\": { \"width\": 16, \"height\": 12, \"spp\": 1 },"
        "  \"camera\": { \"position\": [0, 0.5, -4], \"target\": [0, 0.5, 0], \"fov\": 40 },"
        "  \"materials\": { \"w\": { \"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5] } },"
        "  \"lights\": [ { \"type\": \"point\", \"position\": [0, 3, -2], \"intensity\": [5, 5, 5] } ],"
        "  \"shapes\": [ { \"type\": \"mesh\", \"file\": \"mesh.obj\", \"material\": \"w\", \"instances\": ["
        "                  { \"translate\": { \"keys\": [[1, [0, 0, 0]], [4, [1.5, 0, 0]]] } },"
        "                  { \"translate\": [-2, 0, 1] } ] },"
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
    for (int f = 1; f <= 4; f++) {
        if (f == 4) {
            /* The mesh file changes (and its time with it) between frames 3 and 4. */
            put("mesh.obj", "v -1 0 0\nv 1 0 0\nv 0 2 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 2 4 3\n");
            char obj[128];
            snprintf(obj, sizeof obj, "%s/mesh.obj", dir);
            struct timespec t[2] = {{1000000000, 0}, {1000000000, 0}};
            utimensat(AT_FDCWD, obj, t, 0);
        }
        co.frame = f;
        snprintf(out, sizeof out, "%s/f%d.fbin", dir, f);
        int rc = reuse_compile(&st, scene, &co, out, patch, NULL, &r, &err);
        CHECK(rc == 0, "frame %d: %s", f, rc ? err.msg : "");
        CHECK(r.reused == (f == 2 || f == 3), "frame %d: reused %d", f, r.reused);
        CHECK(same_as_full(out, &co, f), "frame %d: the bytes of its full compile", f);
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
              same_as_full(out, &co, 4),
          "frame 4 made again of itself is its full compile");
    reuse_free(&st);
    const char *names[] = {"mesh.obj", "scene.json", "scene.patch", "f1.fbin", "f2.fbin", "f3.fbin", "f4.fbin"};
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        char path[160];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        unlink(path);
    }
    CHECK(rmdir(dir) == 0, "nothing else left in %s", dir);
    return check_done();
}
