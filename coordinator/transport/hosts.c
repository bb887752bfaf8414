/* hosts.c -- the host table parser (format in hosts.h and franja-hosts(5)). */
#include "transport/hosts.h"

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "file.h"

#define HOSTS_MAX_LINE 4096
#define HOSTS_MAX_BYTES ((size_t)16 << 20)   /* a host table larger than 16 MiB is not one */

/* Copies src into a fixed field, refusing what would not fit rather than
 * silently cutting a path or a name. */
static int copy_field(char *dst, size_t cap, const char *src, const char *path, int line,
                      const char *what, fr_error *err)
{
    size_t n = strlen(src);
    if (n == 0)
        return fr_fail(err, "%s:%d: empty %s", path, line, what);
    if (n >= cap)
        return fr_fail(err, "%s:%d: %s is longer than %zu characters", path, line, what, cap - 1);
    memcpy(dst, src, n + 1);
    return 0;
}

/* Parses a decimal integer in [lo, hi]; returns -1 if it is anything else. */
static long parse_range(const char *s, long lo, long hi)
{
    if (!*s)
        return -1;
    for (const char *p = s; *p; p++)
        if (!isdigit((unsigned char)*p))
            return -1;
    errno = 0;
    long v = strtol(s, NULL, 10);
    if (errno || v < lo || v > hi)
        return -1;
    return v;
}

static int valid_name(const char *s)
{
    for (; *s; s++)
        if (!isalnum((unsigned char)*s) && !strchr("-_.", *s))
            return 0;
    return 1;
}

/* address[:port], [ipv6]:port or a bare IPv6 address (more than one colon). */
static int parse_address(hosts_entry *h, const char *s, const char *path, int line, fr_error *err)
{
    char host[256];
    const char *port = NULL;
    if (s[0] == '[') {
        const char *close = strchr(s, ']');
        if (!close)
            return fr_fail(err, "%s:%d: address '%s': '[' without ']'", path, line, s);
        size_t n = (size_t)(close - s - 1);
        if (n == 0 || n >= sizeof host)
            return fr_fail(err, "%s:%d: address '%s': bad bracketed address", path, line, s);
        memcpy(host, s + 1, n);
        host[n] = 0;
        if (close[1] == ':')
            port = close + 2;
        else if (close[1])
            return fr_fail(err, "%s:%d: address '%s': expected ':PORT' after ']'", path, line, s);
    } else {
        const char *colon = strchr(s, ':');
        if (colon && strchr(colon + 1, ':'))
            colon = NULL; /* a bare IPv6 address */
        size_t n = colon ? (size_t)(colon - s) : strlen(s);
        if (n == 0 || n >= sizeof host)
            return fr_fail(err, "%s:%d: address '%s': expected HOST[:PORT]", path, line, s);
        memcpy(host, s, n);
        host[n] = 0;
        if (colon)
            port = colon + 1;
    }
    if (port) {
        long p = parse_range(port, 1, 65535);
        if (p < 0)
            return fr_fail(err, "%s:%d: bad port '%s' in address '%s': expected 1..65535", path, line,
                           port, s);
        h->port = (int)p;
    }
    if (!strcmp(host, "local") && port)
        return fr_fail(err, "%s:%d: address 'local' takes no port", path, line);
    return copy_field(h->address, sizeof h->address, host, path, line, "address", err);
}

int hosts_parse_size(const char *s, uint64_t *bytes)
{
    uint64_t v = 0;
    const char *p = s;
    if (*p < '0' || *p > '9')
        return -1;
    for (; *p >= '0' && *p <= '9'; p++) {
        v = v * 10 + (uint64_t)(*p - '0');
        if (v > (1ull << 60))
            return -1;
    }
    static const char units[] = "kmgt";
    const char *u = *p ? strchr(units, *p | 0x20) : NULL;
    if (u) {
        for (int i = 0; i <= u - units; i++) {
            if (v > (1ull << 50))
                return -1;
            v <<= 10;
        }
        p++;
        if ((*p | 0x20) == 'i' && p[1])
            p++;
        if ((*p | 0x20) == 'b')
            p++;
    } else if ((*p | 0x20) == 'b') {
        p++;
    }
    if (*p || v == 0 || v > (1ull << 60))
        return -1;
    *bytes = v;
    return 0;
}

