/* jsoncheck.c -- strict JSON syntax, with line and column (see jsoncheck.h).
 *
 * A recursive-descent recognizer of RFC 8259 that builds nothing: it only
 * remembers the (unescaped) member names of the objects it is inside, to
 * find duplicates when each object closes, and the path to the current
 * value, to say in which object a duplicate is. */
#include "compile/jsoncheck.h"

#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct { size_t name, len, at; } member;   /* name: offset into names; at: its opening quote */
typedef struct { int is_member; size_t at, len, index; } step;   /* how a value was reached */

typedef struct {
    const char *s;
    size_t n, i;
    const char *file;
    fr_error *err;
    int depth;
    step path[JC_MAX_DEPTH];
    member *mem;
    size_t n_mem, cap_mem;
    char *names;
    size_t n_names, cap_names;
} jc;

/* Line and column (from 1; columns count UTF-8 characters) of byte `at`. */
static void line_col(const jc *c, size_t at, int *line, int *col)
{
    int l = 1, k = 1;
    for (size_t i = 0; i < at && i < c->n; i++) {
        if (c->s[i] == '\n')
            l++, k = 1;
        else if (((unsigned char)c->s[i] & 0xC0) != 0x80)
            k++;
    }
    *line = l;
    *col = k;
}

static int fail(jc *c, size_t at, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

static int fail(jc *c, size_t at, const char *fmt, ...)
{
    char what[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    int line, col;
    line_col(c, at, &line, &col);
    return fr_fail(c->err, "%s:%d:%d: %s", c->file, line, col, what);
}

/* "'x'" for a printable character at byte at, "byte 0xNN" otherwise, or
 * "the end of the text". */
static const char *show(const jc *c, size_t at, char buf[16])
{
    if (at >= c->n)
        return "the end of the text";
    unsigned char ch = (unsigned char)c->s[at];
    if (ch >= 0x20 && ch < 0x7f)
        snprintf(buf, 16, "'%c'", ch);
    else
        snprintf(buf, 16, "byte 0x%02x", ch);
    return buf;
}

static void skip_ws(jc *c)
{
    while (c->i < c->n && (c->s[c->i] == ' ' || c->s[c->i] == '\t' || c->s[c->i] == '\n' || c->s[c->i] == '\r'))
        c->i++;
}

static int keep(jc *c, const char *bytes, size_t len)
{
    if (c->cap_names - c->n_names < len) {
        size_t cap = c->cap_names ? c->cap_names : 256;
        while (cap - c->n_names < len)
            cap *= 2;
        char *more = realloc(c->names, cap);
        if (!more)
            return -1;
        c->names = more;
        c->cap_names = cap;
    }
    memcpy(c->names + c->n_names, bytes, len);
    c->n_names += len;
    return 0;
}

static int hex4(const jc *c, size_t at, unsigned *out)
{
    unsigned v = 0;
    for (size_t k = 0; k < 4; k++) {
        if (at + k >= c->n)
            return -1;
        char h = c->s[at + k];
        int d = h >= '0' && h <= '9' ? h - '0' : h >= 'a' && h <= 'f' ? h - 'a' + 10 : h >= 'A' && h <= 'F' ? h - 'A' + 10 : -1;
        if (d < 0)
            return -1;
        v = v * 16 + (unsigned)d;
    }
    *out = v;
    return 0;
}

/* The string at c->i (its opening quote); with `decode`, its unescaped
 * UTF-8 bytes are appended to names. */
static int string(jc *c, int decode)
{
    size_t open = c->i++;
    for (;;) {
        if (c->i >= c->n) {
            int l, k;
            line_col(c, open, &l, &k);
            return fail(c, c->i, "unterminated string (it opens at %d:%d)", l, k);
        }
        unsigned char ch = (unsigned char)c->s[c->i];
        if (ch == '"') {
            c->i++;
            return 0;
        }
        if (ch == '\n' || ch == '\r') {
            int l, k;
            line_col(c, open, &l, &k);
            return fail(c, c->i, "unterminated string (it opens at %d:%d; a line break inside a string is written "
                        "\\n)", l, k);
        }
        if (ch < 0x20)
            return fail(c, c->i, "a control character (byte 0x%02x) in a string: write it as an escape such as \\t",
                        ch);
        if (ch != '\\') {
            if (decode && keep(c, (const char *)&ch, 1) < 0)
                return fail(c, c->i, "out of memory checking the JSON");
            c->i++;
            continue;
        }
        size_t esc = c->i++;
        char e = c->i < c->n ? c->s[c->i] : 0;
        const char *simple = strchr("\"\\/bfnrt", e);
        if (e && simple) {
            static const char out[] = "\"\\/\b\f\n\r\t";
            if (decode && keep(c, &out[simple - "\"\\/bfnrt"], 1) < 0)
                return fail(c, esc, "out of memory checking the JSON");
            c->i++;
            continue;
        }
        if (e != 'u')
            return fail(c, esc, "bad escape in a string (expected \\\" \\\\ \\/ \\b \\f \\n \\r \\t or \\uXXXX)");
        unsigned cp, lo;
        if (hex4(c, c->i + 1, &cp) < 0)
            return fail(c, esc, "bad \\u escape (expected four hexadecimal digits)");
        c->i += 5;
        if (cp >= 0xdc00 && cp <= 0xdfff)
            return fail(c, esc, "bad \\u escape: a low surrogate without a high one before it");
        if (cp >= 0xd800 && cp <= 0xdbff) {
            if (c->i + 1 >= c->n || c->s[c->i] != '\\' || c->s[c->i + 1] != 'u' || hex4(c, c->i + 2, &lo) < 0 ||
                lo < 0xdc00 || lo > 0xdfff)
                return fail(c, esc, "bad \\u escape: a high surrogate without a low one after it");
            c->i += 6;
            cp = 0x10000 + ((cp - 0xd800) << 10) + (lo - 0xdc00);
        }
        if (cp == 0)
            return fail(c, esc, "\\u0000 (a NUL character) in a string");
        char u[4];
        size_t nu = cp < 0x80 ? 1 : cp < 0x800 ? 2 : cp < 0x10000 ? 3 : 4;
        if (nu == 1) {
            u[0] = (char)cp;
        } else {
            for (size_t k = nu - 1; k > 0; k--, cp >>= 6)
                u[k] = (char)(0x80 | (cp & 0x3f));
            u[0] = (char)((nu == 2 ? 0xc0 : nu == 3 ? 0xe0 : 0xf0) | cp);
        }
        if (decode && keep(c, u, nu) < 0)
            return fail(c, esc, "out of memory checking the JSON");
    }
}

static int digits(jc *c)
{
    size_t start = c->i;
    while (c->i < c->n && c->s[c->i] >= '0' && c->s[c->i] <= '9')
        c->i++;
    return c->i > start ? 0 : -1;
}

static int number(jc *c)
{
    size_t start = c->i;
    if (c->s[c->i] == '-')
        c->i++;
    if (c->i < c->n && c->s[c->i] == '0') {
        c->i++;
        if (c->i < c->n && c->s[c->i] >= '0' && c->s[c->i] <= '9')
            return fail(c, start, "bad number: no leading zeros");
    } else if (digits(c) < 0) {
        return fail(c, start, "bad number: a digit must follow '-'");
    }
    if (c->i < c->n && c->s[c->i] == '.') {
        c->i++;
        if (digits(c) < 0)
            return fail(c, start, "bad number: a digit must follow '.'");
    }
    if (c->i < c->n && (c->s[c->i] == 'e' || c->s[c->i] == 'E')) {
        c->i++;
        if (c->i < c->n && (c->s[c->i] == '+' || c->s[c->i] == '-'))
            c->i++;
        if (digits(c) < 0)
            return fail(c, start, "bad number: a digit must follow the exponent's 'e'");
    }
    return 0;
}

/* Where the object reached by path[0 .. depth-1] is, for messages. */
static void path_text(const jc *c, int depth, char *out, size_t cap)
{
    if (depth == 0) {
        snprintf(out, cap, "the top-level object");
        return;
    }
    size_t n = 0;
    out[0] = 0;
    for (int k = 0; k < depth && n + 1 < cap; k++) {
        const step *p = &c->path[k];
        int w = p->is_member ? snprintf(out + n, cap - n, "%s%.*s", k ? "." : "", (int)(p->len > 60 ? 60 : p->len),
                                        c->s + p->at)
                             : snprintf(out + n, cap - n, "[%zu]", p->index);
        if (w < 0)
            break;
        n += (size_t)w;
    }
}

static int by_name(const void *a, const void *b, void *names)
{
    const member *x = a, *y = b;
    if (x->len != y->len)
        return x->len < y->len ? -1 : 1;
    int d = memcmp((const char *)names + x->name, (const char *)names + y->name, x->len);
    if (d)
        return d;
    return x->at < y->at ? -1 : x->at > y->at;
}

static int same_name(const jc *c, const member *a, const member *b)
{
    return a->len == b->len && !memcmp(c->names + a->name, c->names + b->name, a->len);
}

/* The members of the object closing now, mem[first ..]: sorted by name
 * and position, the second of each run of equal names is a duplicate;
 * the one earliest in the text is reported. */
static int no_duplicates(jc *c, size_t first)
{
    member *m = c->mem + first;
    size_t n = c->n_mem - first;
    if (n < 2)
        return 0;
    qsort_r(m, n, sizeof *m, by_name, c->names);
    const member *dup = NULL, *orig = NULL;
    for (size_t k = 1; k < n; k++)
        if (same_name(c, &m[k], &m[k - 1]) && (k == 1 || !same_name(c, &m[k - 1], &m[k - 2])) &&
            (!dup || m[k].at < dup->at))
            dup = &m[k], orig = &m[k - 1];
    if (!dup)
        return 0;
    char where[200];
    path_text(c, c->depth - 1, where, sizeof where);
    int l, k;
    line_col(c, orig->at, &l, &k);
    return fail(c, dup->at, "duplicate member \"%.*s\" in %s (first at %d:%d): each name may appear once",
                (int)(dup->len > 60 ? 60 : dup->len), c->names + dup->name, where, l, k);
}

static int value(jc *c);

static int object(jc *c)
{
    size_t open = c->i++;
    if (c->depth >= JC_MAX_DEPTH)
        return fail(c, open, "values nested deeper than %d levels", JC_MAX_DEPTH);
    c->depth++;
    size_t first = c->n_mem, names_mark = c->n_names;
    int l, k;
    char buf[16];
    skip_ws(c);
    if (c->i < c->n && c->s[c->i] == '}') {
        c->i++;
        c->depth--;
        return 0;
    }
    for (int after_comma = 0;; after_comma = 1) {
        skip_ws(c);
        if (c->i >= c->n || c->s[c->i] != '"') {
            line_col(c, open, &l, &k);
            if (after_comma && c->i < c->n && c->s[c->i] == '}')
                return fail(c, c->i, "a comma before '}' (JSON allows no trailing comma)");
            return fail(c, c->i, "expected a member name (a string in double quotes) in the object that opens at "
                        "%d:%d, found %s", l, k, show(c, c->i, buf));
        }
        size_t at = c->i, name = c->n_names;
        if (string(c, 1) < 0)
            return -1;
        if (c->n_mem == c->cap_mem) {
            size_t cap = c->cap_mem ? 2 * c->cap_mem : 64;
            member *more = realloc(c->mem, cap * sizeof *more);
            if (!more)
                return fail(c, at, "out of memory checking the JSON");
            c->mem = more;
            c->cap_mem = cap;
        }
        c->mem[c->n_mem++] = (member){name, c->n_names - name, at};
        c->path[c->depth - 1] = (step){1, at + 1, c->i - at - 2, 0};
        skip_ws(c);
        if (c->i >= c->n || c->s[c->i] != ':')
            return fail(c, c->i, "expected ':' after the member name, found %s", show(c, c->i, buf));
        c->i++;
        if (value(c) < 0)
            return -1;
        skip_ws(c);
        if (c->i < c->n && c->s[c->i] == ',') {
            c->i++;
            continue;
        }
        if (c->i < c->n && c->s[c->i] == '}') {
            c->i++;
            break;
        }
        line_col(c, open, &l, &k);
        return fail(c, c->i, "expected ',' or '}' after a member of the object that opens at %d:%d, found %s", l, k,
                    show(c, c->i, buf));
    }
    if (no_duplicates(c, first) < 0)
        return -1;
    c->n_mem = first;
    c->n_names = names_mark;
    c->depth--;
    return 0;
}

static int array(jc *c)
{
    size_t open = c->i++;
    if (c->depth >= JC_MAX_DEPTH)
        return fail(c, open, "values nested deeper than %d levels", JC_MAX_DEPTH);
    c->depth++;
    int l, k;
    char buf[16];
    skip_ws(c);
    if (c->i < c->n && c->s[c->i] == ']') {
        c->i++;
        c->depth--;
        return 0;
    }
    for (size_t index = 0;; index++) {
        c->path[c->depth - 1] = (step){0, 0, 0, index};
        if (value(c) < 0)
            return -1;
        skip_ws(c);
        if (c->i < c->n && c->s[c->i] == ',') {
            c->i++;
            skip_ws(c);
            if (c->i < c->n && c->s[c->i] == ']')
                return fail(c, c->i, "a comma before ']' (JSON allows no trailing comma)");
            continue;
        }
        if (c->i < c->n && c->s[c->i] == ']') {
            c->i++;
            break;
        }
        line_col(c, open, &l, &k);
        return fail(c, c->i, "expected ',' or ']' after an element of the array that opens at %d:%d, found %s", l,
                    k, show(c, c->i, buf));
    }
    c->depth--;
    return 0;
}

static int value(jc *c)
{
    skip_ws(c);
    char buf[16];
    if (c->i >= c->n)
        return fail(c, c->i, "expected a value, found the end of the text");
    char ch = c->s[c->i];
    if (ch == '{')
        return object(c);
    if (ch == '[')
        return array(c);
    if (ch == '"')
        return string(c, 0);
    if (ch == '-' || (ch >= '0' && ch <= '9'))
        return number(c);
    static const char *const words[] = {"true", "false", "null"};
    for (int w = 0; w < 3; w++) {
        size_t len = strlen(words[w]);
        if (c->n - c->i >= len && !memcmp(c->s + c->i, words[w], len)) {
            c->i += len;
            return 0;
        }
    }
    return fail(c, c->i, "expected a value (an object, array, string, number, true, false or null), found %s",
                show(c, c->i, buf));
}

int jc_check(const char *text, size_t len, const char *file, fr_error *err)
{
    jc c;
    memset(&c, 0, sizeof c);
    c.s = text;
    c.n = len;
    c.file = file;
    c.err = err;
    int rc = value(&c);
    if (rc == 0) {
        size_t end = c.i;
        skip_ws(&c);
        if (c.i < c.n) {
            int l, k;
            char buf[16];
            line_col(&c, end, &l, &k);
            rc = fail(&c, c.i, "%s after the end of the JSON value (which ends at %d:%d)", show(&c, c.i, buf), l, k);
        }
    }
    free(c.mem);
    free(c.names);
    return rc;
}
