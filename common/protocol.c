/* protocol.c -- the worker protocol (see protocol.h). */
#include "protocol.h"

#include "suggest.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fbin.h"
#include "passes.h"
#include "scene.h"
#include "trace.h"

static const char *const format_names[] = {"pf", "ppm16", "ppm8"};
static const char *const integrator_names[] = {"path", "bdpt", "mlt"};

int proto_integrator_parse(const char *name, int *out)
{
    for (int i = 0; i < FR_INTEGRATORS; i++)
        if (!strcmp(name, integrator_names[i])) {
            *out = i;
            return 0;
        }
    return -1;
}

const char *proto_integrator_name(int i)
{
    return i >= 0 && i < FR_INTEGRATORS ? integrator_names[i] : "?";
}

static int parse_u32(const char *s, uint32_t *out)
{
    char *end;
    errno = 0;
    if (s[0] == '-' || s[0] == '+')
        return -1;
    unsigned long v = strtoul(s, &end, 10);
    if (errno || end == s || *end || v > 0xffffffffUL)
        return -1;
    *out = (uint32_t)v;
    return 0;
}

/* "A<sep>B" into two integers. */
static int parse_pair(const char *s, char sep, uint32_t *a, uint32_t *b)
{
    const char *p = strchr(s, sep);
    char first[32];
    if (!p || (size_t)(p - s) >= sizeof first)
        return -1;
    memcpy(first, s, (size_t)(p - s));
    first[p - s] = 0;
    return parse_u32(first, a) < 0 || parse_u32(p + 1, b) < 0 ? -1 : 0;
}

int proto_parse_size(const char *s, uint32_t *w, uint32_t *h)
{
    uint32_t a, b;
    if (parse_pair(s, 'x', &a, &b) < 0 || a == 0 || b == 0 || a > PROTO_MAX_SIZE || b > PROTO_MAX_SIZE)
        return -1;
    *w = a;
    *h = b;
    return 0;
}

int proto_slab_argv(const proto_slab *s, proto_argv *a, fr_error *err)
{
    if (!s->scene || !s->out)
        return fr_fail(err, "slab without a scene or an output");
    if (s->y0 >= s->y1 || s->y1 > PROTO_MAX_SIZE)
        return fr_fail(err, "rows %u:%u: not a slab of an image of at most %u rows", s->y0, s->y1, PROTO_MAX_SIZE);
    if ((s->width || s->height) && (!s->width || !s->height || s->width > PROTO_MAX_SIZE ||
                                    s->height > PROTO_MAX_SIZE || s->y1 > s->height))
        return fr_fail(err, "size %ux%u: out of 1..%u or shorter than rows %u:%u", s->width, s->height,
                       PROTO_MAX_SIZE, s->y0, s->y1);
    if (s->spp > PROTO_MAX_SPP)
        return fr_fail(err, "%u samples per pixel: more than %u", s->spp, PROTO_MAX_SPP);
    if (!(s->noise_threshold >= 0.0f && s->noise_threshold <= 1.0f))
        return fr_fail(err, "noise threshold %g: not in [0, 1]", (double)s->noise_threshold);
    if ((unsigned)s->format >= sizeof format_names / sizeof *format_names)
        return fr_fail(err, "unknown partial image format %d", (int)s->format);
    if (s->integrator < 0 || s->integrator > FR_INTEGRATORS)
        return fr_fail(err, "unknown integrator %d", s->integrator - 1);
    if (s->mlt_norm && (s->mlt_depths == 0 || s->mlt_depths > PROTO_MLT_DEPTHS))
        return fr_fail(err, "Metropolis normalisation of %u depths: not in 1..%u", s->mlt_depths, PROTO_MLT_DEPTHS);
    int n = 0;
    snprintf(a->rows, sizeof a->rows, "%u:%u", s->y0, s->y1);
    a->argv[n++] = "--scene";
    a->argv[n++] = s->scene;
    a->argv[n++] = "--rows";
    a->argv[n++] = a->rows;
    if (s->spp) {
        snprintf(a->spp, sizeof a->spp, "%u", s->spp);
        a->argv[n++] = "--spp";
        a->argv[n++] = a->spp;
    }
    if (s->noise_threshold > 0.0f) {
        /* Nine significant digits give back the same float. */
        snprintf(a->noise, sizeof a->noise, "%.9g", (double)s->noise_threshold);
        a->argv[n++] = "--noise-threshold";
        a->argv[n++] = a->noise;
    }
    if (s->width) {
        snprintf(a->size, sizeof a->size, "%ux%u", s->width, s->height);
        a->argv[n++] = "--size";
        a->argv[n++] = a->size;
    }
    if (s->integrator) {
        a->argv[n++] = "--integrator";
        a->argv[n++] = integrator_names[s->integrator - 1];
    }
    a->argv[n++] = "--format";
    a->argv[n++] = format_names[s->format];
    a->argv[n++] = "-o";
    a->argv[n++] = s->out;
    if (s->lifeline)
        a->argv[n++] = "--lifeline";
    if (s->sums)
        a->argv[n++] = "--sums";
    if (s->continue_from) {
        a->argv[n++] = "--continue";
        a->argv[n++] = s->continue_from;
    }
    if (s->passes & PASS_ALL) {
        pass_format(s->passes & PASS_ALL, a->passes, sizeof a->passes);
        a->argv[n++] = "--passes";
        a->argv[n++] = a->passes;
    }
    if (s->mlt_norm) {
        /* The floats' bits, exact: every worker gets the same numbers. */
        size_t o = 0;
        for (uint32_t d = 0; d < s->mlt_depths; d++) {
            uint32_t bits;
            memcpy(&bits, &s->mlt_norm[d], sizeof bits);
            o += (size_t)snprintf(a->mlt_norm + o, sizeof a->mlt_norm - o, "%s%08x", d ? "," : "", bits);
        }
        a->argv[n++] = "--mlt-norm";
        a->argv[n++] = a->mlt_norm;
    }
    a->argv[n] = NULL;
    return 0;
}

