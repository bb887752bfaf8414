/* bvhbench.c -- Franja's BVH against Embree 3 on the same triangles and rays.
 *
 *   bvhbench SCENE.fbin [--reps N] [--size WxH] [--worker PATH] [--pages map|2m|4k]
 *            [--default-walk]
 *
 * Loads a compiled scene, takes its triangles, and measures single-threaded:
 *   - BVH build time: bvh_build versus rtcCommitScene (Embree device with
 *     threads=1) at Embree's default build quality and at
 *     RTC_BUILD_QUALITY_HIGH (its spatial-split builder);
 *   - closest-hit (trace_closest / rtcIntersect1) and any-hit
 *     (trace_occluded / rtcOccluded1) throughput for primary rays (one per
 *     pixel through the scene camera) and diffuse bounce rays (cosine
 *     directions from the primary hits, incoherent), against both Embree
 *     trees; Franja's figure is its default walk's (the fastest this
 *     processor runs: trace.h), and unless --default-walk is given each
 *     walk the processor runs (portable, AVX2, AVX-512) is timed too, in
 *     the same rounds, with the ratio of the AVX-512 walk to the AVX2 one;
 *   - with --worker: worker start-up, from process start to its first pixel
 *     written (a 1x1-pixel, 1-sample render of the scene);
 *   - the binary scene's bytes per triangle.
 * The tree is walked where a worker walks it: copied to memory of 2 MiB
 * pages where it is large enough (scn_bvh_large_pages), mapped from the
 * file otherwise; the program says how much of the memory holding it has
 * 2 MiB pages (the walk's speed depends on it: bench_pages.h).  --pages
 * map walks it where the file is mapped, --pages 2m or 4k copies the
 * nodes and leaf blocks into anonymous memory of pages of that size.
 * Every figure is the median of N runs, timed in process CPU seconds (both
 * sides run on one thread; CPU time keeps a busy machine's scheduling out
 * of the figures; start-up is wall time).  Embree's hits are checked
 * against Franja's (same triangle, t within 1e-4 relative).  Linked with
 * Embree only here: nothing else in Franja uses it. */
#include <embree3/rtcore.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "bench_pages.h"
#include "bench_rays.h"
#include "compile/bvh_build.h"
#include "fbin.h"
#include "scene_pages.h"
#include "geom.h"
#include "pathtrace.h"
#include "trace.h"

static double clock_s(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double now(void) { return clock_s(CLOCK_PROCESS_CPUTIME_ID); }
static double wall(void) { return clock_s(CLOCK_MONOTONIC); }

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* The scene's triangles as one Embree-style mesh: vertex array (padded by
 * one float for Embree's 16-byte loads) and index triples. */
typedef struct {
    float *vert;               /* 3 floats per vertex, +1 padding */
    uint32_t *idx;             /* 3 per triangle */
    uint32_t n_vert, n_tri;
    uint32_t *prim_of_tri;     /* Franja prim of each triangle, for checking */
} tri_mesh;

static int take_triangles(const fr_scene *s, tri_mesh *m)
{
    m->n_vert = s->n_positions;
    m->n_tri = s->n_triangles;
    m->vert = malloc(((size_t)m->n_vert * 3 + 1) * sizeof *m->vert);
    m->idx = malloc((size_t)m->n_tri * 3 * sizeof *m->idx);
    m->prim_of_tri = malloc((size_t)m->n_tri * sizeof *m->prim_of_tri);
    if (!m->vert || !m->idx || !m->prim_of_tri)
        return -1;
    for (uint32_t i = 0; i < m->n_vert; i++) {
        m->vert[3 * i] = s->positions[i].x;
        m->vert[3 * i + 1] = s->positions[i].y;
        m->vert[3 * i + 2] = s->positions[i].z;
    }
    m->vert[3 * m->n_vert] = 0.0f;
    for (uint32_t i = 0; i < m->n_tri; i++)
        for (int k = 0; k < 3; k++)
            m->idx[3 * i + k] = s->triangles[i].v[k];
    for (uint32_t p = 0; p < s->n_prims; p++)
        if (s->prims[p].kind == FR_PRIM_TRIANGLE)
            m->prim_of_tri[s->prims[p].index] = p;
    return 0;
}

/* A builder holding just the triangles, for timing bvh_build. */
static void fill_builder(fr_builder *b, const fr_scene *s)
{
    bld_init(b);
    fr_material mat;
    bld_material_init(&mat);
    mat.diffuse = v3s(0.5f);
    bld_push(&b->materials, &mat);
    for (uint32_t i = 0; i < s->n_positions; i++)
        bld_push(&b->positions, &s->positions[i]);
    for (uint32_t i = 0; i < s->n_triangles; i++) {
        bld_push(&b->triangles, &s->triangles[i]);
        fr_prim p = {FR_PRIM_TRIANGLE, i, 0, FR_NONE};
        bld_push(&b->prims, &p);
    }
}

static RTCScene embree_scene(RTCDevice dev, const tri_mesh *m, enum RTCBuildQuality q)
{
    RTCScene sc = rtcNewScene(dev);
    rtcSetSceneBuildQuality(sc, q);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, m->vert, 0, 12, m->n_vert);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m->idx, 0, 12, m->n_tri);
    rtcCommitGeometry(g);
    rtcAttachGeometry(sc, g);
    rtcReleaseGeometry(g);
    return sc;
}

