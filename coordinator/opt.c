/* opt.c -- option parsing for the subcommands (see opt.h). */
#include "opt.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "protocol.h"
#include "suggest.h"

/* A decimal integer in [lo, hi], no sign, nothing after it. */
static int parse_uint(const char *s, uint32_t lo, uint32_t hi, uint32_t *out)
{
    char *end;
    errno = 0;
    if (!s || !*s || *s == '-' || *s == '+')
        return -1;
    unsigned long v = strtoul(s, &end, 10);
    if (errno || *end || v < lo || v > hi)
        return -1;
    *out = (uint32_t)v;
    return 0;
}

int opt_default_output(const char *scene, const char *ext, char *buf, size_t cap)
{
    const char *slash = strrchr(scene, '/');
    const char *base = slash ? slash + 1 : scene;
    size_t n = strlen(base);
    static const char *const scene_ext[] = {".json", ".gltf", ".glb", ".fbin"};
    for (size_t i = 0; i < sizeof scene_ext / sizeof *scene_ext; i++) {
        size_t e = strlen(scene_ext[i]);
        if (n >= e && !strcasecmp(base + n - e, scene_ext[i])) {
            n -= e;
            break;
        }
    }
    if (n == 0 || (n == 1 && base[0] == '.') || (n == 2 && !strncmp(base, "..", 2)))
        return -1;
    int len = snprintf(buf, cap, "%.*s%s", (int)n, base, ext);
    return len < 0 || (size_t)len >= cap ? -1 : 0;
}

int opt_suggest(const char *typed, const char *shortopts, const struct option *longopts, char *buf, size_t cap)
{
    /* The command's names as sug_option takes them: a one-letter string for
     * each short option, then the long ones. */
    char shorts[64][2];
    const char *names[192];
    size_t count = 0, k = 0;
    for (const char *c = shortopts; *c && k < 64; c++)
        if (*c != ':') {
            shorts[k][0] = *c;
            shorts[k][1] = 0;
            names[count++] = shorts[k++];
        }
    for (const struct option *o = longopts; o->name && count < 192; o++)
        names[count++] = o->name;
    return sug_option(typed, names, count, buf, cap);
}

char **opt_copy(int argc, char **argv)
{
    char **v = calloc((size_t)argc + 1, sizeof *v);
    if (v)
        memcpy(v, argv, (size_t)argc * sizeof *v);
    return v;
}

int opt_next(const char *cmd, int argc, char **argv, const char *shortopts, const struct option *longopts)
{
    char spec[64];
    snprintf(spec, sizeof spec, ":%s", shortopts);
    opterr = 0;
    int c = getopt_long(argc, argv, spec, longopts, NULL);
    if (c != '?' && c != ':')
        return c;
    /* What was typed: the long option just passed, else the short one. */
    char typed[80];
    const char *prev = optind > 0 && optind <= argc ? argv[optind - 1] : "";
    if (!strncmp(prev, "--", 2))
        snprintf(typed, sizeof typed, "%.*s", (int)strcspn(prev, "="), prev);
    else
        snprintf(typed, sizeof typed, "-%c", optopt ? optopt : '?');
    if (c == ':') {
        fprintf(stderr, "franja %s: %s needs a value (see franja %s --help)\n", cmd, typed, cmd);
        return '?';
    }
    if (typed[1] == '-' && strchr(prev, '=')) {
        /* --flag=value for an option that takes none. */
        const struct option *match = NULL;
        int matches = 0;
        for (const struct option *o = longopts; o->name; o++)
            if (!strncmp(o->name, typed + 2, strlen(typed + 2))) {
                matches++;
                match = o;
                if (!strcmp(o->name, typed + 2)) {
                    matches = 1;   /* an exact name wins over longer ones */
                    break;
                }
            }
        if (matches == 1 && match->has_arg == no_argument) {
            fprintf(stderr, "franja %s: --%s takes no value\n", cmd, match->name);
            return '?';
        }
    }
    if (typed[1] == '-') {
        /* A known prefix of several options is ambiguous, not unknown. */
        size_t n = strlen(typed + 2), k = 0;
        char which[256] = "";
        for (const struct option *o = longopts; o->name; o++)
            if (n && !strncmp(o->name, typed + 2, n)) {
                size_t used = strlen(which);
                snprintf(which + used, sizeof which - used, "%s--%s", k++ ? ", " : "", o->name);
            }
        if (k > 1) {
            fprintf(stderr, "franja %s: %s is ambiguous: %s\n", cmd, typed, which);
            return '?';
        }
    }
    char near[80];
    if (opt_suggest(typed, shortopts, longopts, near, sizeof near) == 0)
        fprintf(stderr, "franja %s: unknown option '%s'; did you mean %s? (see franja %s --help)\n", cmd, typed,
                near, cmd);
    else
        fprintf(stderr, "franja %s: unknown option '%s' (see franja %s --help)\n", cmd, typed, cmd);
    return '?';
}