/* Parses --mlt-norm's LIST into out (at most PROTO_MLT_DEPTHS values, their
 * count in *n): 8 hex digits a value, the bits of a finite float >= 0,
 * separated by commas.  Fails naming the byte offset of what is wrong. */
static int parse_mlt_norm(const char *list, float *out, uint32_t *n, fr_error *err)
{
    const char *p = list;
    *n = 0;
    for (;;) {
        if (*n == PROTO_MLT_DEPTHS)
            return fr_fail(err, "--mlt-norm: byte %zu: more than %u values", (size_t)(p - list), PROTO_MLT_DEPTHS);
        uint32_t bits = 0;
        for (int k = 0; k < 8; k++, p++) {
            int c = *p, v = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
            if (v < 0)
                return fr_fail(err, "--mlt-norm: byte %zu: expected a hex digit (0-9, a-f)", (size_t)(p - list));
            bits = bits << 4 | (uint32_t)v;
        }
        float f;
        memcpy(&f, &bits, sizeof f);
        if (!(f >= 0.0f) || !isfinite(f))
            return fr_fail(err, "--mlt-norm: byte %zu: not a finite value >= 0", (size_t)(p - 8 - list));
        out[(*n)++] = f;
        if (!*p)
            return 0;
        if (*p != ',')
            return fr_fail(err, "--mlt-norm: byte %zu: expected ',' or the end", (size_t)(p - list));
        p++;
    }
}