static void to_embree(const fr_ray *r, struct RTCRayHit *rh)
{
    memset(rh, 0, sizeof *rh);
    rh->ray.org_x = r->o.x; rh->ray.org_y = r->o.y; rh->ray.org_z = r->o.z;
    rh->ray.dir_x = r->d.x; rh->ray.dir_y = r->d.y; rh->ray.dir_z = r->d.z;
    rh->ray.tnear = 0.0f;
    rh->ray.tfar = INFINITY;
    rh->ray.mask = 0xffffffffu;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
}

typedef struct {
    double franja, embree, high;
    double walk[TRACE_WALKS];  /* Mrays/s of each walk this processor runs (0: not run) */
} trio;

/* Seconds of CPU time for Embree scene es to answer rays[0..n). */
static double embree_pass(RTCScene es, const fr_ray *rays, uint32_t n, int any, volatile uint32_t *sink)
{
    struct RTCIntersectContext ctx;
    uint32_t acc = 0;
    double t0 = now();
    for (uint32_t i = 0; i < n; i++) {
        struct RTCRayHit rh;
        to_embree(&rays[i], &rh);
        rtcInitIntersectContext(&ctx);
        if (any) {
            rtcOccluded1(es, &ctx, &rh.ray);
            acc += rh.ray.tfar < 0.0f;
        } else {
            rtcIntersect1(es, &ctx, &rh);
            acc += rh.hit.primID;
        }
    }
    double t = now() - t0;
    *sink += acc;
    return t;
}

/* CPU seconds of Franja's walk (the one in use) for rays[0..n). */
static double franja_pass(const fr_scene *s, const fr_ray *rays, uint32_t n, int any, volatile uint32_t *sink)
{
    uint32_t acc = 0;
    double t0 = now();
    if (any) {
        for (uint32_t i = 0; i < n; i++)
            acc += (uint32_t)trace_occluded(s, &rays[i], INFINITY, FR_NONE);
    } else {
        for (uint32_t i = 0; i < n; i++) {
            fr_hit h;
            if (trace_closest(s, &rays[i], INFINITY, &h))
                acc += h.prim;
        }
    }
    double t = now() - t0;
    *sink += acc;
    return t;
}

/* Mrays/s of closest-hit (any = 0) or any-hit queries on rays[0..n):
 * Franja, Embree default (es) and Embree high quality (eh), interleaved;
 * with `walks`, also each of Franja's walks that this processor runs, in
 * the same rounds (Franja's figure is the default walk's). */
static trio throughput(const fr_scene *s, RTCScene es, RTCScene eh, const fr_ray *rays, uint32_t n, int any, int reps,
                       int walks, volatile uint32_t *sink)
{
    double tf[TRACE_WALKS][64], te[64], th[64];
    int def = trace_walk();
    for (int k = 0; k < reps; k++) {
        /* The walks in turn, their order reversed every other round. */
        for (int j = 0; j < TRACE_WALKS; j++) {
            int w = k & 1 ? TRACE_WALKS - 1 - j : j;
            if (w != def && (!walks || !(trace_walks() >> w & 1)))
                continue;
            trace_set_walk(w);
            tf[w][k] = franja_pass(s, rays, n, any, sink);
        }
        trace_set_walk(def);
        te[k] = embree_pass(es, rays, n, any, sink);
        th[k] = embree_pass(eh, rays, n, any, sink);
    }
    trio r = {n / median(tf[def], reps) / 1e6, n / median(te, reps) / 1e6, n / median(th, reps) / 1e6, {0}};
    for (int w = 0; w < TRACE_WALKS; w++)
        if (w == def || (walks && (trace_walks() >> w & 1)))
            r.walk[w] = n / median(tf[w], reps) / 1e6;
    return r;
}

