/* rlimit.c -- the limits of a child process that reads untrusted input
 * (see rlimit.h). */
#include "compile/rlimit.h"

#include <stdio.h>
#include <sys/resource.h>
#include <unistd.h>

void rlimit_child(uint64_t extra, uint64_t cpu_soft, uint64_t cpu_hard)
{
    struct rlimit r = {0, 0};
    setrlimit(RLIMIT_CORE, &r);
    long pages = 0, page = sysconf(_SC_PAGESIZE);
    FILE *statm = fopen("/proc/self/statm", "r");
    if (statm) {
        if (fscanf(statm, "%ld", &pages) != 1)
            pages = 0;
        fclose(statm);
    }
    if (pages > 0 && page > 0 && extra < ((uint64_t)1 << 62)) {
        r.rlim_cur = r.rlim_max = (rlim_t)pages * (rlim_t)page + (rlim_t)extra;
        setrlimit(RLIMIT_AS, &r);
    }
    r.rlim_cur = (rlim_t)cpu_soft;
    r.rlim_max = (rlim_t)cpu_hard;
    setrlimit(RLIMIT_CPU, &r);
}