int proto_parse_args(int argc, char *const *argv, proto_request *r, fr_error *err)
{
    memset(r, 0, sizeof *r);
    r->slab.out = "-";
    const char *fmt_name = "pf", *rows = NULL;
    int check = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int has_arg = i + 1 < argc;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            r->mode = PROTO_HELP;
            return 0;
        } else if (!strcmp(a, "--version")) {
            r->mode = PROTO_VERSION;
            return 0;
        } else if (!strcmp(a, "--check")) {
            check = 1;
        } else if (!strcmp(a, "--features")) {
            r->mode = PROTO_FEATURES;
            return 0;
        } else if (!strcmp(a, "--lifeline")) {
            r->slab.lifeline = 1;
        } else if (!strcmp(a, "--sums")) {
            r->slab.sums = 1;
        } else if (!has_arg && (!strcmp(a, "--scene") || !strcmp(a, "--rows") || !strcmp(a, "--spp") ||
                                !strcmp(a, "--size") || !strcmp(a, "--format") || !strcmp(a, "--integrator") ||
                                !strcmp(a, "--noise-threshold") || !strcmp(a, "--continue") || !strcmp(a, "-o") ||
                                !strcmp(a, "--unpack") || !strcmp(a, "--passes") || !strcmp(a, "--mlt-norm"))) {
            return fr_fail(err, "%s needs a value", a);
        } else if (!strcmp(a, "--scene")) {
            r->slab.scene = argv[++i];
        } else if (!strcmp(a, "--rows")) {
            rows = argv[++i];
        } else if (!strcmp(a, "--spp")) {
            if (parse_u32(argv[++i], &r->slab.spp) < 0 || r->slab.spp == 0 || r->slab.spp > PROTO_MAX_SPP)
                return fr_fail(err, "--spp: expected an integer in [1, %u], got '%s'", PROTO_MAX_SPP, argv[i]);
        } else if (!strcmp(a, "--noise-threshold")) {
            char *end;
            float e = strtof(argv[++i], &end);
            if (end == argv[i] || *end || !(e > 0.0f && e <= 1.0f))
                return fr_fail(err, "--noise-threshold: expected a number in (0, 1], got '%s'", argv[i]);
            r->slab.noise_threshold = e;
        } else if (!strcmp(a, "--size")) {
            if (proto_parse_size(argv[++i], &r->slab.width, &r->slab.height) < 0)
                return fr_fail(err, "--size: expected WxH with 1 <= W,H <= %u, got '%s'", PROTO_MAX_SIZE, argv[i]);
        } else if (!strcmp(a, "--format")) {
            fmt_name = argv[++i];
        } else if (!strcmp(a, "--integrator")) {
            int k;
            if (proto_integrator_parse(argv[++i], &k) < 0)
                return fr_fail(err, "--integrator: expected path, bdpt or mlt, got '%s'", argv[i]);
            r->slab.integrator = 1 + k;
        } else if (!strcmp(a, "-o")) {
            r->slab.out = argv[++i];
        } else if (!strcmp(a, "--continue")) {
            r->slab.continue_from = argv[++i];
        } else if (!strcmp(a, "--unpack")) {
            r->unpack = argv[++i];
        } else if (!strcmp(a, "--passes")) {
            fr_error e;
            if (pass_parse(argv[++i], &r->slab.passes, &e) < 0)
                return fr_fail(err, "--passes: %s", e.msg);
        } else if (!strcmp(a, "--mlt-norm")) {
            if (parse_mlt_norm(argv[++i], r->mlt_norm, &r->slab.mlt_depths, err) < 0)
                return -1;
            r->slab.mlt_norm = r->mlt_norm;
        } else {
            static const char *const known[] = {"help",       "version",         "check",    "lifeline", "sums",
                                                "scene",      "rows",            "spp",      "size",     "format",
                                                "integrator", "noise-threshold", "continue", "o",        "h",
                                                "features",   "unpack",          "passes",   "mlt-norm"};
            char near[64];
            if (a[0] == '-' && sug_option(a, known, sizeof known / sizeof *known, near, sizeof near) == 0)
                return fr_fail(err, "unknown argument '%s' (did you mean %s? see --help)", a, near);
            return fr_fail(err, "unknown argument '%s' (see --help)", a);
        }
    }
    if (img_format_parse(fmt_name, &r->slab.format) < 0)
        return fr_fail(err, "--format: expected pf, ppm16 or ppm8, got '%s'", fmt_name);
    if (!r->slab.scene)
        return fr_fail(err, "--scene is required (see --help)");
    if (r->unpack) {
        if (rows || check)
            return fr_fail(err, "--unpack takes --scene OUT only (see --help)");
        r->mode = PROTO_UNPACK;
        return 0;
    }
    if (!rows && !check)
        return fr_fail(err, "--rows is required (see --help)");
    if (rows && parse_pair(rows, ':', &r->slab.y0, &r->slab.y1) < 0)
        return fr_fail(err, "--rows: expected Y0:Y1 (two integers), got '%s'", rows);
    r->have_rows = rows != NULL;
    r->mode = check ? PROTO_CHECK : PROTO_RENDER;
    return 0;
}

void proto_version_line(const char *program, char *out, size_t cap)
{
    snprintf(out, cap, "%s %s scene-format %d", program, FRANJA_VERSION, FBIN_VERSION);
}

void proto_walk_line(char *out, size_t cap)
{
    int n = snprintf(out, cap, "walk %s (this processor runs:", trace_walk_name(trace_walk()));
    for (int k = 0; k < TRACE_WALKS && n >= 0 && (size_t)n < cap; k++)
        if (trace_walks() >> k & 1)
            n += snprintf(out + n, cap - (size_t)n, " %s", trace_walk_name(k));
    if (n >= 0 && (size_t)n < cap)
        snprintf(out + n, cap - (size_t)n, ")");
}