/* Rays where Embree and Franja disagree (hit/miss, triangle, or t). */
static uint32_t disagreements(const fr_scene *s, RTCScene es, const tri_mesh *m, const fr_ray *rays, uint32_t n)
{
    uint32_t bad = 0;
    struct RTCIntersectContext ctx;
    for (uint32_t i = 0; i < n; i++) {
        fr_hit h;
        int f = trace_closest(s, &rays[i], INFINITY, &h);
        struct RTCRayHit rh;
        to_embree(&rays[i], &rh);
        rtcInitIntersectContext(&ctx);
        rtcIntersect1(es, &ctx, &rh);
        int e = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        if (f != e || (f && m->prim_of_tri[rh.hit.primID] != h.prim && fabsf(rh.ray.tfar - h.t) > 1e-4f * h.t))
            bad++;
    }
    return bad;
}

/* Process start to first pixel: a 1x1, 1-sample render of the scene. */
static double startup_ms(const char *worker, const char *scene, int reps)
{
    double t[64];
    for (int k = 0; k < reps; k++) {
        double t0 = wall();
        pid_t pid = fork();
        if (pid == 0) {
            execl(worker, worker, "--scene", scene, "--rows", "0:1", "--size", "1x1", "--spp", "1", "-o", "/dev/null",
                  (char *)NULL);
            _exit(127);
        }
        int st;
        waitpid(pid, &st, 0);
        t[k] = (wall() - t0) * 1e3;
        if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) {
            fprintf(stderr, "bvhbench: %s failed on %s\n", worker, scene);
            return -1.0;
        }
    }
    return median(t, reps);
}

