/* scene_pages.c -- a loaded scene's BVH copied into memory of 2 MiB pages (see
 * scene_pages.h). */

#include "scene_pages.h"

#include <stdint.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#define LARGE ((size_t)2 << 20)

static size_t round_up(size_t n, size_t to) { return (n + to - 1) / to * to; }

int scn_bvh_large_pages(fr_scene *s)
{
    if (s->bvh_copy || s->n_nodes == 0)
        return 0;
    size_t nodes = round_up((size_t)s->n_nodes * sizeof(fr_bvh_node), 64);
    size_t bytes = nodes + (size_t)s->n_leaves * sizeof(fr_bvh_leaf);
    long cpus = sysconf(_SC_NPROCESSORS_ONLN), pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (cpus < 1)
        cpus = 1;
    if (bytes < SCN_PAGES_MIN || pages <= 0 || page <= 0 ||
        bytes > (size_t)pages / 8 * (size_t)page / (size_t)cpus)
        return 0;
    /* Reserve a large page more than needed, keep the aligned part. */
    size_t len = round_up(bytes, LARGE);
    char *m = mmap(NULL, len + LARGE, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED)
        return 0;
    char *a = (char *)round_up((uintptr_t)m, LARGE);
    if (a > m)
        munmap(m, (size_t)(a - m));
    if (a + len < m + len + LARGE)
        munmap(a + len, (size_t)(m + len + LARGE - (a + len)));
#ifdef MADV_HUGEPAGE
    madvise(a, len, MADV_HUGEPAGE);   /* advice: without it the copy still works */
#endif
    memcpy(a, s->nodes, (size_t)s->n_nodes * sizeof(fr_bvh_node));
    memcpy(a + nodes, s->leaves, (size_t)s->n_leaves * sizeof(fr_bvh_leaf));
    mprotect(a, len, PROT_READ);
    s->nodes = (const fr_bvh_node *)a;
    s->leaves = (const fr_bvh_leaf *)(a + nodes);
    s->bvh_copy = a;
    s->bvh_copy_size = len;
    return 1;
}

void scn_bvh_pages_free(fr_scene *s)
{
    if (s->bvh_copy)
        munmap(s->bvh_copy, s->bvh_copy_size);
    s->bvh_copy = NULL;
    s->bvh_copy_size = 0;
}