int proto_parse_version(const char *line, proto_version *v, fr_error *err)
{
    memset(v, 0, sizeof *v);
    int fmt, end = 0;
    char extra;
    if (sscanf(line, "%31s %31s scene-format %d%n%c", v->program, v->version, &fmt, &end, &extra) != 3 ||
        line[end] != 0 || fmt < 0)
        return fr_fail(err, "'%.120s' is not a version line (expected 'PROGRAM VERSION scene-format N')", line);
    v->scene_format = fmt;
    return 0;
}

void proto_check_argv(const char *path, const char *argv[4])
{
    argv[0] = "--scene";
    argv[1] = path;
    argv[2] = "--check";
    argv[3] = NULL;
}

void proto_unpack_argv(const char *in, const char *out, const char *argv[6])
{
    argv[0] = "--unpack";
    argv[1] = in;
    argv[2] = "--scene";
    argv[3] = out;
    argv[4] = NULL;
    argv[5] = NULL;
}

int proto_has_feature(const char *out, size_t len, const char *feature)
{
    size_t n = strlen(feature);
    for (size_t i = 0; i < len;) {
        while (i < len && (out[i] == ' ' || out[i] == '\t' || out[i] == '\n' || out[i] == '\r'))
            i++;
        size_t j = i;
        while (j < len && !(out[j] == ' ' || out[j] == '\t' || out[j] == '\n' || out[j] == '\r'))
            j++;
        if (j - i == n && !memcmp(out + i, feature, n))
            return 1;
        i = j;
    }
    return 0;
}

int proto_parse_check(const char *out, size_t len, uint64_t *hash, fr_error *err)
{
    if (len > 0 && out[len - 1] == '\n')
        len--;
    uint64_t h = 0;
    int ok = len == 16;
    for (size_t i = 0; ok && i < 16; i++) {
        char c = out[i];
        int d = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
        ok = d >= 0;
        h = h << 4 | (uint64_t)(ok ? d : 0);
    }
    if (!ok)
        return fr_fail(err, "--check printed '%.*s', not a 16-digit scene hash", (int)(len < 64 ? len : 64), out);
    *hash = h;
    return 0;
}

const char PROTO_PROBE_SCRIPT[] =
    "uname -m && uname -s && (nproc 2>/dev/null || getconf _NPROCESSORS_ONLN) && exec \"$0\" --version";

/* The next line of out[*pos..len) into line[cap] (without its newline);
 * -1 when there is none or it does not fit. */
static int next_line(const char *out, size_t len, size_t *pos, char *line, size_t cap)
{
    if (*pos >= len)
        return -1;
    const char *s = out + *pos, *nl = memchr(s, '\n', len - *pos);
    size_t n = nl ? (size_t)(nl - s) : len - *pos;
    *pos += n + (nl != NULL);
    if (n >= cap || memchr(s, 0, n))
        return -1;
    memcpy(line, s, n);
    line[n] = 0;
    return 0;
}

int proto_parse_probe(const char *out, size_t len, proto_host *h, fr_error *err)
{
    memset(h, 0, sizeof *h);
    size_t pos = 0;
    char cores[32];
    uint32_t n;
    if (next_line(out, len, &pos, h->arch, sizeof h->arch) || next_line(out, len, &pos, h->os, sizeof h->os) ||
        next_line(out, len, &pos, cores, sizeof cores) ||
        next_line(out, len, &pos, h->version, sizeof h->version) || parse_u32(cores, &n) || n == 0)
        return fr_fail(err, "unexpected answer to uname/nproc/--version");
    /* The walk line, where the worker prints one (a worker before it did
     * not): its first word after "walk". */
    char walk[128];
    if (next_line(out, len, &pos, walk, sizeof walk) == 0 && !strncmp(walk, "walk ", 5)) {
        size_t w = strcspn(walk + 5, " ");
        if (w >= sizeof h->walk)
            w = sizeof h->walk - 1;
        memcpy(h->walk, walk + 5, w);
        h->walk[w] = 0;
        proto_printable(h->walk);
    }
    h->cores_reported = n;
    h->cores = n > PROTO_MAX_CORES ? PROTO_MAX_CORES : (int)n;
    proto_printable(h->arch);
    proto_printable(h->os);
    proto_printable(h->version);
    return 0;
}

char *proto_printable(char *s)
{
    for (char *c = s; *c; c++)
        if ((unsigned char)*c < 0x20 || *c == 0x7f)
            *c = '?';
    return s;
}