int main(int argc, char **argv)
{
    const char *path = NULL, *worker = NULL, *pages = NULL;
    int reps = 5, walks = 1;
    uint32_t w = 512, h = 512;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--reps") && i + 1 < argc) reps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--size") && i + 1 < argc) sscanf(argv[++i], "%ux%u", &w, &h);
        else if (!strcmp(argv[i], "--worker") && i + 1 < argc) worker = argv[++i];
        else if (!strcmp(argv[i], "--pages") && i + 1 < argc) pages = argv[++i];
        else if (!strcmp(argv[i], "--default-walk")) walks = 0;
        else if (argv[i][0] != '-') path = argv[i];
        else { fprintf(stderr, "bvhbench: unknown argument %s\n", argv[i]); return 2; }
    }
    if (pages && strcmp(pages, "map") && strcmp(pages, "2m") && strcmp(pages, "4k"))
        path = NULL;
    if (!path || reps < 1 || reps > 64 || w == 0 || h == 0) {
        fprintf(stderr, "usage: bvhbench SCENE.fbin [--reps N] [--size WxH] [--worker PATH] [--pages map|2m|4k] "
                        "[--default-walk]\n");
        return 2;
    }
    fr_scene s;
    fr_error err;
    if (fbin_load(path, &s, &err) < 0) {
        fprintf(stderr, "bvhbench: %s\n", err.msg);
        return 1;
    }
    tri_mesh m;
    if (take_triangles(&s, &m) < 0 || m.n_tri == 0) {
        fprintf(stderr, "bvhbench: %s: no triangles (or out of memory)\n", path);
        return 1;
    }
    printf("scene %s: %u triangles, %zu bytes (%.1f bytes/triangle), %u nodes, %u leaf blocks\n", path, m.n_tri,
           s.blob_size, (double)s.blob_size / m.n_tri, s.n_nodes, s.n_leaves);
    if (!pages)
        scn_bvh_large_pages(&s);   /* as the worker does */
    else if (strcmp(pages, "map")) {
        s.nodes = page_copy(s.nodes, (size_t)s.n_nodes * sizeof *s.nodes, !strcmp(pages, "2m"));
        s.leaves = page_copy(s.leaves, (size_t)s.n_leaves * sizeof *s.leaves, !strcmp(pages, "2m"));
        if (!s.nodes || !s.leaves) {
            fprintf(stderr, "bvhbench: out of memory for the tree's copy\n");
            return 1;
        }
    }
    unsigned long nkb, nhuge, lkb, lhuge;
    if (page_state(s.nodes, &nkb, &nhuge) == 0 && page_state(s.leaves, &lkb, &lhuge) == 0)
        printf("pages      tree %s: %lu of %lu KiB in 2 MiB pages where the nodes lie, %lu of %lu where the leaves "
               "do (at the start)\n", !pages ? (s.bvh_copy ? "copied as the worker does" : "as mapped from the file (too small to copy)")
               : !strcmp(pages, "map") ? "as mapped from the file"
               : !strcmp(pages, "2m") ? "copied to 2 MiB pages" : "copied to 4 KiB pages", nhuge, nkb, lhuge, lkb);
    printf("tree       SAH cost %.4f (node tests + slots / 2 + leaf blocks per ray through the root box)\n",
           bvh_sah_cost(s.nodes, s.n_nodes));

    /* Build times. */
    double bf[64], be[64], bh[64];
    RTCDevice dev = rtcNewDevice("threads=1");
    if (!dev) {
        fprintf(stderr, "bvhbench: rtcNewDevice failed\n");
        return 1;
    }
    for (int k = 0; k < reps; k++) {
        fr_builder b;
        fill_builder(&b, &s);
        fr_array nodes = {NULL, 0, 0, sizeof(fr_bvh_node)}, leaves = {NULL, 0, 0, sizeof(fr_bvh_leaf)};
        double t0 = now();
        if (bvh_build(&b, &nodes, &leaves, NULL, &err) < 0) {
            fprintf(stderr, "bvhbench: %s\n", err.msg);
            return 1;
        }
        bf[k] = now() - t0;
        free(nodes.data);
        free(leaves.data);
        bld_free(&b);
        RTCScene es = embree_scene(dev, &m, RTC_BUILD_QUALITY_MEDIUM);
        t0 = now();
        rtcCommitScene(es);
        be[k] = now() - t0;
        rtcReleaseScene(es);
        es = embree_scene(dev, &m, RTC_BUILD_QUALITY_HIGH);
        t0 = now();
        rtcCommitScene(es);
        bh[k] = now() - t0;
        rtcReleaseScene(es);
    }
    double mbf = median(bf, reps), mbe = median(be, reps), mbh = median(bh, reps);
    printf("build      franja %8.1f ms   embree %8.1f ms   embree-high %8.1f ms   franja/embree %.2f   "
           "franja/embree-high %.2f (time ratios: lower is better)\n",
           mbf * 1e3, mbe * 1e3, mbh * 1e3, mbf / mbe, mbf / mbh);

    RTCScene es = embree_scene(dev, &m, RTC_BUILD_QUALITY_MEDIUM);
    rtcCommitScene(es);
    RTCScene eh = embree_scene(dev, &m, RTC_BUILD_QUALITY_HIGH);
    rtcCommitScene(eh);
    uint32_t np = 0, nb = 0;
    fr_ray *rays = make_rays(&s, w, h, &np, &nb);
    if (!rays) {
        fprintf(stderr, "bvhbench: out of memory for the rays\n");
        return 1;
    }
    uint32_t bad = disagreements(&s, es, &m, rays, np + nb), badh = disagreements(&s, eh, &m, rays, np + nb);
    printf("rays       %u primary (%ux%u), %u diffuse bounces; Embree disagrees on %u (%.3f %%), high quality on %u\n",
           np, w, h, nb, bad, 100.0 * bad / (np + nb), badh);
    volatile uint32_t sink = 0;
    const char *names[4] = {"primary closest", "primary any    ", "bounce closest ", "bounce any     "};
    for (int q = 0; q < 4; q++) {
        const fr_ray *r = q < 2 ? rays : rays + np;
        uint32_t n = q < 2 ? np : nb;
        if (n == 0)
            continue;
        trio p = throughput(&s, es, eh, r, n, q & 1, reps, walks, &sink);
        printf("%s franja %6.2f Mrays/s   embree %6.2f   embree-high %6.2f   ratio %.2f   ratio-high %.2f\n", names[q],
               p.franja, p.embree, p.high, p.franja / p.embree, p.franja / p.high);
        if (walks) {
            printf("  walks   ");
            for (int k = 0; k < TRACE_WALKS; k++)
                if (p.walk[k] > 0.0)
                    printf(" %s %6.2f", trace_walk_name(k), p.walk[k]);
            if (p.walk[TRACE_WALK_AVX512] > 0.0 && p.walk[TRACE_WALK_AVX2] > 0.0)
                printf("   avx512/avx2 %.3f", p.walk[TRACE_WALK_AVX512] / p.walk[TRACE_WALK_AVX2]);
            printf("\n");
        }
    }
    if (worker) {
        double ms = startup_ms(worker, path, reps);
        if (ms < 0)
            return 1;
        printf("start-up   %s: %.1f ms from process start to first pixel\n", worker, ms);
    }
    rtcReleaseScene(es);
    rtcReleaseScene(eh);
    rtcReleaseDevice(dev);
    free(rays);
    scn_free(&s);
    return 0;
}