void hosts_format_size(uint64_t bytes, char *out)
{
    static const char *const units[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    if (bytes < 1024) {
        snprintf(out, 32, "%u B", (unsigned)bytes);
        return;
    }
    double v = (double)bytes / 1024;
    int u = 0;
    while (v >= 1024 && u < 5) {
        v /= 1024;
        u++;
    }
    snprintf(out, 32, "%.1f %s", v, units[u]);
}

static int parse_option(hosts_entry *h, char *kv, const char *path, int line, fr_error *err)
{
    char *eq = strchr(kv, '=');
    if (!eq || eq == kv)
        return fr_fail(err, "%s:%d: '%s': expected key=value (identity, worker, workdir, arch, os, cache)",
                       path, line, kv);
    *eq = 0;
    const char *key = kv, *val = eq + 1;
    if (!strcmp(key, "cache")) {
        if (h->cache)
            return fr_fail(err, "%s:%d: cache= given twice", path, line);
        if (hosts_parse_size(val, &h->cache))
            return fr_fail(err, "%s:%d: cache='%s': expected a size such as 500M or 10G (K, M, G, T: "
                           "powers of 1024), at least 1 byte", path, line, val);
        return 0;
    }
    struct { const char *key; char *dst; size_t cap; } keys[] = {
        {"identity", h->identity, sizeof h->identity},
        {"worker", h->worker, sizeof h->worker},
        {"workdir", h->workdir, sizeof h->workdir},
        {"arch", h->arch, sizeof h->arch},
        {"os", h->os, sizeof h->os},
    };
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        if (strcmp(key, keys[i].key))
            continue;
        if (keys[i].dst[0])
            return fr_fail(err, "%s:%d: %s= given twice", path, line, key);
        return copy_field(keys[i].dst, keys[i].cap, val, path, line, key, err);
    }
    return fr_fail(err, "%s:%d: unknown key '%s': expected identity, worker, workdir, arch, os or cache",
                   path, line, key);
}

/* Splits a line into whitespace-separated words in place; a '#' starts a
 * comment.  Returns the number of words. */
static int split(char *s, char **w, int max)
{
    int n = 0;
    for (;;) {
        while (*s == ' ' || *s == '\t' || *s == '\r')
            s++;
        if (!*s || *s == '#')
            return n;
        if (n == max)
            return max + 1;
        w[n++] = s;
        while (*s && *s != ' ' && *s != '\t' && *s != '\r' && *s != '#')
            s++;
        if (*s == '#') {
            *s = 0;
            return n;
        }
        if (*s)
            *s++ = 0;
    }
}

static int parse_line(hosts_entry *h, char **w, int nw, const char *path, int line, fr_error *err)
{
    memset(h, 0, sizeof *h);
    h->line = line;
    static const char *fields[] = {"name", "address[:port]", "user", "cores"};
    if (nw < 4)
        return fr_fail(err, "%s:%d: missing %s: expected NAME ADDRESS[:PORT] USER CORES [key=value ...]",
                       path, line, fields[nw]);
    if (!valid_name(w[0]))
        return fr_fail(err, "%s:%d: host name '%s': expected letters, digits, '-', '_' or '.'", path,
                       line, w[0]);
    if (copy_field(h->name, sizeof h->name, w[0], path, line, "host name", err) ||
        parse_address(h, w[1], path, line, err))
        return -1;
    if (strcmp(w[2], "-") && copy_field(h->user, sizeof h->user, w[2], path, line, "user", err))
        return -1;
    if (strcmp(w[3], "auto")) {
        long c = parse_range(w[3], 1, HOSTS_MAX_CORES);
        if (c < 0)
            return fr_fail(err, "%s:%d: cores '%s': expected 1..%d or 'auto'", path, line, w[3], HOSTS_MAX_CORES);
        h->cores = (int)c;
    }
    for (int i = 4; i < nw; i++)
        if (parse_option(h, w[i], path, line, err))
            return -1;
    return 0;
}

/* A host's name and where it is, for finding repeated names. */
typedef struct {
    const char *name;
    int line, i;
} name_at;

static int by_name(const void *a, const void *b)
{
    const name_at *x = a, *y = b;
    int c = strcmp(x->name, y->name);
    return c ? c : (x->line > y->line) - (x->line < y->line);
}

/* The entry of t that repeats an earlier name on the lowest line, or -1
 * (-2 out of memory); *first is the earlier one.  Sorting keeps this
 * O(n log n): a table of many hosts must not take minutes to read. */
