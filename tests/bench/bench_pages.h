/* bench_pages.h -- where a BVH benchmark's arrays lie in memory pages.
 *
 * The walk's speed depends on the pages its tree lies in: with 4 KiB pages
 * a ray through a tree of tens of MiB misses the address translation
 * caches on most nodes and leaf blocks, with 2 MiB pages it seldom does.
 * Embree asks for 2 MiB pages for its trees; a binary scene is mapped from
 * its file, where the kernel gives 2 MiB mappings only to parts of the
 * page cache that happen to be in large folios.  These functions copy arrays
 * into pages of either size and report how a mapping is paged, so that the
 * benchmarks say what they measured. */
#ifndef FRANJA_BENCH_PAGES_H
#define FRANJA_BENCH_PAGES_H

#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>

/* A copy of `bytes` (> 0) at p in anonymous memory on a 2 MiB boundary,
 * with 2 MiB pages asked for (huge, madvise) or refused.  Never freed (the
 * benchmarks keep their trees to the end).  NULL when out of memory. */
static inline void *page_copy(const void *p, size_t bytes, int huge)
{
    size_t big = (size_t)2 << 20, len = (bytes + 2 * big - 1) / big * big;
    char *m = mmap(NULL, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED)
        return NULL;
    char *q = (char *)(((uintptr_t)m + big - 1) / big * big);
    madvise(q, len - (size_t)(q - m), huge ? MADV_HUGEPAGE : MADV_NOHUGEPAGE);
    memcpy(q, p, bytes);
    return q;
}

/* The mapping of this process holding `addr`: its size and how much of it
 * is mapped with 2 MiB pages (file or anonymous), in KiB, from
 * /proc/self/smaps.  Returns 0, or -1 when that cannot be read. */
static inline int page_state(const void *addr, unsigned long *size_kb, unsigned long *huge_kb)
{
    FILE *f = fopen("/proc/self/smaps", "r");
    if (!f)
        return -1;
    char line[512];
    int in = 0, found = 0;
    *size_kb = *huge_kb = 0;
    while (fgets(line, sizeof line, f)) {
        unsigned long lo, hi, v;
        if (sscanf(line, "%lx-%lx ", &lo, &hi) == 2 && strchr(line, '-') < strchr(line, ' ')) {
            if (found)
                break;
            in = (uintptr_t)addr >= lo && (uintptr_t)addr < hi;
            found = in;
            continue;
        }
        if (!in)
            continue;
        if (sscanf(line, "Size: %lu kB", &v) == 1)
            *size_kb = v;
        else if (sscanf(line, "FilePmdMapped: %lu kB", &v) == 1 || sscanf(line, "AnonHugePages: %lu kB", &v) == 1)
            *huge_kb += v;
    }
    fclose(f);
    return found ? 0 : -1;
}

#endif