int opt_uint(const char *cmd, const char *opt, const char *v, uint32_t lo, uint32_t hi, uint32_t *out)
{
    if (parse_uint(v, lo, hi, out) == 0)
        return 0;
    fprintf(stderr, "franja %s: %s: '%s' is not an integer in %u..%u\n", cmd, opt, v, lo, hi);
    return -1;
}

int opt_float(const char *cmd, const char *opt, const char *v, float lo, float hi, float *out)
{
    char *end;
    errno = 0;
    double d = strtod(v, &end);
    if (!errno && end != v && !*end && d >= lo && d <= hi) {
        *out = (float)d;
        return 0;
    }
    fprintf(stderr, "franja %s: %s: '%s' is not a number in %g..%g\n", cmd, opt, v, (double)lo, (double)hi);
    return -1;
}

int opt_fraction(const char *cmd, const char *opt, const char *v, float *out)
{
    char *end;
    errno = 0;
    double d = strtod(v, &end);
    /* Above 0 as the float it becomes: 1e-50 would be 0, "not given". */
    if (!errno && end != v && !*end && d > 0.0 && d <= 1.0 && (float)d > 0.0f) {
        *out = (float)d;
        return 0;
    }
    fprintf(stderr, "franja %s: %s: '%s' is not a number in (0, 1] (above 0, at most 1)\n", cmd, opt, v);
    return -1;
}

int opt_size(const char *cmd, const char *opt, const char *v, uint32_t *w, uint32_t *h)
{
    if (proto_parse_size(v, w, h) == 0)
        return 0;
    fprintf(stderr, "franja %s: %s: '%s' is not WxH (width and height in pixels, each in 1..%u, like 640x480)\n",
            cmd, opt, v, PROTO_MAX_SIZE);
    return -1;
}

int opt_choice(const char *cmd, const char *opt, const char *v, const char *const *choices)
{
    for (int i = 0; choices[i]; i++)
        if (!strcmp(v, choices[i]))
            return i;
    char list[256] = "";
    for (int i = 0; choices[i]; i++) {
        size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s%s", i ? ", " : "", choices[i]);
    }
    fprintf(stderr, "franja %s: %s: '%s' is not one of: %s\n", cmd, opt, v, list);
    return -1;
}


int opt_scale(const char *cmd, const char *opt, const char *v, double *out)
{
    char *end;
    errno = 0;
    double d = strtod(v, &end);
    int pct = end != v && *end == '%' && end[1] == 0;
    if (pct)
        d /= 100.0;
    if (!errno && end != v && (pct || !*end) && d > 0.0 && d <= OPT_SCALE_MAX) {
        *out = d;
        return 0;
    }
    fprintf(stderr, "franja %s: %s: '%s' is not a scale: a percentage above 0%% and at most %g%% (like 50%%), "
            "or a factor above 0 and at most %g (like 0.5)\n", cmd, opt, v, OPT_SCALE_MAX * 100.0, OPT_SCALE_MAX);
    return -1;
}

int opt_duration(const char *cmd, const char *opt, const char *v, double *out)
{
    char *end;
    errno = 0;
    double d = strtod(v, &end);
    double unit = 1.0;
    if (end != v && *end && !end[1]) {
        unit = *end == 's' ? 1.0 : *end == 'm' ? 60.0 : *end == 'h' ? 3600.0 : 0.0;
        end++;
    }
    /* Digits only: no "inf", "nan", hexadecimal or exponent forms. */
    int plain = strspn(v, "0123456789.") == strlen(v) - (*v && strchr("smh", v[strlen(v) - 1]) ? 1 : 0);
    if (!errno && end != v && !*end && plain && unit > 0.0 && d * unit > 0.0 && d * unit <= OPT_DURATION_MAX) {
        *out = d * unit;
        return 0;
    }
    fprintf(stderr, "franja %s: %s: '%s' is not a duration: a number above 0 followed by s (seconds, the default), "
            "m (minutes) or h (hours), like 90s, 10m or 1.5h, at most %g h\n", cmd, opt, v, OPT_DURATION_MAX / 3600.0);
    return -1;
}

uint32_t opt_scaled(uint32_t n, double s)
{
    double x = floor((double)n * s + 0.5);
    return x < 1.0 ? 1u : x > (double)UINT32_MAX ? UINT32_MAX : (uint32_t)x;
}

static uint32_t gcd(uint32_t a, uint32_t b)
{
    while (b) {
        uint32_t t = a % b;
        a = b;
        b = t;
    }
    return a;
}

int opt_aspect_note(uint32_t w, uint32_t h, uint32_t sw, uint32_t sh, char *buf, size_t cap)
{
    if (cap)
        buf[0] = 0;
    if (!w || !h || !sw || !sh || (uint64_t)w * sh == (uint64_t)h * sw)
        return 0;
    uint32_t g = gcd(w, h), sg = gcd(sw, sh);
    snprintf(buf, cap, "%ux%u is %u:%u (%.3f), the scene's %ux%u is %u:%u (%.3f): the aspect ratio changes "
             "(the vertical field of view stays, so the image shows more or less at the sides)",
             w, h, w / g, h / g, (double)w / h, sw, sh, sw / sg, sh / sg, (double)sw / sh);
    return 1;
}
