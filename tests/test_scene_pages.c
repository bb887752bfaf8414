/* test_scene_pages.c -- a large tree copied to memory of large pages has
 * the same bytes and gives the same hits; a small one stays where it is;
 * the copy is released with the scene. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bsdf.h"
#include "compile/builder.h"
#include "check.h"
#include "fbin.h"
#include "compile/freeze.h"
#include "scene_pages.h"
#include "trace.h"

static uint64_t rng = 0x9e3779b97f4a7c15ull;
static float rnd(void)
{
    rng ^= rng << 13; rng ^= rng >> 7; rng ^= rng << 17;
    return (float)(rng >> 40) * (1.0f / 16777216.0f);
}

/* A height grid of 2 n^2 triangles over [-1, 1]^2. */
static int grid_scene(int n, fr_scene *s)
{
    fr_builder b;
    bld_init(&b);
    fr_material m;
    bld_material_init(&m);
    m.diffuse = v3s(0.5f);
    bsdf_lobe_probs(&m);
    bld_push(&b.materials, &m);
    b.settings = (fr_settings){.width = 16, .height = 16, .spp = 1, .max_depth = 2};
    b.camera.position = v3(0, 3, -3);
    b.camera.target = v3(0, 0, 0);
    b.camera.up = v3(0, 1, 0);
    b.camera.vfov = 1.0f;
    b.camera.focus = 4.0f;
    for (int i = 0; i <= n; i++)
        for (int j = 0; j <= n; j++) {
            vec3 p = v3(2.0f * i / n - 1.0f, 0.2f * rnd(), 2.0f * j / n - 1.0f);
            bld_push(&b.positions, &p);
        }
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            uint32_t a = (uint32_t)(i * (n + 1) + j), c = a + (uint32_t)n + 1;
            uint32_t t[2][3] = {{a, c, c + 1}, {a, c + 1, a + 1}};
            for (int k = 0; k < 2; k++) {
                fr_triangle tr = {{t[k][0], t[k][1], t[k][2]}, 0};
                fr_prim p = {FR_PRIM_TRIANGLE, bld_push(&b.triangles, &tr), 0, FR_NONE};
                bld_push(&b.prims, &p);
            }
        }
    fr_error err;
    int rc = frz_scene(&b, s, &err);
    CHECK(rc == 0, "grid %d: %s", n, rc ? err.msg : "");
    bld_free(&b);
    return rc;
}

#define RAYS 20000

typedef struct { int hit; float t; uint32_t prim; float a, b; int occluded; } answer;

/* The same random rays every call: from above the grid, downward and
 * sideways, so they hit, graze and miss. */
static void trace_all(const fr_scene *s, answer *out)
{
    uint64_t keep = rng;
    rng = 0x2545f4914f6cdd1dull;
    for (int i = 0; i < RAYS; i++) {
        fr_ray r;
        r.o = v3(2.4f * rnd() - 1.2f, 0.3f + rnd(), 2.4f * rnd() - 1.2f);
        r.d = v3_norm(v3(rnd() - 0.5f, -rnd(), rnd() - 0.5f));
        fr_hit h;
        memset(&h, 0, sizeof h);
        out[i].hit = trace_closest(s, &r, 1e30f, &h);
        out[i].t = out[i].hit ? h.t : 0.0f;
        out[i].prim = out[i].hit ? h.prim : FR_NONE;
        out[i].a = out[i].hit ? h.a : 0.0f;
        out[i].b = out[i].hit ? h.b : 0.0f;
        out[i].occluded = trace_occluded(s, &r, 1.5f, FR_NONE);
    }
    rng = keep;
}

/* Whether the copy's conditions hold here (see scene_pages.h). */
static int fits(const fr_scene *s)
{
    size_t bytes = ((size_t)s->n_nodes * sizeof(fr_bvh_node) + 63) / 64 * 64 + (size_t)s->n_leaves * sizeof(fr_bvh_leaf);
    long cpus = sysconf(_SC_NPROCESSORS_ONLN), pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (cpus < 1)
        cpus = 1;
    return bytes >= SCN_PAGES_MIN && (double)bytes * (double)cpus <= (double)pages * (double)page / 8.0;
}