static int first_duplicate(const hosts_table *t, int *first)
{
    name_at *v = malloc((size_t)(t->n ? t->n : 1) * sizeof *v);
    if (!v)
        return -2;
    for (int i = 0; i < t->n; i++)
        v[i] = (name_at){t->v[i].name, t->v[i].line, i};
    qsort(v, (size_t)t->n, sizeof *v, by_name);
    int dup = -1;
    /* The second of each run of one name, the first of the run before it. */
    for (int i = 1; i < t->n; i++)
        if (!strcmp(v[i].name, v[i - 1].name) && (i < 2 || strcmp(v[i - 2].name, v[i].name)) &&
            (dup < 0 || v[i].line < t->v[dup].line)) {
            dup = v[i].i;
            *first = v[i - 1].i;
        }
    free(v);
    return dup;
}

int hosts_parse(const char *text, const char *path, hosts_table *t, fr_error *err)
{
    memset(t, 0, sizeof *t);
    snprintf(t->path, sizeof t->path, "%s", path);
    int cap = 0, line = 0, bad = 0;
    const char *p = text;
    char buf[HOSTS_MAX_LINE];
    fr_error why;
    /* Every line is read up to the first bad one; a name repeated before
     * it is the first error, else that line's. */
    while (*p) {
        line++;
        const char *nl = strchr(p, '\n');
        size_t len = nl ? (size_t)(nl - p) : strlen(p);
        if (len >= sizeof buf) {
            bad = fr_fail(&why, "%s:%d: line longer than %d characters", path, line, HOSTS_MAX_LINE - 1);
            break;
        }
        memcpy(buf, p, len);
        buf[len] = 0;
        p = nl ? nl + 1 : p + len;
        char *w[32];
        int nw = split(buf, w, 32);
        if (nw == 0)
            continue;
        if (nw > 32) {
            bad = fr_fail(&why, "%s:%d: too many fields", path, line);
            break;
        }
        if (t->n == HOSTS_MAX_HOSTS) {
            bad = fr_fail(&why, "%s:%d: more than %d hosts", path, line, HOSTS_MAX_HOSTS);
            break;
        }
        if (t->n == cap) {
            cap = cap ? cap * 2 : 8;
            hosts_entry *v = realloc(t->v, (size_t)cap * sizeof *v);
            if (!v) {
                bad = fr_fail(&why, "%s:%d: out of memory", path, line);
                break;
            }
            t->v = v;
        }
        if (parse_line(&t->v[t->n], w, nw, path, line, &why)) {
            bad = -1;
            break;
        }
        t->n++;
    }
    int first = -1, dup = first_duplicate(t, &first);
    if (dup == -2) {
        hosts_free(t);
        return fr_fail(err, "%s: out of memory", path);
    }
    if (dup >= 0) {
        int at = t->v[dup].line, was = t->v[first].line;
        char name[sizeof t->v[dup].name];
        memcpy(name, t->v[dup].name, sizeof name);
        hosts_free(t);
        return fr_fail(err, "%s:%d: duplicate host name '%s' (first defined on line %d)", path, at, name, was);
    }
    if (bad) {
        hosts_free(t);
        *err = why;
        return -1;
    }
    if (t->n == 0) {
        hosts_free(t);
        return fr_fail(err, "%s: no hosts: expected lines NAME ADDRESS[:PORT] USER CORES", path);
    }
    return 0;
}

int hosts_load(const char *path, hosts_table *t, fr_error *err)
{
    memset(t, 0, sizeof *t);
    int fd;
    size_t size;
    fr_error e;
    if (file_open_regular(path, HOSTS_MAX_BYTES, &fd, &size, &e) < 0) {
        /* e.msg is "PATH: why" (file.h): say what the file was for. */
        size_t n = strlen(path);
        const char *why = strncmp(e.msg, path, n) == 0 && e.msg[n] == ':' ? e.msg + n + 2 : e.msg;
        return fr_fail(err, "%s: cannot open host table: %s", path, why);
    }
    FILE *f = fdopen(fd, "rb");
    if (!f) {
        close(fd);
        return fr_fail(err, "%s: cannot open host table: %s", path, strerror(errno));
    }
    char *text;
    size_t n;
    if (file_read_stream(f, path, &text, &n, err))
        return -1;
    if (memchr(text, 0, n)) {
        free(text);
        return fr_fail(err, "%s: binary data in host table", path);
    }
    int rc = hosts_parse(text, path, t, err);
    free(text);
    return rc;
}

int hosts_is_local(const hosts_entry *h) { return !strcmp(h->address, "local"); }

const char *hosts_workdir(const hosts_entry *h) { return h->workdir[0] ? h->workdir : ".cache/franja"; }

void hosts_free(hosts_table *t)
{
    free(t->v);
    t->v = NULL;
    t->n = 0;
}
