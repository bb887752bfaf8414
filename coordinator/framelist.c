/* framelist.c -- frame lists (--frames) and '#' file-name patterns. */
#include "framelist.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Reads a frame number at *p (decimal digits only) and moves past it. */
static int number(const char **p, uint32_t *v)
{
    const char *s = *p;
    uint64_t x = 0;
    if (*s < '0' || *s > '9')
        return -1;
    while (*s >= '0' && *s <= '9') {
        x = x * 10 + (uint64_t)(*s - '0');
        if (x > FRAMES_MAX_NUMBER)
            return -1;
        s++;
    }
    *v = (uint32_t)x;
    *p = s;
    return 0;
}

static int push(frame_list *l, size_t *cap, uint32_t f)
{
    if (l->n == *cap) {
        size_t c = *cap ? *cap * 2 : 16;
        uint32_t *v = realloc(l->v, c * sizeof *v);
        if (!v)
            return -1;
        l->v = v;
        *cap = c;
    }
    l->v[l->n++] = f;
    return 0;
}

int framelist_parse(const char *spec, frame_list *out, fr_error *err)
{
    out->v = NULL;
    out->n = 0;
    size_t cap = 0;
    const char *p = spec;
    if (!*p)
        return fr_fail(err, "--frames: empty; expected frames like 1-240, 1-240:2 or 1,5,9");
    for (;;) {
        size_t at = (size_t)(p - spec);
        uint32_t a, b, step = 1;
        if (number(&p, &a))
            goto bad;
        b = a;
        if (*p == '-') {
            p++;
            if (number(&p, &b))
                goto bad;
            if (*p == ':') {
                p++;
                if (number(&p, &step) || step == 0)
                    goto bad;
            }
            if (b < a) {
                framelist_free(out);
                return fr_fail(err, "--frames '%s': at byte %zu: the range %u-%u runs backwards", spec, at, a, b);
            }
        }
        if (*p && *p != ',')
            goto bad;
        for (uint64_t f = a; f <= b; f += step) {
            if (out->n >= FRAMES_MAX) {
                framelist_free(out);
                return fr_fail(err, "--frames '%s': more than %u frames", spec, FRAMES_MAX);
            }
            if (push(out, &cap, (uint32_t)f)) {
                framelist_free(out);
                return fr_fail(err, "--frames: out of memory");
            }
        }
        if (!*p)
            return 0;
        p++;
        continue;
    bad:
        framelist_free(out);
        return fr_fail(err, "--frames '%s': at byte %zu: expected N, A-B or A-B:S (numbers 0..%u, S > 0), "
                       "separated by commas", spec, at, FRAMES_MAX_NUMBER);
    }
}

void framelist_free(frame_list *l)
{
    free(l->v);
    l->v = NULL;
    l->n = 0;
}

int framelist_is_pattern(const char *s)
{
    return strchr(s, '#') != NULL;
}

int framelist_subst(const char *pattern, uint32_t frame, char *buf, size_t cap)
{
    size_t o = 0;
    for (const char *p = pattern; *p;) {
        if (*p != '#') {
            if (o + 1 >= cap)
                return -1;
            buf[o++] = *p++;
            continue;
        }
        int w = 0;
        while (*p == '#') {
            w++;
            p++;
        }
        int k = snprintf(buf + o, cap - o, "%0*u", w, frame);
        if (k < 0 || (size_t)k >= cap - o)
            return -1;
        o += (size_t)k;
    }
    if (o >= cap)
        return -1;
    buf[o] = '\0';
    return 0;
}