static void large(const char *name, fr_scene *s)
{
    answer *before = calloc(RAYS, sizeof *before), *after = calloc(RAYS, sizeof *after);
    size_t nb = (size_t)s->n_nodes * sizeof(fr_bvh_node), lb = (size_t)s->n_leaves * sizeof(fr_bvh_leaf);
    const void *nodes = s->nodes, *leaves = s->leaves;
    trace_all(s, before);
    int want = fits(s);
    int got = scn_bvh_large_pages(s);
    CHECK(got == want, "%s: copied %d, expected %d (%zu bytes of tree)", name, got, want, nb + lb);
    if (got) {
        CHECK(s->bvh_copy && (const void *)s->nodes != nodes && (const void *)s->leaves != leaves,
              "%s: the scene does not point at the copy", name);
        CHECK((uintptr_t)s->nodes % ((size_t)2 << 20) == 0, "%s: the copy at %p is not 2 MiB-aligned", name,
              (const void *)s->nodes);
        CHECK((uintptr_t)s->leaves % 64 == 0, "%s: leaves at %p not 64-byte aligned", name, (const void *)s->leaves);
        CHECK(!memcmp(s->nodes, nodes, nb) && !memcmp(s->leaves, leaves, lb), "%s: the copy's bytes differ", name);
        CHECK(scn_bvh_large_pages(s) == 0, "%s: copied twice", name);
    }
    trace_all(s, after);
    int same = 0, hits = 0, occluded = 0;
    for (int i = 0; i < RAYS; i++) {
        same += !memcmp(&before[i], &after[i], sizeof before[i]);
        hits += after[i].hit;
        occluded += after[i].occluded;
    }
    CHECK(same == RAYS, "%s: %d of %d rays answer otherwise after the copy", name, RAYS - same, RAYS);
    CHECK(hits > RAYS / 4 && hits < RAYS, "%s: %d of %d rays hit: the rays do not exercise the tree", name, hits,
          RAYS);
    CHECK(occluded > 0 && occluded < RAYS, "%s: %d of %d shadow rays blocked", name, occluded, RAYS);
    scn_free(s);
    CHECK(s->bvh_copy == NULL && s->nodes == NULL, "%s: scn_free left the copy", name);
    free(before);
    free(after);
}

int main(void)
{
    fr_scene s;
    /* A small tree stays in the blob. */
    if (grid_scene(20, &s) == 0) {
        const void *nodes = s.nodes;
        CHECK(scn_bvh_large_pages(&s) == 0 && s.nodes == nodes && !s.bvh_copy, "a small tree was copied");
        scn_free(&s);
    }
    /* 2 x 256^2 triangles: about 5 MiB of nodes and leaves, built in memory. */
    if (grid_scene(256, &s) == 0) {
        CHECK(fits(&s) || sysconf(_SC_PHYS_PAGES) < (1L << 20), "the large grid's tree is under %zu bytes",
              (size_t)SCN_PAGES_MIN);
        /* The same scene written and mapped from a file, as a worker loads it. */
        char path[] = "/tmp/franja-pages-XXXXXX";
        int fd = mkstemp(path);
        CHECK(fd >= 0, "temporary file");
        if (fd >= 0) {
            close(fd);
            fr_error err;
            unlink(path);
            CHECK(fbin_write(&s, path, &err) == 0, "write: %s", err.msg);
            fr_scene m;
            if (fbin_load(path, &m, &err) == 0) {
                CHECK(m.mapped, "the loaded scene is not mapped");
                large("mapped grid", &m);
            } else {
                CHECK(0, "load: %s", err.msg);
            }
            unlink(path);
        }
        large("grid in memory", &s);
    }
    return check_done();
}
