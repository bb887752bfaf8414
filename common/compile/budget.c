/* budget.c -- the compile budget (budget.h). */
#include "compile/budget.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static const struct {
    const char *name, *unit, *value;
    uint64_t def;
} limits[BUDGET_N] = {
    {"read", "bytes", "BYTES", BUDGET_DEFAULT_READ},
    {"vertices", "vertices", "N", BUDGET_DEFAULT_VERTICES},
    {"triangles", "triangles", "N", BUDGET_DEFAULT_TRIANGLES},
    {"fbin", "bytes", "BYTES", BUDGET_DEFAULT_FBIN},
    {"cpu", "seconds", "SECONDS", BUDGET_DEFAULT_CPU},
    {"memory", "bytes", "BYTES", BUDGET_DEFAULT_MEMORY},
};

void budget_init(fr_budget *b)
{
    memset(b, 0, sizeof *b);
    for (int k = 0; k < BUDGET_N; k++)
        b->limit[k] = limits[k].def;
}

int budget_set(fr_budget *b, const char *spec, fr_error *err)
{
    const char *eq = strchr(spec, '=');
    int k = -1;
    for (int i = 0; eq && i < BUDGET_N && k < 0; i++)
        if (strlen(limits[i].name) == (size_t)(eq - spec) && !strncmp(spec, limits[i].name, (size_t)(eq - spec)))
            k = i;
    if (k < 0)
        return fr_fail(err, "'%s': expected NAME=VALUE with NAME one of read, vertices, triangles, fbin, cpu, "
                       "memory", spec);
    const char *v = eq + 1;
    char *end;
    errno = 0;
    unsigned long long x = v[0] >= '0' && v[0] <= '9' ? strtoull(v, &end, 10) : 0;
    uint64_t scale = 1;
    if (x && !errno && *end && !end[1]) {
        const char *units = k == BUDGET_CPU ? "smh" : "KMGT";
        const char *u = strchr(units, k == BUDGET_CPU ? *end : (*end & ~0x20));
        if (u && *end) {
            scale = k == BUDGET_CPU ? (uint64_t[]){1, 60, 3600}[u - units] : (uint64_t)1 << (10 * (u - units + 1));
            end++;
        }
    }
    if (!x || errno || *end || x > UINT64_MAX / scale)
        return fr_fail(err, "%s: '%s' is not a whole number at least 1%s", limits[k].name, v,
                       k == BUDGET_CPU ? " with an optional s, m or h (like 600 or 2h)"
                                       : " with an optional K, M, G or T (powers of 1024, like 8G)");
    b->limit[k] = (uint64_t)x * scale;
    return 0;
}

/* Fails as budget_take would if n more of k would pass the limit, without
 * counting them. */
static int budget_check(const fr_budget *b, int k, uint64_t n, const char *where, fr_error *err)
{
    if (!b || (n <= b->limit[k] && b->used[k] <= b->limit[k] - n))
        return 0;
    return fr_fail(err, "%s: %llu %s%s would pass the compile's limit of %llu %s (--limit %s=%s raises it)", where,
                   (unsigned long long)n, b->used[k] ? "more " : "", limits[k].unit,
                   (unsigned long long)b->limit[k], limits[k].unit, limits[k].name, limits[k].value);
}

int budget_take(fr_budget *b, int k, uint64_t n, const char *where, fr_error *err)
{
    if (budget_check(b, k, n, where, err) < 0)
        return -1;
    if (b)
        b->used[k] += n;
    return 0;
}

int budget_take_file(fr_budget *b, const char *path, const char *where, fr_error *err)
{
    struct stat st;
    if (!b || stat(path, &st) < 0 || !S_ISREG(st.st_mode))
        return 0;
    return budget_take(b, BUDGET_READ, (uint64_t)st.st_size, where, err);
}
